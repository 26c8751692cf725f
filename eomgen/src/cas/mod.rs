//! softarm's computer algebra system.
//!
//! * `expr`: the hash-consed DAG (arena, interning, typed ids).
//! * `canonical`: canonical constructors and the rewrite rules.
//! * `diff`: memoised partial and time derivatives.
//! * `eval`: direct evaluation.
//! * `lower`: CSE and linearisation into a runtime tape.
//! * `fuse`: single-use products fused into the sums that read them.
//! * `turning`: vectors turned by a moving frame, with their rates by w x u.
//! * `substitute`: symbols replaced by expressions.

mod canonical;
mod diff;
mod eval;
mod expr;
mod fuse;
mod lower;
mod reverse;
mod substitute;
mod turning;

pub(crate) use expr::Variables;
pub use expr::{Cas, ExprId, Func, Node, Scope, SymId, SymKind};
pub use fuse::fuse_multiply_adds;
pub use lower::{Hoist, Lowerer};
