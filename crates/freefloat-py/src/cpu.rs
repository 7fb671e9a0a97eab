//! The CPU features the engine is compiled for (the baseline of `.cargo/config.toml`, or the builder's
//! RUSTFLAGS). Loaded on a processor without them, the engine would die of an illegal instruction in its first
//! computation, or already while Python initialises the module; so the list is also stored as a marker string in
//! the binary, which `freefloat/_cpu.py` reads from the file *before* importing it and compares with the
//! processor's features, failing the import with a clear message instead.

/// Comma-separated target features of this build (cargo's names, e.g. `avx2,fma,...`).
pub const FEATURES: &str = env!("FREEFLOAT_CPU_FEATURES");

/// The marker `freefloat/_cpu.py` searches for in the binary: `FREEFLOAT_CPU_FEATURES=<list>;`.
#[used]
pub static MARKER: &str = concat!("FREEFLOAT_CPU_FEATURES=", env!("FREEFLOAT_CPU_FEATURES"), ";");

/// The compiled features as a list (exposed as `_core.COMPILED_CPU_FEATURES`).
pub fn compiled_features() -> Vec<&'static str> {
    FEATURES.split(',').filter(|s| !s.is_empty()).collect()
}
