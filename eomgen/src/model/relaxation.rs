//! Viscoelastic materials: a segment's relaxation as a Prony series of
//! standard linear solids. The modulus the segment declares is the
//! instantaneous one, E_0; a step strain held from t = 0 meets
//!
//!   E(t) = E_0 (1 - sum_k ratio_k (1 - exp(-t / time_k))),
//!
//! so the long-term modulus is E_0 (1 - sum_k ratio_k). Every stiffness of
//! the segment (bending, twist, stretch, shear, a rigid joint's spring)
//! relaxes alike. Not structural: the kernels are the elastic ones, and
//! the runtime carries each branch's relaxed force as extra states
//! (`runtime::relaxation`).

use serde::{Deserialize, Serialize};

/// One branch of the Prony series.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Relaxation {
    /// The share of the instantaneous modulus that relaxes, in (0, 1).
    pub ratio: f64,
    /// Its relaxation time (s).
    pub time: f64,
}
