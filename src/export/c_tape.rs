//! A tape as a C99 function: one `const double` a slot, in the tape's
//! order, so the C code runs the interpreter's operations in its order.

use std::fmt::Write;

use runtime::tape::{Op, Slot, Tape};

/// The C signature every exported kernel shares (what it does not read,
/// it ignores; `scratch` serves the kernels run from a table).
pub const KERNEL_ARGS: &str = "double t, const double *q, const double *qd, const double *qdd, \
                               const double *dir, const double *p, const double *aux, double *out, \
                               double *scratch";

/// Kernels of more operations than this go as a table (`table`): straight
/// line, a 90,000-operation kernel is 4 MB of C that a compiler takes many
/// minutes over at -O2; as a table it compiles in seconds and runs at the
/// speed of softarm's own interpreter.
pub const STRAIGHT_LINE_MAX: usize = 5_000;

/// The kernel as straight-line code or, past `STRAIGHT_LINE_MAX`
/// operations, a table.
pub fn kernel(name: &str, tape: &Tape) -> String {
    match tape.ops.len() > STRAIGHT_LINE_MAX {
        true => table(name, tape),
        false => function(name, tape),
    }
}

/// The scratch values `kernel` needs: for a table a value a slot, then
/// 45 a Rodrigues family; none for straight-line code.
pub fn scratch(tape: &Tape) -> usize {
    if tape.ops.len() <= STRAIGHT_LINE_MAX {
        return 0;
    }
    let mut families: Vec<Slot> = Vec::new();
    for op in &tape.ops {
        if let Op::Rodrigues(j, n, a) = *op
            && usize::from(j) < runtime::rodrigues::FAMILY_J
            && usize::from(n) < runtime::rodrigues::FAMILY_ORDERS
            && !families.contains(&a)
        {
            families.push(a);
        }
    }
    tape.ops.len() + 45 * families.len()
}

/// `static void NAME(KERNEL_ARGS)` computing `tape` into `out`.
pub fn function(name: &str, tape: &Tape) -> String {
    let mut c = format!("static void {name}({KERNEL_ARGS})\n{{\n");
    // Inputs a tape does not read stay unused: say so once, for -Wall.
    c.push_str(
        "    (void)t; (void)q; (void)qd; (void)qdd; (void)dir; (void)p; (void)aux; (void)scratch;\n",
    );
    // Slots no output reads are left out (-Wall would call them unused).
    let mut live = vec![false; tape.ops.len()];
    for &s in &tape.outputs {
        live[s as usize] = true;
    }
    for i in (0..tape.ops.len()).rev() {
        if live[i] {
            for a in tape.ops[i].operands() {
                live[a as usize] = true;
            }
        }
    }
    let mut families: Vec<Slot> = Vec::new();
    for (i, op) in tape.ops.iter().enumerate() {
        if !live[i] {
            continue;
        }
        if let Op::Rodrigues(j, n, a) = *op
            && usize::from(j) < runtime::rodrigues::FAMILY_J
            && usize::from(n) < runtime::rodrigues::FAMILY_ORDERS
        {
            // One family a distinct argument, as the interpreter keeps.
            if !families.contains(&a) {
                families.push(a);
                let _ = writeln!(c, "    double f{a}[9][5]; sa_family(s{a}, f{a});");
            }
            let _ = writeln!(c, "    const double s{i} = f{a}[{j}][{n}];");
            continue;
        }
        let _ = writeln!(c, "    const double s{i} = {};", expression(op));
    }
    for (k, s) in tape.outputs.iter().enumerate() {
        let _ = writeln!(c, "    out[{k}] = s{s};");
    }
    c.push_str("}\n");
    c
}

/// `static void NAME(KERNEL_ARGS)` running the tape as a table of
/// operations (`sa_run` of the support code) in `scratch`.
fn table(name: &str, tape: &Tape) -> String {
    let mut c = format!("static const sa_op {name}_ops[] = {{\n");
    let mut families: Vec<Slot> = Vec::new();
    for op in &tape.ops {
        let (code, a, b, cc, f, k) = encoded(op, &mut families);
        let _ = writeln!(c, "{{{code},{a},{b},{cc},{f},{}}},", literal(k));
    }
    c.push_str("};\n");
    let outs: Vec<String> = tape.outputs.iter().map(|s| s.to_string()).collect();
    let outs = if outs.is_empty() {
        "0".into()
    } else {
        outs.join(",")
    };
    let len = tape.ops.len();
    let _ = writeln!(
        c,
        "static const unsigned {name}_outs[] = {{{outs}}};\n\
         static void {name}({KERNEL_ARGS})\n{{\n    \
         sa_run({name}_ops, {len}, {name}_outs, {nout}, scratch, (double (*)[9][5])(scratch + {len}),\n        \
         t, q, qd, qdd, dir, p, aux, out);\n}}",
        nout = tape.outputs.len()
    );
    c
}

