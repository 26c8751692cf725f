//! Symbolic differentiation: partial derivatives and time derivatives.
//!
//! Both are one mechanism, a directional derivative d(e)[seed] where `seed`
//! gives the derivative of each symbol (a partial derivative seeds one
//! symbol with 1; a time derivative seeds q with qd, and optionally qd with
//! qdd). Results are memoised per node, and `Bind` maps to `Bind`, so the
//! derivative of a kinematic chain is again a chain that shares its links.

use rustc_hash::FxHashMap as HashMap;

use super::expr::{Cas, ExprId, Func, Node, SymId, Variables};

impl Cas {
    /// d e / d s, memoised across calls.
    pub fn diff(&mut self, e: ExprId, s: ExprId) -> ExprId {
        let sid = self
            .sym_id(s)
            .expect("diff: differentiate with respect to a symbol");
        self.diff_sym(e, sid)
    }

    fn diff_sym(&mut self, e: ExprId, s: SymId) -> ExprId {
        if let Some(&d) = self.diff_memo.get(&(e, s)) {
            return d;
        }
        let d = self.chain_rule(e, &mut |cas, child| cas.diff_sym(child, s), &|sym| {
            (sym == s).then_some(1.0)
        });
        self.diff_memo.insert((e, s), d);
        d
    }

    /// Time derivative by the chain rule: d e/dt = sum_k (d e/d x_k) xdot_k
    /// over the pairs (x_k, xdot_k) given. Pass (q, qd) pairs alone for the
    /// convective part (qdd = 0); add (qd, qdd) pairs for the full one.
    pub fn time_derivative(&mut self, e: ExprId, pairs: &[(ExprId, ExprId)]) -> ExprId {
        self.time_derivatives(&[e], pairs)[0]
    }

    /// Several time derivatives sharing one memo (so shared subexpressions
    /// are differentiated once).
    pub fn time_derivatives(&mut self, es: &[ExprId], pairs: &[(ExprId, ExprId)]) -> Vec<ExprId> {
        self.time_derivatives_by(es, pairs, false)
    }

    /// Convective time derivatives (`pairs`: each q with its qd, the seed the
    /// frames' angular velocities were built with) that use the rate rules of
    /// turned vectors (`turning.rs`): velocities and accelerations of a chain
    /// by w x u instead of by differentiating its rotation matrices.
    pub fn kinematic_rates(&mut self, es: &[ExprId], pairs: &[(ExprId, ExprId)]) -> Vec<ExprId> {
        self.time_derivatives_by(es, pairs, true)
    }

    fn time_derivatives_by(
        &mut self,
        es: &[ExprId],
        pairs: &[(ExprId, ExprId)],
        turned: bool,
    ) -> Vec<ExprId> {
        let map: HashMap<SymId, ExprId> = pairs
            .iter()
            .map(|&(x, xd)| {
                (
                    self.sym_id(x).expect("time_derivative: pair of symbols"),
                    xd,
                )
            })
            .collect();
        let mut memo = HashMap::default();
        es.iter()
            .map(|&e| self.directional(e, &map, &mut memo, turned))
            .collect()
    }

    fn directional(
        &mut self,
        e: ExprId,
        seed: &HashMap<SymId, ExprId>,
        memo: &mut HashMap<ExprId, ExprId>,
        turned: bool,
    ) -> ExprId {
        if let Some(&d) = memo.get(&e) {
            return d;
        }
        if turned {
            let rule = self.turned_rate(e, &mut |cas, x| cas.directional(x, seed, memo, true));
            if let Some(d) = rule {
                memo.insert(e, d);
                return d;
            }
        }
        let node = self.node(e).clone();
        let d = match node {
            Node::Sym(s) => match seed.get(&s) {
                Some(&v) => v,
                None => self.zero(),
            },
            // A bound function of one variable, f(x): f'(x) xdot with f'
            // bound too, so that second derivatives read f''(x) xdot^2 off
            // a chain of bound scalars instead of re-expanding products of
            // f's pieces (the local geometry of a pcc element).
            Node::Bind(x) if matches!(self.variables(x), Variables::One(_)) => {
                let Variables::One(s) = self.variables(x) else {
                    unreachable!()
                };
                match seed.get(&s) {
                    Some(&rate) => {
                        let fp = self.diff_sym(x, s);
                        let fp = self.bind(fp);
                        self.mul(fp, rate)
                    }
                    None => self.zero(),
                }
            }
            _ => self.chain_rule(
                e,
                &mut |cas, child| cas.directional(child, seed, memo, turned),
                &|_| None,
            ),
        };
        memo.insert(e, d);
        d
    }

