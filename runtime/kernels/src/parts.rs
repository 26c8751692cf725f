//! Mass + bias and the Jvp of a system that is a sum of *parts*, each a
//! small kernel of a few of the arm's coordinates: an eba arm's elements
//! (a body of its own six coordinates) and the beam springs between
//! neighbours (twelve). M and h are the parts' blocks scattered and
//! summed; no frames are composed (that is the link recursion's case,
//! `links`). Identical parts share one kernel, so generated code
//! grows with the kinds of parts, not with their number.

use std::borrow::Cow;

use serde::{Deserialize, Serialize};

use crate::links::{CellFn, CellTangentFn};
use crate::output;

/// One part: its kernel, the arm's coordinates it reads (its local
/// coordinate i is the arm's `coords[i]`) and its parameters (its local
/// parameter i is `p[params[i]]`, past the model's parameters the
/// actuation loads': [`PartLayout::loads`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PartSpec {
    pub kernel: usize,
    pub coords: Vec<usize>,
    pub params: Vec<usize>,
}

/// The parts of a system.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PartLayout {
    pub dof: usize,
    pub parts: Vec<PartSpec>,
    /// The coordinates the pose kernel reads (the last element's).
    pub pose_coords: Vec<usize>,
    /// How many values the loads kernel ([`Parts::loads`]: the actuators'
    /// loads, of the parameters alone, then a zero triple for the bare
    /// segments) gives; the parts read them past the model's `params`
    /// parameters (not past derived ones).
    #[serde(default)]
    pub loads: usize,
    /// The model's parameter count (where the loads start).
    #[serde(default)]
    pub params: usize,
}

/// The part kernels of a model: kernel k maps a part's local coordinates,
/// rates and parameters to its block of M (upper triangle, row by row),
/// its block of h and its potential energy (positions relative to a
/// straight-arm centre); `tangents[k]` gives those and their directional
/// derivatives along the local (dx, dxd). For the outputs, `pose` (of the
/// layout's `pose_coords` and the model's parameters) gives the tip
/// point relative to the same kind of centre and the tip quaternion, and
/// `offsets` (of the parameters) the potential energy the parts leave out
/// and that centre.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PartKernels {
    pub layout: PartLayout,
    pub kernels: Vec<crate::Tape>,
    pub tangents: Vec<crate::Tape>,
    pub pose: Option<crate::Tape>,
    pub offsets: Option<crate::Tape>,
    /// The actuators' loads ([`PartLayout::loads`] values but the zero
    /// triple); None without actuators.
    pub loads: Option<crate::Tape>,
}

/// What the sums evaluate: generated code, or the tapes in tests.
pub trait Parts {
    /// Kernel `k` at local coordinates `x`, rates `xd`, parameters `p`.
    fn eval(&mut self, k: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]);
    /// Kernel `k` then its directional derivative along (dx, dxd).
    #[allow(clippy::too_many_arguments)]
    fn tangent(
        &mut self,
        k: usize,
        x: &[f64],
        xd: &[f64],
        dx: &[f64],
        dxd: &[f64],
        p: &[f64],
        out: &mut [f64],
    );
    /// The pose kernel at the pose coordinates `x`, the model's `p`.
    fn pose(&mut self, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]);
    /// The offsets kernel of the model's `p`.
    fn offsets(&mut self, p: &[f64], out: &mut [f64]);
    /// The loads kernel of the model's `p`: the actuators' loads
    /// ([`PartKernels::loads`]; nothing without actuators).
    fn loads(&mut self, p: &[f64], out: &mut [f64]);
}

/// The parameters the parts read: the model's, then the actuation loads
/// and a zero triple (once per call, not per part).
fn with_loads<'a, P: Parts>(layout: &PartLayout, parts: &mut P, p: &'a [f64]) -> Cow<'a, [f64]> {
    if layout.loads == 0 {
        return Cow::Borrowed(p);
    }
    let n = layout.params;
    let mut all = p[..n].to_vec();
    all.resize(n + layout.loads, 0.0);
    parts.loads(p, &mut all[n..n + layout.loads - 3]);
    Cow::Owned(all)
}

/// A part kernel compiled into a model, found by key
/// (`eomgen::build::kernel_key` of its tape and tangent) by systems of the
/// same kinds of parts and other lengths (`LinkedParts`).
#[derive(Clone, Copy)]
pub struct CompiledPart {
    pub key: &'static str,
    /// At local coordinates, rates and parameters, into the part's outputs.
    pub eval: CellFn,
    /// Those and their derivatives along (dx, dxd): x, xd, dx, dxd, p, out.
    pub tangent: CellTangentFn,
}

/// The part kernels a model compiled in ([`CompiledPart`]), by a call to
/// its `Parts` implementation (`$parts`) for kernel `$k`.
#[macro_export]
macro_rules! compiled_part {
    ($key:expr, $parts:expr, $k:literal) => {
        $crate::parts::CompiledPart {
            key: $key,
            eval: |x, xd, p, out| $crate::parts::Parts::eval(&mut $parts, $k, x, xd, p, out),
            tangent: |x, xd, dx, dxd, p, out| {
                $crate::parts::Parts::tangent(&mut $parts, $k, x, xd, dx, dxd, p, out)
            },
        }
    };
}

