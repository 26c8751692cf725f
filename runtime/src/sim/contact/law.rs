//! Contact force laws (the chapter's section 8.3.2): the normal force from
//! the penetration depth and its rate, and regularised Coulomb friction,
//! written once over any number type so that their exact derivatives come
//! from dual numbers.

use num_dual::DualNum;

use super::distance::V;

/// The normal law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Normal {
    /// F = k delta + c delta', never pulling.
    SpringDashpot { k: f64, c: f64 },
    /// F = k delta^n.
    Hertz { k: f64, n: f64 },
    /// F = k delta^n (1 + alpha delta'), never pulling: `damping` gives
    /// k alpha directly; `restitution` gives alpha = a(e) / v_in at each
    /// impact (see [`restitution_damping`]).
    HuntCrossley { k: f64, n: f64, damping: Damping },
    /// The impact stage: a velocity jump with restitution e, then a
    /// unilateral constraint (`integrate::contact`).
    Impulse { e: f64 },
}

/// How Hunt-Crossley's damping is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Damping {
    /// k alpha (N s / m^(n+1)).
    Given(f64),
    /// The coefficient of restitution; a = alpha v_in solved from it.
    Restitution { e: f64, a: f64 },
}

/// A contact law: normal and friction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Law {
    pub normal: Normal,
    /// Coulomb coefficient.
    pub friction: f64,
    /// Regularisation speed v_s of the friction (m/s).
    pub slip: f64,
}

/// The slowest impact speed (m/s) that sets Hunt-Crossley's damping from
/// the restitution, so that alpha stays finite: a contact that begins at
/// rest is damped at the scale of its load (`settle::settling_speed`),
/// this where nothing presses it in.
pub const SLOWEST_IMPACT: f64 = 1e-3;

impl Law {
    /// The normal force magnitude at depth `delta` (> 0: penetrating)
    /// growing at `rate`, for a contact that began at normal speed `v_in`.
    pub fn normal_force<T: DualNum<Primitive = f64> + Copy>(
        &self,
        delta: T,
        rate: T,
        v_in: f64,
    ) -> T {
        let zero = T::from(0.0);
        if delta.re() <= 0.0 {
            return zero;
        }
        let f = match self.normal {
            Normal::SpringDashpot { k, c } => delta * k + rate * c,
            Normal::Hertz { k, n } => power(delta, n) * k,
            Normal::HuntCrossley { k, n, damping } => {
                let alpha = match damping {
                    Damping::Given(b) => b / k,
                    Damping::Restitution { a, .. } => a / v_in.max(SLOWEST_IMPACT),
                };
                power(delta, n) * k * (rate * alpha + 1.0)
            }
            // Held by the constraint, not by a force law.
            Normal::Impulse { .. } => zero,
        };
        if f.re() < 0.0 { zero } else { f }
    }

    /// The conservative part of the normal force, k delta^n (or k delta):
    /// what the contact gives back. The rest of the force dissipates.
    pub fn elastic_force<T: DualNum<Primitive = f64> + Copy>(&self, delta: T) -> T {
        if delta.re() <= 0.0 {
            return T::from(0.0);
        }
        match self.normal {
            Normal::SpringDashpot { k, .. } => delta * k,
            Normal::Hertz { k, n } | Normal::HuntCrossley { k, n, .. } => power(delta, n) * k,
            Normal::Impulse { .. } => T::from(0.0),
        }
    }

