//! `rom`: a reduced-order model. Curvature, twist, stretch and shear are
//! polynomials in s of degree `order` (the variable-strain rod of SoRoSim), their coefficients the segment's
//! coordinates; kinematics, masses and energies by `quadrature` slices,
//! each a constant-strain arc of the fields integrated over it; the strain
//! energy integrated exactly. 3D only.

use super::{ModellingMethod, needs_bending_stiffness};
use crate::cas::{Cas, ExprId};
use crate::model::{Check, ElementParam, ModelError, Segment, SegmentShape};
use crate::tmt::actuation::{Strain, thinning};
use crate::tmt::cell_kind::{CellKind, PointsOn};
use crate::tmt::spatial::{ArcStrain, SpatialArm, V3, arc, bind3, half_k_sq, mid_arc_rotation};
use crate::tmt::system::{Coordinates, ParamSymbols};

pub(super) struct Rom;

impl ModellingMethod for Rom {
    fn slices(&self, s: &Segment) -> usize {
        s.quadrature.unwrap_or(4 * (s.rom_order() + 1))
    }

    fn polynomial_fields(&self) -> bool {
        true
    }

    /// A slice is two half-arcs (`RomFields::halves`).
    fn cell_kind(&self, _g: &SegmentShape, _spatial: bool) -> CellKind {
        CellKind::HalfArc
    }

    fn own_keys(&self) -> &'static [&'static str] {
        &["order", "quadrature"]
    }

    fn spatial_only(&self) -> bool {
        true
    }

    fn check_keys(&self, ck: &Check, i: usize, s: &Segment) -> Result<(), ModelError> {
        needs_bending_stiffness(ck, i, s)?;
        if s.rom_order() > 8 {
            return ck.err(
                format!("segment[{i}].order"),
                format!(
                    "must be between 0 and 8 (the polynomial degree of the strains), got {}",
                    s.rom_order()
                ),
            );
        }
        if s.slices() == 0 || s.slices() > 64 {
            return ck.err(
                format!("segment[{i}].quadrature"),
                format!("must be between 1 and 64 slices, got {}", s.slices()),
            );
        }
        Ok(())
    }

    fn coordinate_names(&self, g: &SegmentShape, s: usize) -> Vec<String> {
        let mut names = Vec::new();
        for field in g.strain_fields() {
            names.extend((0..=g.order).map(|i| format!("{field}_{s}_c{i}")));
        }
        names
    }

    fn build_spatial(&self, cas: &mut Cas, arm: &mut SpatialArm, g: &SegmentShape, s: usize) {
        // The segment's coefficients, shared by its slices, and its strain
        // energy integrated exactly.
        let rom = RomFields::of(g, arm.c);
        arm.c += rom.coordinates();
        arm.shared_coordinates = true;
        let [e, d] = rom.energies(cas, &arm.coords, arm.symbols, arm.k);
        arm.elastic.push(e);
        arm.rayleigh.push(d);
        for e in 0..g.elements {
            let el = arm.element();
            let first = arm.c;
            let p = |q| arm.symbols.element(arm.k, q);
            let kb = p(ElementParam::BendStiffness);
            let kb_y = (arm.symbols).element_or(arm.k, ElementParam::BendStiffnessY, kb);
            let kt = p(ElementParam::TwistStiffness);
            let rest = p(ElementParam::Rest);
            // The slice by its two half-arcs (`RomFields::halves`): each
            // turns by half its link coordinates and carries half the
            // slice's mass, as the link cells have them.
            let mut arcs = Vec::with_capacity(2);
            for h in 0..2 {
                let (rho, rate, st, shear) = rom.half(cas, &arm.coords, e, h, el.l);
                let len = cas.add(el.l, st);
                // Incompressible: bending and twist energy half by half
                // with the half's thinning (`RomFields::energies` leaves
                // them out); each half holds half the slice's energy.
                let thin = rom.incompressible.then(|| {
                    let (soft, off) = thinning(cas, el.l, len);
                    let bz = cas.sub(rho[2], rest);
                    for (kk, x) in [(kb_y, rho[1]), (kb, bz), (kt, rho[0])] {
                        let share = cas.constant(0.5);
                        let kk = cas.mul_all(&[kk, soft, share]);
                        arm.elastic.push(half_k_sq(cas, kk, x));
                    }
                    off
                });
                // The actuators' work is linear in the strain: half of it
                // on each half's coordinates.
                arm.strains.push(Strain {
                    segment: s,
                    element: arm.k,
                    stretch: cas.scaled(0.5, st),
                    rho: rho.map(|x| cas.scaled(0.5, x)),
                    offset_scale: thin,
                });
                let strain = ArcStrain {
                    rho,
                    rate,
                    len,
                    shear,
                };
                arcs.push(strain.part(cas, 0.5));
            }
            let [a, b] = [arcs[0], arcs[1]];
            let f = arm.f;
            let middle = arc(cas, &f, &a).3;
            arm.sample(cas, None, |cas, s| match s <= 0.5 {
                true => {
                    let part = a.part(cas, 2.0 * s);
                    arc(cas, &f, &part).3
                }
                false => {
                    let part = b.part(cas, 2.0 * s - 1.0);
                    arc(cas, &middle, &part).3
                }
            });
            let body = el.half(cas);
            for part in [a, b] {
                let (centroid, axis, omega, end) = arc(cas, &arm.f, &part);
                let centroid = bind3(cas, centroid);
                let turn = (axis, mid_arc_rotation(&arm.f, &part));
                arm.bodies.push(body.body(cas, turn, centroid, omega, body.m));
                arm.f = end;
            }
            arm.close_link(first);
        }
    }

    fn link_cells(&self) -> bool {
        true
    }

    fn points_on_links(&self, _g: &SegmentShape, _spatial: bool) -> Option<PointsOn> {
        Some(PointsOn::Arcs)
    }
}

