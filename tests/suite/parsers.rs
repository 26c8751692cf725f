//! The command line's parsers under random input: `--vary` values, `--set`
//! overrides and whole argument lists give a result or a clear error,
//! never a panic or an abort.

use proptest::prelude::*;

use crate::common::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn a_vary_spec_parses_or_is_refused(s in ".{0,60}") {
        if let Ok(v) = softarm::grid::Vary::parse(&s) {
            prop_assert!(!v.values.is_empty());
            prop_assert!(v.values.len() <= softarm::grid::MAX_VALUES.max(s.len()));
            prop_assert!(v.values.iter().all(|x| !x.is_empty()));
        }
    }

    #[test]
    fn a_range_is_bounded_before_it_is_expanded(
        kind in prop::sample::select(vec!["lin", "log", "lim", ""]),
        a in prop::num::f64::ANY,
        b in prop::num::f64::ANY,
        n in prop::num::u64::ANY,
    ) {
        let s = format!("tip.mass={kind}:{a}:{b}:{n}");
        if let Ok(v) = softarm::grid::Vary::parse(&s) {
            prop_assert!(v.values.len() <= softarm::grid::MAX_VALUES);
        }
    }

    #[test]
    fn a_set_override_parses_or_is_refused(s in ".{0,60}") {
        let _ = eomgen::model::Override::parse(&s);
    }
}

/// Words the CLI knows, and values of every kind, drawn at random.
const WORDS: &[&str] = &[
    "simulate",
    "static",
    "modes",
    "sweep",
    "inspect",
    "eom",
    "linearize",
    "animate",
    "chain",
    "double_pendulum",
    "--t-end",
    "--dt",
    "--output-dt",
    "--solver",
    "--rtol",
    "--atol",
    "--max-steps",
    "--q0",
    "--qd0",
    "--set",
    "--vary",
    "--shape-points",
    "--out",
    "--size",
    "--fps",
    "--speed",
    "--jobs",
    "--run",
    "--inputs",
    "--u0",
    "--q",
    "--qd",
    "--json",
    "--quiet",
    "--backend",
    "--yes",
    "0",
    "-1",
    "1e308",
    "nan",
    "inf",
    "1,2",
    "1,2,3,4,5",
    "radau5",
    "rk4",
    "tip.mass=1",
    "tip.mass=lin:0:1:3",
    "gravity=[0,0,0]",
    "=",
    "",
    "x=",
    "100000x100000",
    "o",
];

#[test]
fn random_command_lines_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = crate::common::Rng::new(7);
    for case in 0..60 {
        let len = 1 + (rng.next_f64() * 6.0) as usize;
        let mut args: Vec<&str> = (0..len)
            .map(|_| WORDS[(rng.next_f64() * WORDS.len() as f64) as usize % WORDS.len()])
            .collect();
        // Short runs: whatever else is drawn, a run ends quickly.
        args.extend(["--t-end", "0.05"]);
        let out = softarm(&args, dir.path());
        let err = stderr(&out);
        assert!(
            out.status.code().is_some_and(|c| c != 101) && !err.contains("panicked"),
            "case {case}: softarm {args:?} panicked: {err}"
        );
    }
}
