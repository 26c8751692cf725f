//! Contact along the whole arm (docs/design.md section 8): the generated
//! `Contact` kernel gives every sampled point's position (and a chain's
//! contact frames), the `ContactJacobian` groups their positions,
//! velocities and Jacobians; here each pair (a point and an obstacle, two
//! points of the arms, a point and a body) gets its gap, its normal and
//! friction forces from its law, and the forces reach the equations as
//! the generalised force Q_c = sum J^T f (virtual work), subtracted from
//! h. On the hot path of a chain with contact frames no point is computed
//! before the broad phase has kept its element.
//!
//! Invariant: contact is a force on the right-hand side, never a change of
//! the generated kernels; an obstacle or a law changes without a rebuild.
//! Its Jacobian is exact: the `ContactJvp` kernel's dJ and dv along each
//! coordinate, and the laws' derivatives by dual numbers.

pub mod distance;
pub mod impact;
pub mod law;
pub mod settle;

use std::cell::RefCell;

use num_dual::{Dual64, DualNum};

use crate::arm::Dynamics;
use crate::kernels::{CONTACT_BOUND, KernelKind};
use crate::signal::Signal;

pub use crate::obstacle::Shape;
use distance as obstacle;
pub use distance::Distance;
pub use law::{Damping, Law, Normal, restitution_damping};

use distance::V;

/// A sampled point: the radius of the tube (or body) around it, and where
/// it is on the arms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint {
    pub radius: f64,
    /// Arm and element index along that arm; `None` for a body's centre.
    pub element: Option<(usize, usize)>,
}

/// A moving obstacle's displacement along x, y, z (input signals) and
/// their rates.
#[derive(Clone, Debug)]
pub struct Motion {
    pub displacement: [Signal; 3],
    pub velocity: [Signal; 3],
}

impl Motion {
    pub fn new(displacement: [Signal; 3]) -> Self {
        let velocity = [0, 1, 2].map(|c| displacement[c].derivative());
        Self {
            displacement,
            velocity,
        }
    }

    pub fn at(&self, t: f64) -> ([f64; 3], [f64; 3]) {
        (
            [0, 1, 2].map(|c| self.displacement[c].at(t)),
            [0, 1, 2].map(|c| self.velocity[c].at(t)),
        )
    }
}

/// An obstacle: a shape, its law, and its motion if it moves.
#[derive(Clone, Debug)]
pub struct Obstacle {
    pub name: String,
    pub shape: Shape,
    pub law: Law,
    pub motion: Option<Motion>,
}

/// What a point touches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Against {
    Obstacle(usize),
    /// Another sampled point (self contact, a body): sphere on sphere.
    Point(usize),
}

/// A pair that may touch, its law, and the output channel its forces add
/// to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pair {
    pub point: usize,
    pub other: Against,
    pub law: Law,
    pub channel: usize,
}

impl Pair {
    /// The other point of a point-point pair (self or arm-arm contact).
    pub fn other_point(&self) -> Option<usize> {
        match self.other {
            Against::Point(j) => Some(j),
            Against::Obstacle(_) => None,
        }
    }
}

/// Per run, for the pairs that keep records (Hunt-Crossley from a
/// restitution): whether each touches, and the normal speed at which it
/// began to, which its damping reads. Changed only between legs
/// (`integrate::touch`), so the right-hand side stays smooth in a leg.
#[derive(Clone, Debug, Default)]
pub struct ContactState {
    pub touching: Vec<bool>,
    pub impact: Vec<f64>,
    /// Impulse pairs held as unilateral constraints (after e = 0).
    pub held: Vec<bool>,
}

/// Every pair of a model, and its running state.
#[derive(Debug)]
pub struct ContactSet {
    pub points: Vec<ContactPoint>,
    pub obstacles: Vec<Obstacle>,
    /// Every point against every obstacle, point-major (pair
    /// `i * obstacles.len() + k` is point i against obstacle k:
    /// `penetrating` relies on it), then the point-point pairs.
    pub pairs: Vec<Pair>,
    /// Output channels by name (`contact_<name>_fn`, `_ft`).
    pub channels: Vec<String>,
    /// (A `RefCell` like the scratch: the set is used by one thread, and
    /// every right-hand side that touches reads it.)
    pub state: RefCell<ContactState>,
    scratch: RefCell<Scratch>,
    /// Some pair's law is `impulse` (only those are ever held).
    holds: bool,
}

impl Clone for ContactSet {
    fn clone(&self) -> Self {
        Self {
            points: self.points.clone(),
            obstacles: self.obstacles.clone(),
            pairs: self.pairs.clone(),
            channels: self.channels.clone(),
            state: RefCell::new(self.state()),
            scratch: RefCell::new(Scratch::default()),
            holds: self.holds,
        }
    }
}

