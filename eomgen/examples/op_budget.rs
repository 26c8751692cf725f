//! Where a model's mass + bias operations go: the kinematics level by level
//! (alone, and cumulative as the tape shares them), M alone, h alone, both,
//! and how many values the mass + bias tape keeps live on average (what a
//! compiled kernel has to hold in registers or spill).
//!
//! `cargo run --release -p eomgen --example op_budget -- models/tentacle3d.toml [KEY=VALUE ...]`
//!
//! The `KEY=VALUE` arguments are `--set` overrides, e.g.
//! `segment.0.method=rom segment.0.quadrature=8`.

use std::path::Path;

use eomgen::build::system;
use eomgen::cas::{Cas, ExprId, Hoist};
use eomgen::load::load_model;
use eomgen::model::{Override, ParamLayout, Structure};
use eomgen::tmt::assemble;
use runtime::Tape;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or("usage: op_budget MODEL.toml [KEY=VALUE ...]")?;
    let sets = args
        .map(|s| Override::parse(&s))
        .collect::<Result<Vec<_>, _>>()?;
    let model = load_model(Path::new(&path), &sets)?;
    let mut cas = Cas::new();
    let structure = Structure::of(&model);
    let layout = ParamLayout::of(&structure);
    let sys = system(&mut cas, &structure, &layout);
    let n_params = layout.len();
    let tape =
        |cas: &mut Cas, outs: &[ExprId]| cas.to_tape_hoisted(outs, &mut Hoist::new(n_params));

    let pairs = sys.coords.rate_pairs();
    let positions: Vec<ExprId> = sys.bodies.iter().flat_map(|b| b.position).collect();
    let omegas: Vec<ExprId> = sys.bodies.iter().flat_map(|b| b.omega).collect();
    let velocities = cas.kinematic_rates(&positions, &pairs);
    let accelerations = cas.kinematic_rates(&velocities, &pairs);
    let angular_accelerations = cas.kinematic_rates(&omegas, &pairs);
    let mut so_far = Vec::new();
    println!("{:<32} {:>8} {:>11}", "part", "alone", "cumulative");
    for (name, part) in [
        ("body positions", positions),
        ("body angular velocities", omegas),
        ("body velocities", velocities),
        ("convective accelerations", accelerations),
        ("convective angular accel.", angular_accelerations),
    ] {
        so_far.extend(part.iter().copied());
        let alone = tape(&mut cas, &part).op_count();
        let cumulative = tape(&mut cas, &so_far).op_count();
        println!("{name:<32} {alone:>8} {cumulative:>11}");
    }
    let eq = assemble(&mut cas, &sys);
    let mut both = eq.mass_upper.clone();
    both.extend_from_slice(&eq.bias);
    let mass_bias = tape(&mut cas, &both);
    println!(
        "{:<32} {:>8}",
        "M",
        tape(&mut cas, &eq.mass_upper).op_count()
    );
    println!("{:<32} {:>8}", "h", tape(&mut cas, &eq.bias).op_count());
    println!(
        "{:<32} {:>8}",
        "M + h (the MassBias kernel)",
        mass_bias.op_count()
    );
    let (mean, max) = live_values(&mass_bias);
    println!("values live across the M + h tape: mean {mean:.0}, max {max}");
    Ok(())
}

/// Mean and maximum over the tape's operations of how many computed values
/// are still to be read by a later operation.
fn live_values(tape: &Tape) -> (f64, usize) {
    let n = tape.ops.len();
    let mut last_use = vec![0; n];
    for (i, op) in tape.ops.iter().enumerate() {
        for a in op.operands() {
            last_use[a as usize] = i;
        }
    }
    let mut dying = vec![0usize; n];
    let (mut live, mut sum, mut max, mut count) = (0usize, 0usize, 0usize, 0usize);
    for (i, op) in tape.ops.iter().enumerate() {
        if op.is_leaf() {
            continue;
        }
        live -= dying[i];
        if last_use[i] > i {
            live += 1;
            dying[last_use[i]] += 1;
        }
        sum += live;
        max = max.max(live);
        count += 1;
    }
    (sum as f64 / count.max(1) as f64, max)
}
