//! Direct numeric evaluation of expressions (the reference the tape and the
//! emitted code are tested against).

use std::collections::HashMap;

use super::expr::{Cas, ExprId, Node, SymId};

impl Cas {
    /// Evaluate `roots` with symbol values from `value` (None: unbound, an error).
    pub fn eval_many(
        &self,
        roots: &[ExprId],
        value: &dyn Fn(SymId) -> Option<f64>,
    ) -> Result<Vec<f64>, String> {
        // Ids are a topological order: evaluate the reachable set by id.
        let mut reach: Vec<ExprId> = Vec::new();
        let mut seen: HashMap<ExprId, ()> = HashMap::new();
        let mut stack: Vec<ExprId> = roots.to_vec();
        while let Some(e) = stack.pop() {
            if seen.insert(e, ()).is_some() {
                continue;
            }
            reach.push(e);
            stack.extend(self.children(e));
        }
        reach.sort();
        let mut val: HashMap<ExprId, f64> = HashMap::with_capacity(reach.len());
        for &e in &reach {
            let v = match self.node(e) {
                Node::Const(bits) => f64::from_bits(*bits),
                Node::Sym(s) => {
                    value(*s).ok_or_else(|| format!("symbol {} has no value", self.sym_name(*s)))?
                }
                Node::Add(xs) => xs.iter().map(|x| val[x]).sum(),
                Node::Mul(xs) => xs.iter().map(|x| val[x]).product(),
                Node::Pow(b, x) => pow_value(val[b], val[x]),
                Node::Func(f, x) => f.apply(val[x]),
                Node::Bind(x) => val[x],
            };
            val.insert(e, v);
        }
        Ok(roots.iter().map(|r| val[r]).collect())
    }

    /// Evaluate one expression with values given by symbol name.
    pub fn eval_named(&self, e: ExprId, values: &HashMap<String, f64>) -> Result<f64, String> {
        let v = self.eval_many(&[e], &|s| values.get(self.sym_name(s)).copied())?;
        Ok(v[0])
    }
}

/// b^x as the tape and emitted code compute it (powi for small integers).
pub(crate) fn pow_value(b: f64, x: f64) -> f64 {
    if x == 0.5 {
        b.sqrt()
    } else if x == -0.5 {
        1.0 / b.sqrt()
    } else if x.fract() == 0.0 && x.abs() <= 64.0 {
        b.powi(x as i32)
    } else {
        b.powf(x)
    }
}
