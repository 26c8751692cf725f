//! Reverse accumulation: vector-Jacobian products J^T c.
//!
//! TMT assembly is full of transpose products, sum_i T_i^T f_i. Forming
//! each T_i column and dotting costs O(n) per coordinate and body; the
//! reverse sweep costs O(1) per node. Each `Bind` node binds its adjoint,
//! so along a kinematic chain the adjoints are shared suffix sums: the
//! composite-body recursion emerges from the algebra, for any kinematics.

use std::collections::BTreeMap;

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use super::expr::{Cas, ExprId, Node, SymId};

impl Cas {
    /// For each symbol s in `wrt`: `sum_k cotangents[k] * d outputs[k] / d s`.
    pub fn vjp(
        &mut self,
        outputs: &[ExprId],
        cotangents: &[ExprId],
        wrt: &[ExprId],
    ) -> Vec<ExprId> {
        assert_eq!(
            outputs.len(),
            cotangents.len(),
            "vjp: one cotangent per output"
        );
        let targets: HashSet<SymId> = wrt
            .iter()
            .map(|&s| {
                self.sym_id(s)
                    .expect("vjp: differentiate with respect to symbols")
            })
            .collect();
        let mut depends: HashMap<ExprId, bool> = HashMap::default();
        // Contributions to each node's adjoint; processed from the largest
        // id down, so a node's parents (larger ids) have all contributed.
        let mut pending: BTreeMap<ExprId, Vec<ExprId>> = BTreeMap::new();
        for (&o, &c) in outputs.iter().zip(cotangents) {
            if !self.is_zero(c) && self.depends_on(o, &targets, &mut depends) {
                pending.entry(o).or_default().push(c);
            }
        }
        let mut adjoint_of_symbol: HashMap<SymId, ExprId> = HashMap::default();
        while let Some((e, contributions)) = pending.pop_last() {
            let adj = self.add_all(&contributions);
            if self.is_zero(adj) {
                continue;
            }
            let mut push = |cas: &mut Cas,
                            child: ExprId,
                            value: ExprId,
                            depends: &mut HashMap<ExprId, bool>| {
                if cas.depends_on(child, &targets, depends) && !cas.is_zero(value) {
                    pending.entry(child).or_default().push(value);
                }
            };
            match self.node(e).clone() {
                Node::Const(_) => {}
                Node::Sym(s) => {
                    adjoint_of_symbol.insert(s, adj);
                }
                Node::Bind(x) => {
                    let a = self.bind(adj);
                    push(self, x, a, &mut depends);
                }
                Node::Add(xs) => {
                    for &x in xs.iter() {
                        push(self, x, adj, &mut depends);
                    }
                }
                Node::Mul(fs) => {
                    for i in 0..fs.len() {
                        if !self.depends_on(fs[i], &targets, &mut depends) {
                            continue;
                        }
                        let mut others: Vec<ExprId> = fs
                            .iter()
                            .enumerate()
                            .filter(|&(j, _)| j != i)
                            .map(|(_, &f)| f)
                            .collect();
                        others.push(adj);
                        let v = self.mul_all(&others);
                        push(self, fs[i], v, &mut depends);
                    }
                }
                Node::Pow(b, x) => {
                    if self.depends_on(b, &targets, &mut depends) {
                        // d b^x / db = x b^(x-1)
                        let m1 = self.constant(-1.0);
                        let xm1 = self.add(x, m1);
                        let p = self.pow(b, xm1);
                        let v = self.mul_all(&[adj, x, p]);
                        push(self, b, v, &mut depends);
                    }
                    if self.depends_on(x, &targets, &mut depends) {
                        // d b^x / dx = b^x ln b
                        let lnb = self.func(super::Func::Ln, b);
                        let v = self.mul_all(&[adj, e, lnb]);
                        push(self, x, v, &mut depends);
                    }
                }
                Node::Func(f, x) => {
                    let fp = self.func_derivative(f, x);
                    let v = self.mul(adj, fp);
                    push(self, x, v, &mut depends);
                }
            }
        }
        let zero = self.zero();
        wrt.iter()
            .map(|&s| {
                let id = self.sym_id(s).expect("checked above");
                adjoint_of_symbol.get(&id).copied().unwrap_or(zero)
            })
            .collect()
    }

    /// Whether `e` depends on any of `targets` (memoised in `memo`).
    fn depends_on(
        &self,
        e: ExprId,
        targets: &HashSet<SymId>,
        memo: &mut HashMap<ExprId, bool>,
    ) -> bool {
        if let Some(&d) = memo.get(&e) {
            return d;
        }
        let d = match self.node(e) {
            Node::Const(_) => false,
            Node::Sym(s) => targets.contains(s),
            _ => self
                .children(e)
                .into_iter()
                .any(|c| self.depends_on(c, targets, memo)),
        };
        memo.insert(e, d);
        d
    }
}
