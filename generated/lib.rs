//! softarm's compiled-in models: one module per `models/<name>.toml`, each
//! the kernels eomgen emitted for its structure, and the registry `MODELS`.
//! Everything but this file and Cargo.toml is written by the top-level
//! `build.rs` (`eomgen::generate::sync`); `softarm derive --check` says
//! whether it is current.

// Generated code is formatted by prettyplease, not rustfmt: `cargo fmt`
// must leave it byte-identical to what `softarm derive --check` expects.
#[cfg(not(softarm_out_dir))]
#[rustfmt::skip]
#[path = "mod.rs"]
mod models;

#[cfg(softarm_out_dir)]
mod models {
    include!(concat!(env!("OUT_DIR"), "/generated/mod.rs"));
}

pub use models::*;
