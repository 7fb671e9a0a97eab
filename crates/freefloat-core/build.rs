//! Embed every model file of the repository's `models/` folder, so `builtin::load(name)` works
//! from Rust, from Python and from the CLI without locating data files at run time.

use std::{env, fs, path::Path};

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut entries: Vec<(String, String)> = vec![];
    if let Ok(rd) = fs::read_dir(&dir) {
        for e in rd.flatten() {
            let p = e.path();
            if p.extension().and_then(|s| s.to_str()) == Some("yaml") {
                println!("cargo:rerun-if-changed={}", p.display());
                let name = p.file_stem().unwrap().to_string_lossy().to_string();
                entries.push((name, p.canonicalize().unwrap().display().to_string()));
            }
        }
    }
    entries.sort();
    let mut code = String::from("pub static MODELS: &[(&str, &str)] = &[\n");
    for (name, path) in entries {
        code.push_str(&format!("    ({name:?}, include_str!({path:?})),\n"));
    }
    code.push_str("];\n");
    fs::write(Path::new(&env::var("OUT_DIR").unwrap()).join("builtin_models.rs"), code).unwrap();
}
