//! Four lanes at once give what four scalar calls give (`lanes`).

use runtime_kernels::lanes::*;
use runtime_kernels::rodrigues::{self, FAMILY_J};

/// Four arguments in lanes give the bits of four scalar calls, when
/// the lanes share a branch and when they do not.
#[test]
fn family_in_lanes_has_the_bits_of_the_scalar_family() {
    if !(is_x86_feature_detected!("avx") && is_x86_feature_detected!("fma")) {
        return;
    }
    let groups = [
        [0.0, 1e-9, -0.3, 0.97],
        [1.0, -2.5, 8.9, 4.0],
        [0.5, 3.0, -20.0, 120.0],
        [-1e-300, 0.999_999, 1.000_001, -8.999],
    ];
    for w in groups {
        // SAFETY: AVX and FMA are available (checked above).
        let lanes = unsafe { family_x4::<3>(from_array(w)) };
        for (l, &wl) in w.iter().enumerate() {
            let scalar = rodrigues::family::<3>(wl);
            for j in 0..FAMILY_J {
                for n in 0..3 {
                    let got = to_array(lanes[j][n])[l];
                    assert_eq!(
                        got.to_bits(),
                        scalar[j][n].to_bits(),
                        "w {wl} c_{j} order {n}"
                    );
                }
            }
        }
    }
}