    /// The energy stored in the elastic part at depth delta: k delta^2 / 2
    /// or k delta^(n+1) / (n+1).
    pub fn potential(&self, delta: f64) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        match self.normal {
            Normal::SpringDashpot { k, .. } => 0.5 * k * delta * delta,
            Normal::Hertz { k, n } | Normal::HuntCrossley { k, n, .. } => {
                k * delta.powf(n + 1.0) / (n + 1.0)
            }
            Normal::Impulse { .. } => 0.0,
        }
    }

    /// Friction on the point sliding at `v_t` (tangential) under normal
    /// force `f_n`: -mu f_n v_t / sqrt(|v_t|^2 + v_s^2), smooth through
    /// v_t = 0 and within v_s of Coulomb's magnitude when sliding.
    pub fn friction_force<T: DualNum<Primitive = f64> + Copy>(&self, f_n: T, v_t: V<T>) -> V<T> {
        if self.friction == 0.0 || f_n.re() == 0.0 {
            return [T::from(0.0); 3];
        }
        // |v_t|^2 as a dot product: the norm's derivative is undefined at
        // rest, where friction's is largest.
        let sq = v_t[0] * v_t[0] + v_t[1] * v_t[1] + v_t[2] * v_t[2];
        let speed = (sq + self.slip * self.slip).sqrt();
        let scale = f_n * (-self.friction) / speed;
        v_t.map(|c| c * scale)
    }
}

/// Hunt-Crossley's a = alpha v_in for restitution e, exactly: a particle
/// on F = k delta^n (1 + alpha delta') has the first integral
/// m (v / alpha - ln(1 + alpha v) / alpha^2) + k delta^(n+1) / (n+1), so
/// between touching at v_in and leaving at -e v_in,
///
///   a (1 + e) - ln(1 + a) + ln(1 - a e) = 0,
///
/// independent of k, n and m. Near e = 1 its root is Hunt and Crossley's
/// 3 (1 - e) / 2; solved on (0, 1/e), where the left
/// side falls from positive to minus infinity (bisection in
/// b = -ln(1 - a e)). e = 1 gives 0; e = 0 has
/// no root (no finite damping stops a penalty contact dead).
pub fn restitution_damping(e: f64) -> Option<f64> {
    if !(e > 0.0 && e <= 1.0) {
        return None;
    }
    if e == 1.0 {
        return Some(0.0);
    }
    // In b = -ln(1 - a e) the root is well conditioned even by the pole
    // (a -> 1/e as e -> 0): a = (1 - exp(-b)) / e.
    let a_of = |b: f64| -(-b).exp_m1() / e;
    let g = |b: f64| {
        let a = a_of(b);
        a * (1.0 + e) - a.ln_1p() - b
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    while g(hi) > 0.0 {
        hi *= 2.0;
    }
    // g > 0 just above 0 (its leading term a^2 (1 - e^2) / 2).
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid == lo || mid == hi {
            break;
        }
        if g(mid) > 0.0 { lo = mid } else { hi = mid }
    }
    Some(a_of(0.5 * (lo + hi)))
}

