//! M and h of a chain whose links may share coordinates (a rom segment's
//! slices, the two halves of a stretching or shearing element) over rows
//! of the arm's coordinates.
//!
//! With W_e the map from the arm's rates to link e's cell rates (rows of
//! `LinkSpec::map`), S_e the twists of e's cell rates, D_e e's own block
//! and R_e = sum_{e' > e} F_e' W_e' the momenta the arm's rates give the
//! links past e (F_e: the momenta of e's cell rates on e and past):
//! M = X + X^T with X = sum_e W_e^T (S_e^T R_e + D_e W_e / 2). Each link
//! costs O(cell coordinates x arm coordinates), not a Jacobian product
//! over all pairs of the arm's coordinates.
//!
//! Every row operation is column by column, so an arm wider than
//! [`AT_ONCE`] coordinates is summed a block of columns at a time, the
//! forward sweep done once: rows of a fixed length stay on the stack and
//! in vector registers for any arm.

use super::{
    Cells, LinkLayout, MAX_LINK_DOF, SCRATCH, Scratch, Tip, flat, forward, link_sums,
    subtract_loads, take_scratch,
};
use crate::rows;

/// The widest rows summed at once; an arm of more coordinates is summed
/// in blocks of [`BLOCK`] columns.
pub const AT_ONCE: usize = 64;

/// The columns of a block of a wider arm: narrow enough that its last
/// block wastes little, wide enough that the sums from the tip, done
/// again for each block, cost little beside the rows.
pub(super) const BLOCK: usize = 32;

/// The length of the rows a chain of `dof` coordinates is summed in (the
/// stride of [`LinkLayout::weights`]): the next multiple of four, past
/// [`AT_ONCE`] the next multiple of [`BLOCK`].
pub fn padded(dof: usize) -> usize {
    match dof <= AT_ONCE {
        true => dof.div_ceil(4) * 4,
        false => dof.div_ceil(BLOCK) * BLOCK,
    }
}

/// M and h like [`super::mass_bias_owned`] for any chain of at most
/// [`AT_ONCE`] coordinates, links of shared coordinates included, `N` the
/// arm's coordinates padded to whole vectors ([`padded`]).
/// `Cells::forces` gives the generalised forces that are not any link's
/// (a rom segment's strain energy and damping, integrated over the
/// segment), added to h, when `layout.forces`. `BODIES`: as
/// [`super::mass_bias_owned`]'s.
#[inline(always)]
pub fn mass_bias_shared<const N: usize, C: Cells, const BODIES: bool>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) {
    assert_eq!(N, padded(layout.dof), "rows of padded(dof)");
    let mut s = take_scratch(layout, out);
    cell_coordinates::<N>(layout, q, qd, p, &mut s);
    let tip = forward::<C, BODIES>(layout, cells, p, &mut s);
    sums::<N, BODIES>(layout, &mut s, &tip, p, out);
    finish(layout, cells, (q, qd, p), s, out);
}

/// [`mass_bias_shared`] for an arm of more than [`AT_ONCE`] coordinates:
/// X and h a block of columns at a time.
#[inline(always)]
pub fn mass_bias_wide<C: Cells, const BODIES: bool>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) {
    let mut s = take_scratch(layout, out);
    cell_coordinates::<BLOCK>(layout, q, qd, p, &mut s);
    let tip = forward::<C, BODIES>(layout, cells, p, &mut s);
    sums::<0, BODIES>(layout, &mut s, &tip, p, out);
    finish(layout, cells, (q, qd, p), s, out);
}

