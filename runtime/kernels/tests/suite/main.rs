//! The kernel layer's tests, one binary linking the library as built for
//! the rest of the workspace: a unit-test harness would compile the crate
//! a second time (at opt-level 3). A module per part, each against an
//! independent reference.

mod dual;
mod lanes;
mod linalg;
mod links;
mod obstacle;
mod output;
mod rodrigues;
mod rotation;
mod rows;
mod solver;
mod special;
mod tape;
mod tape_text;
