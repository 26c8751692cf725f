//! A section's area and second moments, chambers' holes included, against
//! grid integrals.

use eomgen::model::*;

/// The section of `seg` (outer radius `ro`, inner `ri`, its holes turned
/// by `turn` rad) by the midpoint rule on a fine grid over the square
/// around it: the area, the centroid (y, z), and the second moments
/// about y and z and the product moment, about the centroid.
fn grid_section(seg: &Segment, ro: f64, ri: f64, turn: f64) -> [f64; 6] {
    let c = seg.chambers.clone().unwrap();
    let n = 2000;
    let h = 2.0 * ro / n as f64;
    // Sums of 1, y, z, y^2, z^2, y z over the material.
    let mut m = [0.0f64; 6];
    for a in 0..n {
        for b in 0..n {
            let (y, z) = (-ro + (a as f64 + 0.5) * h, -ro + (b as f64 + 0.5) * h);
            let r2 = y * y + z * z;
            if r2 > ro * ro || r2 < ri * ri {
                continue;
            }
            let hole = c.hole_list().iter().any(|hole| {
                let phi = hole.angle.to_radians() + turn;
                let (cy, cz) = (c.offset() * phi.cos(), c.offset() * phi.sin());
                (y - cy).powi(2) + (z - cz).powi(2) < hole.radius * hole.radius
            });
            if !hole {
                for (k, v) in [1.0, y, z, y * y, z * z, y * z].iter().enumerate() {
                    m[k] += v * h * h;
                }
            }
        }
    }
    let area = m[0];
    let (yc, zc) = (m[1] / area, m[2] / area);
    [
        area,
        yc,
        zc,
        m[4] - area * zc * zc,
        m[3] - area * yc * yc,
        m[5] - area * yc * zc,
    ]
}

fn segment_with(chambers: &str, ri: f64) -> Segment {
    toml::from_str(&format!(
        r#"
        method = "pcc"
        length = 0.1
        outer_radius = 0.0125
        inner_radius = {ri}
        {chambers}
        "#
    ))
    .unwrap()
}

/// Holes of unequal radii: the area, the centroid (off the axis), the
/// second moments and the product moment about it, against a grid
/// integral of the section.
#[test]
fn chambers_of_unequal_radii_shape_the_section_as_a_grid_integral_says() {
    for chambers in [
        "chambers = { angles = [90, 270], radius = [0.003, 0.0015], distance = 0.007 }",
        "chambers = { angles = [0, 120, 240], radius = [0.002, 0.003, 0.0025], distance = 0.0075 }",
    ] {
        let seg = segment_with(chambers, 0.003);
        let [area, yc, zc, iy, iz, iyz] = grid_section(&seg, 0.0125, 0.003, 0.0);
        let a = seg.area().unwrap();
        assert!((a - area).abs() < 2e-3 * a, "area {a} vs grid {area}");
        let [cy, cz] = seg.centroid();
        let scale = 2e-3 * (yc.abs() + zc.abs());
        assert!(
            (cy - yc).abs() + (cz - zc).abs() < scale,
            "centroid {cy} {cz} vs {yc} {zc}"
        );
        let [sy, sz] = seg.second_moments().unwrap();
        assert!((sy - iy).abs() < 2e-3 * sy, "I_y {sy} vs grid {iy}");
        assert!((sz - iz).abs() < 2e-3 * sz, "I_z {sz} vs grid {iz}");
        let p = seg.product_moment();
        assert!((p - iyz).abs() < 2e-3 * sy, "I_yz {p} vs grid {iyz}");
    }
}

#[test]
fn chamber_holes_reduce_area_and_second_moment_as_a_grid_integral_says() {
    // Six equally spaced holes, and STIFF-FLOP's three pairs at +-20.33
    // degrees: both isotropic, each pattern also turned by 0.3 rad.
    for chambers in [
        "chambers = { count = 6, radius = 0.0018, distance = 0.007 }",
        "chambers = { angles = [0, 240, 120], pair_spacing = 20.33, radius = 0.0025, distance = 0.0085 }",
    ] {
        let seg = segment_with(chambers, 0.004);
        let [area, _, _, iy, iz, _] = grid_section(&seg, 0.0125, 0.004, 0.3);
        let (a, i) = (seg.area().unwrap(), seg.second_moment().unwrap());
        assert!((a - area).abs() < 2e-3 * a, "area {a} vs grid {area}");
        for grid in [iy, iz] {
            assert!((i - grid).abs() < 2e-3 * i, "I {i} vs grid {grid}");
        }
    }
}