/// [`mass_bias_shared`] or [`mass_bias_wide`] with `N` and `BODIES`
/// picked at run time ([`padded`], [`LinkLayout::general_bodies`]); for
/// any chain, owned links included (tests check the two strategies
/// agree). The forward sweep is built once for the cells and the bodies,
/// the row operations once for each width: each in a function of its
/// own, built for FMA where the processor has it (every width's sweep
/// inlined into one caller would be slow to build, and past what the
/// compiler inlines: the rows' vector code and the sweep's closures would
/// then stay out of line, without FMA). Inlined into its caller, which
/// linked chains build for FMA.
#[inline(always)]
pub fn mass_bias_shared_dyn<C: Cells>(
    layout: &LinkLayout,
    cells: &mut C,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    out: &mut [f64],
) {
    let mut s = take_scratch(layout, out);
    let (n, bodies) = (padded(layout.dof), layout.general_bodies());
    macro_rules! by_width {
        ($($n:literal)*) => {
            match n {
                $($n => coordinates_apart::<$n>(layout, (q, qd, p), &mut s),)*
                _ => coordinates_apart::<0>(layout, (q, qd, p), &mut s),
            }
            let tip = match bodies {
                true => forward_apart::<C, true>(layout, cells, p, &mut s),
                false => forward_apart::<C, false>(layout, cells, p, &mut s),
            };
            match (n, bodies) {
                $(($n, true) => sums_apart::<$n, true>(layout, &mut s, &tip, p, out),
                ($n, false) => sums_apart::<$n, false>(layout, &mut s, &tip, p, out),)*
                (_, true) => sums_apart::<0, true>(layout, &mut s, &tip, p, out),
                (_, false) => sums_apart::<0, false>(layout, &mut s, &tip, p, out),
            }
        };
    }
    by_width!(4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64);
    finish(layout, cells, (q, qd, p), s, out);
}

/// [`cell_coordinates`] `N` columns at a time (0: [`BLOCK`]), apart.
#[inline(never)]
fn coordinates_apart<const N: usize>(
    layout: &LinkLayout,
    (q, qd, p): (&[f64], &[f64], &[f64]),
    s: &mut Scratch,
) {
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,fma")]
    unsafe fn fma<const N: usize>(l: &LinkLayout, a: [&[f64]; 3], s: &mut Scratch) {
        plain::<N>(l, a, s)
    }
    #[inline(always)]
    fn plain<const N: usize>(l: &LinkLayout, [q, qd, p]: [&[f64]; 3], s: &mut Scratch) {
        match N {
            0 => cell_coordinates::<BLOCK>(l, q, qd, p, s),
            _ => cell_coordinates::<N>(l, q, qd, p, s),
        }
    }
    #[cfg(target_arch = "x86_64")]
    if rows::simd_available() {
        // SAFETY: the processor has AVX and FMA.
        return unsafe { fma::<N>(layout, [q, qd, p], s) };
    }
    plain::<N>(layout, [q, qd, p], s)
}

/// [`forward`], apart.
#[inline(never)]
fn forward_apart<C: Cells, const BODIES: bool>(
    layout: &LinkLayout,
    cells: &mut C,
    p: &[f64],
    s: &mut Scratch,
) -> Tip {
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,fma")]
    unsafe fn fma<C: Cells, const BODIES: bool>(
        l: &LinkLayout,
        cells: &mut C,
        p: &[f64],
        s: &mut Scratch,
    ) -> Tip {
        forward::<C, BODIES>(l, cells, p, s)
    }
    #[cfg(target_arch = "x86_64")]
    if rows::simd_available() {
        // SAFETY: the processor has AVX and FMA.
        return unsafe { fma::<C, BODIES>(layout, cells, p, s) };
    }
    forward::<C, BODIES>(layout, cells, p, s)
}

/// [`sums`], apart.
#[inline(never)]
fn sums_apart<const N: usize, const BODIES: bool>(
    layout: &LinkLayout,
    s: &mut Scratch,
    tip: &Tip,
    p: &[f64],
    out: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,fma")]
    unsafe fn fma<const N: usize, const BODIES: bool>(
        l: &LinkLayout,
        s: &mut Scratch,
        tip: &Tip,
        p: &[f64],
        out: &mut [f64],
    ) {
        sums::<N, BODIES>(l, s, tip, p, out)
    }
    #[cfg(target_arch = "x86_64")]
    if rows::simd_available() {
        // SAFETY: the processor has AVX and FMA.
        return unsafe { fma::<N, BODIES>(layout, s, tip, p, out) };
    }
    sums::<N, BODIES>(layout, s, tip, p, out)
}

