//! The rom method's Legendre fields and their slice integrals.

use eomgen::method::*;

#[test]
fn legendre_polynomials_and_their_slice_integrals() {
    for &y in &[-1.0f64, -0.3, 0.0, 0.7, 1.0] {
        let p = legendre(4, y);
        let closed = [
            1.0,
            y,
            0.5 * (3.0 * y * y - 1.0),
            0.5 * (5.0 * y * y * y - 3.0 * y),
            (35.0 * y.powi(4) - 30.0 * y * y + 3.0) / 8.0,
        ];
        for (a, b) in p.iter().zip(closed) {
            assert!((a - b).abs() < 1e-14, "{a} vs {b} at {y}");
        }
    }
    // Over the whole rod: int_0^1 P_i = 1 for i = 0, else 0 (to the
    // Gauss rule's h^4 past degree 3); and on
    // many slices, sum_e w_i w_j n approaches int P_i P_j = delta_ij /
    // (2 i + 1).
    let rom = RomFields {
        first: 0,
        order: 6,
        slices: 400,
        twist: false,
        extension: false,
        shear: false,
        incompressible: false,
        varying: false,
    };
    // Slices' Gram matrices sum to the whole's.
    let coarse = RomFields {
        slices: 3,
        ..rom.clone()
    };
    let grams: Vec<_> = (0..3).map(|e| coarse.slice_gram(e)).collect();
    for i in 0..=6 {
        for j in 0..=6 {
            let sum: f64 = grams.iter().map(|g| g[i][j]).sum();
            let exact = f64::from(u8::from(i == j)) / (2 * i + 1) as f64;
            assert!((sum - exact).abs() < 1e-14, "Gram {i} {j}: {sum}");
        }
    }
    // A slice's two halves turn by half their weights each: together the
    // two-point Gauss rule of the slice.
    let w: Vec<Vec<f64>> = (0..rom.slices)
        .map(|e| {
            let [a, b] = rom.halves(e);
            a.iter().zip(&b).map(|(a, b)| 0.5 * (a + b)).collect()
        })
        .collect();
    for i in 0..=6 {
        let total: f64 = w.iter().map(|we| we[i]).sum();
        assert!(
            (total - f64::from(u8::from(i == 0))).abs() < 1e-9,
            "int P_{i} = {total}"
        );
        for j in 0..=6 {
            let gram: f64 = w.iter().map(|we| we[i] * we[j]).sum::<f64>() * rom.slices as f64;
            let exact = if i == j {
                1.0 / (2 * i + 1) as f64
            } else {
                0.0
            };
            assert!((gram - exact).abs() < 1e-3, "Gram {i} {j}: {gram}");
        }
    }
}
