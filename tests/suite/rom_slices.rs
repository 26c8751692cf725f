//! rom integrates its strain fields along the rod slice by slice, each
//! slice by the commutator-free Magnus method of order four (two
//! constant-strain half-arcs, `RomFields::halves`): the pose error falls
//! as slices^-4. The reference is that law: the static tip of `rom_arm`
//! under a large 3D tip load at 4, 8, 16 and 32 slices, whose successive
//! differences must shrink sixteen-fold (one arc of the slice's mean
//! strain, the scheme before, shrinks them four-fold).

use crate::common::*;

fn tip(slices: usize) -> [f64; 3] {
    let dir = tempfile::tempdir().unwrap();
    let quadrature = format!("segment.0.quadrature={slices}");
    let args = [
        "static",
        "rom_arm",
        "--set",
        &quadrature,
        "--set",
        "tip.force=[0.5,0.3,-1.0]",
        "--shape-points",
        "0",
        "--json",
    ];
    let o = softarm(&args, dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    std::array::from_fn(|c| v["tip_position"][c].as_f64().unwrap())
}

#[test]
fn rom_slices_converge_at_fourth_order() {
    let tips: Vec<[f64; 3]> = [4, 8, 16, 32].into_iter().map(tip).collect();
    let gap = |a: &[f64; 3], b: &[f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let gaps: Vec<f64> = tips.windows(2).map(|w| gap(&w[0], &w[1])).collect();
    eprintln!("successive tip differences (m): {gaps:?}");
    // The load bends the rod well past small deflection: the slicing
    // matters.
    assert!(gaps[0] > 1e-7, "{gaps:?}");
    for w in gaps.windows(2) {
        let ratio = w[0] / w[1];
        assert!((11.0..24.0).contains(&ratio), "ratio {ratio} of {gaps:?}");
    }
}
