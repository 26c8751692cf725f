//! rom in the Legendre basis spans the same strain fields as the monomial
//! basis it replaced (issue 24): the static tip and the natural
//! frequencies are those the monomial code gave (commit 07dc388, `softarm
//! static rom_arm --json` and `softarm modes rom_arm --json`, with and
//! without a tip load), a reference from another basis of the same model.

mod common;

use common::*;

fn json(args: &[&str]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let o = softarm(args, dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_str(&stdout(&o)).unwrap()
}

#[test]
fn the_legendre_rom_has_the_monomial_roms_equilibria_and_frequencies() {
    let length = 0.3;
    let cases: [(&[&str], [f64; 3]); 2] = [
        (&[], [0.191654603937708, 0.0, -0.2138672078744206]),
        (
            &["--set", "tip.force=[0.5,0.3,-1.0]"],
            [
                0.16770269705759852,
                0.04954466543718243,
                -0.22803373093808504,
            ],
        ),
    ];
    for (sets, monomial) in cases {
        let mut args = vec!["static", "rom_arm", "--shape-points", "0", "--json"];
        args.extend(sets);
        let v = json(&args);
        for (c, m) in monomial.iter().enumerate() {
            let tip = v["tip_position"][c].as_f64().unwrap();
            assert!((tip - m).abs() < 1e-9 * length, "tip {c}: {tip} vs {m}");
        }
    }
    let monomial_hz = [
        1.3280367441255136,
        1.4354584062382436,
        6.108036214444954,
        6.463646605475901,
    ];
    let v = json(&["modes", "rom_arm", "--json"]);
    for (k, m) in monomial_hz.iter().enumerate() {
        let f = v["frequencies_hz"][k].as_f64().unwrap();
        assert_close(f, *m, 1e-9, 0.0, &format!("f{}", k + 1));
    }
}
