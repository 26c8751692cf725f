//! Solver names as model files and the CLI spell them (`solver`).

use runtime_kernels::solver::*;

#[test]
fn every_name_parses_to_the_solver_that_prints_it() {
    for name in Solver::NAMES {
        let s = Solver::parse(name).expect("listed names parse");
        assert_eq!(s.name(), name);
    }
    assert_eq!(Solver::parse("radau"), None);
}