impl ContactSet {
    /// Pairs every point with every obstacle (its channel the obstacle's
    /// name); with `self_law`, every two arm points of elements that are
    /// not neighbours (channel `self`); with `body_law`, every arm point
    /// with every body centre (the body's name, from `bodies`).
    pub fn new(
        points: Vec<ContactPoint>,
        obstacles: Vec<Obstacle>,
        self_law: Option<Law>,
        bodies: Option<(Law, Vec<String>)>,
    ) -> Self {
        let mut pairs = Vec::new();
        let mut channels: Vec<String> = obstacles.iter().map(|o| o.name.clone()).collect();
        for (i, _) in points.iter().enumerate() {
            for (k, o) in obstacles.iter().enumerate() {
                pairs.push(Pair {
                    point: i,
                    other: Against::Obstacle(k),
                    law: o.law,
                    channel: k,
                });
            }
        }
        if let Some(law) = self_law {
            let channel = channels.len();
            channels.push("self".into());
            for (i, a) in points.iter().enumerate() {
                for (j, b) in points.iter().enumerate().skip(i + 1) {
                    if let (Some((arm_a, ea)), Some((arm_b, eb))) = (a.element, b.element)
                        && (arm_a != arm_b || ea.abs_diff(eb) >= 2)
                    {
                        pairs.push(Pair {
                            point: i,
                            other: Against::Point(j),
                            law,
                            channel,
                        });
                    }
                }
            }
        }
        let arm_points = points.iter().any(|p| p.element.is_some());
        if let Some((law, names)) = bodies.filter(|_| arm_points) {
            let centres: Vec<usize> = (0..points.len())
                .filter(|&i| points[i].element.is_none())
                .collect();
            for (b, &j) in centres.iter().enumerate() {
                let channel = channels.len();
                channels.push(names.get(b).cloned().unwrap_or_else(|| format!("body{b}")));
                for (i, a) in points.iter().enumerate() {
                    if a.element.is_some() {
                        pairs.push(Pair {
                            point: i,
                            other: Against::Point(j),
                            law,
                            channel,
                        });
                    }
                }
            }
        }
        let holds = pairs
            .iter()
            .any(|p| matches!(p.law.normal, Normal::Impulse { .. }));
        let set = Self {
            points,
            obstacles,
            pairs,
            channels,
            holds,
            state: RefCell::new(ContactState::default()),
            scratch: RefCell::new(Scratch::default()),
        };
        set.clear_records();
        set
    }

    /// A pair whose force depends on how it began (its impact speed), or
    /// that changes the velocities when it begins (impulse).
    pub fn keeps_record(&self, pair: usize) -> bool {
        matches!(
            self.pairs[pair].law.normal,
            Normal::HuntCrossley {
                damping: Damping::Restitution { .. },
                ..
            } | Normal::Impulse { .. }
        )
    }

    /// The impulse pairs held now.
    pub fn held_pairs(&self) -> Vec<usize> {
        if !self.any_held() {
            return Vec::new();
        }
        let state = self.state();
        (0..self.pairs.len())
            .filter(|&i| state.held.get(i) == Some(&true))
            .collect()
    }

    /// Some impulse pair is held (no copy of the state: the hot path asks).
    pub fn any_held(&self) -> bool {
        self.holds && self.state.borrow().held.iter().any(|&h| h)
    }

    /// Some pair keeps records: runs go in legs between contact switches.
    pub fn keeps_records(&self) -> bool {
        (0..self.pairs.len()).any(|i| self.keeps_record(i))
    }

    /// Bring the records up to the state at `forces`: a pair that keeps
    /// records and now touches (gap <= 0) without a record gets one, its
    /// speed of approach; one that no longer touches loses it; a held pair
    /// whose normal force (`held`: pair, force) no longer pushes is let go.
    /// Returns the pairs that began to touch (an impulse pair's impact is
    /// the caller's to apply; with e = 0 it is held from here).
    pub fn update_records(&self, forces: &[PairForce<f64>], held: &[(usize, f64)]) -> Vec<usize> {
        let mut state = self.state();
        let mut began = Vec::new();
        for &(i, f_n) in held {
            if f_n <= 0.0 {
                state.held[i] = false;
                state.touching[i] = false;
            }
        }
        for (i, f) in forces.iter().enumerate() {
            if !self.keeps_record(i) || state.held[i] {
                continue;
            }
            // Exactly at the surface, the pair touches if it approaches.
            let touches = f.gap < 0.0 || (f.gap == 0.0 && f.approach > 0.0);
            if touches && !state.touching[i] {
                state.impact[i] = f.approach.max(0.0);
                began.push(i);
                state.held[i] = impact::restitution(self, i) == Some(0.0);
            }
            state.touching[i] = touches || state.held[i];
        }
        self.set_state(state);
        began
    }

    /// Pair `i` touches, damped as an impact at `speed` at least
    /// (`settle::settling_speed`).
    pub fn touch_as_impact_at(&self, i: usize, speed: f64) {
        let mut state = self.state.borrow_mut();
        state.touching[i] = true;
        state.impact[i] = state.impact[i].max(speed);
    }

    /// A copy of the running state.
    pub fn state(&self) -> ContactState {
        self.state.borrow().clone()
    }

    /// Replace the running state (the contact driver, between legs).
    pub fn set_state(&self, s: ContactState) {
        *self.state.borrow_mut() = s;
    }

    /// Forget how the contacts began: nothing touching, no impact speeds,
    /// nothing held. A run continues the records the last run on this set
    /// left (a control loop's steps are one run); a run from a new start
    /// begins from these.
    pub fn clear_records(&self) {
        let n = self.pairs.len();
        self.set_state(ContactState {
            touching: vec![false; n],
            impact: vec![0.0; n],
            held: vec![false; n],
        });
    }
}

