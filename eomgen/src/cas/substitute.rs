//! Substitution: an expression with some symbols replaced by expressions.
//!
//! The contact frames (derive.rs) take a point of an arm's element with
//! the coordinates before the element set to zero: the point in its
//! element's own frame, which the `ContactJacobian` groups then place by
//! the frame the `Accel` kernel exported.

use rustc_hash::FxHashMap as HashMap;

use super::expr::{Cas, ExprId, Node, SymId};

impl Cas {
    /// `es` with each symbol of `values` replaced by its expression,
    /// rebuilt through the canonical constructors (so the result is
    /// simplified as if written so), memoised per node: shared
    /// subexpressions stay shared, `Bind` stays `Bind`.
    pub fn substitute(&mut self, es: &[ExprId], values: &HashMap<SymId, ExprId>) -> Vec<ExprId> {
        let mut memo = HashMap::default();
        es.iter()
            .map(|&e| self.substitute_one(e, values, &mut memo))
            .collect()
    }

    fn substitute_one(
        &mut self,
        e: ExprId,
        values: &HashMap<SymId, ExprId>,
        memo: &mut HashMap<ExprId, ExprId>,
    ) -> ExprId {
        if let Some(&r) = memo.get(&e) {
            return r;
        }
        let mut sub = |cas: &mut Cas, xs: &[ExprId]| -> Option<Vec<ExprId>> {
            let ys: Vec<ExprId> = xs
                .iter()
                .map(|&x| cas.substitute_one(x, values, memo))
                .collect();
            (ys != xs).then_some(ys)
        };
        let r = match self.node(e).clone() {
            Node::Const(_) => e,
            Node::Sym(s) => values.get(&s).copied().unwrap_or(e),
            Node::Add(xs) => sub(self, &xs).map_or(e, |ys| self.add_all(&ys)),
            Node::Mul(xs) => sub(self, &xs).map_or(e, |ys| self.mul_all(&ys)),
            Node::Pow(b, x) => sub(self, &[b, x]).map_or(e, |ys| self.pow(ys[0], ys[1])),
            Node::Func(f, x) => sub(self, &[x]).map_or(e, |ys| self.func(f, ys[0])),
            Node::Bind(x) => sub(self, &[x]).map_or(e, |ys| self.bind(ys[0])),
        };
        memo.insert(e, r);
        r
    }
}
