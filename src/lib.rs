//! softarm: declared soft robot arms to fast, specialised equations of motion.
//!
//! This crate is the CLI's library: the compiled-in models (`generated`),
//! choosing a backend for a model ([`backend`]) and the on-disk tape cache
//! ([`cache`]). The generator is `eomgen`; the numerics are in `runtime`.

// Generated code is formatted by prettyplease, not rustfmt: `cargo fmt`
// must leave it byte-identical to what `softarm derive --check` expects.
#[cfg(not(softarm_out_dir))]
#[rustfmt::skip]
#[path = "../generated/mod.rs"]
pub mod generated;

#[cfg(softarm_out_dir)]
pub mod generated {
    include!(concat!(env!("OUT_DIR"), "/generated/mod.rs"));
}

pub mod backend;
pub mod cache;
pub mod compare;
pub mod continuum;
pub mod data;
pub mod inputs;