/// The points at one state: the `Contact` kernel's positions (or, on the
/// hot path of a chain with contact frames, none of them: the `Accel`
/// kernel's frames instead), and the `ContactJacobian` kernel's positions,
/// velocities and dp/dq for the groups of points asked for
/// (`velocities_of`): a right-hand side where nothing touches needs none,
/// one where the tip presses the tip's group alone.
#[derive(Debug)]
pub struct PointKinematics {
    n: usize,
    /// Every point's position (3 each), when `all_positions`.
    buf: Vec<f64>,
    all_positions: bool,
    /// The contact frames (`ModelInfo::contact_frames`; empty: none).
    frames: Vec<f64>,
    /// The groups' outputs, per point p (3), v (3), dp/dq (3 x n).
    jac: Vec<f64>,
    /// Each point's `ContactJacobian` group.
    group_of: Vec<usize>,
    /// The first point and count of each group.
    ranges: Vec<(usize, usize)>,
    /// Whether a group's outputs are in `jac` at this state.
    have: Vec<bool>,
    /// The groups to evaluate, as the kernel's `dir` reads them.
    mask: Vec<f64>,
}

impl PointKinematics {
    /// The positions of every point.
    pub fn eval<D: Dynamics + ?Sized>(d: &D, t: f64, q: &[f64], qd: &[f64]) -> Self {
        let mut k = Self::empty(d, q.len());
        k.update(d, t, q, qd);
        k
    }

    fn empty<D: Dynamics + ?Sized>(d: &D, n: usize) -> Self {
        let info = d.info();
        let ranges: Vec<(usize, usize)> = info.contact_group_ranges().collect();
        let mut group_of = Vec::with_capacity(info.contact_points);
        for (g, &(_, len)) in ranges.iter().enumerate() {
            group_of.extend(std::iter::repeat_n(g, len));
        }
        Self {
            n,
            buf: Vec::new(),
            all_positions: false,
            frames: vec![0.0; info.contact_frames],
            jac: vec![0.0; KernelKind::ContactJacobian.output_len(info)],
            group_of,
            have: vec![false; ranges.len()],
            ranges,
            mask: vec![0.0; 2 * n],
        }
    }

    /// Re-evaluate the positions into the same buffers; the groups'
    /// outputs are dropped.
    pub fn update<D: Dynamics + ?Sized>(&mut self, d: &D, t: f64, q: &[f64], qd: &[f64]) {
        self.update_from(d, t, q, qd, None);
    }

    /// `update`, from what the `Accel` kernel gives after its factors (the
    /// contact frames, or where the chain has none the positions), or
    /// else from the `Contact` kernel (every position, then the frames).
    fn update_from<D: Dynamics + ?Sized>(
        &mut self,
        d: &D,
        t: f64,
        q: &[f64],
        qd: &[f64],
        accel: Option<&[f64]>,
    ) {
        self.n = q.len();
        let info = d.info();
        match accel {
            Some(f) if info.contact_frames > 0 => {
                self.frames.copy_from_slice(f);
                self.all_positions = false;
            }
            Some(p) => {
                self.buf.clear();
                self.buf.extend_from_slice(p);
                self.all_positions = true;
            }
            None => {
                self.buf.resize(KernelKind::Contact.output_len(info), 0.0);
                d.eval_kernel(KernelKind::Contact, t, q, qd, &mut self.buf);
                let points = 3 * info.contact_points;
                self.frames.copy_from_slice(&self.buf[points..]);
                self.buf.truncate(points);
                self.all_positions = true;
            }
        }
        self.have.fill(false);
    }

    /// The contact frames' bounds alone, where the kernels give them
    /// without the points (`Dynamics::contact_bounds`): the broad phase then
    /// picks the groups to evaluate. False (nothing changed) where not.
    fn update_bounds<D: Dynamics + ?Sized>(
        &mut self,
        d: &D,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> bool {
        self.n = q.len();
        if self.frames.is_empty() || !d.contact_bounds(t, q, qd, &mut self.frames) {
            return false;
        }
        self.all_positions = false;
        self.have.fill(false);
        true
    }

    /// Positions, velocities and dp/dq.
    pub fn with_jacobian<D: Dynamics + ?Sized>(d: &D, t: f64, q: &[f64], qd: &[f64]) -> Self {
        let mut k = Self::eval(d, t, q, qd);
        k.velocities(d, t, q, qd);
        k
    }

    /// Evaluate every point's velocity and dp/dq (once).
    pub fn velocities<D: Dynamics + ?Sized>(&mut self, d: &D, t: f64, q: &[f64], qd: &[f64]) {
        self.velocities_of(d, t, q, qd, 0..self.group_of.len());
    }

    /// Evaluate the velocities and dp/dq of `points` (their groups, once).
    pub fn velocities_of<D: Dynamics + ?Sized>(
        &mut self,
        d: &D,
        t: f64,
        q: &[f64],
        qd: &[f64],
        points: impl IntoIterator<Item = usize>,
    ) {
        // Moved out while `groups` borrows the rest (no copy).
        let group_of = std::mem::take(&mut self.group_of);
        self.groups(d, t, q, qd, points.into_iter().map(|i| group_of[i]));
        self.group_of = group_of;
    }

    /// Evaluate `groups` (each once): positions, velocities and dp/dq.
    fn groups<D: Dynamics + ?Sized>(
        &mut self,
        d: &D,
        t: f64,
        q: &[f64],
        qd: &[f64],
        groups: impl IntoIterator<Item = usize>,
    ) {
        self.mask.fill(0.0);
        let mut any = false;
        for g in groups {
            if !self.have[g] {
                self.have[g] = true;
                self.mask[g] = 1.0;
                any = true;
            }
        }
        if any {
            d.eval_direction(
                KernelKind::ContactJacobian,
                t,
                q,
                qd,
                &self.mask,
                &self.frames,
                &mut self.jac,
            );
        }
    }

    /// Whether some point's velocity and dp/dq are there.
    pub fn has_velocity_any(&self) -> bool {
        self.have.iter().any(|&h| h)
    }

    /// Whether point i's velocity and dp/dq are there.
    pub fn has_velocity(&self, i: usize) -> bool {
        self.have[self.group_of[i]]
    }

    /// The points whose positions are there.
    fn known_points(&self) -> impl Iterator<Item = usize> + '_ {
        let all = self.all_positions;
        self.ranges
            .iter()
            .zip(&self.have)
            .filter(move |&(_, &have)| all || have)
            .flat_map(|(&(first, len), _)| first..first + len)
    }