/// Part kernels compiled where a compiled-in model has them
/// (`compiled[k]`), else their tapes; the pose and offsets (of the whole
/// model's parameters) always the tapes.
pub struct LinkedParts<'a> {
    pub tapes: TapeParts<'a>,
    pub compiled: &'a [Option<CompiledPart>],
}

impl Parts for LinkedParts<'_> {
    fn eval(&mut self, k: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]) {
        match self.compiled[k] {
            Some(c) => (c.eval)(x, xd, p, out),
            None => self.tapes.eval(k, x, xd, p, out),
        }
    }
    fn tangent(
        &mut self,
        k: usize,
        x: &[f64],
        xd: &[f64],
        dx: &[f64],
        dxd: &[f64],
        p: &[f64],
        out: &mut [f64],
    ) {
        match self.compiled[k] {
            Some(c) => (c.tangent)(x, xd, dx, dxd, p, out),
            None => self.tapes.tangent(k, x, xd, dx, dxd, p, out),
        }
    }
    fn pose(&mut self, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]) {
        self.tapes.pose(x, xd, p, out)
    }
    fn offsets(&mut self, p: &[f64], out: &mut [f64]) {
        self.tapes.offsets(p, out)
    }
    fn loads(&mut self, p: &[f64], out: &mut [f64]) {
        self.tapes.loads(p, out)
    }
}

/// What a part kernel writes for `m` coordinates: M's block, h's block,
/// the potential energy.
fn part_len(m: usize) -> usize {
    tri(m) + m + 1
}

/// Entries of an m x m upper triangle.
fn tri(m: usize) -> usize {
    m * (m + 1) / 2
}

/// `v` at `at` into `buf` (a part's local values of the arm's `v`, or
/// its parameters), reusing its allocation across parts.
fn gather<'a>(buf: &'a mut Vec<f64>, at: &[usize], v: &[f64]) -> &'a [f64] {
    buf.clear();
    buf.extend(at.iter().map(|&i| v[i]));
    buf
}

/// A part's inputs, gathered into buffers reused from part to part.
#[derive(Default)]
struct Gathered {
    x: Vec<f64>,
    xd: Vec<f64>,
    params: Vec<f64>,
    /// The Jvp's: the direction's parts and the accelerations.
    dx: Vec<f64>,
    dxd: Vec<f64>,
    xdd: Vec<f64>,
}

/// M (upper triangle, row by row) and h into `out` (the `MassBias`
/// layout): every part's block added where its coordinates are.
pub fn mass_bias<P: Parts>(
    layout: &PartLayout,
    parts: &mut P,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) {
    let n = layout.dof;
    assert_eq!(out.len(), tri(n) + n, "MassBias output length");
    let p = &*with_loads(layout, parts, p);
    out.fill(0.0);
    let (mass, bias) = out.split_at_mut(tri(n));
    let index = |i: usize, j: usize| {
        let (i, j) = (i.min(j), i.max(j));
        i * n - i * (i + 1) / 2 + j
    };
    let (mut local, mut g) = (Vec::new(), Gathered::default());
    for spec in &layout.parts {
        let m = spec.coords.len();
        local.resize(part_len(m), 0.0);
        let x = gather(&mut g.x, &spec.coords, q);
        let xd = gather(&mut g.xd, &spec.coords, qd);
        let params = gather(&mut g.params, &spec.params, p);
        parts.eval(spec.kernel, x, xd, params, &mut local);
        let mut at = 0;
        for a in 0..m {
            for b in a..m {
                mass[index(spec.coords[a], spec.coords[b])] += local[at];
                at += 1;
            }
            bias[spec.coords[a]] += local[tri(m) + a];
        }
    }
}

/// The directional derivative of tau = M qdd + h along `dir` = (dq, dqd)
/// into `dtau`: the `Jvp` kernel of a system of parts. Only the parts the
/// direction moves are evaluated, so a column of the Jacobian (a unit
/// direction) costs the few parts of one coordinate, not the whole system.
#[allow(clippy::too_many_arguments)]
pub fn jvp<P: Parts>(
    layout: &PartLayout,
    parts: &mut P,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    dir: &[f64],
    p: &[f64],
    dtau: &mut [f64],
) {
    let n = layout.dof;
    assert!(dir.len() == 2 * n && dtau.len() == n);
    let p = &*with_loads(layout, parts, p);
    let (dq, dqd) = dir.split_at(n);
    dtau.fill(0.0);
    let (mut out, mut g) = (Vec::new(), Gathered::default());
    for spec in &layout.parts {
        let dx = gather(&mut g.dx, &spec.coords, dq);
        let dxd = gather(&mut g.dxd, &spec.coords, dqd);
        if dx.iter().chain(dxd).all(|&v| v == 0.0) {
            continue;
        }
        let m = spec.coords.len();
        let len = part_len(m);
        out.resize(2 * len, 0.0);
        let params = gather(&mut g.params, &spec.params, p);
        let x = gather(&mut g.x, &spec.coords, q);
        let xd = gather(&mut g.xd, &spec.coords, qd);
        parts.tangent(spec.kernel, x, xd, dx, dxd, params, &mut out);
        let a_local = gather(&mut g.xdd, &spec.coords, qdd);
        // Row a of the block's derivative times the local accelerations.
        let entry = |a: usize, b: usize| {
            let (a, b) = (a.min(b), a.max(b));
            a * m - a * (a + 1) / 2 + b
        };
        for a in 0..m {
            let mut d = out[len + tri(m) + a];
            for (b, &acc) in a_local.iter().enumerate() {
                d += out[len + entry(a, b)] * acc;
            }
            dtau[spec.coords[a]] += d;
        }
    }
}