/// A rom segment: strain fields sum_i c_i P_i(sigma) over sigma = s / L in
/// [0, 1], P_i the Legendre polynomials shifted to [0, 1] (orthogonal:
/// int P_i P_j = delta_ij / (2 i + 1)), the coefficients c (angles:
/// curvature times L; the stretch field is dimensionless) its
/// coordinates, field by field. The monomials sigma^i span the same
/// fields, but their Gram matrix (the Hilbert matrix) is ill-conditioned
/// past order 5: the mass matrix inherits it and the step control stalls
/// (docs/validation.md, the rom conditioning table).
#[derive(Clone)]
#[doc(hidden)] // white-box tests (tests/suite)
pub struct RomFields {
    pub first: usize,
    pub order: usize,
    pub slices: usize,
    pub twist: bool,
    pub extension: bool,
    pub shear: bool,
    /// Bending and twist energy by slices (see `Rom::build_spatial`), not here.
    pub incompressible: bool,
    /// The section varies along the segment: each slice's stiffness over
    /// its own part of the fields (`slice_gram`), not the first slice's
    /// over the whole.
    pub varying: bool,
}

impl RomFields {
    /// The rom of segment shape `g` whose coefficients start at `first`.
    pub(crate) fn of(g: &crate::model::SegmentShape, first: usize) -> Self {
        RomFields {
            first,
            order: g.order,
            slices: g.elements,
            twist: g.twist,
            extension: g.extension,
            shear: g.shear,
            incompressible: g.incompressible,
            varying: g.varying,
        }
    }

    /// Slice e's Gram matrix of the Legendre polynomials, int P_i P_j d
    /// sigma over its part of [0, 1], by the Gauss rule of order + 1
    /// points (exact for their degree 2 order): summed over the slices,
    /// delta_ij / (2 i + 1).
    pub fn slice_gram(&self, e: usize) -> Vec<Vec<f64>> {
        let n = self.slices as f64;
        let (a, b) = (e as f64 / n, (e + 1) as f64 / n);
        let mut g = vec![vec![0.0; self.order + 1]; self.order + 1];
        for (y, w) in gauss_legendre(self.order + 1) {
            let p = legendre(self.order, 2.0 * (a + (b - a) * 0.5 * (y + 1.0)) - 1.0);
            for i in 0..=self.order {
                for j in 0..=self.order {
                    g[i][j] += 0.5 * (b - a) * w * p[i] * p[j];
                }
            }
        }
        g
    }