    /// Whether point i's position is there (every point's, unless the
    /// state came from the contact frames: then its group's).
    pub fn has_position(&self, i: usize) -> bool {
        self.all_positions || self.has_velocity(i)
    }

    #[inline]
    pub fn position(&self, i: usize) -> [f64; 3] {
        // From the point's group where it ran (its position, velocity and
        // dp/dq from one evaluation), else from every point's.
        let b = match self.has_velocity(i) {
            true => &self.jac[i * self.width()..],
            false => {
                debug_assert!(self.all_positions, "point {i}'s position was not evaluated");
                &self.buf[3 * i..]
            }
        };
        [b[0], b[1], b[2]]
    }

    fn width(&self) -> usize {
        6 + 3 * self.n
    }

    /// (after `velocities` or `velocities_of` point i)
    pub fn velocity(&self, i: usize) -> [f64; 3] {
        debug_assert!(
            self.has_velocity(i),
            "point {i}'s velocity was not evaluated"
        );
        let b = &self.jac[i * self.width() + 3..];
        [b[0], b[1], b[2]]
    }

    /// Row c of dp/dq (after `velocities` or `velocities_of` point i).
    pub fn jacobian_row(&self, i: usize, c: usize) -> &[f64] {
        debug_assert!(
            self.has_velocity(i),
            "point {i}'s Jacobian was not evaluated"
        );
        let start = i * self.width() + 6 + c * self.n;
        &self.jac[start..start + self.n]
    }
}

/// Buffers of the right-hand side's contact forces, reused.
#[derive(Debug, Default)]
struct Scratch {
    points: Option<PointKinematics>,
    /// The pairs that penetrate.
    touching: Vec<usize>,
    broad: BroadPhase,
}

/// The broad phase's buffers.
#[derive(Debug, Default)]
struct BroadPhase {
    /// The groups it keeps.
    groups: Vec<usize>,
    /// Each group's largest radius.
    radius: Vec<f64>,
    /// The planes now: normal n and level n.x.
    planes: Vec<([f64; 3], f64)>,
    /// The other obstacles and their displacements now.
    others: Vec<(usize, [f64; 3])>,
}

/// A pair's state: gap, normal force, total force on the point (normal
/// plus friction), friction magnitude, and the normal speed of approach.
#[derive(Clone, Copy, Debug)]
pub struct PairForce<T> {
    pub gap: T,
    pub normal: T,
    pub force: V<T>,
    pub friction: T,
    pub approach: T,
    /// The power the contact dissipates (W): its normal force beyond the
    /// elastic part times the rate of penetration, and friction's.
    pub power: T,
}

/// The other side of a pair: its position and velocity offsets and radius.
struct Other<T> {
    p: V<T>,
    v: V<T>,
    radius: f64,
}

