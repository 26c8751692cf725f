//! Rectangular and elliptic sections (`[segment.section]`) against beam
//! theory: a planar arm bends by M / (E I_z) with I_z = w h^3 / 12 (a
//! rectangle) or pi w h^3 / 64 (an ellipse), h its side in the plane; it
//! sags under its own weight by q L^4 / (8 E I) with q = rho A g; a square
//! twists by M L / (G J), J St-Venant's 0.1406 a^4 (the series solution).

use std::f64::consts::PI;

use crate::common::*;

const L: f64 = 0.2;
const E: f64 = 1e6;
const RHO: f64 = 1000.0;

fn arm(dimensions: u8, section: &str, elements: usize, extra: &str) -> String {
    format!(
        r#"
name = "sectioned"
dimensions = {dimensions}
gravity = [0.0, 0.0, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = {L}
elements = {elements}
density = {RHO}
youngs_modulus = {E}
section = {section}
{extra}
"#
    )
}

#[test]
fn a_planar_arm_bends_by_its_sections_second_moment_in_the_plane() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h): (f64, f64) = (0.02, 0.006);
    let m = 1e-4;
    let moment = format!("[tip]\nmoment = [0.0, 0.0, {m}]");
    for (shape, iz) in [
        ("rectangle", w * h.powi(3) / 12.0),
        ("ellipse", PI * w * h.powi(3) / 64.0),
    ] {
        let section = format!("{{ shape = \"{shape}\", width = {w}, height = {h} }}");
        let tip = static_tip(dir.path(), &arm(2, &section, 1, &moment), &[]);
        let theta = m * L / (E * iz);
        let want = [L * theta.sin() / theta, L * (1.0 - theta.cos()) / theta];
        for c in 0..2 {
            assert_close(
                tip[c],
                want[c],
                1e-9,
                L,
                format_args!("{shape}, component {c}"),
            );
        }
    }
    // Its own weight, in the plane: q = rho w h g.
    let g = 9.81e-3;
    let section = format!("{{ shape = \"rectangle\", width = {w}, height = {h} }}");
    let want = RHO * w * h * g * L.powi(4) / (8.0 * E * w * h.powi(3) / 12.0);
    let err = |n| {
        let text = arm(2, &section, n, "").replace("[0.0, 0.0, 0.0]", &format!("[0.0, -{g}, 0.0]"));
        (-static_tip(dir.path(), &text, &[])[1] - want) / want
    };
    let (coarse, fine) = (err(8), err(16));
    assert!(
        fine.abs() < 3e-3 && fine.abs() * 3.5 < coarse.abs(),
        "its own weight: {coarse:.2e} at 8 elements, {fine:.2e} at 16"
    );
}

#[test]
fn a_square_twists_by_st_venants_torsion_constant() {
    let dir = tempfile::tempdir().unwrap();
    let a: f64 = 0.01;
    let m = 1e-4;
    let section = format!("{{ shape = \"rectangle\", width = {a}, height = {a} }}");
    let text = arm(3, &section, 4, &format!("[tip]\nmoment = [{m}, 0.0, 0.0]"));
    let mut l = load_text(dir.path(), &text, &[]);
    let n = l.arm.dof();
    let sol = runtime::solve_static(
        &mut *l.arm,
        &vec![0.0; n],
        &runtime::StaticOptions::default(),
    )
    .unwrap();
    let names = &l.arm.info().coordinates;
    let twist: f64 = (names.iter().zip(&sol.q))
        .filter(|(n, _)| n.starts_with("twist"))
        .map(|(_, q)| q)
        .sum();
    // J of a square by the series solution (Timoshenko and Goodier).
    let want = m * L / (E / 3.0 * 0.140577 * a.powi(4));
    assert_close(twist, want, 3e-3, 0.0, "the square's twist");
}

