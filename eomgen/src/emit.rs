//! Tapes -> Rust source, with quote and prettyplease.
//!
//! Each kernel becomes straight-line SSA split into `#[inline(never)]`
//! chunks of at most [`CHUNK_OPS`] operations (docs/design.md section 6: one giant
//! function makes rustc superlinear). A value used by a later chunk is
//! spilled to a workspace array; inputs and constants are read in place.

use std::collections::HashMap;

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};
use runtime::kernels::ArmBlocks;
use runtime::{KernelKind, Op, Slot, Tape, TapeSet};

/// Operations per emitted function. A cut costs a store and a load per
/// value that crosses it (the 10-element pcc cantilever's mass + bias:
/// 450 ns in two chunks, 405 ns in one). Functions this long overflow
/// rustc's default stack at opt-level 1 with debug info (4000 ops did at
/// 8 MiB, 3000 did too): `.cargo/config.toml` raises `RUST_MIN_STACK`.
pub const CHUNK_OPS: usize = 3000;

fn lit(c: f64) -> TokenStream {
    let l = Literal::f64_suffixed(c.abs());
    if c.is_sign_negative() {
        quote!((-#l))
    } else {
        quote!(#l)
    }
}

/// What a slot of a generic kernel is (`emit_generic`): an `f64`
/// (constants, time), a parameter (`S::Param`) or a moving value (`S`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Class {
    Const,
    Param,
    Moving,
}

struct KernelEmitter<'a> {
    tape: &'a Tape,
    /// Chunk of each slot (leaves: none).
    chunk_of: Vec<Option<usize>>,
    /// Workspace index of spilled slots.
    spill: Vec<Option<usize>>,
    n_spill: usize,
    /// Four evaluations at once in `runtime::lanes::X4` (`emit_lanes`).
    lanes: bool,
    /// Outputs from this index on go to a second array, `out2` (one tape
    /// for two kernels: `emit_accel`).
    split: Option<usize>,
    /// Written over `S: runtime::scalar::Scalar` (`emit_generic`), each
    /// slot of its class.
    generic: bool,
    class: Vec<Class>,
    /// A generic kernel's parameters are `S::Param` (for its lane instance).
    lane_params: bool,
    /// Zero outputs stored one by one even when many (`zero_filled`): a
    /// cell or a part is inlined into its sums, where the compiler drops
    /// the stores no sum reads, and a clear of the whole output would
    /// defeat that (soft_finger's mass + bias took 9 % longer).
    keep_zeros: bool,
}

impl<'a> KernelEmitter<'a> {
    fn new(tape: &'a Tape) -> Self {
        let mut chunk_of = vec![None; tape.ops.len()];
        let mut count = 0;
        for (i, op) in tape.ops.iter().enumerate() {
            if !op.is_leaf() {
                chunk_of[i] = Some(count / CHUNK_OPS);
                count += 1;
            }
        }
        // A family's members are computed by one call where the first of
        // them is; the later ones are read from there (spilled when that
        // is an earlier chunk) instead of being evaluated again.
        let mut first: HashMap<(Family, Slot), Option<usize>> = HashMap::new();
        for (i, op) in tape.ops.iter().enumerate() {
            if let Some((family, _, a)) = family_of(op) {
                chunk_of[i] = *first.entry((family, a)).or_insert(chunk_of[i]);
            }
        }
        let mut spill = vec![None; tape.ops.len()];
        let mut n_spill = 0;
        let mut mark = |s: Slot, user_chunk: usize| {
            if let Some(c) = chunk_of[s as usize]
                && c != user_chunk
                && spill[s as usize].is_none()
            {
                spill[s as usize] = Some(n_spill);
                n_spill += 1;
            }
        };
        for (i, op) in tape.ops.iter().enumerate() {
            if let Some(c) = chunk_of[i] {
                for a in op.operands() {
                    mark(a, c);
                }
            }
        }
        Self {
            tape,
            chunk_of,
            spill,
            n_spill,
            lanes: false,
            split: None,
            generic: false,
            class: Vec::new(),
            lane_params: false,
            keep_zeros: false,
        }
    }

    /// Keep this kernel's zero stores (`keep_zeros`).
    fn keeping_zeros(self) -> Self {
        Self {
            keep_zeros: true,
            ..self
        }
    }

    /// The emitter of `emit_generic`: one chunk, no spills. Parameters are
    /// `S::Param` with `lanes` (a lane instance reads each link's own),
    /// else `f64` like constants.
    fn new_generic(tape: &'a Tape, lanes: bool) -> Self {
        let mut class = vec![Class::Const; tape.ops.len()];
        for (i, op) in tape.ops.iter().enumerate() {
            class[i] = match op {
                Op::Q(_) | Op::Qd(_) | Op::Aux(_) => Class::Moving,
                Op::Param(_) if lanes => Class::Param,
                _ => (op.operands().map(|a| class[a as usize]))
                    .max()
                    .unwrap_or(Class::Const),
            };
        }
        Self {
            generic: true,
            class,
            lane_params: lanes,
            ..Self::new(tape)
        }
    }

    /// Whether `emit_generic` can write this tape: one chunk, so that no
    /// value crosses an `f64` workspace.
    fn fits_generic(tape: &Tape) -> bool {
        KernelEmitter::new(tape).n_chunks() <= 1
    }

    /// The emitter of `emit_lanes`.
    fn new_lanes(tape: &'a Tape) -> Self {
        Self {
            lanes: true,
            ..Self::new(tape)
        }
    }

    fn n_chunks(&self) -> usize {
        self.chunk_of.iter().flatten().max().map_or(0, |c| c + 1)
    }

    /// How slot `s` is read from inside chunk `c`.
    fn read(&self, s: Slot, c: usize) -> TokenStream {
        let leaf = self.read_scalar(s, c);
        if self.lanes {
            match self.tape.ops[s as usize] {
                Op::Const(_) | Op::Time => quote!(_mm256_set1_pd(#leaf)),
                op if op.is_leaf() => quote!(runtime::lanes::from_array(#leaf)),
                _ => leaf,
            }
        } else {
            leaf
        }
    }

    fn read_scalar(&self, s: Slot, c: usize) -> TokenStream {
        let i = s as usize;
        match self.tape.ops[i] {
            Op::Const(v) => lit(v),
            Op::Q(k) => {
                let k = k as usize;
                quote!(q[#k])
            }
            Op::Qd(k) => {
                let k = k as usize;
                quote!(qd[#k])
            }
            Op::Qdd(k) => {
                let k = k as usize;
                quote!(qdd[#k])
            }
            Op::Dir(k) => {
                let k = k as usize;
                quote!(dir[#k])
            }
            Op::Param(k) => {
                let k = k as usize;
                quote!(p[#k])
            }
            Op::Aux(k) => {
                let k = k as usize;
                quote!(aux[#k])
            }
            Op::Time => quote!(t),
            _ => {
                if self.chunk_of[i] == Some(c) {
                    let v = format_ident!("v{}", i);
                    quote!(#v)
                } else {
                    let w = self.spill[i].expect("value read across chunks is spilled");
                    quote!(w[#w])
                }
            }
        }
    }

    fn expr(&self, op: &Op, c: usize) -> TokenStream {
        let r = |s: Slot| self.read(s, c);
        if self.generic {
            let class = (op.operands().map(|a| self.class[a as usize])).max();
            if let Some(class @ (Class::Param | Class::Moving)) = class {
                return self.expr_typed(op, c, class);
            }
        }
        if self.lanes {
            // One instruction per operation, each lane the scalar one.
            match *op {
                Op::Add(a, b) => return self.intrinsic(quote!(_mm256_add_pd), &[r(a), r(b)]),
                Op::Sub(a, b) => return self.intrinsic(quote!(_mm256_sub_pd), &[r(a), r(b)]),
                Op::Mul(a, b) => return self.intrinsic(quote!(_mm256_mul_pd), &[r(a), r(b)]),
                Op::Div(a, b) => return self.intrinsic(quote!(_mm256_div_pd), &[r(a), r(b)]),
                Op::MulAdd(a, b, c) => {
                    return self.intrinsic(quote!(_mm256_fmadd_pd), &[r(a), r(b), r(c)]);
                }
                Op::MulSub(a, b, c) => {
                    return self.intrinsic(quote!(_mm256_fmsub_pd), &[r(a), r(b), r(c)]);
                }
                Op::NegMulAdd(a, b, c) => {
                    return self.intrinsic(quote!(_mm256_fnmadd_pd), &[r(a), r(b), r(c)]);
                }
                Op::Neg(a) => {
                    return self
                        .intrinsic(quote!(_mm256_xor_pd), &[r(a), quote!(_mm256_set1_pd(-0.0))]);
                }
                Op::Sqrt(a) => return self.intrinsic(quote!(_mm256_sqrt_pd), &[r(a)]),
                Op::Abs(a) => {
                    return self.intrinsic(
                        quote!(_mm256_andnot_pd),
                        &[quote!(_mm256_set1_pd(-0.0)), r(a)],
                    );
                }
                Op::Powi(a, n) => {
                    let a = r(a);
                    return quote!(runtime::lanes::map(#a, |x| x.powi(#n)));
                }
                Op::Powf(a, b) => {
                    let (a, b) = (r(a), r(b));
                    return quote!(runtime::lanes::from_array({
                        let (a, b) = (runtime::lanes::to_array(#a), runtime::lanes::to_array(#b));
                        std::array::from_fn(|l| a[l].powf(b[l]))
                    }));
                }
                _ => {}
            }
        }
        match *op {
            Op::Add(a, b) => {
                let (a, b) = (r(a), r(b));
                quote!(#a + #b)
            }
            Op::Sub(a, b) => {
                let (a, b) = (r(a), r(b));
                quote!(#a - #b)
            }
            Op::Mul(a, b) => {
                let (a, b) = (r(a), r(b));
                quote!(#a * #b)
            }
            Op::MulAdd(a, b, c) | Op::MulSub(a, b, c) | Op::NegMulAdd(a, b, c) => {
                fused(op, [r(a), r(b), r(c)])
            }
            Op::Div(a, b) => {
                let (a, b) = (r(a), r(b));
                quote!(#a / #b)
            }
            Op::Neg(a) => {
                let a = r(a);
                quote!(-#a)
            }
            Op::Powi(a, n) => {
                let a = r(a);
                quote!(#a.powi(#n))
            }
            Op::Powf(a, b) => {
                let (a, b) = (r(a), r(b));
                quote!(#a.powf(#b))
            }
            Op::Sqrt(a) => {
                let a = r(a);
                quote!(#a.sqrt())
            }
            Op::Sin(a) => self.call1(r(a), quote!(runtime::special::sin)),
            Op::Cos(a) => self.call1(r(a), quote!(runtime::special::cos)),
            Op::Tan(a) => self.call1(r(a), quote!(f64::tan)),
            Op::Exp(a) => self.call1(r(a), quote!(f64::exp)),
            Op::Ln(a) => self.call1(r(a), quote!(f64::ln)),
            Op::Abs(a) => {
                let a = r(a);
                quote!(#a.abs())
            }
            Op::Sign(a) => self.call1(r(a), quote!(runtime::special::sign)),
            Op::Sinc(k, a) => self.call1(r(a), quote!(runtime::special::sinc, #k)),
            Op::Cosc(k, a) => self.call1(r(a), quote!(runtime::special::cosc, #k)),
            Op::SincRem(k, a) => self.call1(r(a), quote!(runtime::special::sinc_rem, #k)),
            Op::Rodrigues(j, n, a) => {
                self.call1(r(a), quote!(runtime::rodrigues::rodrigues, #j, #n))
            }
            _ => unreachable!("leaves are read in place"),
        }
    }

    /// An operation of a generic kernel whose result is of `class` (a
    /// parameter or a moving value): the higher operand first where the
    /// operation commutes, `sub_from`, `div_into` and the `_p` methods
    /// where it does not, lower operands lifted into fused and power
    /// operations. The `f64` instance is the plain kernel's code.
    fn expr_typed(&self, op: &Op, c: usize, class: Class) -> TokenStream {
        let k = |s: Slot| self.class[s as usize];
        let r = |s: Slot| self.read(s, c);
        let lift = |s: Slot| {
            let v = r(s);
            match (k(s), class) {
                (a, b) if a == b => v,
                (Class::Const, Class::Param) => quote!(S::pc(#v)),
                (Class::Const, _) => quote!(S::c(#v)),
                _ => quote!(S::from_param(#v)),
            }
        };
        // (higher, lower) operands of a commuting operation.
        let ordered = |a: Slot, b: Slot| if k(a) >= k(b) { (a, b) } else { (b, a) };
        // `a op b`, or `a.f_p(b)` for a moving a and a parameter b.
        let mixed = |a: Slot, b: Slot, op: TokenStream, f: &str| {
            let (x, y) = (r(a), r(b));
            match (k(a), k(b)) {
                (Class::Moving, Class::Param) => {
                    let f = format_ident!("{}", f);
                    quote!(#x.#f(#y))
                }
                _ => quote!(#x #op #y),
            }
        };
        match *op {
            Op::Add(a, b) => {
                let (a, b) = ordered(a, b);
                mixed(a, b, quote!(+), "add_p")
            }
            Op::Mul(a, b) => {
                let (a, b) = ordered(a, b);
                mixed(a, b, quote!(*), "mul_p")
            }
            Op::Sub(a, b) | Op::Div(a, b) if k(a) < k(b) => {
                let (x, y) = (r(a), r(b));
                let f = match (op, k(a)) {
                    (Op::Sub(..), Class::Const) => quote!(sub_from),
                    (Op::Sub(..), _) => quote!(rsub_p),
                    (_, Class::Const) => quote!(div_into),
                    _ => quote!(rdiv_p),
                };
                quote!(#y.#f(#x))
            }
            Op::Sub(a, b) => mixed(a, b, quote!(-), "sub_p"),
            Op::Div(a, b) => mixed(a, b, quote!(/), "div_p"),
            Op::MulAdd(a, b, c) | Op::MulSub(a, b, c) | Op::NegMulAdd(a, b, c) => {
                fused(op, [lift(a), lift(b), lift(c)])
            }
            Op::Powf(a, b) => {
                let (a, b) = (lift(a), lift(b));
                quote!(#a.powf(#b))
            }
            Op::Neg(a) => {
                let a = r(a);
                quote!(-#a)
            }
            Op::Powi(a, n) => {
                let a = r(a);
                quote!(#a.powi(#n))
            }
            _ => {
                let a = r(op.operands().next().expect("a unary operation"));
                let method = match *op {
                    Op::Sqrt(_) => quote!(sqrt()),
                    Op::Sin(_) => quote!(sin()),
                    Op::Cos(_) => quote!(cos()),
                    Op::Tan(_) => quote!(tan()),
                    Op::Exp(_) => quote!(exp()),
                    Op::Ln(_) => quote!(ln()),
                    Op::Abs(_) => quote!(abs()),
                    Op::Sign(_) => quote!(sign()),
                    Op::Sinc(k, _) => quote!(sinc(#k)),
                    Op::Cosc(k, _) => quote!(cosc(#k)),
                    Op::SincRem(k, _) => quote!(sinc_rem(#k)),
                    Op::Rodrigues(j, n, _) => quote!(rodrigues(#j, #n)),
                    _ => unreachable!("every operation with operands is above"),
                };
                quote!(#a.#method)
            }
        }
    }

    fn intrinsic(&self, f: TokenStream, args: &[TokenStream]) -> TokenStream {
        quote!(#f(#(#args),*))
    }

    /// `f(leading.., a)`, `f` and its leading constant arguments given as
    /// `f, leading..`: lane by lane in lane kernels.
    fn call1(&self, a: TokenStream, f_and_leading: TokenStream) -> TokenStream {
        let mut parts = f_and_leading.into_iter().collect::<Vec<_>>();
        let comma = parts
            .iter()
            .position(|t| matches!(t, proc_macro2::TokenTree::Punct(p) if p.as_char() == ','));
        // "f, k": leading is ", k", and the arguments "k, a".
        let leading: TokenStream = match comma {
            Some(i) => parts.drain(i..).skip(1).collect(),
            None => TokenStream::new(),
        };
        let f: TokenStream = parts.into_iter().collect();
        let args = |x: TokenStream| {
            if leading.is_empty() {
                x
            } else {
                quote!(#leading, #x)
            }
        };
        if self.lanes {
            let args = args(quote!(x));
            quote!(runtime::lanes::map(#a, |x| #f(#args)))
        } else {
            let args = args(a);
            quote!(#f(#args))
        }
    }

    /// Whether slot `s` is the constant +0.
    fn is_zero(&self, s: Slot) -> bool {
        matches!(self.tape.ops[s as usize], Op::Const(v) if v.to_bits() == 0)
    }

    /// Whether the output is cleared first and its zeros not stored: at
    /// least eight of them and a quarter of the outputs (a contact group's
    /// Jacobian columns of the later coordinates), in a kernel writing one
    /// plain array.
    fn zero_filled(&self) -> bool {
        let outs = &self.tape.outputs;
        let zeros = outs.iter().filter(|&&s| self.is_zero(s)).count();
        !(self.lanes || self.lane_params || self.keep_zeros)
            && self.split.is_none()
            && zeros >= 8
            && 4 * zeros >= outs.len()
    }

    /// The length of the `aux` input this tape reads (0: none).
    fn aux_len(&self) -> usize {
        self.tape
            .ops
            .iter()
            .filter_map(|op| match op {
                Op::Aux(k) => Some(*k as usize + 1),
                _ => None,
            })
            .max()
            .unwrap_or(0)
    }

    /// The statements of chunk `c`: its operations (a family's members from
    /// one call, in the chunk of the first), the values it spills, and the
    /// outputs it computes (leaf outputs in the last chunk).
    fn chunk_body(
        &self,
        c: usize,
        n_chunks: usize,
        groups: &HashMap<(Family, Slot), Vec<(Member, usize)>>,
        group_of: &HashMap<usize, (Family, Slot)>,
    ) -> Vec<TokenStream> {
        let mut body = Vec::new();
        // Many zero outputs: the first chunk clears the output, and no
        // zero is stored one by one.
        let zeros = self.zero_filled();
        if zeros && c == 0 {
            body.push(match self.generic {
                true => quote!(out.fill(S::c(0f64));),
                false => quote!(out.fill(0f64);),
            });
        }
        for (i, op) in self.tape.ops.iter().enumerate() {
            if self.chunk_of[i] != Some(c) {
                continue;
            }
            let defined: Vec<usize> = match group_of.get(&i) {
                Some(&(family, a)) => {
                    let members = &groups[&(family, a)];
                    if members.iter().map(|m| m.1).min() != Some(i) {
                        continue;
                    }
                    let class = self.class.get(a as usize).copied();
                    let a = self.read(a, c);
                    body.push(match class {
                        Some(Class::Moving) => family.call_generic(members, a, quote!(S)),
                        Some(Class::Param) => family.call_generic(members, a, quote!(S::Param)),
                        _ => family.call(members, a, self.lanes),
                    });
                    members.iter().map(|m| m.1).collect()
                }
                None => {
                    let v = format_ident!("v{}", i);
                    let e = self.expr(op, c);
                    // The type follows from the operands (an f64 or a
                    // lane vector).
                    body.push(quote!(let #v = #e;));
                    vec![i]
                }
            };
            for d in defined {
                if let Some(w) = self.spill[d] {
                    let v = format_ident!("v{}", d);
                    body.push(quote!(w[#w] = #v;));
                }
            }
        }
        // Outputs are written by the chunk that computes them; leaf
        // outputs (constants, inputs) by the last chunk.
        for (k, &s) in self.tape.outputs.iter().enumerate() {
            let owner = self.chunk_of[s as usize].unwrap_or(n_chunks - 1);
            if zeros && self.is_zero(s) {
                continue;
            }
            if owner == c {
                let val = match self.tape.ops[s as usize] {
                    // A constant output without lit's parentheses.
                    Op::Const(v) if !self.lanes => {
                        let l = Literal::f64_suffixed(v.abs());
                        match v.is_sign_negative() {
                            true => quote!(-#l),
                            false => quote!(#l),
                        }
                    }
                    _ => self.read(s, c),
                };
                body.push(if self.lanes {
                    quote!(out[#k] = runtime::lanes::to_array(#val);)
                } else if self.generic {
                    let val = match self.class[s as usize] {
                        Class::Const => quote!(S::c(#val)),
                        Class::Param => quote!(S::from_param(#val)),
                        Class::Moving => val,
                    };
                    match self.lane_params {
                        true => quote!(out[#k] = #val.store();),
                        false => quote!(out[#k] = #val;),
                    }
                } else {
                    match self.split {
                        Some(first) if k >= first => {
                            let k = k - first;
                            quote!(out2[#k] = #val;)
                        }
                        _ => quote!(out[#k] = #val;),
                    }
                });
            }
        }
        body
    }

    /// Members of one family at the same argument come from one call (in
    /// the chunk of the first, see `new`): sin and cos from `sin_cos`, the
    /// orders of a removable function from `*_orders`, the Rodrigues
    /// coefficients from `rodrigues::family`.
    #[allow(clippy::type_complexity)]
    fn families(
        &self,
    ) -> (
        HashMap<(Family, Slot), Vec<(Member, usize)>>,
        HashMap<usize, (Family, Slot)>,
    ) {
        let mut groups: HashMap<(Family, Slot), Vec<(Member, usize)>> = HashMap::new();
        for (i, op) in self.tape.ops.iter().enumerate() {
            if let Some((family, member, a)) = family_of(op) {
                groups.entry((family, a)).or_default().push((member, i));
            }
        }
        groups.retain(|_, members| members.len() >= 2);
        let group_of: HashMap<usize, (Family, Slot)> = groups
            .iter()
            .flat_map(|(&(f, a), ms)| ms.iter().map(move |&(_, i)| (i, (f, a))))
            .collect();
        (groups, group_of)
    }

    /// The chunk functions `name_0`, `name_1`, ... and their names. Built
    /// for FMA and never inlined; with `inline`, always inlined into a
    /// caller built for FMA instead (a kernel composed of others).
    fn chunks(
        &self,
        name: &str,
        dof: usize,
        n_params: usize,
        n_aux: usize,
        inline: bool,
    ) -> (Vec<TokenStream>, Vec<Ident>) {
        assert!(self.aux_len() <= n_aux, "{name} reads past its aux input");
        let (aux_param, aux_generic) = match self.aux_len() {
            0 => (quote!(), quote!()),
            _ => (quote!(aux: &[f64; #n_aux],), quote!(aux: &[S; #n_aux],)),
        };
        let n_all = self.tape.outputs.len();
        let (n_out, out2) = match self.split {
            Some(first) => {
                let n2 = n_all - first;
                (first, quote!(, out2: &mut [f64; #n2]))
            }
            None => (n_all, quote!()),
        };
        let n_chunks = self.n_chunks().max(1);
        let n_spill = self.n_spill;
        let n_dir = 2 * dof;
        let (groups, group_of) = self.families();
        // A generic chunk's lane instance computes in 256-bit vectors.
        let features = if self.generic { "avx,fma" } else { "fma" };
        // A parameter's methods need the trait in scope.
        let store = match self.lane_params {
            true => quote!(S::Store),
            false => quote!(S),
        };
        let (param, scope) = match self.lane_params {
            true => (
                quote!(S::Param),
                quote!(
                    #[allow(unused_imports)]
                    use runtime::scalar::Scalar as _;
                ),
            ),
            false => (quote!(f64), quote!()),
        };
        let attributes = match (inline, self.generic) {
            (true, _) => quote!(#[inline(always)]),
            // A generic kernel's f64 instance may be inlined into the link
            // recursion (built for the same features): its outputs then
            // stay in registers.
            (false, true) => quote! {
                #[inline]
                #[cfg_attr(target_arch = "x86_64", target_feature(enable = #features))]
            },
            (false, false) => quote! {
                #[inline(never)]
                #[cfg_attr(target_arch = "x86_64", target_feature(enable = #features))]
            },
        };
        let mut chunks = Vec::new();
        let mut names = Vec::new();
        for c in 0..n_chunks {
            let body = self.chunk_body(c, n_chunks, &groups, &group_of);
            let f = format_ident!("{}_{}", name, c);
            chunks.push(match self.generic {
                true => quote! {
                    #attributes
                    fn #f<S: runtime::scalar::Scalar>(t: f64, q: &[S; #dof], qd: &[S; #dof], qdd: &[f64; #dof],
                          dir: &[f64; #n_dir], p: &[#param; #n_params], #aux_generic out: &mut [#store; #n_out]) {
                        #scope
                        #(#body)*
                    }
                },
                false => quote! {
                    #attributes
                    fn #f(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir],
                          p: &[f64; #n_params], #aux_param w: &mut [f64; #n_spill], out: &mut [f64; #n_out] #out2) {
                        #(#body)*
                    }
                },
            });
            names.push(f);
        }
        (chunks, names)
    }

    /// The lane kernel `name`: four evaluations in vector lanes.
    fn emit_lanes_kernel(&self, name: &str, dof: usize, n_params: usize) -> TokenStream {
        let n_out = self.tape.outputs.len();
        let (groups, group_of) = self.families();
        assert!(
            self.n_chunks() <= 1 && self.n_spill == 0,
            "lane kernels are one chunk"
        );
        assert!(
            !self
                .tape
                .ops
                .iter()
                .any(|op| matches!(op, Op::Time | Op::Qdd(_) | Op::Dir(_) | Op::Aux(_))),
            "lane kernels read q, qd and p"
        );
        let body = self.chunk_body(0, 1, &groups, &group_of);
        let f = format_ident!("{}", name);
        let doc = format!(
            " Kernel `{name}`: {} operations, four evaluations in vector lanes.",
            self.tape.op_count()
        );
        quote! {
            #[doc = #doc]
            #[cfg(target_arch = "x86_64")]
            #[inline(never)]
            #[target_feature(enable = "avx,fma")]
            fn #f(q: &[[f64; 4]; #dof], qd: &[[f64; 4]; #dof], p: &[[f64; 4]; #n_params],
                  out: &mut [[f64; 4]; #n_out]) {
                use std::arch::x86_64::*;
                #(#body)*
            }
        }
    }

    /// A kernel written once over `S: runtime::scalar::Scalar` (its chunk
    /// `name_0`) and its `f64` entry `name`; with `tangent` (for a tape
    /// without `aux`) also `name_tangent`, its outputs and then their derivatives along (dq,
    /// dqd) = `dir`, in dual numbers: what a symbolic tangent tape
    /// (`tmt::cell_outputs::with_tangent`) gives, from the same source.
    #[allow(clippy::too_many_arguments)]
    fn emit_generic(
        &self,
        name: &str,
        dof: usize,
        n_params: usize,
        n_aux: usize,
        tangent: bool,
        lanes: bool,
    ) -> TokenStream {
        assert!(
            self.generic && self.n_spill == 0 && self.n_chunks() <= 1,
            "a generic kernel is one chunk"
        );
        let (chunks, names) = self.chunks(name, dof, n_params, n_aux, false);
        let chunk = &names[0];
        let n_out = self.tape.outputs.len();
        let n_dir = 2 * dof;
        let (aux_param, aux_arg) = match self.aux_len() {
            0 => (quote!(), quote!()),
            _ => (quote!(aux: &[f64; #n_aux],), quote!(aux,)),
        };
        let f = Ident::new(name, Span::call_site());
        let doc = format!(
            " Kernel `{name}`: {} operations, over f64 or dual numbers.",
            self.tape.op_count()
        );
        let tangent = match self.aux_len() {
            0 if tangent => {
                let ft = format_ident!("{}_tangent", name);
                let n2 = 2 * n_out;
                let doc = format!(" `{name}` and its derivatives along `dir`, in dual numbers.");
                quote! {
                    #[doc = #doc]
                    pub fn #ft(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params], out: &mut [f64; #n2]) {
                        runtime::cpu::require_fma();
                        let x = runtime::dual::seed(q, &dir[..#dof]);
                        let xd = runtime::dual::seed(qd, &dir[#dof..]);
                        let mut o = [runtime::dual::Dual::ZERO; #n_out];
                        // SAFETY: `require_fma` has checked that the processor has FMA.
                        unsafe { #chunk::<runtime::dual::Dual>(t, &x, &xd, qdd, dir, p, &mut o) };
                        runtime::dual::split(&o, out);
                    }
                }
            }
            _ => quote!(),
        };
        let four = match lanes {
            true => {
                assert_eq!(self.aux_len(), 0, "lane kernels read q, qd and p");
                let f4 = format_ident!("{}_x4", name);
                let doc = format!(" `{name}` of four links at once, in vector lanes.");
                quote! {
                    #[doc = #doc]
                    #[cfg(target_arch = "x86_64")]
                    #[target_feature(enable = "avx,fma")]
                    fn #f4(q: &[[f64; 4]; #dof], qd: &[[f64; 4]; #dof], p: &[[f64; 4]; #n_params],
                           out: &mut [[f64; 4]; #n_out]) {
                        use runtime::x4::X4;
                        let (x, xd, px) = (X4::from_arrays(q), X4::from_arrays(qd), X4::from_arrays(p));
                        #chunk::<X4>(0.0, &x, &xd, &[0.0; #dof], &[0.0; #n_dir], &px, out);
                    }
                }
            }
            false => quote!(),
        };
        quote! {
            #[doc = #doc]
            pub fn #f(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params], #aux_param out: &mut [f64; #n_out]) {
                runtime::cpu::require_fma();
                // SAFETY: `require_fma` has checked that the processor has FMA.
                unsafe { #chunk::<f64>(t, q, qd, qdd, dir, p, #aux_arg out) };
            }
            #tangent
            #four
            #(#chunks)*
        }
    }

    /// The kernel function `name` and its chunks; a tape that reads `aux`
    /// takes it after `p`, `n_aux` values.
    fn emit(&self, name: &str, dof: usize, n_params: usize, n_aux: usize) -> TokenStream {
        if self.lanes {
            return self.emit_lanes_kernel(name, dof, n_params);
        }
        let (aux_param, aux_arg) = match self.aux_len() {
            0 => (quote!(), quote!()),
            _ => (quote!(aux: &[f64; #n_aux],), quote!(aux,)),
        };
        let n_out = self.tape.outputs.len();
        let n_dir = 2 * dof;
        let (chunks, names) = self.chunks(name, dof, n_params, n_aux, false);
        let calls = names.iter().map(|f| {
            quote!(
                // SAFETY: `require_fma` has checked that the processor has FMA.
                unsafe { #f(t, q, qd, qdd, dir, p, #aux_arg w, out) };
            )
        });
        let f = Ident::new(name, Span::call_site());
        let doc = format!(
            " Kernel `{name}`: {} operations in {} chunk(s).",
            self.tape.op_count(),
            names.len()
        );
        let body = with_workspace(self.n_spill, quote!(#(#calls)*));
        quote! {
            #[doc = #doc]
            pub fn #f(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params], #aux_param out: &mut [f64; #n_out]) {
                runtime::cpu::require_fma();
                #body
            }
            #(#chunks)*
        }
    }
}

/// A fused operation on its operands' code: a * b + c, a * b - c, or
/// c - a * b, each with one rounding.
fn fused(op: &Op, [a, b, c]: [TokenStream; 3]) -> TokenStream {
    match op {
        Op::MulAdd(..) => quote!(#a.mul_add(#b, #c)),
        Op::MulSub(..) => quote!(#a.mul_add(#b, -#c)),
        _ => quote!((-#a).mul_add(#b, #c)),
    }
}

/// `calls` with `w`, the spill workspace of `n_spill` values: a per-thread
/// buffer, allocated on the first call. A fresh array would be zeroed on
/// every call (a memset of several kilobytes for a 3D arm) and a large one
/// would crowd the stack.
fn with_workspace(n_spill: usize, calls: TokenStream) -> TokenStream {
    if n_spill == 0 {
        return quote! {
            let w = &mut [0.0f64; 0];
            #calls
        };
    }
    quote! {
        thread_local! {
            static WORKSPACE: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        WORKSPACE.with_borrow_mut(|heap| {
            heap.resize(#n_spill, 0.0);
            let w: &mut [f64; #n_spill] = (&mut heap[..]).try_into().expect("workspace length");
            #calls
        });
    }
}

/// Kernel `name` and `name_tangent`, its outputs and their derivatives
/// along `dir` (the symbolic `tangent` tape's outputs): written once over
/// `runtime::scalar::Scalar` and run on dual numbers for the tangent where
/// the kernel is one chunk, else both tapes as plain kernels.
fn with_tangent(
    tape: &Tape,
    tangent: &Tape,
    name: &str,
    dof: usize,
    n_params: usize,
    lanes: bool,
) -> TokenStream {
    if KernelEmitter::fits_generic(tape) {
        return KernelEmitter::new_generic(tape, lanes)
            .keeping_zeros()
            .emit_generic(name, dof, n_params, 0, true, lanes);
    }
    let plain = KernelEmitter::new(tape)
        .keeping_zeros()
        .emit(name, dof, n_params, 0);
    let tangent = KernelEmitter::new(tangent).keeping_zeros().emit(
        &format!("{name}_tangent"),
        dof,
        n_params,
        0,
    );
    let four = match lanes {
        true => KernelEmitter::new_lanes(tape).emit(&format!("{name}_x4"), dof, n_params, 0),
        false => quote!(),
    };
    quote!(#plain #tangent #four)
}

/// A cell's entry in the model's registry (`runtime::compiled_cell!`),
/// with its lane kernel's glue where it has one.
fn emit_linked_cell(
    c: usize,
    n: usize,
    (tape, tangent, pose): (&Tape, &Tape, &Tape),
    (f, f4, ft, fp): (&Ident, Option<&Ident>, &Ident, &Ident),
) -> (TokenStream, TokenStream) {
    let key = crate::build::kernel_key(&[tape, tangent, pose]);
    let (l4, four) = (
        format_ident!("cell_{c}_x4_linked"),
        format_ident!("CELL_{c}_FOUR"),
    );
    let linked = match f4 {
        Some(f4) => quote! {
            #[cfg(target_arch = "x86_64")]
            fn #l4(x: &[[f64; 4]], xd: &[[f64; 4]], p: &[[f64; 4]], out: &mut [[f64; 4]]) {
                runtime::cpu::require_fma();
                // SAFETY: `require_fma` has checked that the processor has FMA.
                unsafe { #f4(x.try_into().expect("link coordinates"), xd.try_into().expect("link rates"),
                             p.try_into().expect("cell parameters"), out.try_into().expect("cell outputs")) }
            }
            #[cfg(target_arch = "x86_64")]
            const #four: Option<runtime::links::CellLanesFn> = Some(#l4);
            #[cfg(not(target_arch = "x86_64"))]
            const #four: Option<runtime::links::CellLanesFn> = None;
        },
        None => quote! {
            const #four: Option<runtime::links::CellLanesFn> = None;
        },
    };
    let n = proc_macro2::Literal::usize_unsuffixed(n);
    let registry = quote! {
        runtime::compiled_cell!(#key, #n, #f, #ft, #fp, #four),
    };
    (linked, registry)
}

/// The generated cells of a chain: their kernels (`defs`), and the arms
/// of `Cells::one`, `four`, `tangent` and `pose`; the cells others may link
/// (3D chains', whose every kernel the recursion gives) and their registry.
#[derive(Default)]
struct EmittedCells {
    defs: Vec<TokenStream>,
    ones: Vec<TokenStream>,
    fours: Vec<TokenStream>,
    tangents: Vec<TokenStream>,
    poses: Vec<TokenStream>,
    linked: Vec<TokenStream>,
    registry: Vec<TokenStream>,
}

/// Whether a chain's cells get lane kernels: the 3D recursion's mass +
/// bias evaluates four links at once; the planar one (`links::planar`)
/// one at a time, inlined.
fn lanes(links: &runtime::links::LinkKernels) -> bool {
    links.mass_bias && links.layout.base_angle.is_none()
}

fn emit_cells(links: &runtime::links::LinkKernels) -> EmittedCells {
    use runtime::links::CELL_PARAMS;
    let layout = &links.layout;
    let EmittedCells {
        mut defs,
        mut ones,
        mut fours,
        mut tangents,
        mut poses,
        mut linked,
        mut registry,
    } = EmittedCells::default();
    for (c, ((tape, tangent), pose)) in links
        .cells
        .iter()
        .zip(&links.tangents)
        .zip(&links.poses)
        .enumerate()
    {
        let n = layout
            .links
            .iter()
            .find(|l| l.cell == c)
            .map_or(0, |l| l.map.len());
        let name = format!("cell_{c}");
        let name4 = format!("cell_{c}_x4");
        let name_t = format!("cell_{c}_tangent");
        let name_p = format!("cell_{c}_pose");
        // A pose serves the outputs (a row's tip, not the right-hand side):
        // interpreted, as the derived parameters are.
        defs.push(emit_interpreted(pose, &name_p, n, CELL_PARAMS));
        let fp = Ident::new(&name_p, Span::call_site());
        defs.push(with_tangent(
            tape,
            tangent,
            &name,
            n,
            CELL_PARAMS,
            lanes(links),
        ));
        let (f, f4, ft) = (
            Ident::new(&name, Span::call_site()),
            Ident::new(&name4, Span::call_site()),
            Ident::new(&name_t, Span::call_site()),
        );
        let n2 = 2 * n;
        let f0 = format_ident!("{}_0", name);
        ones.push(quote! {
            // SAFETY: the kernel that made `LinkCells` has checked that the
            // processor has FMA (and so AVX, as for `four`); called straight,
            // the cell may be inlined into the recursion.
            #c => unsafe { #f0::<f64>(0.0, x.try_into().expect("link coordinates"), xd.try_into().expect("link rates"),
                     &[0.0; #n], &[0.0; #n2], p.try_into().expect("cell parameters"),
                     out.try_into().expect("cell outputs")) },
        });
        fours.push(quote! {
            // SAFETY: `mass_bias` has checked that the processor has FMA
            // (and so AVX: `is_x86_feature_detected` reports FMA only
            // where the system saves the AVX registers).
            #c => unsafe { #f4(x.try_into().expect("link coordinates"), xd.try_into().expect("link rates"),
                               p.try_into().expect("cell parameters"), out.try_into().expect("cell outputs")) },
        });
        poses.push(quote! {
            #c => #fp(0.0, x.try_into().expect("link coordinates"), xd.try_into().expect("link rates"),
                      &[0.0; #n], &[0.0; #n2], p.try_into().expect("cell parameters"),
                      out.try_into().expect("pose outputs")),
        });
        // Every chain's cells, for arms no compiled-in model has.
        let f4 = lanes(links).then_some(&f4);
        let (one, reg) = emit_linked_cell(c, n, (tape, tangent, pose), (&f, f4, &ft, &fp));
        linked.push(one);
        registry.push(reg);
        tangents.push(quote! {
            #c => {
                let mut dir = [0.0; #n2];
                dir[..#n].copy_from_slice(dx);
                dir[#n..].copy_from_slice(dxd);
                #ft(0.0, x.try_into().expect("link coordinates"), xd.try_into().expect("link rates"),
                    &[0.0; #n], &dir, p.try_into().expect("cell parameters"),
                    out.try_into().expect("cell outputs and derivatives"))
            }
        });
    }
    EmittedCells {
        defs,
        ones,
        fours,
        tangents,
        poses,
        linked,
        registry,
    }
}

/// The chain's kernels of the whole arm, pushed to `defs`, and how
/// `Cells` calls them: a rom segment's forces and their tangent, its
/// energy, the actuation loads.
fn emit_link_globals(
    links: &runtime::links::LinkKernels,
    dof: usize,
    n_params: usize,
    defs: &mut Vec<TokenStream>,
) -> [TokenStream; 4] {
    let n_dir = 2 * dof;
    let (forces, forces_tangent) = match (&links.forces, &links.forces_tangent) {
        (Some(tape), Some(tangent)) => {
            defs.push(with_tangent(
                tape,
                tangent,
                "link_forces",
                dof,
                n_params,
                false,
            ));
            (
                quote! {
                    link_forces(0.0, self.q, self.qd, &[0.0; #dof], &[0.0; #n_dir], self.p,
                                out.try_into().expect("force outputs"))
                },
                quote! {
                    link_forces_tangent(0.0, self.q, self.qd, &[0.0; #dof],
                                        dir.try_into().expect("a direction of 2 DOF entries"), self.p,
                                        out.try_into().expect("force outputs and derivatives"))
                },
            )
        }
        _ => (
            quote!(unreachable!("no non-local forces")),
            quote!(unreachable!("no non-local forces")),
        ),
    };
    let energy = match &links.energy {
        Some(tape) => {
            defs.push(KernelEmitter::new(tape).emit("link_energy", dof, n_params, 0));
            quote! {
                let mut out = [0.0];
                link_energy(0.0, self.q, self.qd, &[0.0; #dof], &[0.0; #n_dir], self.p, &mut out);
                out[0]
            }
        }
        None => quote!(unreachable!("no non-local forces")),
    };
    let loads = match &links.loads {
        Some(tape) => {
            defs.push(KernelEmitter::new(tape).emit("link_loads", dof, n_params, 0));
            quote! {
                link_loads(0.0, self.q, self.qd, &[0.0; #dof], &[0.0; #n_dir], self.p,
                           out.try_into().expect("load outputs"))
            }
        }
        None => quote!(unreachable!("no actuators")),
    };
    [forces, forces_tangent, energy, loads]
}

/// `LinkCells`, the `Cells` the generated recursion evaluates.
fn emit_cells_impl(
    links: &runtime::links::LinkKernels,
    cells: &EmittedCells,
    globals: [TokenStream; 4],
    dof: usize,
    n_params: usize,
) -> TokenStream {
    let EmittedCells {
        ones,
        fours,
        tangents,
        poses,
        ..
    } = cells;
    let [forces, forces_tangent, loads, energy] = globals;
    // Lane kernels serve the 3D recursion's mass + bias alone.
    let four = match lanes(links) {
        true => quote! {
            #[cfg(target_arch = "x86_64")]
            #[inline(always)]
            fn four(&mut self, c: usize, x: &[[f64; 4]], xd: &[[f64; 4]], p: &[[f64; 4]], out: &mut [[f64; 4]]) {
                match c {
                    #(#fours)*
                    _ => unreachable!("cell index from the layout"),
                }
            }
        },
        false => quote!(),
    };
    quote! {
        /// The compiled cells and forces the link recursion evaluates.
        #[allow(dead_code)] // the arm's coordinates serve the forces kernel alone
        struct LinkCells<'a> {
            q: &'a [f64; #dof],
            qd: &'a [f64; #dof],
            p: &'a [f64; #n_params],
        }
        impl runtime::links::Cells for LinkCells<'_> {
            #[inline(always)]
            fn one(&mut self, c: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]) {
                match c {
                    #(#ones)*
                    _ => unreachable!("cell index from the layout"),
                }
            }
            #four
            #[inline(always)]
            fn forces(&mut self, out: &mut [f64]) {
                #forces
            }
            fn tangent(&mut self, c: usize, x: &[f64], xd: &[f64], dx: &[f64], dxd: &[f64], p: &[f64], out: &mut [f64]) {
                match c {
                    #(#tangents)*
                    _ => unreachable!("cell index from the layout"),
                }
            }
            fn forces_tangent(&mut self, dir: &[f64], out: &mut [f64]) {
                #forces_tangent
            }
            #[inline(always)]
            fn loads(&mut self, out: &mut [f64]) {
                #loads
            }
            fn pose(&mut self, c: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]) {
                match c {
                    #(#poses)*
                    _ => unreachable!("cell index from the layout"),
                }
            }
            fn energy(&mut self) -> f64 {
                #energy
            }
        }
    }
}

/// `mass_bias` and `jvp` as the link recursion (`runtime::links`) over the
/// model's cells: each cell a kernel of one link's coordinates and
/// parameters, with its lane form (four links at once) and its tangent
/// (outputs and their directional derivatives, for the Jvp's dual sweep).
fn emit_link_recursion(
    links: &runtime::links::LinkKernels,
    dof: usize,
    n_params: usize,
    n_out: usize,
) -> TokenStream {
    let layout = &links.layout;
    let mut cells = emit_cells(links);
    let [forces, forces_tangent, energy, loads] =
        emit_link_globals(links, dof, n_params, &mut cells.defs);
    let n_dir = 2 * dof;
    let n_outputs = runtime::N_OUTPUTS;
    // Chains of owned links sum by composite bodies; shared links (rom
    // slices) need the arm's coordinates in rows of a fixed length.
    // The sweep is built for the bodies this chain has.
    let bodies = layout.general_bodies();
    let call = if runtime::links::all_owned(layout) {
        quote!(runtime::links::mass_bias_owned::<_, #bodies>(
            &LINKS, &mut cells, q, qd, p, out
        ))
    } else if dof > runtime::links::AT_ONCE {
        quote!(runtime::links::mass_bias_wide::<_, #bodies>(
            &LINKS, &mut cells, q, qd, p, out
        ))
    } else {
        let rows = runtime::links::padded(dof);
        quote!(runtime::links::mass_bias_shared::<#rows, _, #bodies>(&LINKS, &mut cells, q, qd, p, out))
    };
    let cells_impl = emit_cells_impl(
        links,
        &cells,
        [forces, forces_tangent, loads, energy],
        dof,
        n_params,
    );
    let EmittedCells {
        defs,
        linked,
        registry,
        ..
    } = cells;
    let doc = format!(
        " Kernel `mass_bias`: the link recursion (`runtime::links`) over {} links, {} cell(s).",
        layout.links.len(),
        links.cells.len()
    );
    let mass_bias = match links.mass_bias {
        true => quote! {
            #[doc = #doc]
            pub fn mass_bias(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params], out: &mut [f64; #n_out]) {
                runtime::cpu::require_fma();
                // SAFETY: `require_fma` has checked that the processor has FMA.
                unsafe { mass_bias_links(q, qd, p, out) }
            }
            #[cfg_attr(target_arch = "x86_64", target_feature(enable = "avx,fma"))]
            unsafe fn mass_bias_links(q: &[f64; #dof], qd: &[f64; #dof], p: &[f64; #n_params], out: &mut [f64; #n_out]) {
                let mut cells = LinkCells { q, qd, p };
                #call
            }
        },
        false => quote!(),
    };
    let accelerations = match links.mass_bias && layout.direct_accelerations() {
        true => quote! {
            /// The accelerations by the articulated-body sweeps
            /// (`runtime::links::accelerations_owned`), O(links), without M;
            /// false where a link's D is not positive definite.
            pub fn link_accelerations(q: &[f64; #dof], qd: &[f64; #dof], p: &[f64; #n_params], qdd: &mut [f64; #dof]) -> bool {
                runtime::cpu::require_fma();
                // SAFETY: `require_fma` has checked that the processor has FMA.
                unsafe { link_accelerations_fma(q, qd, p, qdd) }
            }
            #[cfg_attr(target_arch = "x86_64", target_feature(enable = "avx,fma"))]
            unsafe fn link_accelerations_fma(q: &[f64; #dof], qd: &[f64; #dof], p: &[f64; #n_params], qdd: &mut [f64; #dof]) -> bool {
                let mut cells = LinkCells { q, qd, p };
                runtime::links::accelerations_owned::<_, #bodies>(&LINKS, &mut cells, q, qd, p, qdd)
            }
        },
        false => quote!(),
    };
    let json = serde_json::to_string(layout).expect("a link layout serialises");
    // A raw string: JSON's quotes unescaped (it has no `#`).
    assert!(!json.contains('#'), "a link layout's JSON has no #");
    let json: TokenStream = format!("r#\"{json}\"#").parse().expect("a raw string");
    let doc_jvp = format!(
        " Kernel `jvp`: the inverse dynamics' tangent by the link recursion (`runtime::links::inverse_dynamics_tangent`) over {} links.",
        layout.links.len(),
    );
    quote! {
        static LINKS: std::sync::LazyLock<runtime::links::LinkLayout> = std::sync::LazyLock::new(|| {
            serde_json::from_str(#json).expect("the generated link layout parses")
        });
        #mass_bias
        #accelerations
        #[doc = #doc_jvp]
        pub fn jvp(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params], out: &mut [f64; #dof]) {
            runtime::cpu::require_fma();
            // SAFETY: `require_fma` has checked that the processor has FMA.
            unsafe { jvp_fma(q, qd, qdd, dir, p, out) }
        }
        /// The recursion inlined into a function built for FMA: its dual
        /// numbers' fused products are instructions, not library calls.
        #[inline(never)]
        #[cfg_attr(target_arch = "x86_64", target_feature(enable = "fma"))]
        fn jvp_fma(q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params], out: &mut [f64; #dof]) {
            let mut cells = LinkCells { q, qd, p };
            let mut tau = [0.0; #dof];
            runtime::links::inverse_dynamics_tangent(&LINKS, &mut cells, q, qd, qdd, dir, p, &mut tau, out)
        }
        /// Kernel `outputs`: one sweep over the links' pose cells (`runtime::links::outputs`).
        pub fn outputs(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params], out: &mut [f64; #n_outputs]) {
            runtime::cpu::require_fma();
            let mut cells = LinkCells { q, qd, p };
            runtime::links::outputs(&LINKS, &mut cells, q, qd, p, out)
        }
        #cells_impl
        #(#defs)*
        #(#linked)*
        /// This model's cells, for chains of other lengths to link.
        pub static CELLS: &[runtime::links::CompiledCell] = &[#(#registry)*];
    }
}

/// `mass_bias` and `jvp` of a system of parts (`runtime::parts`): the
/// layout as JSON and one kernel and its tangent per kind of part.
fn emit_parts(
    parts: &runtime::parts::PartKernels,
    dof: usize,
    n_params: usize,
    n_out: usize,
) -> TokenStream {
    let mut defs = Vec::new();
    let (mut evals, mut tangents, mut registry) = (Vec::new(), Vec::new(), Vec::new());
    for (k, (tape, tangent)) in parts.kernels.iter().zip(&parts.tangents).enumerate() {
        let key = crate::build::kernel_key(&[tape, tangent]);
        registry.push(quote!(runtime::compiled_part!(#key, PartKernels, #k),));
        let spec = parts
            .layout
            .parts
            .iter()
            .find(|s| s.kernel == k)
            .expect("every part kernel is used");
        let (m, np) = (spec.coords.len(), spec.params.len());
        let (name, name_t) = (format!("part_{k}"), format!("part_{k}_tangent"));
        defs.push(with_tangent(tape, tangent, &name, m, np, false));
        let (f, ft) = (
            Ident::new(&name, Span::call_site()),
            Ident::new(&name_t, Span::call_site()),
        );
        let m2 = 2 * m;
        evals.push(quote! {
            #k => #f(0.0, x.try_into().expect("part coordinates"), xd.try_into().expect("part rates"),
                     &[0.0; #m], &[0.0; #m2], p.try_into().expect("part parameters"),
                     out.try_into().expect("part outputs")),
        });
        tangents.push(quote! {
            #k => {
                let mut dir = [0.0; #m2];
                dir[..#m].copy_from_slice(dx);
                dir[#m..].copy_from_slice(dxd);
                #ft(0.0, x.try_into().expect("part coordinates"), xd.try_into().expect("part rates"),
                    &[0.0; #m], &dir, p.try_into().expect("part parameters"),
                    out.try_into().expect("part outputs and derivatives"))
            }
        });
    }
    let (pose, offsets) = (
        parts.pose.as_ref().expect("a pose kernel"),
        parts.offsets.as_ref().expect("an offsets kernel"),
    );
    let np = parts.layout.pose_coords.len();
    defs.push(KernelEmitter::new(pose).emit("part_pose", np, n_params, 0));
    defs.push(KernelEmitter::new(offsets).emit("part_offsets", 0, n_params, 0));
    let loads = match &parts.loads {
        Some(loads) => {
            defs.push(KernelEmitter::new(loads).emit("part_loads", 0, n_params, 0));
            quote! {
                part_loads(0.0, &[], &[], &[], &[], p.try_into().expect("parameter vector length"),
                           out.try_into().expect("loads outputs"))
            }
        }
        None => quote! {
            let _ = p;
            debug_assert!(out.is_empty(), "no actuator acts")
        },
    };
    let np2 = 2 * np;
    let json = serde_json::to_string(&parts.layout).expect("a part layout serialises");
    let n_dir = 2 * dof;
    let doc = format!(
        " Kernel `mass_bias`: the sum of {} parts (`runtime::parts`), {} kind(s).",
        parts.layout.parts.len(),
        parts.kernels.len()
    );
    quote! {
        static PARTS: std::sync::LazyLock<runtime::parts::PartLayout> = std::sync::LazyLock::new(|| {
            serde_json::from_str(#json).expect("the generated part layout parses")
        });
        /// The compiled part kernels.
        struct PartKernels;
        /// This model's part kernels, for systems of other lengths to link.
        pub static PART_KERNELS: &[runtime::parts::CompiledPart] = &[#(#registry)*];
        impl runtime::parts::Parts for PartKernels {
            fn eval(&mut self, k: usize, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]) {
                match k {
                    #(#evals)*
                    _ => unreachable!("part kernel index from the layout"),
                }
            }
            fn tangent(&mut self, k: usize, x: &[f64], xd: &[f64], dx: &[f64], dxd: &[f64], p: &[f64], out: &mut [f64]) {
                match k {
                    #(#tangents)*
                    _ => unreachable!("part kernel index from the layout"),
                }
            }
            fn pose(&mut self, x: &[f64], xd: &[f64], p: &[f64], out: &mut [f64]) {
                part_pose(0.0, x.try_into().expect("pose coordinates"), xd.try_into().expect("pose rates"),
                          &[0.0; #np], &[0.0; #np2], p.try_into().expect("parameter vector length"),
                          out.try_into().expect("pose outputs"))
            }
            fn offsets(&mut self, p: &[f64], out: &mut [f64]) {
                part_offsets(0.0, &[], &[], &[], &[], p.try_into().expect("parameter vector length"),
                             out.try_into().expect("offsets outputs"))
            }
            fn loads(&mut self, p: &[f64], out: &mut [f64]) {
                #loads
            }
        }
        /// Kernel `outputs`: the parts' energies, the pose and the offsets (`runtime::parts::outputs`).
        pub fn outputs(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params], out: &mut [f64; runtime::N_OUTPUTS]) {
            runtime::cpu::require_fma();
            runtime::parts::outputs(&PARTS, &mut PartKernels, q, qd, p, out)
        }
        #[doc = #doc]
        pub fn mass_bias(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params], out: &mut [f64; #n_out]) {
            runtime::cpu::require_fma();
            runtime::parts::mass_bias(&PARTS, &mut PartKernels, q, qd, p, out)
        }
        /// Kernel `jvp`: the inverse dynamics' tangent, over the parts the direction moves (`runtime::parts`).
        pub fn jvp(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params], out: &mut [f64; #dof]) {
            runtime::cpu::require_fma();
            runtime::parts::jvp(&PARTS, &mut PartKernels, q, qd, qdd, dir, p, out)
        }
        #(#defs)*
    }
}

/// Which member of its family an op is: the derivative order (sin 0, cos
/// 1), and for the Rodrigues coefficients c_j also j.
type Member = (u8, u8);

/// Functions evaluated together when several members share an argument.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
enum Family {
    /// Order 0: sin, 1: cos.
    SinCos,
    Sinc,
    Cosc,
    SincRem,
    /// The c_j of `runtime::rodrigues::family`, members (j, order).
    Rodrigues,
}

fn family_of(op: &Op) -> Option<(Family, Member, Slot)> {
    match *op {
        Op::Sin(a) => Some((Family::SinCos, (0, 0), a)),
        Op::Cos(a) => Some((Family::SinCos, (0, 1), a)),
        Op::Sinc(k, a) => Some((Family::Sinc, (0, k), a)),
        Op::Cosc(k, a) => Some((Family::Cosc, (0, k), a)),
        Op::SincRem(k, a) => Some((Family::SincRem, (0, k), a)),
        Op::Rodrigues(j, n, a)
            if usize::from(j) < runtime::rodrigues::FAMILY_J
                && usize::from(n) < runtime::rodrigues::FAMILY_ORDERS =>
        {
            Some((Family::Rodrigues, (j, n), a))
        }
        _ => None,
    }
}

impl Family {
    /// `call` in a generic kernel, at a moving argument: the members as
    /// `S`, from the `Scalar` methods.
    fn call_generic(
        self,
        members: &[(Member, usize)],
        a: TokenStream,
        ty: TokenStream,
    ) -> TokenStream {
        let n = Self::orders(members);
        if self == Family::Rodrigues {
            let lets = Self::rodrigues_members(members, &ty);
            return quote! {
                let c: [[#ty; #n]; runtime::rodrigues::FAMILY_J] = #a.rodrigues_family::<#n>();
                #(#lets)*
            };
        }
        let names = Self::names(members, n);
        let f = match self {
            Family::SinCos => return quote!(let (#(#names),*): (#ty, #ty) = #a.sin_cos();),
            Family::Sinc => quote!(sinc_orders),
            Family::Cosc => quote!(cosc_orders),
            Family::SincRem => quote!(sinc_rem_orders),
            Family::Rodrigues => unreachable!("handled above"),
        };
        quote!(let [#(#names),*]: [#ty; #n] = #a.#f::<#n>();)
    }

    /// How many orders one call gives: up to the highest member's.
    fn orders(members: &[(Member, usize)]) -> usize {
        members
            .iter()
            .map(|m| usize::from(m.0.1))
            .max()
            .unwrap_or(0)
            + 1
    }

    /// Each Rodrigues member's `let`, of type `ty`, from the family `c`.
    fn rodrigues_members(members: &[(Member, usize)], ty: &TokenStream) -> Vec<TokenStream> {
        members
            .iter()
            .map(|&((j, k), i)| {
                let (j, k) = (usize::from(j), usize::from(k));
                let v = format_ident!("v{}", i);
                quote!(let #v: #ty = c[#j][#k];)
            })
            .collect()
    }

    /// The binding of each order below `n`: its member's value, or `_`.
    fn names(members: &[(Member, usize)], n: usize) -> Vec<TokenStream> {
        (0..n)
            .map(|k| match members.iter().find(|m| usize::from(m.0.1) == k) {
                Some(&(_, i)) => {
                    let v = format_ident!("v{}", i);
                    quote!(#v)
                }
                None => quote!(_),
            })
            .collect()
    }

    /// `let` binding the members (member, op index) from one call at `a`.
    fn call(self, members: &[(Member, usize)], a: TokenStream, lanes: bool) -> TokenStream {
        let ty = if lanes { quote!(__m256d) } else { quote!(f64) };
        let n = Self::orders(members);
        if self == Family::Rodrigues {
            let lets = Self::rodrigues_members(members, &ty);
            let family = if lanes {
                quote!(runtime::lanes::family)
            } else {
                quote!(runtime::rodrigues::family)
            };
            return quote! {
                let c: [[#ty; #n]; runtime::rodrigues::FAMILY_J] = #family::<#n>(#a);
                #(#lets)*
            };
        }
        let names = Self::names(members, n);
        let f = match self {
            Family::SinCos if lanes => {
                return quote!(let (#(#names),*): (#ty, #ty) = runtime::lanes::sin_cos(#a););
            }
            Family::SinCos => {
                return quote!(let (#(#names),*): (f64, f64) = runtime::special::sin_cos(#a););
            }
            Family::Sinc => quote!(sinc_orders),
            Family::Cosc => quote!(cosc_orders),
            Family::SincRem => quote!(sinc_rem_orders),
            Family::Rodrigues => unreachable!("handled above"),
        };
        if lanes {
            quote!(let [#(#names),*]: [#ty; #n] = runtime::lanes::orders(#a, runtime::special::#f::<#n>);)
        } else {
            quote!(let [#(#names),*]: [f64; #n] = runtime::special::#f::<#n>(#a);)
        }
    }
}

/// The `contact_jacobian` kernel: one kernel per group of points, and the
/// function that runs the groups `dir` selects (all of them when `all`).
fn emit_groups(tapes: &TapeSet, dof: usize, n_params: usize, generic: bool) -> TokenStream {
    let info = &tapes.info;
    let n_dir = 2 * dof;
    let width = 6 + 3 * dof;
    let n_out = info.contact_points * width;
    let n_aux = info.contact_frames;
    let aux_param = match n_aux {
        0 => quote!(),
        _ => quote!(aux: &[f64; #n_aux],),
    };
    let mut kernels = Vec::new();
    let mut calls = Vec::new();
    let groups = info.contact_group_ranges();
    for (g, ((first, len), tape)) in groups.zip(&tapes.contact_jacobian).enumerate() {
        let name = format!("contact_jacobian_{g}");
        let emitter = match generic {
            true => KernelEmitter::new_generic(tape, false),
            false => KernelEmitter::new(tape),
        };
        kernels.push(match generic {
            true => emitter.emit_generic(&name, dof, n_params, n_aux, false, false),
            false => emitter.emit(&name, dof, n_params, n_aux),
        });
        let f = Ident::new(&name, Span::call_site());
        let (a, b) = (first * width, (first + len) * width);
        let aux_arg = match emitter.aux_len() {
            0 => quote!(),
            _ => quote!(aux,),
        };
        calls.push(quote! {
            if all || dir[#g] != 0.0 {
                #f(t, q, qd, qdd, dir, p, #aux_arg (&mut out[#a..#b]).try_into().expect("group output length"));
            }
        });
    }
    let doc = format!(
        " Kernel `contact_jacobian`: the points' positions, velocities and Jacobians in {} groups; group g runs when `all` or `dir[g] != 0`.",
        info.contact_groups.len()
    );
    quote! {
        #[doc = #doc]
        pub fn contact_jacobian(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir],
                                all: bool, p: &[f64; #n_params], #aux_param out: &mut [f64; #n_out]) {
            #(#calls)*
        }
        #(#kernels)*
    }
}

/// The `contact_jvp` kernel from the generic `contact` and
/// `contact_jacobian` groups run on dual numbers moving along dq (the
/// first n of `dir`): each point's dv and d(dp/dq), the tails of its
/// group's rows; the contact frames' derivatives come from `contact`.
fn emit_contact_jvp(tapes: &TapeSet, dof: usize, n_params: usize) -> TokenStream {
    let info = &tapes.info;
    let n_dir = 2 * dof;
    let width = 6 + 3 * dof;
    let tail = 3 + 3 * dof;
    let n_out = info.contact_points * tail;
    let n_aux = info.contact_frames;
    let frames = match n_aux {
        0 => quote!(),
        _ => {
            let n_contact = 3 * info.contact_points + n_aux;
            let first = 3 * info.contact_points;
            quote! {
                let mut c = [runtime::dual::Dual::ZERO; #n_contact];
                // SAFETY: `require_fma` has checked that the processor has FMA.
                unsafe { contact_0::<runtime::dual::Dual>(t, &x, &xd, qdd, dir, p, &mut c) };
                let aux: &[runtime::dual::Dual; #n_aux] = c[#first..].try_into().expect("frames length");
            }
        }
    };
    // A group whose points do not move with any coordinate dq moves is
    // not evaluated: a chain's group reads the coordinates up to its link
    // (through its frame), so a column of a later link skips it.
    let frame_moved = moved_by(&tapes.contact, dof, &[]).split_off(3 * info.contact_points);
    let groups = info.contact_group_ranges().zip(&tapes.contact_jacobian);
    let calls = groups.enumerate().map(|(g, ((first, len), tape))| {
        let f = format_ident!("contact_jacobian_{}_0", g);
        let n = len * width;
        let (a, b) = (first * tail, (first + len) * tail);
        let aux = match KernelEmitter::new(tape).aux_len() {
            0 => quote!(),
            _ => quote!(aux,),
        };
        let moved =
            moved_by(tape, dof, &frame_moved)
                .into_iter()
                .fold(vec![false; dof], |mut m, o| {
                    m.iter_mut().zip(o).for_each(|(m, o)| *m |= o);
                    m
                });
        let eval = quote! {
            let mut o = [runtime::dual::Dual::ZERO; #n];
            // SAFETY: `require_fma` has checked that the processor has FMA.
            unsafe { #f::<runtime::dual::Dual>(t, &x, &xd, qdd, dir, p, #aux &mut o) };
            runtime::dual::row_tails(&o, #width, &mut out[#a..#b]);
        };
        let moving: Vec<usize> = (0..dof).filter(|&k| moved[k]).collect();
        // A chain's group moves with the coordinates up to its link: a range.
        let test = match moving[..] {
            [first, .., last] if last - first + 1 == moving.len() => {
                quote!(dir[#first..=#last].iter().any(|&d| d != 0.0))
            }
            _ => {
                let each = moving.iter().map(|k| quote!(dir[#k] != 0.0));
                quote!(#(#each)||*)
            }
        };
        match (moving.len(), moved.iter().all(|&m| m)) {
            (_, true) => quote!({ #eval }),
            (0, _) => quote!(out[#a..#b].fill(0.0);),
            _ => quote! {
                if #test {
                    #eval
                } else {
                    out[#a..#b].fill(0.0);
                }
            },
        }
    });
    quote! {
        /// Kernel `contact_jvp`: the contact groups on dual numbers along dq.
        pub fn contact_jvp(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir],
                           p: &[f64; #n_params], out: &mut [f64; #n_out]) {
            runtime::cpu::require_fma();
            let x = runtime::dual::seed(q, &dir[..#dof]);
            let xd = qd.map(runtime::dual::Dual::constant);
            #frames
            #(#calls)*
        }
    }
}

/// Which of the `dof` coordinates each output of `tape` moves with: those
/// it reads, and through `Aux(k)` those `aux[k]` moves with.
fn moved_by(tape: &Tape, dof: usize, aux: &[Vec<bool>]) -> Vec<Vec<bool>> {
    let mut moved: Vec<Vec<bool>> = Vec::with_capacity(tape.ops.len());
    for op in &tape.ops {
        let m = match *op {
            Op::Q(k) => (0..dof).map(|i| i == k as usize).collect(),
            Op::Aux(k) => aux[k as usize].clone(),
            _ => op.operands().fold(vec![false; dof], |mut m, a| {
                m.iter_mut()
                    .zip(&moved[a as usize])
                    .for_each(|(m, &o)| *m |= o);
                m
            }),
        };
        moved.push(m);
    }
    (tape.outputs.iter())
        .map(|&s| moved[s as usize].clone())
        .collect()
}

/// The header line that carries the structural hash.
pub const HASH_PREFIX: &str = "// structural-hash: ";

/// `contact_jacobian_framed`: the groups with the contact frames given
/// (`aux`, `n_aux` values), or from the `contact` kernel for a caller that
/// has not run `accel`; nothing without frames.
/// `Kernels::accelerations` of a chain whose accelerations come from the
/// articulated-body sweeps (`link_accelerations`); nothing otherwise (the
/// trait's None: M and its solve).
fn emit_accelerations_method(tapes: &TapeSet) -> TokenStream {
    match &tapes.links {
        Some(links) if links.mass_bias && links.layout.direct_accelerations() => quote! {
            fn accelerations(&self, inp: &Inputs, qdd: &mut [f64]) -> Option<bool> {
                let q = inp.q.try_into().expect("q has DOF entries");
                let qd = inp.qd.try_into().expect("qd has DOF entries");
                let p = inp.p.try_into().expect("parameter vector length");
                Some(link_accelerations(q, qd, p, qdd.try_into().expect("qdd has DOF entries")))
            }
        },
        _ => quote!(),
    }
}

fn emit_framed_groups(
    dof: usize,
    n_params: usize,
    n_aux: usize,
    contact_points: usize,
) -> TokenStream {
    let n_dir = 2 * dof;
    match n_aux {
        0 => quote!(),
        _ => {
            let n_contact = 3 * contact_points + n_aux;
            let first = 3 * contact_points;
            quote! {
                /// The `contact_jacobian` groups with the frames given, or else
                /// from the `contact` kernel.
                fn contact_jacobian_framed(inp: &Inputs, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof],
                          dir: &[f64; #n_dir], p: &[f64; #n_params], out: &mut [f64]) {
                    let out = out.try_into().expect("output length");
                    let all = inp.dir.is_empty();
                    match <&[f64; #n_aux]>::try_from(inp.aux) {
                        Ok(aux) => contact_jacobian(inp.t, q, qd, qdd, dir, all, p, aux, out),
                        Err(_) => {
                            let mut own = [0.0f64; #n_contact];
                            contact(inp.t, q, qd, qdd, dir, p, &mut own);
                            let aux = own[#first..].try_into().expect("frames length");
                            contact_jacobian(inp.t, q, qd, qdd, dir, all, p, aux, out)
                        }
                    }
                }
            }
        }
    }
}

/// Every kernel's function (those the parts or the link recursion give
/// aside) and its arm in `Kernels::eval`.
fn emit_kernels(
    tapes: &TapeSet,
    dof: usize,
    n_params: usize,
    n_aux: usize,
) -> (Vec<TokenStream>, Vec<TokenStream>) {
    let mut kernels = Vec::new();
    let mut arms = Vec::new();
    let generic_contact = tapes.info.contact_points > 0
        && KernelEmitter::fits_generic(&tapes.contact)
        && tapes
            .contact_jacobian
            .iter()
            .all(KernelEmitter::fits_generic);
    for kind in KernelKind::ALL {
        let name = kind.name();
        let by_parts = tapes.parts.is_some()
            && matches!(
                kind,
                KernelKind::MassBias | KernelKind::Jvp | KernelKind::Outputs
            );
        let by_arms = tapes.arm_blocks.as_ref().is_some_and(|b| match kind {
            KernelKind::MassBias | KernelKind::Jvp | KernelKind::Derived => true,
            KernelKind::Outputs => !b.arms.is_empty(),
            KernelKind::Contact | KernelKind::ContactJacobian | KernelKind::ContactJvp => {
                b.rest_contact.is_some()
            }
            _ => false,
        });
        match (&tapes.links, kind) {
            // Emitted with the parts or the arms, below.
            _ if by_parts || by_arms => {}
            // Emitted with the recursion, below.
            (Some(_), KernelKind::Jvp | KernelKind::Outputs) => {}
            (Some(links), KernelKind::MassBias) if links.mass_bias => {}
            (_, KernelKind::Accel) if tapes.info.accel => {
                kernels.push(emit_accel(tapes, dof, n_params))
            }
            // Emitted with `Accel`, on the same code.
            (_, KernelKind::MassBias) if tapes.info.accel => {}
            (_, KernelKind::ContactJacobian) => {
                kernels.push(emit_groups(tapes, dof, n_params, generic_contact))
            }
            (_, KernelKind::Contact) if generic_contact => kernels.push(
                KernelEmitter::new_generic(&tapes.contact, false)
                    .emit_generic(name, dof, n_params, n_aux, false, false),
            ),
            (_, KernelKind::ContactJvp) if generic_contact => {
                kernels.push(emit_contact_jvp(tapes, dof, n_params))
            }
            (_, KernelKind::Derived) => {
                kernels.push(emit_interpreted(&tapes.derived, name, dof, n_params))
            }
            _ => {
                let tape = &tapes.tapes(kind)[0];
                kernels.push(KernelEmitter::new(tape).emit(name, dof, n_params, n_aux))
            }
        }
        let f = Ident::new(name, Span::call_site());
        let variant = Ident::new(&format!("{kind:?}"), Span::call_site());
        // A grouped kernel reads an empty direction as "every group", and
        // the contact frames as `aux`.
        let all = match kind {
            KernelKind::ContactJacobian => quote!(inp.dir.is_empty()),
            _ => quote!(),
        };
        // (`call!`, defined in `eval`, passes the inputs: one line an arm.)
        arms.push(match kind {
            KernelKind::ContactJacobian if n_aux > 0 => quote! {
                KernelKind::#variant => contact_jacobian_framed(inp, q, qd, qdd, dir, p, out),
            },
            _ => quote! {
                KernelKind::#variant => call!(#f, #all),
            },
        });
    }
    (kernels, arms)
}

/// A kernel off the integration's path (the derived parameters, once per
/// parameter set; a cell's pose, for a row's outputs), as its tape in
/// text (`runtime::Tape::to_text`), read once and interpreted: compiled, it
/// bought no time that counts and cost source and build time. Same
/// signature as an emitted kernel.
fn emit_interpreted(tape: &Tape, name: &str, dof: usize, n_params: usize) -> TokenStream {
    let n_out = tape.outputs.len();
    let n_dir = 2 * dof;
    let f = Ident::new(name, Span::call_site());
    let doc = format!(
        " Kernel `{name}`: {} operations off the integration's path, interpreted from its tape (below, as text) rather than compiled.",
        tape.op_count()
    );
    // A raw string: the text's line breaks stay line breaks in the file.
    let text: TokenStream = format!("r\"{}\"", tape.to_text())
        .parse()
        .expect("a tape's text is a raw string");
    quote! {
        #[doc = #doc]
        pub fn #f(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params], out: &mut [f64; #n_out]) {
            runtime::interpreted!(#text, t, q, qd, qdd, dir, p, out);
        }
    }
}

/// `Accel` and `MassBias` from one tape (`TapeSet::accel`: the solve's
/// values, then M and h): its code is emitted once, always inlined, into
/// two functions built for FMA. Each keeps its own values, and the
/// compiler drops the code of the others (in `mass_bias` the solve, in
/// `accel` nothing that M and h do not feed).
fn emit_accel(tapes: &TapeSet, dof: usize, n_params: usize) -> TokenStream {
    let (n_mb, n_out) = (
        KernelKind::MassBias.output_len(&tapes.info),
        KernelKind::Accel.output_len(&tapes.info),
    );
    assert_eq!(
        tapes.accel.outputs.len(),
        n_out + n_mb,
        "the accel tape gives Accel, then MassBias"
    );
    let n_dir = 2 * dof;
    let all = KernelEmitter {
        split: Some(n_out),
        ..KernelEmitter::new(&tapes.accel)
    };
    let (chunks, names) = all.chunks("eom", dof, n_params, 0, true);
    let n_spill = all.n_spill;
    let inputs = quote!(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params]);
    // `outs`: the chunks' two output arrays, the kernel's own and a local
    // one whose values are never read.
    let kernel = |name: &str, n: usize, n_unused: usize, outs: TokenStream, which: &str| {
        let f = Ident::new(name, Span::call_site());
        let fma = format_ident!("{}_fma", name);
        let doc = format!(
            " Kernel `{name}`: the {which} {n} values of `eom` ({} operations for all).",
            tapes.accel.op_count()
        );
        let call = with_workspace(
            n_spill,
            quote!(unsafe { #fma(t, q, qd, qdd, dir, p, w, out) };),
        );
        quote! {
            #[doc = #doc]
            pub fn #f(#inputs, out: &mut [f64; #n]) {
                runtime::cpu::require_fma();
                // SAFETY: `require_fma` has checked that the processor has FMA.
                #call
            }
            #[inline(never)]
            #[cfg_attr(target_arch = "x86_64", target_feature(enable = "fma"))]
            fn #fma(#inputs, w: &mut [f64; #n_spill], out: &mut [f64; #n]) {
                let mut unused = [0.0f64; #n_unused];
                #(#names(t, q, qd, qdd, dir, p, w, #outs);)*
            }
        }
    };
    let accel = kernel("accel", n_out, n_mb, quote!(out, &mut unused), "first");
    let mass_bias = kernel("mass_bias", n_mb, n_out, quote!(&mut unused, out), "last");
    quote! {
        #accel
        #mass_bias
        #(#chunks)*
    }
}

/// An assembly's `MassBias`, `Jvp` and `Derived` through its arms' own
/// kernels (`runtime::arm_blocks`): each distinct arm structure's kernels
/// in a module `arm_K`, called on each arm's slices of q, qd, qdd, the
/// direction and the extended parameters, added to the rest of the
/// system's flat kernels.
fn emit_arm_blocks(
    tapes: &TapeSet,
    blocks: &ArmBlocks,
    dof: usize,
    n_params: usize,
) -> TokenStream {
    let n_dir = 2 * dof;
    let n_base = tapes.info.parameters.len();
    let own = tapes.info.derived;
    let (starts, n_derived) = blocks.derived_layout(own);
    let modules = blocks.kinds.iter().enumerate().map(|(k, kind)| {
        let name = format_ident!("arm_{}", k);
        let items = model_tokens(kind);
        quote! {
            /// The kernels of one arm structure of this assembly, as a single arm's.
            #[allow(dead_code, unused_imports)]
            pub mod #name {
                #items
            }
        }
    });
    let flat = [
        KernelEmitter::new(&blocks.rest_mass_bias).emit("rest_mass_bias", dof, n_params, 0),
        KernelEmitter::new(&blocks.rest_jvp).emit("rest_jvp", dof, n_params, 0),
        KernelEmitter::new(&blocks.rest_outputs).emit("rest_outputs", dof, n_params, 0),
        emit_interpreted(&tapes.derived, "own_derived", dof, n_params),
    ];
    let (mut mass_bias, mut jvp, mut derived) = (Vec::new(), Vec::new(), Vec::new());
    let mut outputs = Vec::new();
    for (i, (a, &start)) in blocks.arms.iter().zip(&starts).enumerate() {
        let module = format_ident!("arm_{}", a.kind);
        let kind = &blocks.kinds[a.kind];
        let (first, m) = (a.first, a.dof);
        let (nb, nd) = (kind.info.parameters.len(), kind.info.derived);
        let (off, x) = (a.params, n_base + start);
        let (m_mb, m_dir, m_ext) = (m * (m + 1) / 2 + m, 2 * m, nb + nd);
        let slice = |v: TokenStream, from: usize, len: usize| quote!(#v[#from..#from + #len].try_into().expect("an arm's slice"));
        let (aq, aqd, aqdd) = (
            slice(quote!(q), first, m),
            slice(quote!(qd), first, m),
            slice(quote!(qdd), first, m),
        );
        let ap = slice(quote!(p), x, m_ext);
        mass_bias.push(quote! {
            let mut block = [0.0f64; #m_mb];
            #module::mass_bias(t, #aq, #aqd, #aqdd, &[0.0; #m_dir], #ap, &mut block);
            runtime::linalg::add_block(#dof, #first, #m, &block, out);
        });
        jvp.push(quote! {
            let mut d = [0.0f64; #m_dir];
            d[..#m].copy_from_slice(&dir[#first..#first + #m]);
            d[#m..].copy_from_slice(&dir[#dof + #first..#dof + #first + #m]);
            // A direction off the arm's block does not move it (a
            // Jacobian's column touches one block).
            if d.iter().any(|&x| x != 0.0) {
                let mut tau = [0.0f64; #m];
                #module::jvp(t, #aq, #aqd, #aqdd, &d, #ap, &mut tau);
                for (o, x) in out[#first..#first + #m].iter_mut().zip(&tau) {
                    *o += x;
                }
            }
        });
        // The energies add up; the tip is the first arm's.
        let tip = match i {
            0 => quote! {
                out[runtime::output::TIP].copy_from_slice(&o[runtime::output::TIP]);
                out[runtime::output::ORIENTATION].copy_from_slice(&o[runtime::output::ORIENTATION]);
            },
            _ => quote!(),
        };
        outputs.push(quote! {
            let mut o = [0.0f64; runtime::N_OUTPUTS];
            #module::outputs(t, #aq, #aqd, #aqdd, &[0.0; #m_dir], #ap, &mut o);
            out[runtime::output::KINETIC] += o[runtime::output::KINETIC];
            out[runtime::output::POTENTIAL] += o[runtime::output::POTENTIAL];
            #tip
        });
        derived.push(quote! {
            let mut pe = [0.0f64; #m_ext];
            pe[..#nb].copy_from_slice(&p[#off..#off + #nb]);
            out[#start..#start + #nb].copy_from_slice(&p[#off..#off + #nb]);
            #module::derived(t, &[0.0; #m], &[0.0; #m], &[0.0; #m], &[0.0; #m_dir], &pe,
                (&mut out[#start + #nb..#start + #m_ext]).try_into().expect("an arm's derived parameters"));
        });
    }
    let n_mb = dof * (dof + 1) / 2 + dof;
    let inputs = quote!(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir], p: &[f64; #n_params]);
    let contact = emit_arm_contact(tapes, blocks, dof, n_params);
    quote! {
        #(#modules)*
        #(#flat)*
        #contact
        /// Kernel `mass_bias`: the rest of the system's, then each arm's in its block.
        pub fn mass_bias(#inputs, out: &mut [f64; #n_mb]) {
            rest_mass_bias(t, q, qd, qdd, dir, p, out);
            #({ #mass_bias })*
        }
        /// Kernel `jvp`: the rest of the system's, then each arm's in its block.
        pub fn jvp(#inputs, out: &mut [f64; #dof]) {
            rest_jvp(t, q, qd, qdd, dir, p, out);
            #({ #jvp })*
        }
        /// Kernel `outputs`: the rest of the system's energies, each arm's
        /// added, and the first arm's tip.
        pub fn outputs(#inputs, out: &mut [f64; runtime::N_OUTPUTS]) {
            rest_outputs(t, q, qd, qdd, dir, p, out);
            #({ #outputs })*
        }
        /// Kernel `derived`: the assembly's own, then each arm's base
        /// parameters and derived ones.
        pub fn derived(#inputs, out: &mut [f64; #n_derived]) {
            own_derived(t, q, qd, qdd, dir, p, (&mut out[..#own]).try_into().expect("own derived parameters"));
            #({ #derived })*
        }
    }
}

/// An arm's slices of the assembly's q, qd, qdd (coordinates `first..first
/// + m`) and of the extended parameters (`x..x + len`).
fn arm_slices(first: usize, m: usize, x: usize, len: usize) -> [TokenStream; 4] {
    let slice = |v: TokenStream, from: usize, len: usize| quote!(#v[#from..#from + #len].try_into().expect("an arm's slice"));
    [
        slice(quote!(q), first, m),
        slice(quote!(qd), first, m),
        slice(quote!(qdd), first, m),
        slice(quote!(p), x, len),
    ]
}

/// The contact kernels through the arms' own (`ArmBlocks::rest_contact`):
/// each arm's points and its groups from its kind's kernels (its contact
/// frames from its `contact`), its Jacobian columns placed in its block;
/// then the points no arm has, from the rest's tapes. Nothing without
/// `rest_contact`.
fn emit_arm_contact(
    tapes: &TapeSet,
    blocks: &ArmBlocks,
    dof: usize,
    n_params: usize,
) -> TokenStream {
    let Some(rest) = &blocks.rest_contact else {
        return quote!();
    };
    let n_base = tapes.info.parameters.len();
    let (starts, _) = blocks.derived_layout(tapes.info.derived);
    let (width, tail) = (6 + 3 * dof, 3 + 3 * dof);
    let (mut points, mut groups, mut tangents) = (Vec::new(), Vec::new(), Vec::new());
    let (mut defs, mut emitted_points) = (Vec::new(), Vec::new());
    let (mut pt, mut g0) = (0, 0);
    for (a, &start) in blocks.arms.iter().zip(&starts) {
        let module = format_ident!("arm_{}", a.kind);
        let info = &blocks.kinds[a.kind].info;
        let (first, m) = (a.first, a.dof);
        let m_dir = 2 * m;
        let [aq, aqd, aqdd, ap] = arm_slices(first, m, n_base + start, info.extended_params());
        let (np, nf, ng) = (
            info.contact_points,
            info.contact_frames,
            info.contact_groups.len(),
        );
        let nc = 3 * np + nf;
        let (np3, nrows, njrows) = (3 * np, np * (6 + 3 * m), np * (3 + 3 * m));
        let own_contact = quote! {
            let mut c = [0.0f64; #nc];
            #module::contact(t, #aq, #aqd, #aqdd, &[0.0; #m_dir], #ap, &mut c);
        };
        let (a3, b3) = (3 * pt, 3 * (pt + np));
        // The positions alone, without the frames (which only the groups
        // read): the kind's `contact` tape sliced.
        let points_fn = format_ident!("arm_points_{}", a.kind);
        if nf > 0 && !emitted_points.contains(&a.kind) {
            emitted_points.push(a.kind);
            let tape = blocks.kinds[a.kind].contact.slice(0, np3);
            let name = points_fn.to_string();
            defs.push(KernelEmitter::new(&tape).emit(&name, m, info.extended_params(), 0));
        }
        let points_of = match nf {
            0 => quote!(#module::contact),
            _ => quote!(#points_fn),
        };
        points.push(quote! {
            #points_of(t, #aq, #aqd, #aqdd, &[0.0; #m_dir], #ap, (&mut out[#a3..#b3]).try_into().expect("an arm's points"));
        });
        let (frames, aux) = match nf {
            0 => (quote!(), quote!()),
            _ => (
                quote! {
                    #own_contact
                    let aux: &[f64; #nf] = c[#np3..].try_into().expect("the arm's contact frames");
                },
                quote!(aux,),
            ),
        };
        let (ga, gb) = (pt * width, (pt + np) * width);
        groups.push(quote! {
            let mut d = [0.0f64; #m_dir];
            d[..#ng].copy_from_slice(&dir[#g0..#g0 + #ng]);
            if all || d.iter().any(|&x| x != 0.0) {
                #frames
                let mut rows = [0.0f64; #nrows];
                #module::contact_jacobian(t, #aq, #aqd, #aqdd, &d, all, #ap, #aux &mut rows);
                runtime::linalg::place_groups(all, &d, #module::CONTACT_GROUPS, #dof, #first, #m, &rows, &mut out[#ga..#gb]);
            }
        });
        let (ja, jb) = (pt * tail, (pt + np) * tail);
        tangents.push(quote! {
            let mut d = [0.0f64; #m_dir];
            d[..#m].copy_from_slice(&dir[#first..#first + #m]);
            let o = &mut out[#ja..#jb];
            // Along a direction off its block, an arm's points do not move.
            if d.iter().any(|&x| x != 0.0) {
                let mut rows = [0.0f64; #njrows];
                #module::contact_jvp(t, #aq, #aqd, #aqdd, &d, #ap, &mut rows);
                runtime::linalg::place_point_rows(3, #dof, #first, #m, &rows, o);
            } else {
                o.fill(0.0);
            }
        });
        pt += np;
        g0 += ng;
    }
    let n_rest: usize = rest.groups.iter().sum();
    if n_rest > 0 {
        defs.push(KernelEmitter::new(&rest.contact).emit("rest_contact", dof, n_params, 0));
        defs.push(KernelEmitter::new(&rest.contact_jvp).emit("rest_contact_jvp", dof, n_params, 0));
        points.push(quote!(rest_contact(t, q, qd, qdd, dir, p, (&mut out[3 * #pt..]).try_into().expect("the rest's points"));));
        tangents.push(quote!(rest_contact_jvp(t, q, qd, qdd, dir, p, (&mut out[#pt * #tail..]).try_into().expect("the rest's points"));));
        let mut at = pt;
        for (r, (tape, &len)) in rest.contact_jacobian.iter().zip(&rest.groups).enumerate() {
            let name = format!("rest_contact_jacobian_{r}");
            defs.push(KernelEmitter::new(tape).emit(&name, dof, n_params, 0));
            let f = Ident::new(&name, Span::call_site());
            let (a, b, g) = (at * width, (at + len) * width, g0 + r);
            groups.push(quote! {
                if all || dir[#g] != 0.0 {
                    #f(t, q, qd, qdd, dir, p, (&mut out[#a..#b]).try_into().expect("group output length"));
                }
            });
            at += len;
        }
    }
    let n_dir = 2 * dof;
    let n_points = tapes.info.contact_points;
    let inputs =
        quote!(t: f64, q: &[f64; #dof], qd: &[f64; #dof], qdd: &[f64; #dof], dir: &[f64; #n_dir]);
    let (n_c, n_j, n_t) = (3 * n_points, n_points * width, n_points * tail);
    quote! {
        #(#defs)*
        /// Kernel `contact`: each arm's points from its own kernels, then the rest's.
        pub fn contact(#inputs, p: &[f64; #n_params], out: &mut [f64; #n_c]) {
            #({ #points })*
        }
        /// Kernel `contact_jacobian`: each arm's groups from its own kernels,
        /// its columns in its block; then the rest's.
        pub fn contact_jacobian(#inputs, all: bool, p: &[f64; #n_params], out: &mut [f64; #n_j]) {
            #({ #groups })*
        }
        /// Kernel `contact_jvp`: each arm's from its own kernels along its
        /// block of dq; then the rest's.
        pub fn contact_jvp(#inputs, p: &[f64; #n_params], out: &mut [f64; #n_t]) {
            #({ #tangents })*
        }
    }
}

/// Rust source of one compiled-in model.
pub fn emit_model(source_path: &str, tapes: &TapeSet) -> String {
    let tokens = unsuffixed(model_tokens(tapes));
    let file: syn::File = syn::parse2(tokens).expect("emitted tokens parse as a Rust file");
    format!(
        "// @generated by eomgen from {source_path}: do not edit; `cargo build` or `softarm derive` rewrites it.\n\
         {HASH_PREFIX}{}\n\n{}",
        tapes.info.hash,
        prettyplease::unparse(&file)
    )
}

/// The items of one model's module: its constants, its `Compiled` kernels
/// and their functions (an assembly's arms' in modules of their own).
fn model_tokens(tapes: &TapeSet) -> TokenStream {
    // An assembly on its arms' kernels has their parameters after its own
    // derived ones.
    let mut info = tapes.info.clone();
    if let Some(b) = &tapes.arm_blocks {
        info.copies = b.copies(info.parameters.len(), info.derived);
        info.derived = b.derived_layout(info.derived).1;
    }
    let info = &info;
    let dof = info.dof();
    let n_params = info.extended_params();
    let n_dir = 2 * dof;
    let n_derived = info.derived;
    let accel = info.accel;
    let loads = &info.loads;
    let rows = &info.constraints;
    let blocks = &info.blocks;
    let contact_points = info.contact_points;
    let contact_groups = &info.contact_groups;
    let contact_frames = info.contact_frames;
    let copies = info.copies.iter().map(|&(j, k)| quote!((#j, #k)));
    let n_aux = contact_frames;
    let hash = &info.hash;
    let (coords, params) = (names(&info.coordinates), names(&info.parameters));
    let frames_fn = emit_framed_groups(dof, n_params, n_aux, contact_points);
    let accelerations_fn = emit_accelerations_method(tapes);
    let (mut kernels, arms) = emit_kernels(tapes, dof, n_params, n_aux);
    match &tapes.parts {
        Some(parts) => {
            let n_out = tapes.mass_bias.outputs.len();
            kernels.push(emit_parts(parts, dof, n_params, n_out));
        }
        None => kernels.push(quote! {
            /// This model's part kernels: none.
            pub static PART_KERNELS: &[runtime::parts::CompiledPart] = &[];
        }),
    }
    if let Some(blocks) = &tapes.arm_blocks {
        kernels.push(emit_arm_blocks(tapes, blocks, dof, n_params));
    }
    if let Some(links) = &tapes.links {
        let n_out = tapes.mass_bias.outputs.len();
        kernels.push(emit_link_recursion(links, dof, n_params, n_out));
    } else {
        kernels.push(emit_arm_cells(tapes));
    }
    quote! {
        // Generated code: arguments every kernel takes though some read
        // none, glue of every shape.
        #![allow(unused_variables, unused_unsafe, unused_parens, unused_macros, dead_code, clippy::all)]
        use runtime::{Inputs, KernelKind, Kernels, ModelInfo};

        /// Structural hash of the model this was derived from.
        pub const HASH: &str = #hash;
        pub const DOF: usize = #dof;
        /// The coordinates' names, separated by white space.
        pub const COORDINATES: &str = #coords;
        /// The parameters' names, separated by white space.
        pub const PARAMETERS: &str = #params;
        /// Derived parameters, computed once per parameter set.
        pub const DERIVED: usize = #n_derived;
        /// Whether the mass solve is generated (the `accel` kernel).
        pub const ACCEL: bool = #accel;
        /// Base parameters that are loads (scaled by load continuation).
        pub const LOADS: &[usize] = &[#(#loads),*];
        /// The rows of the joints' constraint equations.
        pub const CONSTRAINTS: &[&str] = &[#(#rows),*];
        /// Coordinates per independent subsystem (M block diagonal).
        pub const BLOCKS: &[usize] = &[#(#blocks),*];
        /// Contact points along the arms and at the bodies.
        pub const CONTACT_POINTS: usize = #contact_points;
        /// Points per group of the `contact_jacobian` kernel.
        pub const CONTACT_GROUPS: &[usize] = &[#(#contact_groups),*];
        /// Length of the contact frames the `contact_jacobian` groups read.
        pub const CONTACT_FRAMES: usize = #contact_frames;
        /// (j, k): extended parameter k is a copy of base parameter j.
        pub const COPIES: &[(usize, usize)] = &[#(#copies),*];

        /// The compiled kernels of this structure.
        pub struct Compiled {
            info: ModelInfo,
        }

        impl Default for Compiled {
            fn default() -> Self {
                Self {
                    info: ModelInfo {
                        hash: HASH.to_string(),
                        coordinates: COORDINATES.split_whitespace().map(String::from).collect(),
                        parameters: PARAMETERS.split_whitespace().map(String::from).collect(),
                        derived: DERIVED,
                        accel: ACCEL,
                        loads: LOADS.to_vec(),
                        constraints: CONSTRAINTS.iter().map(|s| s.to_string()).collect(),
                        blocks: BLOCKS.to_vec(),
                        contact_points: CONTACT_POINTS,
                        contact_groups: CONTACT_GROUPS.to_vec(),
                        contact_frames: CONTACT_FRAMES,
                        copies: COPIES.to_vec(),
                    },
                }
            }
        }

        impl Kernels for Compiled {
            fn info(&self) -> &ModelInfo {
                &self.info
            }
            fn backend(&self) -> &'static str {
                "compiled"
            }
            fn eval(&self, kind: KernelKind, inp: &Inputs, out: &mut [f64]) {
                let q: &[f64; #dof] = inp.q.try_into().expect("q has DOF entries");
                let qd: &[f64; #dof] = inp.qd.try_into().expect("qd has DOF entries");
                let p: &[f64; #n_params] = inp.p.try_into().expect("parameter vector length");
                // Only the Jvp kernel reads accelerations and a direction.
                let no_qdd = [0.0f64; #dof];
                let qdd: &[f64; #dof] = if inp.qdd.is_empty() {
                    &no_qdd
                } else {
                    inp.qdd.try_into().expect("qdd has DOF entries")
                };
                let no_dir = [0.0f64; #n_dir];
                let dir: &[f64; #n_dir] = if inp.dir.is_empty() {
                    &no_dir
                } else {
                    inp.dir.try_into().expect("dir has 2 DOF entries")
                };
                // A kernel on the inputs (and, for the grouped one, whether
                // every group is asked for).
                macro_rules! call {
                    ($f:ident, $($all:expr)?) => {
                        $f(inp.t, q, qd, qdd, dir, $($all,)? p, out.try_into().expect("output length"))
                    };
                }
                match kind {
                    #(#arms)*
                }
            }
            #accelerations_fn
        }

        #frames_fn
        #(#kernels)*
    }
}

/// The cells of a model without a chain of its own: an assembly's are its
/// arm kinds' (each module registers its own).
fn emit_arm_cells(tapes: &TapeSet) -> TokenStream {
    let arm_cells = (tapes.arm_blocks.iter())
        .flat_map(|b| b.kinds.iter().enumerate())
        .flat_map(|(k, kind)| {
            let module = format_ident!("arm_{}", k);
            let count = kind.links.as_ref().map_or(0, |l| l.cells.len());
            (0..count).map(move |c| quote! { #module::CELLS[#c], })
        });
    quote! {
        /// This model's cells, for chains of other lengths to link.
        pub static CELLS: &[runtime::links::CompiledCell] = &[#(#arm_cells)*];
    }
}

/// Names as one raw string, eight a line: a list of string literals took
/// three times the room.
fn names(names: &[String]) -> TokenStream {
    assert!(
        names
            .iter()
            .all(|n| !n.is_empty() && !n.contains(char::is_whitespace) && !n.contains('"')),
        "names are single words without quotes"
    );
    let lines: Vec<String> = names.chunks(8).map(|c| c.join(" ")).collect();
    format!("r\"{}\"", lines.join("\n"))
        .parse()
        .expect("a raw string")
}

/// `tokens` with every `usize` literal unsuffixed: quote writes `q[3usize]`,
/// where an index or a length is a usize anyway (a sixth of the generated
/// code was these suffixes).
fn unsuffixed(tokens: TokenStream) -> TokenStream {
    use proc_macro2::{Group, TokenTree};
    tokens
        .into_iter()
        .map(|t| match t {
            TokenTree::Literal(l) => match l.to_string().strip_suffix("usize") {
                Some(digits) if digits.bytes().all(|b| b.is_ascii_digit()) => {
                    let mut u = Literal::u64_unsuffixed(digits.parse().expect("digits"));
                    u.set_span(l.span());
                    TokenTree::Literal(u)
                }
                _ => TokenTree::Literal(l),
            },
            TokenTree::Group(g) => {
                let mut inner = Group::new(g.delimiter(), unsuffixed(g.stream()));
                inner.set_span(g.span());
                TokenTree::Group(inner)
            }
            other => other,
        })
        .collect()
}

/// The structural hash recorded in a generated file's header, if any.
pub fn hash_in_header(source: &str) -> Option<&str> {
    source
        .lines()
        .take(3)
        .find_map(|l| l.strip_prefix(HASH_PREFIX))
        .map(str::trim)
}