/// The force of `pair` with the point at (p, v) and the other side as
/// given.
fn pair_force<T: DualNum<Primitive = f64> + Copy>(
    set: &ContactSet,
    pair: &Pair,
    t: f64,
    p: V<T>,
    v: V<T>,
    other: Option<Other<T>>,
    v_in: f64,
) -> PairForce<T> {
    let r = set.points[pair.point].radius;
    let (dist, n, v_rel) = match (pair.other, other) {
        (Against::Obstacle(k), _) => {
            let o = &set.obstacles[k];
            let (offset, speed) = o.motion.as_ref().map_or(([0.0; 3], [0.0; 3]), |m| m.at(t));
            let (d, n) = o.shape.distance(p, offset);
            let v_rel = [0, 1, 2].map(|c| v[c] - speed[c]);
            (d - r, n, v_rel)
        }
        (Against::Point(_), Some(b)) => {
            let rel = [0, 1, 2].map(|c| p[c] - b.p[c]);
            let n = obstacle::unit(rel, [0.0, 0.0, 1.0]);
            let d = obstacle::norm(rel) - b.radius;
            let v_rel = [0, 1, 2].map(|c| v[c] - b.v[c]);
            (d - r, n, v_rel)
        }
        (Against::Point(_), None) => unreachable!("a point pair is evaluated with its other point"),
    };
    let v_n = v_rel[0] * n[0] + v_rel[1] * n[1] + v_rel[2] * n[2];
    let depth = -dist;
    let f_n = pair.law.normal_force(depth, -v_n, v_in);
    let v_t = [0, 1, 2].map(|c| v_rel[c] - v_n * n[c]);
    let f_t = pair.law.friction_force(f_n, v_t);
    let slip_power = f_t[0] * v_t[0] + f_t[1] * v_t[1] + f_t[2] * v_t[2];
    let damped = f_n - pair.law.elastic_force(depth);
    PairForce {
        gap: dist,
        normal: f_n,
        force: [0, 1, 2].map(|c| n[c] * f_n + f_t[c]),
        friction: obstacle::norm(f_t),
        approach: -v_n,
        power: damped * (-v_n) - slip_power,
    }
}

/// Every pair's force at (t, q, qd) (f64); the velocities are evaluated
/// when a pair penetrates (`all_velocities`: always, so that pairs apart
/// report their speed too).
pub fn pair_forces<D: Dynamics + ?Sized>(
    d: &D,
    set: &ContactSet,
    t: f64,
    q: &[f64],
    qd: &[f64],
    all_velocities: bool,
) -> Vec<PairForce<f64>> {
    let mut k = PointKinematics::eval(d, t, q, qd);
    if all_velocities {
        k.velocities(d, t, q, qd);
    }
    let mut out = Vec::new();
    pair_forces_into(d, set, &mut k, t, q, qd, &mut out);
    out
}

/// `pair_forces` on given kinematics into a reused buffer: the gaps from
/// the positions, and the forces of the pairs that penetrate (and of every
/// pair whose velocities are there), with the velocities of their points.
fn pair_forces_into<D: Dynamics + ?Sized>(
    d: &D,
    set: &ContactSet,
    k: &mut PointKinematics,
    t: f64,
    q: &[f64],
    qd: &[f64],
    out: &mut Vec<PairForce<f64>>,
) {
    out.clear();
    out.extend(set.pairs.iter().map(|pair| PairForce {
        gap: gap_of(set, pair, k, t),
        normal: 0.0,
        force: [0.0; 3],
        friction: 0.0,
        approach: 0.0,
        power: 0.0,
    }));
    if out.iter().all(|f| f.gap >= 0.0) && !k.has_velocity_any() {
        return;
    }
    let touching = set
        .pairs
        .iter()
        .zip(out.iter())
        .filter(|(_, f)| f.gap < 0.0)
        .flat_map(|(pair, _)| std::iter::once(pair.point).chain(pair.other_point()));
    k.velocities_of(d, t, q, qd, touching);
    let state = set.state.borrow();
    for (i, pair) in set.pairs.iter().enumerate() {
        let known = |p: usize| k.has_velocity(p);
        if !known(pair.point) || !pair.other_point().is_none_or(known) {
            continue;
        }
        let other = pair.other_point().map(|j| Other {
            p: k.position(j),
            v: k.velocity(j),
            radius: set.points[j].radius,
        });
        let v_in = state.impact.get(i).copied().unwrap_or(0.0);
        out[i] = pair_force(
            set,
            pair,
            t,
            k.position(pair.point),
            k.velocity(pair.point),
            other,
            v_in,
        );
    }
}

/// The groups whose points may touch something, into `out`, from the
/// contact frames' bounds (`Shape::clears`): the hot path of a chain with
/// frames, where no point's position is known before its group runs. A
/// group may touch an obstacle unless its ellipsoid clears it by the
/// points' largest radius; two groups (self contact) unless their spheres
/// do.
fn broad_phase(set: &ContactSet, k: &PointKinematics, t: f64, s: &mut BroadPhase) {
    s.groups.clear();
    let groups = k.ranges.len();
    if s.radius.len() != groups {
        s.radius = k
            .ranges
            .iter()
            .map(|&(first, len)| {
                set.points[first..first + len]
                    .iter()
                    .fold(0.0, |r: f64, p| r.max(p.radius))
            })
            .collect();
    }
    // Planes as n.x = level now; the other shapes with their offsets.
    s.planes.clear();
    s.others.clear();
    for (i, o) in set.obstacles.iter().enumerate() {
        let offset = o.motion.as_ref().map_or([0.0; 3], |m| m.at(t).0);
        match &o.shape {
            Shape::Plane { point, normal } => s.planes.push((
                *normal,
                obstacle::dot(*normal, *point) + obstacle::dot(*normal, offset),
            )),
            _ => s.others.push((i, offset)),
        }
    }
    let bounds = k.frames[..CONTACT_BOUND * groups].chunks_exact(CONTACT_BOUND);
    for (g, (b, &r)) in bounds.zip(&s.radius).enumerate() {
        let (a, e, l) = ([b[0], b[1], b[2]], [b[3], b[4], b[5]], b[6]);
        // Rounding of the frames' own arithmetic, far below any radius.
        let margin = r + 1e-9 * l.abs();
        let near = s
            .planes
            .iter()
            .any(|&(n, level)| !obstacle::plane_clears(n, level, a, e, l, margin))
            || s.others
                .iter()
                .any(|&(i, offset)| !set.obstacles[i].shape.clears(offset, a, e, l, margin));
        if near {
            s.groups.push(g);
        }
    }
    if set.pairs.len() > set.points.len() * set.obstacles.len() {
        let sphere = |g: usize| {
            let b = &k.frames[CONTACT_BOUND * g..];
            let m = [0, 1, 2].map(|i| 0.5 * (b[i] + b[3 + i]));
            (m, 0.5 * b[6].abs() + s.radius[g] + 1e-9 * b[6].abs())
        };
        for g in 0..groups {
            let (m, r) = sphere(g);
            for h in g + 1..groups {
                let (n, rh) = sphere(h);
                let between: f64 = (0..3).map(|i| (m[i] - n[i]).powi(2)).sum();
                if between <= (r + rh).powi(2) {
                    s.groups.extend([g, h]);
                }
            }
        }
    }
}