/// M and h into `out` from the forward sweep's scratch and `tip`: X in
/// rows of `N` columns, or (`N` = 0, an arm wider than [`AT_ONCE`]) a
/// block of [`BLOCK`] columns at a time; M = X + X^T.
#[inline(always)]
fn sums<const N: usize, const BODIES: bool>(
    layout: &LinkLayout,
    s: &mut Scratch,
    tip: &Tip,
    p: &[f64],
    out: &mut [f64],
) {
    if N == 0 {
        return wide_sums::<BODIES>(layout, s, tip, p, out);
    }
    let n = layout.dof;
    let mut x = [[0.0; N]; N];
    let mut h = [0.0; N];
    let every = layout.links.len();
    block_sums::<N, BODIES>(layout, s, tip, p, (0, every), &mut x[..n], &mut h);
    let (mass, bias) = out.split_at_mut(n * (n + 1) / 2);
    let mut at = 0;
    #[allow(clippy::needless_range_loop)] // X's row and column
    for i in 0..n {
        for j in i..n {
            mass[at] = x[i][j] + x[j][i];
            at += 1;
        }
    }
    bias.copy_from_slice(&h[..n]);
}

/// [`sums`] a block of [`BLOCK`] columns at a time.
#[inline(always)]
fn wide_sums<const BODIES: bool>(
    layout: &LinkLayout,
    s: &mut Scratch,
    tip: &Tip,
    p: &[f64],
    out: &mut [f64],
) {
    let n = layout.dof;
    let stride = padded(n);
    let mut x = std::mem::take(&mut s.wide);
    x.resize(n, [0.0; BLOCK]);
    let (mass, bias) = out.split_at_mut(n * (n + 1) / 2);
    mass.fill(0.0);
    let index = |i: usize, j: usize| i * n - i * (i + 1) / 2 + j;
    // The smallest coordinate of each link and those past it: a block
    // left of it has nothing of them but their sums from the tip.
    let mut first = vec![usize::MAX; layout.links.len()];
    let mut least = usize::MAX;
    for (k, spec) in layout.links.iter().enumerate().rev() {
        let own = spec
            .map
            .iter()
            .flat_map(|c| c.terms.iter().map(|t| t.0))
            .min();
        least = least.min(own.unwrap_or(usize::MAX));
        first[k] = least;
    }
    for c0 in (0..stride).step_by(BLOCK) {
        x.fill([0.0; BLOCK]);
        let mut h = [0.0; BLOCK];
        let rows_to = first.partition_point(|&a| a < c0 + BLOCK);
        block_sums::<BLOCK, BODIES>(layout, s, tip, p, (c0, rows_to), &mut x, &mut h);
        let end = n.min(c0 + BLOCK);
        bias[c0..end].copy_from_slice(&h[..end - c0]);
        // M = X + X^T: each X_ij into the upper entry of its pair.
        for (i, row) in x.iter().enumerate() {
            for (j, &v) in (c0..end).zip(row) {
                match i.cmp(&j) {
                    std::cmp::Ordering::Less => mass[index(i, j)] += v,
                    std::cmp::Ordering::Greater => mass[index(j, i)] += v,
                    std::cmp::Ordering::Equal => mass[index(i, i)] = v + v,
                }
            }
        }
    }
    s.wide = x;
}

/// Each link's cell coordinates and rates into `s.x`, `s.xd`: its rows of
/// weights against the arm's q and qd, `N` columns at a time (one block
/// for an arm of at most [`AT_ONCE`] coordinates), scaled where a
/// coordinate has a scale.
#[inline(always)]
fn cell_coordinates<const N: usize>(
    layout: &LinkLayout,
    q: &[f64],
    qd: &[f64],
    p: &[f64],
    s: &mut Scratch,
) {
    let (n, stride) = (layout.dof, padded(layout.dof));
    let simd = rows::simd_available();
    let weights = layout.weights();
    let nl = layout.links.len();
    s.x.resize(nl, [0.0; MAX_LINK_DOF]);
    s.xd.resize(nl, [0.0; MAX_LINK_DOF]);
    for c0 in (0..stride).step_by(N) {
        let (mut qp, mut qdp) = ([0.0; N], [0.0; N]);
        let end = n.min(c0 + N);
        qp[..end - c0].copy_from_slice(&q[c0..end]);
        qdp[..end - c0].copy_from_slice(&qd[c0..end]);
        for (k, spec) in layout.links.iter().enumerate() {
            for f in 0..spec.map.len() {
                let at = (k * MAX_LINK_DOF + f) * stride + c0;
                let row: &[f64; N] = weights[at..at + N].try_into().expect("rows of N");
                let (x, xd) = rows::dot2(simd, row, &qp, &qdp);
                match c0 {
                    0 => (s.x[k][f], s.xd[k][f]) = (x, xd),
                    _ => (s.x[k][f], s.xd[k][f]) = (s.x[k][f] + x, s.xd[k][f] + xd),
                }
            }
        }
    }
    for (k, spec) in layout.links.iter().enumerate() {
        for (f, c) in spec.map.iter().enumerate() {
            if let Some(i) = c.scale {
                s.x[k][f] *= p[i];
                s.xd[k][f] *= p[i];
            }
        }
    }
}

