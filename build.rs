//! Keeps `generated/` in step with `models/` (docs/design.md section 1).
//!
//! A model whose structural hash matches its generated file is not
//! re-derived; files are rewritten only when their content changes. Set
//! SOFTARM_GENERATED_IN_OUT_DIR=1 to write into OUT_DIR instead of the
//! visible `generated/` folder (for packaged builds).

use std::path::PathBuf;

fn main() {
    // The build script of the generated crate: its manifest is
    // generated/Cargo.toml, the project root one folder up. Only models/
    // is watched: watching generated/, which this script writes, would mark
    // every run stale and compile the kernels twice per change (a hand edit
    // of generated/ is caught by `softarm derive --check` and the sync test).
    println!("cargo::rerun-if-changed=../models");
    println!("cargo::rerun-if-env-changed=SOFTARM_GENERATED_IN_OUT_DIR");
    println!("cargo::rustc-check-cfg=cfg(softarm_out_dir)");
    let manifest =
        PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let root = manifest
        .parent()
        .expect("generated/ has a parent")
        .to_path_buf();
    let in_out_dir =
        std::env::var_os("SOFTARM_GENERATED_IN_OUT_DIR").is_some_and(|v| !v.is_empty() && v != "0");
    let (out, opts) = if in_out_dir {
        let out =
            PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("generated");
        (
            out,
            eomgen::generate::SyncOptions {
                absolute_paths: true,
                ..Default::default()
            },
        )
    } else {
        (
            root.join("generated"),
            eomgen::generate::SyncOptions::default(),
        )
    };
    match eomgen::generate::sync(&root.join("models"), &out, &opts) {
        Ok(report) => {
            for name in report.derived {
                println!("cargo::warning=derived the equations of motion of models/{name}.toml");
            }
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
    if in_out_dir {
        println!("cargo::rustc-cfg=softarm_out_dir");
    }
}
