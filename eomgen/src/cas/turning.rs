//! Vectors turned into the world by a moving frame, with their rates.
//!
//! A kinematic chain writes each point as p = p_f + R_f x: the frame's
//! rotation applied to a local vector. Differentiated by the chain rule,
//! R_f's bound entries turn into R_f' = R_f-1' E + R_f-1 E', a product of
//! 3x3 matrices per frame for the velocity and three for the acceleration.
//! The rigid-body identity R_f' = [w_f]x R_f says the same in a cross product:
//!
//!   d/dt (R_f x) = w_f x (R_f x) + R_f x',
//!
//! and R_f x' is again a turned vector, so the rule applies to accelerations
//! too. [`Cas::turn`] records the rule on the bound components of R_f x;
//! [`Cas::kinematic_rates`] uses it. The rule holds for the time seed that
//! w_f was built with (q -> qd, at qdd = 0), which is why only that entry
//! point applies it: the other directional derivatives (a partial
//! derivative, M qdd as the derivative along qd -> qdd) go through R_f.

use super::expr::{Cas, ExprId, Turned};

impl Cas {
    /// R x for a frame with rotation `r` (rows, world from frame) and world
    /// angular velocity `w`, bound, with its rate rule recorded. `w` must be
    /// the angular velocity of `r` under the time seed q -> qd.
    pub fn turn(&mut self, r: &[[ExprId; 3]; 3], w: &[ExprId; 3], x: &[ExprId; 3]) -> [ExprId; 3] {
        let world: [ExprId; 3] = std::array::from_fn(|i| {
            let e = self.dot(&r[i], x);
            self.bind(e)
        });
        for (component, &u) in world.iter().enumerate() {
            // Constants and symbols have exact chain-rule rates already; a
            // node bound twice keeps its first rule (both are true). Under
            // the identity at rest (a link cell's base frame) R x is x
            // itself: the rule would define x's rate by x's rate.
            if matches!(self.node(u), super::Node::Bind(_)) && u != x[component] {
                self.turned.entry(u).or_insert(Turned {
                    r: *r,
                    w: *w,
                    local: *x,
                    world,
                    component,
                });
            }
        }
        world
    }

    /// The rate of a turned component by the rule, with `local_rate` the
    /// rate of a local component.
    pub(super) fn turned_rate(
        &mut self,
        e: ExprId,
        local_rate: &mut dyn FnMut(&mut Cas, ExprId) -> ExprId,
    ) -> Option<ExprId> {
        let t = *self.turned.get(&e)?;
        let xd = t.local.map(|x| local_rate(self, x));
        let rxd = self.turn(&t.r, &t.w, &xd);
        let (i, j) = ((t.component + 1) % 3, (t.component + 2) % 3);
        let a = self.mul(t.w[i], t.world[j]);
        let b = self.mul(t.w[j], t.world[i]);
        let wu = self.sub(a, b);
        let rate = self.add(wu, rxd[t.component]);
        Some(self.bind(rate))
    }
}