    pub(crate) fn coordinates(&self) -> usize {
        self.fields() * (self.order + 1)
    }

    /// The strain fields: bend y, bend z, then twist, stretch and the two
    /// shears where present.
    pub(crate) fn fields(&self) -> usize {
        2 + usize::from(self.twist) + usize::from(self.extension) + 2 * usize::from(self.shear)
    }

    /// Whether field f is a translation strain (stretch or shear,
    /// dimensionless) rather than an angle.
    pub(crate) fn is_translation(&self, f: usize) -> bool {
        f >= 2 + usize::from(self.twist)
    }

    /// Coordinate index of coefficient i of field f.
    pub(crate) fn index(&self, f: usize, i: usize) -> usize {
        self.first + f * (self.order + 1) + i
    }

    /// The link weights of slice e's two half-arcs: the slice is
    /// integrated by the commutator-free Magnus method of order four
    /// (Blanes and Moan 2006), exp(l (a1 xi1 + a2 xi2)) then
    /// exp(l (a2 xi1 + a1 xi2)) with xi1, xi2 the strains at the slice's two Gauss points
    /// and a1, a2 = 1/4 +- sqrt(3)/6: linear in the strains, so each
    /// exponential is a constant-strain arc whose strain a link map carries,
    /// and the pose error falls as slices^-4 where one arc of the slice's
    /// mean strain leaves slices^-2 (the commutator of the strain and its
    /// gradient). A half-arc turns by half its coordinates, so half h's
    /// weight of P_i is 2 (b - a) (a1 P_i(s1) + a2 P_i(s2)) over the slice
    /// [a, b] of sigma (the first half; a1 and a2 swap for the second).
    pub fn halves(&self, e: usize) -> [Vec<f64>; 2] {
        let n = self.slices as f64;
        let (a, b) = (e as f64 / n, (e + 1) as f64 / n);
        let r = 3f64.sqrt() / 6.0;
        let at = |c: f64| legendre(self.order, 2.0 * (a + (b - a) * c) - 1.0);
        let (p1, p2) = (at(0.5 - r), at(0.5 + r));
        let (w1, w2) = (0.5 + 2.0 * r, 0.5 - 2.0 * r);
        let weights = |u: f64, v: f64| -> Vec<f64> {
            (0..=self.order)
                .map(|i| (b - a) * (u * p1[i] + v * p2[i]))
                .collect()
        };
        [weights(w1, w2), weights(w2, w1)]
    }

    /// One field by weights `w` of its coefficients, of q (or, with
    /// `rates`, of qd).
    fn field(
        &self,
        cas: &mut Cas,
        coords: &Coordinates,
        f: usize,
        w: &[f64],
        rates: bool,
    ) -> ExprId {
        let terms: Vec<ExprId> = w
            .iter()
            .enumerate()
            .map(|(i, &w)| {
                let j = self.index(f, i);
                let x = if rates { coords.qd[j] } else { coords.q[j] };
                cas.scaled(w, x)
            })
            .collect();
        cas.add_all(&terms)
    }

    /// The coordinates of half h of slice e's link pair (`halves`): the
    /// rotation vector (twist, bend y, bend z), its rate, the stretch and
    /// the shear displacements, given the slice length l.
    pub(crate) fn half(
        &self,
        cas: &mut Cas,
        coords: &Coordinates,
        e: usize,
        h: usize,
        l: ExprId,
    ) -> (V3, V3, ExprId, Option<[ExprId; 2]>) {
        let w = &self.halves(e)[h];
        let zero = cas.zero();
        let mut rho = [zero; 3];
        let mut rate = [zero; 3];
        // Fields 0, 1 bend about y, z; then twist (about x); then stretch.
        for (f, axis) in [(0, 1), (1, 2)] {
            rho[axis] = self.field(cas, coords, f, w, false);
            rate[axis] = self.field(cas, coords, f, w, true);
        }
        if self.twist {
            rho[0] = self.field(cas, coords, 2, w, false);
            rate[0] = self.field(cas, coords, 2, w, true);
        }
        // A translation strain's weights are in sigma: times L = slices *
        // l, a displacement.
        let mut displacement = |f: usize| {
            let s = self.field(cas, coords, f, w, false);
            let ls = cas.mul(l, s);
            cas.scaled(self.slices as f64, ls)
        };
        let after_twist = 2 + usize::from(self.twist);
        let stretch = match self.extension {
            true => displacement(after_twist),
            false => zero,
        };
        let first_shear = after_twist + usize::from(self.extension);
        let shear = self
            .shear
            .then(|| [displacement(first_shear), displacement(first_shear + 1)]);
        (
            rho.map(|x| cas.bind(x)),
            rate.map(|x| cas.bind(x)),
            stretch,
            shear,
        )
    }

