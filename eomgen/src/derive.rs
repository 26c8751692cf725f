//! Model -> tapes: kinematics, TMT assembly, lowering.

use runtime::{ModelInfo, TapeSet};

use crate::cas::Cas;
use crate::model::{Model, Structure, parameters};
use crate::tmt::{assemble, planar_system};

/// Derive the kernels of a model's structure.
pub fn derive(model: &Model) -> TapeSet {
    let mut cas = Cas::new();
    let sys = planar_system(&mut cas, model);
    let eq = assemble(&mut cas, &sys);
    let mut mass_bias = eq.mass_upper.clone();
    mass_bias.extend_from_slice(&eq.bias);
    TapeSet {
        info: ModelInfo {
            hash: Structure::of(model).hash(),
            coordinates: sys.coords.names.clone(),
            parameters: parameters(model).into_iter().map(|(n, _)| n).collect(),
        },
        mass: cas.to_tape(&eq.mass_upper),
        bias: cas.to_tape(&eq.bias),
        mass_bias: cas.to_tape(&mass_bias),
        outputs: cas.to_tape(&eq.outputs),
    }
}