/// The outputs (`crate::OUTPUT_NAMES`) of a system of parts: the tip from
/// the pose kernel and the offsets, the kinetic energy qd^T M qd / 2 block
/// by block, the potential energy the parts' plus the offsets'.
pub fn outputs<P: Parts>(
    layout: &PartLayout,
    parts: &mut P,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) {
    let mut offsets = [0.0; 4];
    parts.offsets(p, &mut offsets);
    let all = with_loads(layout, parts, p);
    let (mut ke, mut pe) = (0.0, offsets[0]);
    let (mut local, mut g) = (Vec::new(), Gathered::default());
    for spec in &layout.parts {
        let m = spec.coords.len();
        local.resize(part_len(m), 0.0);
        let params = gather(&mut g.params, &spec.params, &all);
        let x = gather(&mut g.x, &spec.coords, q);
        let xd = gather(&mut g.xd, &spec.coords, qd);
        parts.eval(spec.kernel, x, xd, params, &mut local);
        let mut at = 0;
        for a in 0..m {
            for b in a..m {
                let twice = if a == b { 1.0 } else { 2.0 };
                ke += 0.5 * twice * local[at] * xd[a] * xd[b];
                at += 1;
            }
        }
        pe += local[tri(m) + m];
    }
    let x: Vec<f64> = layout.pose_coords.iter().map(|&i| q[i]).collect();
    let xd: Vec<f64> = layout.pose_coords.iter().map(|&i| qd[i]).collect();
    let mut pose = [0.0; 7];
    parts.pose(&x, &xd, p, &mut pose);
    for (k, o) in output::TIP.enumerate() {
        out[o] = offsets[1 + k] + pose[k];
    }
    out[output::KINETIC] = ke;
    out[output::POTENTIAL] = pe;
    out[output::ORIENTATION].copy_from_slice(&pose[3..7]);
}

/// A part tape's inputs: local coordinates, rates and direction, no time
/// or accelerations (parts read neither).
fn still<'a>(q: &'a [f64], qd: &'a [f64], dir: &'a [f64], p: &'a [f64]) -> crate::Inputs<'a> {
    crate::Inputs {
        t: 0.0,
        q,
        qd,
        qdd: &[],
        dir,
        p,
        aux: &[],
    }
}

/// The part kernels run by the tape interpreter: the interpreted
/// backend's `MassBias` and `Jvp` of a system of parts, and the tests'.
pub struct TapeParts<'a> {
    pub kernels: &'a PartKernels,
    pub slots: Vec<f64>,
}

impl Parts for TapeParts<'_> {
    fn eval(&mut self, k: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]) {
        let inp = still(x, xd, &[], p);
        self.kernels.kernels[k].eval(&inp, &mut self.slots, out)
    }
    fn tangent(
        &mut self,
        k: usize,
        x: &[f64],
        xd: &[f64],
        dx: &[f64],
        dxd: &[f64],
        p: &[f64],
        out: &mut [f64],
    ) {
        let dir: Vec<f64> = dx.iter().chain(dxd).copied().collect();
        let inp = still(x, xd, &dir, p);
        self.kernels.tangents[k].eval(&inp, &mut self.slots, out)
    }
    fn pose(&mut self, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]) {
        let inp = still(x, xd, &[], p);
        let pose = self.kernels.pose.as_ref().expect("a pose kernel");
        pose.eval(&inp, &mut self.slots, out)
    }
    fn offsets(&mut self, p: &[f64], out: &mut [f64]) {
        let inp = still(&[], &[], &[], p);
        let offsets = self.kernels.offsets.as_ref().expect("an offsets kernel");
        offsets.eval(&inp, &mut self.slots, out)
    }
    fn loads(&mut self, p: &[f64], out: &mut [f64]) {
        let inp = still(&[], &[], &[], p);
        match &self.kernels.loads {
            Some(loads) => loads.eval(&inp, &mut self.slots, out),
            None => debug_assert!(out.is_empty(), "no actuator acts"),
        }
    }
}
