//! Embed every robot file of the crate's `models/` folder, so `builtin::load(name)` works from Rust, from
//! Python and from the command line without locating data files at run time.
//!
//! The folder lives inside the crate (not beside the workspace) so that `cargo package` ships it; a missing
//! or empty folder is a broken checkout and fails the build instead of producing an engine with no robots.

use std::{env, fs, path::Path, process};

fn fail(msg: &str) -> ! {
    eprintln!("error: freefloat-core build: {msg}");
    process::exit(1);
}

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    println!("cargo:rerun-if-changed={}", dir.display());
    let rd = fs::read_dir(&dir).unwrap_or_else(|e| {
        fail(&format!(
            "cannot read the built-in model folder {} ({e}); it holds the robot YAML files the engine embeds \
             (restore it from the repository)",
            dir.display()
        ))
    });
    let mut entries: Vec<(String, String)> = vec![];
    for e in rd {
        let p = e.unwrap_or_else(|e| fail(&format!("cannot list {}: {e}", dir.display()))).path();
        if p.extension().and_then(|s| s.to_str()) != Some("yaml") {
            continue;
        }
        println!("cargo:rerun-if-changed={}", p.display());
        let name = p
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_else(|| fail(&format!("model file name {} is not UTF-8", p.display())))
            .to_string();
        let abs = p.canonicalize().unwrap_or_else(|e| fail(&format!("cannot resolve {}: {e}", p.display())));
        entries.push((name, abs.display().to_string()));
    }
    if entries.is_empty() {
        fail(&format!("the built-in model folder {} holds no .yaml robot files", dir.display()));
    }
    entries.sort();
    let mut code = String::from(
        "/// Built-in robots: (name, YAML text), sorted by name.\npub static MODELS: &[(&str, &str)] = &[\n",
    );
    for (name, path) in entries {
        code.push_str(&format!("    ({name:?}, include_str!({path:?})),\n"));
    }
    code.push_str("];\n");
    let out = Path::new(&env::var("OUT_DIR").unwrap_or_else(|_| fail("OUT_DIR not set (run through cargo)")))
        .join("builtin_models.rs");
    fs::write(&out, code).unwrap_or_else(|e| fail(&format!("cannot write {}: {e}", out.display())));
}