/// A rectangular cantilever in 3D (w = 20 mm along z, h = 6 mm along y:
/// E I_y = 11.1 E I_z) bends at the Rayleigh beam's first two frequencies
/// about each of its axes, E I_z = E w h^3 / 12 with rho I_z = rho w h^3 /
/// 12 and E I_y = E h w^3 / 12 with rho I_y, by every 3D method. Each
/// reference frequency is met by one of the arm's, within the method's
/// discretisation error at this resolution; an arm bending alike about
/// both axes misses two of the four by a factor of 3.3.
fn rectangular_cantilever_frequencies(methods: &[(&str, usize, f64)]) {
    let dir = tempfile::tempdir().unwrap();
    let (w, h): (f64, f64) = (0.02, 0.006);
    let section = format!("{{ shape = \"rectangle\", width = {w}, height = {h} }}");
    let rho_a = RHO * w * h;
    let mut want: Vec<f64> = Vec::new();
    for i in [w * h.powi(3) / 12.0, h * w.powi(3) / 12.0] {
        want.extend(rayleigh_beam_hz::<2>(E * i, rho_a, RHO * i, L));
    }
    for &(method, n, tol) in methods {
        let mut sets = method_sets(method, n);
        match method {
            "rom" => sets.push("segment.0.order=5".into()),
            // The Rayleigh beam does not shear: a stiff shear modulus
            // leaves pcs and eba their bending alone (at G = E / 3 the
            // wide side's second mode, L / w = 10, is 3 % lower, as
            // Timoshenko's beam has it).
            "pcs" | "eba" => sets.push(format!("segment.0.shear_modulus={}", 1e3 * E)),
            _ => {}
        }
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let l = load_text(dir.path(), &arm(3, &section, 1, ""), &sets);
        let dof = l.arm.dof();
        let got = runtime::modes(&*l.arm, &vec![0.0; dof])
            .unwrap()
            .frequencies_hz;
        for (k, f) in want.iter().enumerate() {
            let nearest = got
                .iter()
                .map(|g| (g - f).abs() / f)
                .fold(f64::INFINITY, f64::min);
            eprintln!("{method}: mode {k} ({f:.5} Hz) within {nearest:.2e}");
            assert!(
                nearest < tol,
                "{method}: no frequency within {tol} of {f} Hz (nearest {nearest:.2e}): {got:?}"
            );
        }
    }
}

#[test]
fn a_rectangular_cantilever_bends_at_each_axis_frequencies_by_the_arc_methods() {
    rectangular_cantilever_frequencies(&[
        ("pcc", 20, 5e-3),
        ("vc", 20, 5e-3),
        ("pcs", 20, 5e-3),
        ("rom", 8, 1e-4),
    ]);
}

#[test]
fn a_rectangular_cantilever_bends_at_each_axis_frequencies_by_the_jointed_methods() {
    rectangular_cantilever_frequencies(&[
        ("ebr", 20, 3e-3),
        ("eba", 20, 6e-3),
        ("rigid", 40, 1e-3),
    ]);
}

/// The Cosserat rod of a rectangular section bends under a small tip force
/// along y by F L^3 / (3 E I_z) and along z by F L^3 / (3 E I_y), and with
/// `shear = true` by the shear's F L / (G A) more (k = 1, G = E / 3: 0.75 %
/// of the bend along z); pcc, which does not shear, by the first alone.
#[test]
fn a_rectangular_rod_deflects_under_a_tip_force_by_each_axis_stiffness() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h): (f64, f64) = (0.02, 0.006);
    let section = format!("{{ shape = \"rectangle\", width = {w}, height = {h} }}");
    let (iz, iy) = (w * h.powi(3) / 12.0, h * w.powi(3) / 12.0);
    let f = 1e-5;
    for (axis, i) in [(1, iz), (2, iy)] {
        let mut force = [0.0; 3];
        force[axis] = f;
        let text = arm(3, &section, 1, &format!("[tip]\nforce = {force:?}"));
        let bend = f * L.powi(3) / (3.0 * E * i);
        let shear = f * L / (E / 3.0 * w * h);
        let cosserat = "segment.0.method=cosserat".to_string();
        let rod = static_tip(dir.path(), &text, std::slice::from_ref(&cosserat));
        assert_close(
            rod[axis],
            bend,
            1e-5,
            0.0,
            format_args!("the rod along {axis}"),
        );
        let shearing = [cosserat, "segment.0.shear=true".into()];
        let rod = static_tip(dir.path(), &text, &shearing);
        let what = format!("the shearing rod along {axis}");
        assert_close(rod[axis], bend + shear, 1e-5, 0.0, &what);
        let pcc = static_tip(dir.path(), &text, &method_sets("pcc", 16));
        assert_close(pcc[axis], bend, 1e-3, 0.0, format_args!("pcc along {axis}"));
    }
}

