//! What `static`, `modes` and `inspect` print for a person (their `--json`
//! is for machines): read off the same JSON value, so the two never
//! disagree.

use serde_json::Value;

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

/// A coordinate's family: its name without its segment, element or
/// coefficient indices (`bend_y_0_3` and `bend_y_1_c2` are `bend_y`).
fn family(name: &str) -> String {
    let index = |p: &str| {
        let digits = p.strip_prefix('c').unwrap_or(p);
        !digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit())
    };
    let kept: Vec<&str> = name.split('_').filter(|p| !index(p)).collect();
    kept.join("_")
}

/// The equilibrium: the tip, how well it holds, the largest coordinates.
pub fn statics(v: &Value) {
    let tip: Vec<f64> = v["tip_position"]
        .as_array()
        .map_or(vec![], |a| a.iter().map(num).collect());
    println!(
        "{}: static equilibrium at t = 0",
        v["model"].as_str().unwrap_or("model")
    );
    if tip.len() == 3 {
        println!(
            "  tip position     x {:.3} mm, y {:.3} mm, z {:.3} mm",
            1e3 * tip[0],
            1e3 * tip[1],
            1e3 * tip[2]
        );
    }
    let plural = |v: &Value, one: &str| match v.as_u64() {
        Some(1) => format!("1 {one}"),
        _ => format!("{v} {one}s"),
    };
    println!(
        "  residual         {:.2e} after {} in {}",
        num(&v["residual"]),
        plural(&v["iterations"], "Newton iteration"),
        plural(&v["load_steps"], "load step")
    );
    if let Some(f) = v["base_force"].as_array() {
        let f: Vec<f64> = f.iter().map(num).collect();
        println!(
            "  base force       [{:.4}, {:.4}, {:.4}] N",
            f[0], f[1], f[2]
        );
    }
    let (Some(names), Some(q)) = (v["coordinates"].as_array(), v["q"].as_array()) else {
        return;
    };
    // The largest of each family of coordinates (bend, twist, stretch,
    // ...): magnitudes compare within a family, whose unit is one.
    let mut largest: Vec<(String, &str, f64)> = Vec::new();
    for (n, q) in names.iter().zip(q) {
        let (name, q) = (n.as_str().unwrap_or("?"), num(q));
        let f = family(name);
        match largest.iter_mut().find(|(g, ..)| *g == f) {
            Some(e) if q.abs() > e.2.abs() => *e = (f, name, q),
            Some(_) => {}
            None => largest.push((f, name, q)),
        }
    }
    println!(
        "  largest coordinate of each kind (of {}; in trajectory.csv's units):",
        names.len()
    );
    for (_, name, q) in &largest {
        println!("    {name:<24} {q:>12.5e}");
    }
    println!("  (--json: every coordinate, the joints' forces and the shape)");
}

/// The natural frequencies with the kind of each mode.
pub fn modes(v: &Value) {
    println!(
        "{}: natural frequencies about the static equilibrium",
        v["model"].as_str().unwrap_or("model")
    );
    println!(
        "  {:>4}  {:>12}  {:<12} share of its kinetic energy",
        "mode", "frequency", "kind"
    );
    let kinds = v["kinds"].as_array();
    for (i, f) in v["frequencies_hz"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
    {
        let kind = kinds.and_then(|k| k.get(i));
        println!(
            "  {:>4}  {:>9.3} Hz  {:<12} {:.0} %",
            i + 1,
            num(f),
            kind.and_then(|k| k["kind"].as_str()).unwrap_or("?"),
            100.0 * kind.map_or(f64::NAN, |k| num(&k["share"]))
        );
    }
    println!("  (--json: the same, --shapes: with the mode shapes)");
}

/// The stiffness verdict and what it means for the choice of solver.
pub fn inspect(v: &Value) {
    println!(
        "{}: stiffness at the static equilibrium",
        v["model"].as_str().unwrap_or("model")
    );
    let ratio = num(&v["stiffness_ratio"]);
    println!(
        "  stiffness ratio       {ratio:.3e} ({})",
        v["class"].as_str().unwrap_or("?")
    );
    println!(
        "  fastest time scale    {:.3e} s (an explicit method's stable step: about {:.3e} s)",
        num(&v["fastest_time_scale_s"]),
        num(&v["stable_explicit_step_s"])
    );
    println!(
        "  fastest damping ratio {:.3}",
        num(&v["fastest_damping_ratio"])
    );
    println!(
        "  recommended solver    {}",
        v["recommended_solver"].as_str().unwrap_or("?")
    );
    println!("  why: {}", v["reason"].as_str().unwrap_or(""));
    println!(
        "  (a ratio above 1000 makes explicit methods take steps far shorter than the motion needs; \
         `--solver auto`, the default, acts on this verdict. --json: the eigenvalues)"
    );
}