/// One operation's row of the table: (code, a, b, c, family, constant),
/// the codes those of `sa_run`.
fn encoded(op: &Op, families: &mut Vec<Slot>) -> (&'static str, u32, i64, u32, usize, f64) {
    let code1 = |name, a: Slot| (name, a, 0, 0, 0, 0.0);
    let code2 = |name, a: Slot, b: Slot| (name, a, i64::from(b), 0, 0, 0.0);
    match *op {
        Op::Rodrigues(j, n, a)
            if usize::from(j) < runtime::rodrigues::FAMILY_J
                && usize::from(n) < runtime::rodrigues::FAMILY_ORDERS =>
        {
            let (code, f) = match families.iter().position(|&x| x == a) {
                Some(f) => ("SA_FAMILY", f),
                None => {
                    families.push(a);
                    ("SA_FAMILY_FIRST", families.len() - 1)
                }
            };
            (code, a, i64::from(j), u32::from(n), f, 0.0)
        }
        Op::Const(v) => ("SA_CONST", 0, 0, 0, 0, v),
        Op::Q(i) => code1("SA_Q", i),
        Op::Qd(i) => code1("SA_QD", i),
        Op::Qdd(i) => code1("SA_QDD", i),
        Op::Dir(i) => code1("SA_DIR", i),
        Op::Param(i) => code1("SA_PARAM", i),
        Op::Time => code1("SA_TIME", 0),
        Op::Aux(i) => code1("SA_AUX", i),
        Op::Add(a, b) => code2("SA_ADD", a, b),
        Op::Sub(a, b) => code2("SA_SUB", a, b),
        Op::Mul(a, b) => code2("SA_MUL", a, b),
        Op::Div(a, b) => code2("SA_DIV", a, b),
        Op::Powf(a, b) => code2("SA_POWF", a, b),
        Op::MulAdd(a, b, c) => ("SA_MULADD", a, i64::from(b), c, 0, 0.0),
        Op::MulSub(a, b, c) => ("SA_MULSUB", a, i64::from(b), c, 0, 0.0),
        Op::NegMulAdd(a, b, c) => ("SA_NEGMULADD", a, i64::from(b), c, 0, 0.0),
        Op::Neg(a) => code1("SA_NEG", a),
        Op::Powi(a, n) => ("SA_POWI", a, i64::from(n), 0, 0, 0.0),
        Op::Sqrt(a) => code1("SA_SQRT", a),
        Op::Sin(a) => code1("SA_SIN", a),
        Op::Cos(a) => code1("SA_COS", a),
        Op::Tan(a) => code1("SA_TAN", a),
        Op::Exp(a) => code1("SA_EXP", a),
        Op::Ln(a) => code1("SA_LN", a),
        Op::Abs(a) => code1("SA_ABS", a),
        Op::Sign(a) => code1("SA_SIGN", a),
        Op::Sinc(k, a) => ("SA_SINC", a, i64::from(k), 0, 0, 0.0),
        Op::Cosc(k, a) => ("SA_COSC", a, i64::from(k), 0, 0, 0.0),
        Op::SincRem(k, a) => ("SA_SINC_REM", a, i64::from(k), 0, 0, 0.0),
        Op::Rodrigues(j, n, a) => ("SA_RODRIGUES", a, i64::from(j), u32::from(n), 0, 0.0),
    }
}

/// The C expression of one operation.
fn expression(op: &Op) -> String {
    let s = |k: Slot| format!("s{k}");
    match *op {
        Op::Const(v) => literal(v),
        Op::Q(i) => format!("q[{i}]"),
        Op::Qd(i) => format!("qd[{i}]"),
        Op::Qdd(i) => format!("qdd[{i}]"),
        Op::Dir(i) => format!("dir[{i}]"),
        Op::Param(i) => format!("p[{i}]"),
        Op::Time => "t".into(),
        Op::Aux(i) => format!("aux[{i}]"),
        Op::Add(a, b) => format!("{} + {}", s(a), s(b)),
        Op::Sub(a, b) => format!("{} - {}", s(a), s(b)),
        Op::Mul(a, b) => format!("{} * {}", s(a), s(b)),
        Op::Div(a, b) => format!("{} / {}", s(a), s(b)),
        Op::MulAdd(a, b, c) => format!("fma({}, {}, {})", s(a), s(b), s(c)),
        Op::MulSub(a, b, c) => format!("fma({}, {}, -{})", s(a), s(b), s(c)),
        Op::NegMulAdd(a, b, c) => format!("fma(-{}, {}, {})", s(a), s(b), s(c)),
        Op::Neg(a) => format!("-{}", s(a)),
        Op::Powi(a, n) => format!("sa_powi({}, {n})", s(a)),
        Op::Powf(a, b) => format!("pow({}, {})", s(a), s(b)),
        Op::Sqrt(a) => format!("sqrt({})", s(a)),
        Op::Sin(a) => format!("sin({})", s(a)),
        Op::Cos(a) => format!("cos({})", s(a)),
        Op::Tan(a) => format!("tan({})", s(a)),
        Op::Exp(a) => format!("exp({})", s(a)),
        Op::Ln(a) => format!("log({})", s(a)),
        Op::Abs(a) => format!("fabs({})", s(a)),
        Op::Sign(a) => format!("sa_sign({})", s(a)),
        Op::Sinc(k, a) => format!("sa_sinc({k}, {})", s(a)),
        Op::Cosc(k, a) => format!("sa_cosc({k}, {})", s(a)),
        Op::SincRem(k, a) => format!("sa_sinc_rem({k}, {})", s(a)),
        Op::Rodrigues(j, n, a) => format!("sa_rodrigues({j}, {n}, {})", s(a)),
    }
}

/// A double literal C reads back to the same bits (Rust's shortest
/// round-trip form, which C's strtod reads exactly).
pub fn literal(v: f64) -> String {
    if v.is_nan() {
        return "NAN".into();
    }
    if v.is_infinite() {
        return if v > 0.0 { "INFINITY" } else { "(-INFINITY)" }.into();
    }
    let text = format!("{v:?}");
    // A literal in parentheses: `- -1.0` must not become `--1.0`.
    if v.is_sign_negative() {
        format!("({text})")
    } else {
        text
    }
}
