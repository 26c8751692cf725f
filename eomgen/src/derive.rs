//! Model -> tapes: kinematics, TMT assembly, lowering.

use runtime::{ModelInfo, TapeSet};

use crate::cas::{Cas, Hoist};
use crate::model::{Model, Structure, drives, parameters};
use crate::tmt::{SYMBOLIC_SOLVE_MAX_DOF, assemble, link_chain, solve_accelerations, system};

/// Derive the kernels of a model's structure.
pub fn derive(model: &Model) -> TapeSet {
    let mut cas = Cas::new();
    let sys = system(&mut cas, model);
    let eq = assemble(&mut cas, &sys);
    let mut mass_bias = eq.mass_upper.clone();
    mass_bias.extend_from_slice(&eq.bias);
    let params: Vec<String> = parameters(model).into_iter().map(|(n, _)| n).collect();
    let driven: Vec<String> = drives(model).into_iter().map(|d| d.param).collect();
    let inputs = params
        .iter()
        .enumerate()
        .filter(|(_, n)| driven.contains(n))
        .map(|(i, _)| i);
    let mut hoist = Hoist::new(params.len()).with_inputs(inputs);
    let mass_bias = cas.to_tape_hoisted(&mass_bias, &mut hoist);
    let outputs = cas.to_tape_hoisted(&eq.outputs, &mut hoist);
    let n = eq.bias.len();
    // Chains the link recursion covers solve M qdd = -h at run time: their
    // compiled mass + bias and an L D L^T solve beat a generated symbolic
    // solve, whose unrolled code is past the instruction caches.
    let links = link_chain(model);
    let accel = n <= SYMBOLIC_SOLVE_MAX_DOF && links.is_none();
    let accel_tape = if accel {
        let (qdd, pivots) = solve_accelerations(&mut cas, &eq.mass_upper, &eq.bias);
        let outs: Vec<_> = qdd.into_iter().chain(pivots).collect();
        cas.to_tape_hoisted(&outs, &mut hoist)
    } else {
        runtime::Tape::default()
    };
    let stiffness = cas.to_tape_hoisted(&eq.stiffness, &mut hoist);
    let jvp = cas.to_tape_hoisted(&eq.jvp, &mut hoist);
    let loads = params
        .iter()
        .enumerate()
        .filter(|(_, n)| {
            n.starts_with("gravity.") || n.starts_with("tip.force.") || n.starts_with("tip.moment.")
        })
        .map(|(i, _)| i)
        .collect();
    let derived = hoist.finish(&mut cas);
    TapeSet {
        info: ModelInfo {
            hash: Structure::of(model).hash(),
            coordinates: sys.coords.names.clone(),
            parameters: params,
            derived: hoist.len(),
            accel,
            loads,
        },
        mass_bias,
        outputs,
        derived,
        accel: accel_tape,
        stiffness,
        jvp,
        links,
    }
}