/// The pairs that penetrate, in order, into `out`: every right-hand side
/// asks, so a fixed plane (every point against it, the common obstacle)
/// is one tight loop over the points, the other pairs one by one. The
/// pairs begin with every point against every obstacle, point-major.
fn penetrating(set: &ContactSet, k: &PointKinematics, t: f64, out: &mut Vec<usize>) {
    out.clear();
    let no = set.obstacles.len();
    for (ko, o) in set.obstacles.iter().enumerate() {
        if let (Shape::Plane { point, normal }, None) = (&o.shape, &o.motion) {
            let c = point[0] * normal[0] + point[1] * normal[1] + point[2] * normal[2];
            if k.all_positions {
                for (i, (p, pt)) in k.buf.chunks_exact(3).zip(&set.points).enumerate() {
                    if p[0] * normal[0] + p[1] * normal[1] + p[2] * normal[2] - pt.radius < c {
                        out.push(i * no + ko);
                    }
                }
                continue;
            }
        }
        for i in k.known_points() {
            if gap_of(set, &set.pairs[i * no + ko], k, t) < 0.0 {
                out.push(i * no + ko);
            }
        }
    }
    let first = set.points.len() * no;
    out.extend((first..set.pairs.len()).filter(|&i| {
        let pair = &set.pairs[i];
        k.has_position(pair.point)
            && pair.other_point().is_none_or(|j| k.has_position(j))
            && gap_of(set, pair, k, t) < 0.0
    }));
    if no > 1 {
        out.sort_unstable();
    }
}

/// A pair's gap from the positions alone: every pair, every right-hand
/// side, so a fixed plane (the common obstacle) takes the short way.
#[inline]
fn gap_of(set: &ContactSet, pair: &Pair, k: &PointKinematics, t: f64) -> f64 {
    let p = k.position(pair.point);
    let r = set.points[pair.point].radius;
    match pair.other {
        Against::Obstacle(o) => {
            let ob = &set.obstacles[o];
            if let (Shape::Plane { point, normal }, None) = (&ob.shape, &ob.motion) {
                return (p[0] - point[0]) * normal[0]
                    + (p[1] - point[1]) * normal[1]
                    + (p[2] - point[2]) * normal[2]
                    - r;
            }
            let offset = ob.motion.as_ref().map_or([0.0; 3], |m| m.at(t).0);
            ob.shape.distance(p, offset).0 - r
        }
        Against::Point(j) => {
            let b = k.position(j);
            let d = [0, 1, 2].map(|c| p[c] - b[c]);
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - set.points[j].radius - r
        }
    }
}

/// Add the generalised contact force Q_c = sum J^T f to `q_force`.
pub fn generalised_force(
    set: &ContactSet,
    k: &PointKinematics,
    forces: &[PairForce<f64>],
    q_force: &mut [f64],
) {
    for (pair, f) in set.pairs.iter().zip(forces) {
        if f.normal == 0.0 {
            continue;
        }
        add_jt(k, pair.point, f.force, 1.0, q_force);
        if let Against::Point(j) = pair.other {
            add_jt(k, j, f.force, -1.0, q_force);
        }
    }
}

fn add_jt(k: &PointKinematics, i: usize, f: [f64; 3], sign: f64, out: &mut [f64]) {
    for (c, fc) in f.iter().enumerate() {
        for (o, j) in out.iter_mut().zip(k.jacobian_row(i, c)) {
            *o += sign * fc * j;
        }
    }
}

/// Subtract Q_c from h (a contact force is an applied force): `h` as the
/// `MassBias` kernel gives it, at (t, q, qd).
pub fn subtract_from_bias<D: Dynamics + ?Sized>(
    d: &D,
    t: f64,
    q: &[f64],
    qd: &[f64],
    h: &mut [f64],
) {
    let mut q_force = vec![0.0; q.len()];
    if generalised_force_at(d, t, q, qd, None, &mut q_force) {
        for (h, f) in h.iter_mut().zip(&q_force) {
            *h -= f;
        }
    }
}