/// Columns `c0..c0 + N` of X (rows `x`, one per arm coordinate) and of h,
/// by the sums from the tip ([`link_sums`], from the forward sweep's
/// `tip`); links from `rows_to` on have no columns in the block (theirs
/// and those past them all lie right of it), only their sums.
#[inline(always)]
fn block_sums<const N: usize, const BODIES: bool>(
    layout: &LinkLayout,
    s: &Scratch,
    tip: &Tip,
    p: &[f64],
    (c0, rows_to): (usize, usize),
    x: &mut [[f64; N]],
    h: &mut [f64; N],
) {
    let stride = padded(layout.dof);
    let simd = rows::simd_available();
    let weights = layout.weights();
    let row = |k: usize, f: usize| -> &[f64; N] {
        let at = (k * MAX_LINK_DOF + f) * stride + c0;
        weights[at..at + N].try_into().expect("rows of N")
    };
    let mut tip = *tip;
    let mut reach = [[0.0; N]; 6];
    for (k, spec) in layout.links.iter().enumerate().rev() {
        let nc = spec.map.len();
        let (momentum, block, g) = link_sums::<BODIES>(s, k, nc, &mut tip);
        if k >= rows_to {
            continue;
        }
        let w: [&[f64; N]; MAX_LINK_DOF] = std::array::from_fn(|f| row(k, f));
        // A cell coordinate's scale goes into every coefficient of its
        // weights.
        let sc: [f64; MAX_LINK_DOF] =
            std::array::from_fn(|f| spec.map.get(f).and_then(|c| c.scale).map_or(1.0, |i| p[i]));
        // Unused cell coordinates have zero blocks, forces and momenta.
        let gs: [f64; MAX_LINK_DOF] = std::array::from_fn(|f| g[f] * sc[f]);
        rows::add_combination(simd, h, &gs, w);
        for f in 0..nc {
            let t = flat(s.twist[s.start[k] + f]);
            let mut row = [0.0; N];
            rows::add_combination(simd, &mut row, &t, std::array::from_fn(|k| &reach[k]));
            let half: [f64; MAX_LINK_DOF] = std::array::from_fn(|f2| 0.5 * block[f][f2] * sc[f2]);
            rows::add_combination(simd, &mut row, &half, w);
            // Terms name distinct coordinates (eomgen's maps); a term's
            // weight is its coordinate's, wherever its column is.
            for &(a, weight) in &spec.map[f].terms {
                rows::add_combination(simd, &mut x[a], &[weight * sc[f]], [&row]);
            }
        }
        for (kk, rk) in reach.iter_mut().enumerate() {
            // Component kk of the momenta (angular, then linear), read in
            // place: a flattened copy is a call to memcpy.
            let mk: [f64; MAX_LINK_DOF] = std::array::from_fn(|f| {
                let (w, v) = &momentum[f];
                (if kk < 3 { w[kk] } else { v[kk - 3] }) * sc[f]
            });
            match nc {
                3 => rows::add_combination(simd, rk, &[mk[0], mk[1], mk[2]], [w[0], w[1], w[2]]),
                _ => rows::add_combination(simd, rk, &mk, w),
            }
        }
    }
}

/// Both sums' end, M and h in `out`: the generalised forces not local to
/// a link (`layout.forces`: a rom segment's energies) added to h, the
/// scratch put back, the applied loads taken from h.
#[inline(always)]
fn finish<C: Cells>(
    layout: &LinkLayout,
    cells: &mut C,
    (q, qd, p): (&[f64], &[f64], &[f64]),
    mut scratch: Scratch,
    out: &mut [f64],
) {
    let n = layout.dof;
    let bias = &mut out[n * (n + 1) / 2..];
    if layout.forces {
        let s = &mut scratch;
        s.forces.resize(n, 0.0);
        cells.forces(&mut s.forces);
        for (h, f) in bias.iter_mut().zip(&s.forces) {
            *h += f;
        }
    }
    SCRATCH.set(scratch);
    if layout.loaded() {
        subtract_loads(layout, cells, (q, qd, p), bias);
    }
}
