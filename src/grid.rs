//! A sweep's grid: `--vary PATH=VALUES` keys (lists, `lin:a:b:n`,
//! `log:a:b:n`) and every combination of their values, the last key
//! fastest. Shared by `softarm sweep` and Python's `softarm.sweep`, so
//! both run the same combinations with the same value strings.

use anyhow::{Context, Result, bail};

/// Values one `lin:`/`log:` range may give: a range is expanded in memory.
pub const MAX_VALUES: usize = 100_000;
/// Runs a sweep makes without being told `yes`: each writes a folder.
pub const CONFIRM_RUNS: usize = 10_000;
/// Runs no sweep makes: the grid itself is held in memory.
pub const MAX_RUNS: usize = 10_000_000;

/// One varied key and its values.
#[derive(Clone, Debug, PartialEq)]
pub struct Vary {
    pub path: String,
    /// The values as `--set` takes them.
    pub values: Vec<String>,
    /// The values as numbers, where they are (for the plot's axis).
    pub numbers: Vec<Option<f64>>,
    pub log: bool,
}

impl Vary {
    /// `PATH=V1,V2,...`, `PATH=lin:a:b:n` or `PATH=log:a:b:n`.
    pub fn parse(s: &str) -> Result<Self> {
        let (path, spec) = s.split_once('=').with_context(|| {
            format!("--vary {s}: expected PATH=VALUES, e.g. tip.mass=0,0.01,0.02")
        })?;
        let path = path.trim().to_string();
        let spec = spec.trim();
        let range = |kind: &str, rest: &str| -> Result<Vec<f64>> {
            let parts: Vec<&str> = rest.split(':').collect();
            let bad = || {
                format!("--vary {s}: expected {kind}:a:b:n with numbers a, b and a count n >= 2")
            };
            if parts.len() != 3 {
                bail!(bad());
            }
            let a: f64 = parts[0].trim().parse().with_context(bad)?;
            let b: f64 = parts[1].trim().parse().with_context(bad)?;
            let n: usize = parts[2].trim().parse().with_context(bad)?;
            if n < 2 || !a.is_finite() || !b.is_finite() {
                bail!(bad());
            }
            if n > MAX_VALUES {
                bail!("--vary {s}: {n} values; a range gives at most {MAX_VALUES}");
            }
            if kind == "log" && (a <= 0.0 || b <= 0.0) {
                bail!("--vary {s}: a log range needs positive ends");
            }
            Ok((0..n)
                .map(|i| {
                    let f = i as f64 / (n - 1) as f64;
                    match kind {
                        "log" => (a.ln() + f * (b.ln() - a.ln())).exp(),
                        _ => a + f * (b - a),
                    }
                })
                .collect())
        };
        // Twelve significant digits: 1e5, not 1.0000000000000001e5.
        let show = |v: &f64| {
            let r: f64 = format!("{v:.11e}").parse().unwrap_or(*v);
            format!("{r}")
        };
        let (values, log): (Vec<String>, bool) = if let Some(rest) = spec.strip_prefix("lin:") {
            (range("lin", rest)?.iter().map(show).collect(), false)
        } else if let Some(rest) = spec.strip_prefix("log:") {
            (range("log", rest)?.iter().map(show).collect(), true)
        } else {
            (split_top_level(spec), false)
        };
        if path.is_empty() || values.is_empty() || values.iter().any(|v| v.is_empty()) {
            bail!("--vary {s}: expected PATH=VALUES with at least one value");
        }
        let numbers = values.iter().map(|v| v.trim().parse().ok()).collect();
        Ok(Self {
            path,
            values,
            numbers,
            log,
        })
    }
}

/// A list split at its commas outside brackets: `[0,1,0],[1,0,0]` is two.
fn split_top_level(s: &str) -> Vec<String> {
    let (mut out, mut cur, mut depth) = (Vec::new(), String::new(), 0i32);
    for c in s.chars() {
        match c {
            '[' => depth += 1,
            ']' => depth -= 1,
            ',' if depth == 0 => {
                out.push(cur.trim().to_string());
                cur.clear();
                continue;
            }
            _ => {}
        }
        cur.push(c);
    }
    out.push(cur.trim().to_string());
    out
}

/// The number of combinations, counted before any is made; an error past
/// [`MAX_RUNS`], or past [`CONFIRM_RUNS`] unless `yes` (what to pass is
/// `confirm`, the front end's spelling of it).
pub fn checked_size(varies: &[Vary], yes: bool, confirm: &str) -> Result<usize> {
    checked_size_with(varies, yes, confirm, |_| None)
}

/// [`checked_size`], the refusal of a grid past [`CONFIRM_RUNS`] saying
/// what `estimate` (of the run count) gives: the disk and time it would
/// take.
pub fn checked_size_with(
    varies: &[Vary],
    yes: bool,
    confirm: &str,
    estimate: impl FnOnce(usize) -> Option<String>,
) -> Result<usize> {
    let size = varies
        .iter()
        .try_fold(1usize, |n, v| n.checked_mul(v.values.len()))
        .filter(|&n| n <= MAX_RUNS);
    let counts: Vec<String> = varies.iter().map(|v| v.values.len().to_string()).collect();
    let Some(size) = size else {
        bail!(
            "the grid has {} runs, more than the {MAX_RUNS} a sweep makes: vary fewer values",
            counts.join(" x ")
        );
    };
    if size > CONFIRM_RUNS && !yes {
        let estimate = estimate(size).map_or(String::new(), |e| format!(" ({e})"));
        bail!(
            "the grid has {} = {size} runs, each writing a folder of its own{estimate}; \
             over {CONFIRM_RUNS} runs a sweep starts only with {confirm}",
            counts.join(" x ")
        );
    }
    Ok(size)
}

/// Every combination, the last key fastest: value indices per key.
pub fn grid(varies: &[Vary]) -> Vec<Vec<usize>> {
    let mut combos = vec![Vec::new()];
    for v in varies {
        combos = combos
            .into_iter()
            .flat_map(|c| {
                (0..v.values.len()).map(move |i| {
                    let mut c = c.clone();
                    c.push(i);
                    c
                })
            })
            .collect();
    }
    combos
}
