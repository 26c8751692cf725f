//! Viscoelastic materials: which elements relax, and how. Each relaxing
//! group of elements (a segment) carries,
//! for each branch k of its Prony series, its relaxed force r_k (n values,
//! one a coordinate) as extra first-order states after x = [q, qd]:
//!
//!   M qdd + h(q, qd) - sum_k r_k = 0,    time_k r_k' = ratio_k f_g(q) - r_k,
//!
//! with f_g(q) the group's elastic force, h(q, 0) less h(q, 0) with the
//! group's stiffnesses zeroed (every elastic term is linear in its
//! stiffness). A strain held from t = 0 then meets the force f_g (1 -
//! sum_k ratio_k (1 - exp(-t / time_k))): the Prony series, on the
//! elastic forces of every method alike (for a geometrically nonlinear
//! arm it is Fung's quasi-linear viscoelasticity). Held long, r_k =
//! ratio_k f_g: the long-term modulus, which statics solves with
//! ([`Relaxation::long_term`]). What the forces do in a run is
//! `relaxed_forces`.

/// One branch of a group's Prony series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Branch {
    /// The share of the instantaneous modulus that relaxes.
    pub ratio: f64,
    /// Its relaxation time (s).
    pub time: f64,
}

/// Elements that relax alike: the base parameters of their stiffnesses,
/// and their branches.
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    pub stiffness: Vec<usize>,
    pub branches: Vec<Branch>,
}

/// A model's relaxing groups.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Relaxation {
    pub groups: Vec<Group>,
}

impl Relaxation {
    /// Branches over all groups, in state order.
    pub fn branches(&self) -> impl Iterator<Item = (usize, &Branch)> {
        (self.groups.iter().enumerate())
            .flat_map(|(g, group)| group.branches.iter().map(move |b| (g, b)))
    }

    /// Extra states of an arm of `dof` coordinates.
    pub fn states(&self, dof: usize) -> usize {
        dof * self.branches().count()
    }

    /// The base parameters with each group's stiffnesses at their
    /// long-term share, 1 - sum of its ratios.
    pub fn long_term(&self, base: &[f64]) -> Vec<f64> {
        let mut p = base.to_vec();
        for g in &self.groups {
            let share = 1.0 - g.branches.iter().map(|b| b.ratio).sum::<f64>();
            for &i in &g.stiffness {
                p[i] *= share;
            }
        }
        p
    }

    /// The base parameters with group `g`'s stiffnesses zeroed.
    pub fn without(&self, g: usize, base: &[f64]) -> Vec<f64> {
        let mut p = base.to_vec();
        for &i in &self.groups[g].stiffness {
            p[i] = 0.0;
        }
        p
    }
}
