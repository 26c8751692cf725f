//! softarm's integration tests, one binary (one link of the compiled-in
//! models, not one a file): a module per concern. Long checks beyond the
//! default run are `#[ignore]`d and run by `.ci/run`'s own step
//! (`cargo test --workspace -- --ignored`).

mod common;

mod actuation;
mod animate;
mod architecture;
mod backends;
mod bad_input;
mod contact;
mod cosserat_transient;
mod double_pendulum;
mod energy;
mod events;
mod export_c;
mod failures;
mod fit;
mod fluid;
mod generated;
mod integrators;
mod interrupted;
mod jacobian;
mod joints;
mod kink;
mod linearize;
mod loads;
mod long_arm;
mod moving_base;
mod output_dir;
mod parsers;
mod pcc;
mod relaxation;
mod rest_shape;
mod rom_slices;
mod section;
mod shape;
mod six_strains;
mod spatial;
mod streamed;
mod sweep;
mod taper;
mod tree;
mod unchanged;
