//! eomgen's tests, one binary linking the library as built for the rest of
//! the workspace: a unit-test harness would compile the whole generator a
//! second time (at opt-level 3, about as long as the library itself). A
//! module per part of the generator, each against an independent reference.

mod atomic_write;
mod cas;
mod composite_sums;
mod fuse;
mod load;
mod parse_fuzz;
mod profile;
mod rest;
mod rom;
mod schema;
mod solve;
mod spatial;
mod suggest;
mod values;
