//! Record the CPU features this engine is compiled for (cargo's `CARGO_CFG_TARGET_FEATURE`: the baseline of
//! `.cargo/config.toml` or the builder's RUSTFLAGS), for the import-time check in `freefloat/_cpu.py`.

fn main() {
    let features = std::env::var("CARGO_CFG_TARGET_FEATURE").unwrap_or_default();
    println!("cargo:rustc-env=FREEFLOAT_CPU_FEATURES={features}");
    println!("cargo:rerun-if-env-changed=CARGO_CFG_TARGET_FEATURE");
}