/// Q_c at (t, q, qd) into `q_force`; false (`q_force` then not Q_c) when
/// no pair pushes. `accel`: what the `Accel` kernel gives after its
/// factors when the caller has it (the contact frames, or the points'
/// positions), else the `Contact` kernel runs. The hot path: buffers are
/// reused; with frames, the groups the broad phase keeps are evaluated,
/// else the groups of the points that penetrate, no others.
pub fn generalised_force_at<D: Dynamics + ?Sized>(
    d: &D,
    t: f64,
    q: &[f64],
    qd: &[f64],
    accel: Option<&[f64]>,
    q_force: &mut [f64],
) -> bool {
    let Some(set) = d.contact() else {
        return false;
    };
    // Not re-entered: nothing below evaluates contact forces.
    let mut guard = set.scratch.borrow_mut();
    let s = &mut *guard;
    let k = s
        .points
        .get_or_insert_with(|| PointKinematics::empty(d, q.len()));
    if accel.is_some() || !k.update_bounds(d, t, q, qd) {
        k.update_from(d, t, q, qd, accel);
    }
    // From the contact frames: the elements that may touch, and their
    // points alone.
    if !k.all_positions {
        broad_phase(set, k, t, &mut s.broad);
        if s.broad.groups.is_empty() {
            return false;
        }
        k.groups(d, t, q, qd, s.broad.groups.iter().copied());
    }
    // Most right-hand sides touch nothing: a gap check and out.
    penetrating(set, k, t, &mut s.touching);
    if s.touching.is_empty() {
        return false;
    }
    let points = s.touching.iter().flat_map(|&i| {
        let pair = &set.pairs[i];
        std::iter::once(pair.point).chain(pair.other_point())
    });
    k.velocities_of(d, t, q, qd, points);
    let state = set.state.borrow();
    q_force.fill(0.0);
    let mut pushes = false;
    for &i in &s.touching {
        let pair = &set.pairs[i];
        let other = pair.other_point().map(|j| Other {
            p: k.position(j),
            v: k.velocity(j),
            radius: set.points[j].radius,
        });
        let v_in = state.impact.get(i).copied().unwrap_or(0.0);
        let (p, v) = (k.position(pair.point), k.velocity(pair.point));
        let f = pair_force(set, pair, t, p, v, other, v_in);
        if f.normal != 0.0 {
            pushes = true;
            add_jt(k, pair.point, f.force, 1.0, q_force);
            if let Some(j) = pair.other_point() {
                add_jt(k, j, f.force, -1.0, q_force);
            }
        }
    }
    pushes
}

/// Subtract dQ_c/dq and dQ_c/dqd from the Jacobian parts of tau
/// (row-major n x n each, as `Dynamics::jacobian_parts` lays them out):
/// the force's own derivative J^T df by dual numbers, and along q the
/// turning of J itself, dJ^T f, from the `ContactJvp` kernel.
pub fn subtract_from_jacobian<D: Dynamics + ?Sized>(
    d: &D,
    t: f64,
    q: &[f64],
    qd: &[f64],
    parts: &mut [f64],
) {
    let Some(set) = d.contact() else { return };
    let n = q.len();
    let mut k = PointKinematics::with_jacobian(d, t, q, qd);
    let mut forces = Vec::new();
    pair_forces_into(d, set, &mut k, t, q, qd, &mut forces);
    // Only touching pairs have force or derivative.
    let active: Vec<usize> = (0..set.pairs.len())
        .filter(|&i| forces[i].gap < 0.0)
        .collect();
    if active.is_empty() {
        return;
    }
    let state = set.state();
    let width = 3 + 3 * n;
    let mut tangent = vec![0.0; KernelKind::ContactJvp.output_len(d.info())];
    let mut col = vec![0.0; n];
    for j in 0..2 * n {
        let along_q = j < n;
        if along_q {
            let mut dir = vec![0.0; 2 * n];
            dir[j] = 1.0;
            d.eval_direction(KernelKind::ContactJvp, t, q, qd, &dir, &[], &mut tangent);
        }
        col.fill(0.0);
        for &i in &active {
            let pair = &set.pairs[i];
            // The point's (p, v) and their derivatives along this column.
            let lift = |pt: usize| -> (V<Dual64>, V<Dual64>, Option<&[f64]>) {
                let (p, v) = (k.position(pt), k.velocity(pt));
                if along_q {
                    let tb = &tangent[pt * width..(pt + 1) * width];
                    let dp = [0, 1, 2].map(|c| k.jacobian_row(pt, c)[j]);
                    (
                        [0, 1, 2].map(|c| Dual64::new(p[c], dp[c])),
                        [0, 1, 2].map(|c| Dual64::new(v[c], tb[c])),
                        Some(&tb[3..]),
                    )
                } else {
                    let jj = j - n;
                    let dv = [0, 1, 2].map(|c| k.jacobian_row(pt, c)[jj]);
                    (
                        p.map(Dual64::from),
                        [0, 1, 2].map(|c| Dual64::new(v[c], dv[c])),
                        None,
                    )
                }
            };
            let (p, v, dj_a) = lift(pair.point);
            let (other, dj_b) = match pair.other {
                Against::Point(b) => {
                    let (pb, vb, dj) = lift(b);
                    let radius = set.points[b].radius;
                    (
                        Some(Other {
                            p: pb,
                            v: vb,
                            radius,
                        }),
                        dj,
                    )
                }
                Against::Obstacle(_) => (None, None),
            };
            let v_in = state.impact.get(i).copied().unwrap_or(0.0);
            let f = pair_force(set, pair, t, p, v, other, v_in);
            let f_re = f.force.map(|c| c.re);
            let df = f.force.map(|c| c.eps);
            add_jt(&k, pair.point, df, 1.0, &mut col);
            if let Some(dj) = dj_a {
                add_djt(dj, n, f_re, 1.0, &mut col);
            }
            if let Against::Point(b) = pair.other {
                add_jt(&k, b, df, -1.0, &mut col);
                if let Some(dj) = dj_b {
                    add_djt(dj, n, f_re, -1.0, &mut col);
                }
            }
        }
        let (part, c) = if along_q { (0, j) } else { (1, j - n) };
        for (r, v) in col.iter().enumerate() {
            parts[part * n * n + r * n + c] -= v;
        }
    }
}

