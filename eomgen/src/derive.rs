//! Model -> tapes: kinematics, TMT assembly, lowering.

use runtime::{ModelInfo, TapeSet};

use crate::cas::{Cas, Hoist};
use crate::model::{Model, ParamLayout, Structure};
use crate::tmt::{SYMBOLIC_SOLVE_MAX_DOF, assemble, link_chain, solve_accelerations, system};

/// Derive the kernels of a model's structure.
pub fn derive(model: &Model) -> TapeSet {
    derive_structure(&Structure::of(model))
}

/// Derive the kernels of a structure. Only the structure and its parameter
/// layout reach the derivation, so no model number can end up in a kernel.
pub fn derive_structure(structure: &Structure) -> TapeSet {
    let layout = ParamLayout::of(structure);
    let mut cas = Cas::new();
    let sys = system(&mut cas, structure, &layout);
    let eq = assemble(&mut cas, &sys);
    let mut mass_bias = eq.mass_upper.clone();
    mass_bias.extend_from_slice(&eq.bias);
    let inputs = layout.driven().iter().map(|d| layout.index(d.param));
    let mut hoist = Hoist::new(layout.len()).with_inputs(inputs);
    let mass_bias = cas.to_tape_hoisted(&mass_bias, &mut hoist);
    let outputs = cas.to_tape_hoisted(&eq.outputs, &mut hoist);
    let n = eq.bias.len();
    // Chains whose mass + bias the link recursion computes solve M qdd =
    // -h at run time: their compiled mass + bias and an L D L^T solve beat
    // a generated symbolic solve, whose unrolled code is past the
    // instruction caches.
    let links = link_chain(structure, &layout);
    let accel = n <= SYMBOLIC_SOLVE_MAX_DOF && !links.as_ref().is_some_and(|l| l.mass_bias);
    let accel_tape = if accel {
        let (qdd, pivots) = solve_accelerations(&mut cas, &eq.mass_upper, &eq.bias);
        let outs: Vec<_> = qdd.into_iter().chain(pivots).collect();
        cas.to_tape_hoisted(&outs, &mut hoist)
    } else {
        runtime::Tape::default()
    };
    let jvp = cas.to_tape_hoisted(&eq.jvp, &mut hoist);
    let derived = hoist.finish(&mut cas);
    TapeSet {
        info: ModelInfo {
            hash: structure.hash(),
            coordinates: sys.coords.names.clone(),
            parameters: layout.names(),
            derived: hoist.len(),
            accel,
            loads: layout.loads(),
        },
        mass_bias,
        outputs,
        derived,
        accel: accel_tape,
        jvp,
        parts: match links {
            None => crate::method::eba::part_kernels(structure, &layout),
            Some(_) => None,
        },
        links,
    }
}