    /// One step of the chain rule at node `e`, with `d` giving the
    /// derivative of a child and `sym` the derivative of a symbol (None: 0).
    fn chain_rule(
        &mut self,
        e: ExprId,
        d: &mut dyn FnMut(&mut Cas, ExprId) -> ExprId,
        sym: &dyn Fn(SymId) -> Option<f64>,
    ) -> ExprId {
        match self.node(e).clone() {
            Node::Const(_) => self.zero(),
            Node::Sym(s) => match sym(s) {
                Some(v) => self.constant(v),
                None => self.zero(),
            },
            Node::Add(xs) => {
                let ds: Vec<ExprId> = xs.iter().map(|&x| d(self, x)).collect();
                self.add_all(&ds)
            }
            Node::Mul(xs) => {
                let mut terms = Vec::new();
                for i in 0..xs.len() {
                    let di = d(self, xs[i]);
                    if self.is_zero(di) {
                        continue;
                    }
                    let mut fs: Vec<ExprId> = Vec::with_capacity(xs.len());
                    fs.extend(
                        xs.iter()
                            .enumerate()
                            .filter(|&(j, _)| j != i)
                            .map(|(_, &x)| x),
                    );
                    fs.push(di);
                    terms.push(self.mul_all(&fs));
                }
                self.add_all(&terms)
            }
            Node::Pow(b, x) => {
                let db = d(self, b);
                let dx = d(self, x);
                if self.is_zero(dx) {
                    if self.is_zero(db) {
                        return self.zero();
                    }
                    // d b^c = c b^(c-1) db
                    let m1 = self.constant(-1.0);
                    let cm1 = self.add(x, m1);
                    let p = self.pow(b, cm1);
                    self.mul_all(&[x, p, db])
                } else {
                    // d b^x = b^x (dx ln b + x db / b)
                    let lnb = self.func(Func::Ln, b);
                    let t1 = self.mul(dx, lnb);
                    let t2 = self.div(x, b);
                    let t2 = self.mul(t2, db);
                    let s = self.add(t1, t2);
                    self.mul(e, s)
                }
            }
            Node::Func(f, x) => {
                let dx = d(self, x);
                if self.is_zero(dx) {
                    return self.zero();
                }
                let fp = self.func_derivative(f, x);
                self.mul(fp, dx)
            }
            Node::Bind(x) => {
                let dx = d(self, x);
                self.bind(dx)
            }
        }
    }

    /// f'(x) in closed form.
    pub(crate) fn func_derivative(&mut self, f: Func, x: ExprId) -> ExprId {
        match f {
            Func::Sin => self.cos(x),
            Func::Cos => {
                let s = self.sin(x);
                self.neg(s)
            }
            Func::Tan => {
                // 1 + tan^2
                let t = self.func(Func::Tan, x);
                let t2 = self.powi(t, 2);
                let one = self.one();
                self.add(one, t2)
            }
            Func::Exp => self.func(Func::Exp, x),
            Func::Ln => {
                let m1 = self.constant(-1.0);
                self.pow(x, m1)
            }
            Func::Abs => self.func(Func::Sign, x),
            Func::Sign => self.zero(),
            Func::Sinc(k) => self.func(Func::Sinc(k + 1), x),
            Func::Cosc(k) => self.func(Func::Cosc(k + 1), x),
            Func::SincRem(k) => self.func(Func::SincRem(k + 1), x),
            Func::Rodrigues(j, n) => self.func(Func::Rodrigues(j, n + 1), x),
        }
    }
}
