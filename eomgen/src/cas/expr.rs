//! The expression DAG: an arena of hash-consed nodes with typed ids.
//!
//! Invariants:
//! * Every node is interned once: equal nodes have equal [`ExprId`]s, so
//!   structural equality is id equality and common subexpressions are shared
//!   by construction.
//! * Children are created before parents, so ids are a topological order.
//! * Nodes are only created through the canonical constructors in
//!   `canonical.rs`; `Add` and `Mul` are flattened, sorted by child id and have
//!   like terms collected (see there).
//! * Ids are handed out in creation order, and construction is deterministic,
//!   so the same model always gives the same ids and byte-identical output.

use rustc_hash::FxHashMap as HashMap;

/// Handle of an interned expression.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Debug)]
pub struct ExprId(pub(crate) u32);

/// Handle of a symbol.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Debug)]
pub struct SymId(pub(crate) u32);

/// What a symbol stands for when the expression is evaluated or lowered.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub enum SymKind {
    /// Generalised coordinate `q[i]`.
    Q(u32),
    /// Its rate `qd[i]`.
    Qd(u32),
    /// Its acceleration `qdd[i]` (only inside derivations, never lowered).
    Qdd(u32),
    /// Component i of a directional derivative's direction (dq, then dqd):
    /// the `Jvp` kernel's input.
    Dir(u32),
    /// Runtime parameter `p[i]`.
    Param(u32),
    /// Time t.
    Time,
    /// Value i of the kernel's `aux` input (`runtime::Op::Aux`).
    Aux(u32),
    /// A free symbol (tests, intermediate algebra).
    Free,
}

/// Unary functions. `Sinc(k)`, `Cosc(k)` and `SincRem(k)` are the k-th
/// derivatives of sin(x)/x, (1 - cos x)/x and (x - sin x)/x^3: removable
/// singularities as first-class ops.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Debug)]
pub enum Func {
    Sin,
    Cos,
    Tan,
    Exp,
    Ln,
    Abs,
    Sign,
    Sinc(u8),
    Cosc(u8),
    /// k-th derivative of (x - sin x) / x^3.
    SincRem(u8),
    /// n-th derivative of the Rodrigues coefficient c_j(w), a function of
    /// the squared rotation angle (`runtime::rodrigues`): (j, n).
    Rodrigues(u8, u8),
}

impl Func {
    /// Numeric value, shared with the runtime so that every backend agrees.
    pub fn apply(self, x: f64) -> f64 {
        use runtime::special;
        match self {
            Func::Sin => special::sin(x),
            Func::Cos => special::cos(x),
            Func::Tan => x.tan(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Abs => x.abs(),
            Func::Sign => special::sign(x),
            Func::Sinc(k) => special::sinc(k, x),
            Func::Cosc(k) => special::cosc(k, x),
            Func::SincRem(k) => special::sinc_rem(k, x),
            Func::Rodrigues(j, n) => runtime::rodrigues::rodrigues(j, n, x),
        }
    }

    /// f(-x) = parity * f(x), when f is even (1) or odd (-1).
    pub fn parity(self) -> Option<f64> {
        let alt = |k: u8| if k.is_multiple_of(2) { 1.0 } else { -1.0 };
        match self {
            Func::Sin | Func::Tan | Func::Sign => Some(-1.0),
            Func::Cos | Func::Abs => Some(1.0),
            Func::Sinc(k) | Func::SincRem(k) => Some(alt(k)),
            Func::Cosc(k) => Some(-alt(k)),
            Func::Exp | Func::Ln | Func::Rodrigues(..) => None,
        }
    }
}

/// One interned node.
#[derive(Clone, PartialEq, Eq, Hash, Debug)]
pub enum Node {
    /// Bits of a finite f64 (never -0.0).
    Const(u64),
    Sym(SymId),
    /// At least two terms: an optional constant first, then the rest by id.
    Add(Box<[ExprId]>),
    /// At least two factors: an optional constant first, then the rest by id.
    Mul(Box<[ExprId]>),
    Pow(ExprId, ExprId),
    Func(Func, ExprId),
    /// An intermediate quantity kept whole: canonicalisation does not look
    /// inside it (a sum under `Bind` is not merged into an outer sum), but
    /// evaluation and differentiation go through it. Kinematic chains bind
    /// each frame so that frame k+1 reuses frame k instead of re-expanding it.
    Bind(ExprId),
}

/// The arena: nodes, their index, and the symbol table.
#[derive(Default)]
pub struct Cas {
    pub(crate) nodes: Vec<Node>,
    index: HashMap<Node, ExprId>,
    symbols: Vec<(String, SymKind)>,
    sym_index: HashMap<String, SymId>,
    pub(crate) diff_memo: HashMap<(ExprId, SymId), ExprId>,
    pub(crate) variables_memo: HashMap<ExprId, Variables>,
    /// Rate rules of turned vectors (`turning.rs`).
    pub(crate) turned: HashMap<ExprId, Turned>,
    /// Parameters that change with time (a prescribed base motion): to
    /// time derivatives they are variables, not constants.
    moving: rustc_hash::FxHashSet<SymId>,
    /// Symbols created now belong to one subsystem of an assembly
    /// (`Cas::scoped`).
    scope: Option<Scope>,
}

/// A subsystem's place in an assembly: its symbols' names get `prefix`, its
/// coordinate and parameter indices the offsets, so a kinematics written
/// for one arm builds any arm of several unchanged.
#[derive(Clone, Debug)]
pub struct Scope {
    pub prefix: String,
    pub coordinates: u32,
    pub parameters: u32,
}

/// The non-parameter symbols an expression depends on, as far as the time
/// derivative cares: none, exactly one, or more.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Variables {
    None,
    One(SymId),
    Many,
}

