//! The base frame of a chain: where it is, how it is turned, and how it
//! moves when inputs drive it (a translation along a path, turns about
//! axes). Every sweep starts from here.

use serde::{Deserialize, Serialize};

use super::{LinkLayout, M3, V3, add, cross, mat_mat, mat_vec, scale, sub};
use crate::rotation::quat_mul;

/// A turn of the base by an input (`base.rotation_inputs`): the slots of
/// its angle, rate and acceleration, and of its unit axis in the frame the
/// turns before it leave (None: z, a planar chain's turn).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BaseTurn {
    pub angle: [usize; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[usize; 3]>,
}

/// What the driven turns give the base: their rotation (rows) and
/// quaternion, and its angular velocity and acceleration (world frame).
struct Spin {
    r: M3,
    quat: [f64; 4],
    omega: V3,
    alpha: V3,
}

/// The turns in sequence, each about its axis in the frame the turns
/// before it left (as `eomgen`'s `tmt::spatial::base_frame` composes
/// them): R = R_1 R_2 ..., w = sum R_<i n_i a_i', and
/// alpha = sum (R_<i n_i a_i'' + w_<i x R_<i n_i a_i').
fn base_spin(layout: &LinkLayout, p: &[f64]) -> Spin {
    let mut s = Spin {
        r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        quat: [1.0, 0.0, 0.0, 0.0],
        omega: [0.0; 3],
        alpha: [0.0; 3],
    };
    for turn in &layout.base_turns {
        let n = turn.axis.map_or([0.0, 0.0, 1.0], |a| a.map(|i| p[i]));
        let [angle, rate, accel] = turn.angle.map(|i| p[i]);
        let world = mat_vec(&s.r, n);
        s.alpha = add(
            s.alpha,
            add(scale(accel, world), scale(rate, cross(s.omega, world))),
        );
        s.omega = add(s.omega, scale(rate, world));
        // exp(angle [n]x) = cos 1 + sin [n]x + (1 - cos) n n^T.
        let (sin, cos) = angle.sin_cos();
        let v = 1.0 - cos;
        let rel: M3 = [
            [
                cos + v * n[0] * n[0],
                v * n[0] * n[1] - sin * n[2],
                v * n[0] * n[2] + sin * n[1],
            ],
            [
                v * n[1] * n[0] + sin * n[2],
                cos + v * n[1] * n[1],
                v * n[1] * n[2] - sin * n[0],
            ],
            [
                v * n[2] * n[0] - sin * n[1],
                v * n[2] * n[1] + sin * n[0],
                cos + v * n[2] * n[2],
            ],
        ];
        let (sh, ch) = (0.5 * angle).sin_cos();
        s.quat = quat_mul(s.quat, [ch, sh * n[0], sh * n[1], sh * n[2]]);
        s.r = mat_mat(&s.r, &rel);
    }
    s
}

/// The base frame's rotation (rows) and quaternion (w, x, y, z): the
/// driven turns, then the declared direction (the rotation and quaternion
/// parameters, or about z by a planar base angle).
#[inline(always)]
pub(crate) fn base_orientation(layout: &LinkLayout, p: &[f64]) -> (M3, [f64; 4]) {
    let (r, quat) = match layout.base_angle {
        Some(i) => {
            let (s, c) = p[i].sin_cos();
            let (sh, ch) = (0.5 * p[i]).sin_cos();
            (
                [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
                [ch, 0.0, 0.0, sh],
            )
        }
        None => (
            std::array::from_fn(|i| std::array::from_fn(|j| p[layout.base_rotation[3 * i + j]])),
            layout.base_quaternion.map(|i| p[i]),
        ),
    };
    match layout.base_turns.is_empty() {
        true => (r, quat),
        false => {
            let spin = base_spin(layout, p);
            (mat_mat(&spin.r, &r), quat_mul(spin.quat, quat))
        }
    }
}

/// The base's angular velocity and acceleration: its driven turns', else
/// at rest.
#[inline(always)]
pub(crate) fn base_rates(layout: &LinkLayout, p: &[f64]) -> (V3, V3) {
    match layout.base_turns.is_empty() {
        true => ([0.0; 3], [0.0; 3]),
        false => {
            let spin = base_spin(layout, p);
            (spin.omega, spin.alpha)
        }
    }
}

/// The base's origin, its velocity and its acceleration: a driven base
/// translation's, else at rest at `base_position`. The turns are about
/// the origin: they do not move it.
#[inline(always)]
pub(crate) fn base_motion(layout: &LinkLayout, p: &[f64]) -> (V3, V3, V3) {
    let pos = layout.base_position.map(|i| p[i]);
    match layout.base_translation {
        None => (pos, [0.0; 3], [0.0; 3]),
        Some([x, v, a]) => (add(pos, x.map(|i| p[i])), v.map(|i| p[i]), a.map(|i| p[i])),
    }
}

/// The gravity the sums of forces see: gravity less a driven base's
/// acceleration, which carries every body alike (so that a base lifted at
/// g is gravity, to the last bit).
#[inline(always)]
pub(crate) fn felt_gravity(layout: &LinkLayout, p: &[f64]) -> V3 {
    let g = layout.gravity.map(|i| p[i]);
    sub(g, base_motion(layout, p).2)
}
