//! The integrators by name: one table that the CLI, the model files'
//! validation and the simulation layer's dispatch all read. It sits in the
//! always-built layer because the generator validates `[simulate] solver`.

use serde::Serialize;

/// Integrators. Names are the CLI's and the model files'.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Solver {
    /// Adaptive Dormand-Prince 5(4), explicit.
    Dopri5,
    /// Adaptive Dormand-Prince 8(5,3), explicit.
    Dop853,
    /// Adaptive Bogacki-Shampine 3(2), explicit (the ode23 family).
    Bs23,
    /// Classic fixed-step Runge-Kutta 4, explicit.
    Rk4,
    /// Fixed-step explicit Euler.
    Euler,
    /// Radau IIA order 5, implicit, L-stable, adaptive (stiff systems).
    Radau5,
    /// Radau IIA order 5 at a fixed step: L-stable, for stiff, lightly
    /// damped structures whose stiffest modes nothing reads.
    #[serde(rename = "radau5-fixed")]
    Radau5Fixed,
    /// Variable-order BDF 1-5, implicit, adaptive (the ode15s family).
    Bdf,
    /// TR-BDF2, L-stable, second order, adaptive (MATLAB's ode23tb).
    Trbdf2,
    /// ESDIRK 3(2) 4-stage, L-stable, adaptive (the crate's).
    Esdirk,
    /// Generalized-alpha (Chung and Hulbert), second order, adaptive: the
    /// structural dynamicist's method, damping unresolved high modes to
    /// the spectral radius `rho_inf`.
    GenAlpha,
    /// Gauss-Legendre, two stages, fourth order, at a fixed step: implicit,
    /// A-stable and symplectic (no numerical damping), for lightly damped
    /// structures over many periods.
    Gauss,
    /// dopri5, switching to radau5 when the arm turns out stiff (checked
    /// from the Jacobian's eigenvalues at the start and every
    /// `AUTO_CHECK_STEPS` accepted steps).
    Auto,
}

/// Every solver with its name and the order of its global error (bdf's
/// highest; auto's dopri5's), in the order `--solver` lists them.
const TABLE: [(Solver, &str, u32); 13] = [
    (Solver::Dopri5, "dopri5", 5),
    (Solver::Bs23, "bs23", 3),
    (Solver::Dop853, "dop853", 8),
    (Solver::Rk4, "rk4", 4),
    (Solver::Euler, "euler", 1),
    (Solver::Radau5, "radau5", 5),
    (Solver::Bdf, "bdf", 5),
    (Solver::Trbdf2, "trbdf2", 2),
    (Solver::Esdirk, "esdirk", 3),
    (Solver::GenAlpha, "genalpha", 2),
    (Solver::Gauss, "gauss", 4),
    (Solver::Radau5Fixed, "radau5-fixed", 5),
    (Solver::Auto, "auto", 5),
];

impl Solver {
    /// The names `--solver` and `[simulate] solver` take.
    pub const NAMES: [&'static str; TABLE.len()] = {
        let mut names = [""; TABLE.len()];
        let mut i = 0;
        while i < TABLE.len() {
            names[i] = TABLE[i].1;
            i += 1;
        }
        names
    };

    /// Every solver, in the table's order.
    pub const ALL: [Solver; TABLE.len()] = {
        let mut all = [Solver::Auto; TABLE.len()];
        let mut i = 0;
        while i < TABLE.len() {
            all[i] = TABLE[i].0;
            i += 1;
        }
        all
    };

    pub fn parse(s: &str) -> Option<Self> {
        TABLE
            .iter()
            .find(|(_, n, _)| *n == s)
            .map(|(solver, _, _)| *solver)
    }

    fn row(self) -> &'static (Solver, &'static str, u32) {
        TABLE
            .iter()
            .find(|(solver, _, _)| *solver == self)
            .expect("every solver is in the table")
    }

    pub fn name(self) -> &'static str {
        self.row().1
    }

    /// The order of the method's global error: halving a fixed step
    /// divides it by 2^order.
    pub fn order(self) -> u32 {
        self.row().2
    }

    /// Fixed-step methods (no error estimate: `dt` sets the step).
    pub fn fixed_step(self) -> bool {
        matches!(
            self,
            Self::Rk4 | Self::Euler | Self::Gauss | Self::Radau5Fixed
        )
    }

    /// Implicit methods (they use the analytic Jacobian).
    pub fn implicit(self) -> bool {
        matches!(
            self,
            Self::Radau5
                | Self::Radau5Fixed
                | Self::Bdf
                | Self::Trbdf2
                | Self::Esdirk
                | Self::GenAlpha
                | Self::Gauss
        )
    }
}