    /// Strain energy and Rayleigh function, integrated exactly:
    /// (k / 2) int_0^1 (field - rest)^2 d sigma with int P_i P_j = delta_ij /
    /// (2 i + 1). Per-slice parameters of slice k: E I / l = slices E I / L.
    pub(crate) fn energies(
        &self,
        cas: &mut Cas,
        coords: &Coordinates,
        symbols: &ParamSymbols,
        k: usize,
    ) -> [ExprId; 2] {
        let n = self.slices as f64;
        let grams: Vec<Vec<Vec<f64>>> = match self.varying {
            true => (0..self.slices).map(|e| self.slice_gram(e)).collect(),
            false => Vec::new(),
        };
        let none = |_: usize| None;
        let (mut elastic, mut rayleigh) = (Vec::new(), Vec::new());
        let first_shear = 2 + usize::from(self.twist) + usize::from(self.extension);
        for f in 0..self.fields() {
            let stretch = self.is_translation(f);
            if self.incompressible && !stretch {
                // Only the elastic part moves to the slices; damping stays.
                let ds = symbols.element(
                    k,
                    match f {
                        0 | 1 => ElementParam::BendDamping,
                        _ => ElementParam::TwistDamping,
                    },
                );
                let xd: Vec<ExprId> = (0..=self.order)
                    .map(|i| coords.qd[self.index(f, i)])
                    .collect();
                let scale = cas.constant(1.0 / n);
                rayleigh.push(quadratic(cas, &grams, &xd, &|_| ds, &none, scale));
                continue;
            }
            // Shear rates damped as the stretch's, as pcs has them.
            let (stiff, damp) = match f {
                _ if stretch && f >= first_shear => {
                    (ElementParam::ShearStiffness, ElementParam::StretchDamping)
                }
                _ if stretch => (ElementParam::StretchStiffness, ElementParam::StretchDamping),
                0 | 1 => (ElementParam::BendStiffness, ElementParam::BendDamping),
                _ => (ElementParam::TwistStiffness, ElementParam::TwistDamping),
            };
            // An anisotropic section's bend about y (field 0) and shear
            // along z (the second shear field) its own.
            let ks = |e: usize| {
                let own = match f {
                    0 => ElementParam::BendStiffnessY,
                    _ if stretch && f == first_shear + 1 => ElementParam::ShearStiffnessZ,
                    _ => return symbols.element(k + e, stiff),
                };
                symbols.element_or(k + e, own, symbols.element(k + e, stiff))
            };
            let ds = |e: usize| symbols.element(k + e, damp);
            // Bending, twist: (E I / L) c^T G c = (k_slice / n) ...; stretch
            // and shear: E A L e^T G e = k_slice n l^2 ....
            let scale = if stretch {
                let l = symbols.element(k, ElementParam::Length);
                let l2 = cas.powi(l, 2);
                cas.scaled(n, l2)
            } else {
                cas.constant(1.0 / n)
            };
            let x: Vec<ExprId> = (0..=self.order)
                .map(|i| coords.q[self.index(f, i)])
                .collect();
            // The field's value at rest, constant over each slice: an angle
            // field's kappa0 L = n rest, a translation field's the strain.
            let extension_at = 2 + usize::from(self.twist);
            let rest_param = match f {
                0 => Some(ElementParam::RestY),
                1 => Some(ElementParam::Rest),
                _ if !stretch => Some(ElementParam::RestTwist),
                _ if self.extension && f == extension_at => Some(ElementParam::RestStretch),
                _ => None,
            };
            let zero = cas.zero();
            let rests: Vec<Option<ExprId>> = (0..self.slices)
                .map(|e| {
                    let r = symbols.element_or(k + e, rest_param?, zero);
                    if r == zero {
                        return None;
                    }
                    Some(match stretch {
                        true => {
                            let l = symbols.element(k + e, ElementParam::Length);
                            let inv = cas.powi(l, -1);
                            cas.mul(r, inv)
                        }
                        false => cas.scaled(n, r),
                    })
                })
                .collect();
            let xd: Vec<ExprId> = (0..=self.order)
                .map(|i| coords.qd[self.index(f, i)])
                .collect();
            let rest = |e: usize| rests[e];
            elastic.push(quadratic(cas, &grams, &x, &ks, &rest, scale));
            rayleigh.push(quadratic(cas, &grams, &xd, &ds, &none, scale));
        }
        let e = cas.add_all(&elastic);
        let d = cas.add_all(&rayleigh);
        [cas.scaled(0.5, e), cas.scaled(0.5, d)]
    }
}