/// delta^n for delta > 0: Hertz's 3/2 (the common exponent) by a square
/// root, whole exponents by products, others by `powf` (several times
/// the cost, on every right-hand side that touches).
fn power<T: DualNum<Primitive = f64> + Copy>(delta: T, n: f64) -> T {
    if n == 1.5 {
        delta * delta.sqrt()
    } else if n == 1.0 {
        delta
    } else if n == 2.0 {
        delta * delta
    } else {
        delta.powf(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The root satisfies its equation, and near e = 1 it is Hunt and
    /// Crossley's 3 (1 - e) / 2 to second order.
    #[test]
    fn restitution_damping_solves_its_equation() {
        for e in [0.1, 0.2, 0.5, 0.9, 0.999] {
            let a = restitution_damping(e).unwrap();
            let g = a * (1.0 + e) - a.ln_1p() + (-a * e).ln_1p();
            // Relative to the terms' size: near e = 0 the root sits by the
            // pole at a = 1/e, where the left side is steep.
            let scale = a * (1.0 + e) + (-a * e).ln_1p().abs();
            assert!(g.abs() < 1e-12 * scale, "e = {e}: a = {a}, residual {g}");
            assert!(a > 0.0 && a * e < 1.0);
        }
        let e: f64 = 0.999;
        let a = restitution_damping(e).unwrap();
        assert!((a / (1.5 * (1.0 - e)) - 1.0).abs() < 2e-3, "{a}");
        assert_eq!(restitution_damping(1.0), Some(0.0));
        assert_eq!(restitution_damping(0.0), None);
    }

    /// A mass dropped on the law at v_in, integrated by RK4 in small
    /// steps: the speed it leaves with over v_in.
    fn rebound(law: &Law, v_in: f64) -> f64 {
        let (m, h) = (0.05, 1e-7);
        // delta > 0 is depth, its rate positive going in.
        let acc = |d: f64, r: f64| -law.normal_force(d, r, v_in) / m;
        let (mut d, mut r) = (0.0, v_in);
        for _ in 0..10_000_000 {
            let (k1d, k1r) = (r, acc(d, r));
            let (k2d, k2r) = (r + 0.5 * h * k1r, acc(d + 0.5 * h * k1d, r + 0.5 * h * k1r));
            let (k3d, k3r) = (r + 0.5 * h * k2r, acc(d + 0.5 * h * k2d, r + 0.5 * h * k2r));
            let (k4d, k4r) = (r + h * k3r, acc(d + h * k3d, r + h * k3r));
            d += h / 6.0 * (k1d + 2.0 * k2d + 2.0 * k3d + k4d);
            r += h / 6.0 * (k1r + 2.0 * k2r + 2.0 * k3r + k4r);
            if d <= 0.0 {
                return -r / v_in;
            }
        }
        panic!("the mass never left");
    }

    /// Hunt-Crossley's damping from the restitution gives that restitution
    /// to a mass dropped on it, whatever the stiffness, exponent and speed
    /// (the first integral's claim, checked by integrating the motion);
    /// without damping the contact gives every joule back.
    #[test]
    fn a_dropped_mass_leaves_at_the_restitution_asked() {
        for (e, k, n, v_in) in [
            (0.5, 1e4, 1.5, 0.3),
            (0.8, 3e5, 1.0, 1.2),
            (0.2, 1e5, 2.0, 0.05),
        ] {
            let a = restitution_damping(e).unwrap();
            let law = Law {
                normal: Normal::HuntCrossley {
                    k,
                    n,
                    damping: Damping::Restitution { e, a },
                },
                friction: 0.0,
                slip: 1e-3,
            };
            let out = rebound(&law, v_in);
            assert!(
                (out - e).abs() < 1e-5,
                "e = {e}, k = {k}, n = {n}: left at {out}"
            );
        }
        let hertz = Law {
            normal: Normal::Hertz { k: 1e4, n: 1.5 },
            friction: 0.0,
            slip: 1e-3,
        };
        assert!((rebound(&hertz, 0.4) - 1.0).abs() < 1e-7);
    }

    /// Regularised Coulomb friction opposes sliding, never exceeds mu f_n,
    /// and reaches it (within (v_s / v)^2 / 2) when sliding fast.
    #[test]
    fn friction_opposes_sliding_within_the_coulomb_bound() {
        let law = Law {
            normal: Normal::Hertz { k: 1e4, n: 1.5 },
            friction: 0.6,
            slip: 1e-3,
        };
        let f_n = 2.0;
        for v in [[1e-5, 0.0, 0.0], [0.3, -0.4, 0.0], [0.0, 2e-3, -1e-3]] {
            let f = law.friction_force(f_n, v);
            let speed = v.iter().map(|c| c * c).sum::<f64>().sqrt();
            let mag = f.iter().map(|c| c * c).sum::<f64>().sqrt();
            let along: f64 = f.iter().zip(&v).map(|(a, b)| a * b).sum();
            assert!(
                along < 0.0 && mag <= 0.6 * f_n * (1.0 + 1e-15),
                "{v:?}: {f:?}"
            );
            if speed > 100.0 * law.slip {
                let gap = 1.0 - mag / (0.6 * f_n);
                assert!(
                    gap < 0.5 * (law.slip / speed).powi(2) * 1.01,
                    "{v:?}: {gap}"
                );
            }
        }
    }
}