impl Variables {
    fn union(self, other: Self) -> Self {
        match (self, other) {
            (Self::None, x) | (x, Self::None) => x,
            (Self::One(a), Self::One(b)) if a == b => Self::One(a),
            _ => Self::Many,
        }
    }
}

impl Cas {
    pub fn new() -> Self {
        Self::default()
    }

    /// Intern a node that is already canonical.
    pub(crate) fn intern(&mut self, node: Node) -> ExprId {
        if let Some(&id) = self.index.get(&node) {
            return id;
        }
        let id = ExprId(u32::try_from(self.nodes.len()).expect("expression arena overflow"));
        self.nodes.push(node.clone());
        self.index.insert(node, id);
        id
    }

    /// The variables (non-parameter symbols) `e` depends on, memoised.
    pub(crate) fn variables(&mut self, e: ExprId) -> Variables {
        if let Some(&v) = self.variables_memo.get(&e) {
            return v;
        }
        let v = match self.node(e) {
            Node::Const(_) => Variables::None,
            Node::Sym(s) => match self.sym_kind(*s) {
                SymKind::Param(_) if !self.moving.contains(s) => Variables::None,
                _ => Variables::One(*s),
            },
            _ => {
                let mut acc = Variables::None;
                for c in self.children(e) {
                    acc = acc.union(self.variables(c));
                    if acc == Variables::Many {
                        break;
                    }
                }
                acc
            }
        };
        self.variables_memo.insert(e, v);
        v
    }

    pub fn node(&self, e: ExprId) -> &Node {
        &self.nodes[e.0 as usize]
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The symbol named `name`, created with `kind` if new.
    pub fn symbol(&mut self, name: &str, kind: SymKind) -> ExprId {
        let scoped;
        let (name, kind) = match &self.scope {
            None => (name, kind),
            Some(sc) => {
                scoped = format!("{}{name}", sc.prefix);
                let kind = match kind {
                    SymKind::Q(i) => SymKind::Q(i + sc.coordinates),
                    SymKind::Qd(i) => SymKind::Qd(i + sc.coordinates),
                    SymKind::Qdd(i) => SymKind::Qdd(i + sc.coordinates),
                    SymKind::Param(i) => SymKind::Param(i + sc.parameters),
                    k => k,
                };
                (scoped.as_str(), kind)
            }
        };
        let id = match self.sym_index.get(name) {
            Some(&s) => s,
            None => {
                let s = SymId(self.symbols.len() as u32);
                self.symbols.push((name.to_string(), kind));
                self.sym_index.insert(name.to_string(), s);
                s
            }
        };
        self.intern(Node::Sym(id))
    }

    /// Run `f` with the symbols it creates in `scope` (one arm of several).
    pub fn scoped<R>(&mut self, scope: Scope, f: impl FnOnce(&mut Self) -> R) -> R {
        let outer = self.scope.replace(scope);
        let r = f(self);
        self.scope = outer;
        r
    }

    /// Declare parameter `e` time-varying (before building expressions of
    /// it: the variable sets are memoised).
    pub fn set_moving(&mut self, e: ExprId) {
        let s = self.sym_id(e).expect("set_moving: a parameter symbol");
        debug_assert!(!self.variables_memo.contains_key(&e), "declared too late");
        self.moving.insert(s);
    }

    pub fn sym_id(&self, e: ExprId) -> Option<SymId> {
        match self.node(e) {
            Node::Sym(s) => Some(*s),
            _ => None,
        }
    }

    pub fn sym_name(&self, s: SymId) -> &str {
        &self.symbols[s.0 as usize].0
    }

    pub fn sym_kind(&self, s: SymId) -> SymKind {
        self.symbols[s.0 as usize].1
    }

    /// The value of a constant node.
    pub fn as_const(&self, e: ExprId) -> Option<f64> {
        match self.node(e) {
            Node::Const(bits) => Some(f64::from_bits(*bits)),
            _ => None,
        }
    }

    pub fn is_zero(&self, e: ExprId) -> bool {
        self.as_const(e) == Some(0.0)
    }

    /// Children of a node, in canonical order.
    pub fn children(&self, e: ExprId) -> Vec<ExprId> {
        match self.node(e) {
            Node::Const(_) | Node::Sym(_) => vec![],
            Node::Add(xs) | Node::Mul(xs) => xs.to_vec(),
            Node::Pow(b, x) => vec![*b, *x],
            Node::Func(_, x) | Node::Bind(x) => vec![*x],
        }
    }

    /// Number of distinct nodes reachable from `roots`.
    pub fn dag_size(&self, roots: &[ExprId]) -> usize {
        let mut seen = vec![false; self.nodes.len()];
        let mut stack: Vec<ExprId> = roots.to_vec();
        let mut count = 0;
        while let Some(e) = stack.pop() {
            if std::mem::replace(&mut seen[e.0 as usize], true) {
                continue;
            }
            count += 1;
            stack.extend(self.children(e));
        }
        count
    }
}

/// How a bound component of R x moves: the frame (R, w) and the local x
/// (recorded by `Cas::turn`, applied by `Cas::kinematic_rates`).
#[derive(Clone, Copy)]
pub(crate) struct Turned {
    pub(crate) r: [[ExprId; 3]; 3],
    pub(crate) w: [ExprId; 3],
    pub(crate) local: [ExprId; 3],
    /// The bound components of R x, this one among them.
    pub(crate) world: [ExprId; 3],
    pub(crate) component: usize,
}