/// per x^T G x scale over the whole segment (G diagonal: the Legendre
/// polynomials' Gram matrix), or, given each slice's Gram matrix `grams`
/// (a varying section), the sum of each slice's parameter `per(e)` on its
/// own part; x's first coefficient less the slice's `rest(e)`.
fn quadratic(
    cas: &mut Cas,
    grams: &[Vec<Vec<f64>>],
    x: &[ExprId],
    per: &dyn Fn(usize) -> ExprId,
    rest: &dyn Fn(usize) -> Option<ExprId>,
    scale: ExprId,
) -> ExprId {
    let less_rest = |cas: &mut Cas, e: usize| -> Vec<ExprId> {
        let mut x = x.to_vec();
        if let Some(r) = rest(e) {
            x[0] = cas.sub(x[0], r);
        }
        x
    };
    if grams.is_empty() {
        let x = less_rest(cas, 0);
        let terms: Vec<ExprId> = (x.iter().enumerate())
            .map(|(i, &a)| {
                let aa = cas.mul(a, a);
                cas.scaled(1.0 / (2 * i + 1) as f64, aa)
            })
            .collect();
        let sum = cas.add_all(&terms);
        return cas.mul_all(&[per(0), scale, sum]);
    }
    let mut slices = Vec::with_capacity(grams.len());
    for (e, g) in grams.iter().enumerate() {
        let x = less_rest(cas, e);
        let mut terms = Vec::new();
        for i in 0..x.len() {
            for j in i..x.len() {
                let c = if i == j { g[i][i] } else { 2.0 * g[i][j] };
                if c.abs() > 1e-15 * g[0][0] {
                    let xx = cas.mul(x[i], x[j]);
                    terms.push(cas.scaled(c, xx));
                }
            }
        }
        let sum = cas.add_all(&terms);
        slices.push(cas.mul(per(e), sum));
    }
    let all = cas.add_all(&slices);
    cas.mul(scale, all)
}

/// The m-point Gauss-Legendre rule on [-1, 1]: nodes (roots of P_m, by
/// Newton from Tricomi's estimate) and weights 2 / ((1 - y^2) P_m'(y)^2).
fn gauss_legendre(m: usize) -> Vec<(f64, f64)> {
    let mf = m as f64;
    (0..m)
        .map(|i| {
            let mut y = (std::f64::consts::PI * (i as f64 + 0.75) / (mf + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let p = legendre(m, y);
                dp = mf * (y * p[m] - p[m - 1]) / (y * y - 1.0);
                let step = p[m] / dp;
                y -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            (y, 2.0 / ((1.0 - y * y) * dp * dp))
        })
        .collect()
}

/// P_0(y), ..., P_n(y), the Legendre polynomials on [-1, 1], by Bonnet's
/// recurrence (k + 1) P_{k+1} = (2 k + 1) y P_k - k P_{k-1}: stable, no
/// large coefficients.
#[doc(hidden)] // white-box tests (tests/suite)
pub fn legendre(n: usize, y: f64) -> Vec<f64> {
    let mut p = vec![1.0, y];
    for k in 1..n {
        let k_f = k as f64;
        p.push(((2.0 * k_f + 1.0) * y * p[k] - k_f * p[k - 1]) / (k_f + 1.0));
    }
    p.truncate(n + 1);
    p
}