/// dJ^T f for the directional derivative dJ (3 x n, row-major).
fn add_djt(dj: &[f64], n: usize, f: [f64; 3], sign: f64, out: &mut [f64]) {
    for (c, fc) in f.iter().enumerate() {
        for (o, j) in out.iter_mut().zip(&dj[c * n..(c + 1) * n]) {
            *o += sign * fc * j;
        }
    }
}

/// Per output channel, the total normal and friction force magnitudes.
pub fn channel_forces(set: &ContactSet, forces: &[PairForce<f64>]) -> Vec<(f64, f64)> {
    let mut out = vec![(0.0, 0.0); set.channels.len()];
    for (pair, f) in set.pairs.iter().zip(forces) {
        out[pair.channel].0 += f.normal;
        out[pair.channel].1 += f.friction;
    }
    out
}

/// Each channel's total normal and friction force at (t, q, qd), flattened
/// (normal, friction, normal, ...), under the run's contact state as it
/// is now: held contacts carry their constraint force.
pub fn channel_columns<D: Dynamics + ?Sized>(
    d: &D,
    set: &ContactSet,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> Vec<f64> {
    let forces = pair_forces(d, set, t, q, qd, false);
    let mut channels = channel_forces(set, &forces);
    let held = set.held_pairs();
    if !held.is_empty()
        && let Ok((_, f)) = impact::held_accelerations(d, set, t, q, qd, &held)
    {
        for (&i, f) in held.iter().zip(f) {
            channels[set.pairs[i].channel].0 += f;
        }
    }
    channels.into_iter().flat_map(|(n, f)| [n, f]).collect()
}

/// `traj.contact` for the samples from `from` on (`channel_columns` under
/// the contact state they ran with).
pub fn record_columns<D: Dynamics + ?Sized>(
    d: &D,
    set: &ContactSet,
    traj: &mut crate::Trajectory,
    from: usize,
) {
    let n = d.dof();
    traj.contact.truncate(from);
    for (t, x) in traj.t[from..].iter().zip(&traj.x[from..]) {
        let c = channel_columns(d, set, *t, &x[..n], &x[n..2 * n]);
        traj.contact.push(c);
    }
}

/// The contact switch: over the pairs that keep records, the gap of those
/// apart, minus the gap of those touching, and the normal force of those
/// held, the least. It falls through zero when a pair begins or ends to
/// touch, or a held one would pull, where the run stops to update the
/// records.
pub fn switching_gap<D: Dynamics + ?Sized>(
    d: &D,
    set: &ContactSet,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> f64 {
    let forces = pair_forces(d, set, t, q, qd, false);
    let state = set.state();
    let held = set.held_pairs();
    let pushing = if held.is_empty() {
        f64::INFINITY
    } else {
        impact::held_accelerations(d, set, t, q, qd, &held).map_or(f64::NEG_INFINITY, |(_, f)| {
            f.into_iter().fold(f64::INFINITY, f64::min)
        })
    };
    forces
        .iter()
        .enumerate()
        .filter(|(i, _)| set.keeps_record(*i) && !state.held[*i])
        .map(|(i, f)| if state.touching[i] { -f.gap } else { f.gap })
        .fold(pushing, f64::min)
}

/// The power the contacts dissipate (W), the deepest penetration (m) and
/// the sum of the normal forces (N) at (t, q, qd): what `SimStats::contact`
/// meters.
pub fn meter_sample<D: Dynamics + ?Sized>(
    d: &D,
    set: &ContactSet,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> crate::MeterSample {
    let forces = pair_forces(d, set, t, q, qd, false);
    crate::MeterSample {
        power_w: forces.iter().map(|f| f.power).sum(),
        depth_m: forces.iter().map(|f| -f.gap).fold(0.0, f64::max),
        normal_n: forces.iter().map(|f| f.normal).sum(),
    }
}

/// The energy stored in the contacts' elastic parts (J) at (t, q, qd):
/// with the arm's kinetic and potential energy, the total that only
/// dissipation lowers.
pub fn potential_energy<D: Dynamics + ?Sized>(
    d: &D,
    set: &ContactSet,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> f64 {
    let forces = pair_forces(d, set, t, q, qd, false);
    set.pairs
        .iter()
        .zip(&forces)
        .map(|(pair, f)| pair.law.potential(-f.gap))
        .sum()
}
