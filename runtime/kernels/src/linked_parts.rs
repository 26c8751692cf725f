//! Compiled part kernels linked at run time: a system of parts (an eba
//! arm) whose element count no compiled-in model has sums the compiled
//! kernels of the same kinds of parts (`parts::CompiledPart`, found by
//! key), as `linked` does for link cells. A kind no compiled-in model has
//! runs on its tapes, as do the pose and the offsets (of the whole
//! model's parameters, once per call).

use std::cell::RefCell;

use crate::kernels::{KernelKind, Kernels, ModelInfo};
use crate::parts::{self, CompiledPart, LinkedParts, PartKernels, TapeParts};
use crate::tape::Inputs;

/// `MassBias`, `Jvp` and `Outputs` of a system of parts over linked
/// compiled part kernels; it has no other kernel (no symbolic solve, no
/// contact, no derived parameters).
pub struct LinkedPartKernels {
    info: ModelInfo,
    parts: PartKernels,
    compiled: Vec<Option<CompiledPart>>,
    slots: RefCell<Vec<f64>>,
}

impl LinkedPartKernels {
    /// `compiled[k]` is the compiled kernel of `parts.kernels[k]`, or None
    /// where no compiled-in model has it.
    pub fn new(info: ModelInfo, parts: PartKernels, compiled: Vec<Option<CompiledPart>>) -> Self {
        assert_eq!(compiled.len(), parts.kernels.len(), "one entry a kind");
        assert!(!info.accel && info.derived == 0 && info.contact_points == 0);
        Self {
            info,
            parts,
            compiled,
            slots: RefCell::new(Vec::new()),
        }
    }
}

impl Kernels for LinkedPartKernels {
    fn info(&self) -> &ModelInfo {
        &self.info
    }

    fn eval(&self, kind: KernelKind, inp: &Inputs, out: &mut [f64]) {
        let mut slots = self.slots.borrow_mut();
        let mut linked = LinkedParts {
            tapes: TapeParts {
                kernels: &self.parts,
                slots: std::mem::take(&mut *slots),
            },
            compiled: &self.compiled,
        };
        let layout = &self.parts.layout;
        match kind {
            KernelKind::MassBias => {
                parts::mass_bias(layout, &mut linked, inp.q, inp.qd, inp.p, out)
            }
            KernelKind::Outputs => parts::outputs(layout, &mut linked, inp.q, inp.qd, inp.p, out),
            KernelKind::Jvp => {
                // Absent accelerations and direction read as zeros, as
                // the compiled models read them.
                let zeros = vec![0.0; 2 * layout.dof];
                let inp = inp.zero_filled(&zeros);
                parts::jvp(
                    layout,
                    &mut linked,
                    inp.q,
                    inp.qd,
                    inp.qdd,
                    inp.dir,
                    inp.p,
                    out,
                )
            }
            _ => debug_assert!(out.is_empty(), "{kind:?} of a linked system of parts"),
        }
        *slots = linked.tapes.slots;
    }

    fn backend(&self) -> &'static str {
        "compiled"
    }
}