/// A section given by its properties (E A, k G A, E I_y, E I_z, G J, rho A,
/// rho I_y, rho I_z) moves as the rectangle whose values they are: the same
/// frequencies to 1e-9. Given a polar inertia rho J twice I_y + I_z, its
/// twist modes (and only they) drop by sqrt(2), as sqrt(G J / rho J) says.
#[test]
fn a_section_given_by_its_properties_moves_as_the_shape_it_describes() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h): (f64, f64) = (0.02, 0.006);
    let shape = SectionShapeValues::rectangle(w, h);
    let rect = format!("{{ shape = \"rectangle\", width = {w}, height = {h} }}");
    let frequencies = |text: &str| {
        let l = load_text(dir.path(), text, &["segment.0.elements=6"]);
        let dof = l.arm.dof();
        runtime::modes(&*l.arm, &vec![0.0; dof])
            .unwrap()
            .frequencies_hz
    };
    let want = frequencies(&arm(3, &rect, 1, ""));
    let given = |rho_j: f64| {
        let section = format!(
            "{{ shape = \"properties\", axial_stiffness = {}, bending_stiffness = [{}, {}], torsional_stiffness = {}, mass_per_length = {}, rotary_inertia = [{}, {}], polar_inertia = {rho_j} }}",
            E * w * h,
            E * shape.i[0],
            E * shape.i[1],
            E / 3.0 * shape.j,
            RHO * w * h,
            RHO * shape.i[0],
            RHO * shape.i[1],
        );
        arm(3, &section, 1, "")
            .replace(&format!("density = {RHO}\n"), "")
            .replace(&format!("youngs_modulus = {E}\n"), "")
    };
    let polar = RHO * (shape.i[0] + shape.i[1]);
    let got = frequencies(&given(polar));
    assert_eq!(got.len(), want.len());
    for (g, f) in got.iter().zip(&want) {
        assert_close(*g, *f, 1e-9, 0.0, "the properties of the rectangle");
    }
    let heavier = frequencies(&given(2.0 * polar));
    let (mut same, mut slower) = (0, 0);
    for f in &want {
        let near = |x: f64| heavier.iter().any(|g| (g - x).abs() < 1e-9 * x);
        if near(*f) {
            same += 1
        } else if near(f / 2f64.sqrt()) {
            slower += 1
        } else {
            panic!("{f} Hz is neither kept nor slowed by sqrt(2): {heavier:?}");
        }
    }
    // Six elements: six twist modes.
    assert_eq!((same, slower), (want.len() - 6, 6), "{want:?}\n{heavier:?}");
}

/// A rectangle's second moments [I_y, I_z] and St-Venant J by Roark's
/// formula, as the model's section computes them.
struct SectionShapeValues {
    i: [f64; 2],
    j: f64,
}

impl SectionShapeValues {
    fn rectangle(w: f64, h: f64) -> Self {
        let (a, b) = (w.max(h), w.min(h));
        let r = b / a;
        Self {
            i: [h * w.powi(3) / 12.0, w * h.powi(3) / 12.0],
            j: a * b.powi(3) * (1.0 / 3.0 - 0.21 * r * (1.0 - r.powi(4) / 12.0)),
        }
    }
}

/// A section given by its properties may shear more stiffly along one axis
/// (`shear_stiffness = [k G A_y, k G A_z]`). A small tip force along y, then
/// along z: the tip moves by bending plus Timoshenko's F L / (k G A) along
/// the force, so swapping the two shear stiffnesses moves it by
/// F L (1 / a - 1 / b) along y and the opposite along z, exactly for every
/// shearing method (the bending part cancels), to the small load's
/// nonlinearity.
#[test]
fn a_properties_section_shears_by_its_own_stiffness_along_each_axis() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (4.0, 12.0);
    let ei = E * PI * 0.01f64.powi(4) / 4.0;
    let f = 1e-4;
    let section = |ga: [f64; 2]| {
        format!(
            "{{ shape = \"properties\", axial_stiffness = 300.0, shear_stiffness = {ga:?}, bending_stiffness = [{ei}, {ei}], torsional_stiffness = {}, mass_per_length = 0.3, rotary_inertia = [1e-5, 1e-5] }}",
            ei / 1.5
        )
    };
    let text = |ga: [f64; 2], force: [f64; 3]| {
        arm(3, &section(ga), 4, &format!("[tip]\nforce = {force:?}"))
            .replace(&format!("density = {RHO}\n"), "")
            .replace(&format!("youngs_modulus = {E}\n"), "")
    };
    let want = f * L * (1.0 / a - 1.0 / b);
    let cases: [(&str, &[&str]); 5] = [
        ("pcs", &[]),
        ("pcc", &["segment.0.shear=true"]),
        ("rom", &["segment.0.shear=true", "segment.0.extension=true"]),
        ("eba", &[]),
        (
            "cosserat",
            &["segment.0.shear=true", "segment.0.extension=true"],
        ),
    ];
    for (method, keys) in cases {
        let mut sets = vec![format!("segment.0.method={method}")];
        sets.extend(keys.iter().map(|k| k.to_string()));
        for (axis, sign) in [(1, 1.0), (2, -1.0)] {
            let mut force = [0.0; 3];
            force[axis] = f;
            let tip = |ga| static_tip(dir.path(), &text(ga, force), &sets)[axis];
            let got = tip([a, b]) - tip([b, a]);
            assert_close(
                got,
                sign * want,
                1e-4,
                0.0,
                format_args!("{method} along {axis}"),
            );
        }
    }
}
