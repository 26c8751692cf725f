//! "Did you mean": the allowed name nearest a misspelt one, for the
//! errors of unknown keys and values (`serde`'s "unknown field `x`,
//! expected one of `a`, `b`").

/// The message with the nearest allowed name added, when one is near
/// (at most a third of its letters changed, inserted or dropped).
pub fn with_suggestion(message: &str) -> String {
    // The suggestion ends the first line (a TOML error goes on with where).
    let (first, rest) = message
        .split_once('\n')
        .map_or((message, None), |(a, b)| (a, Some(b)));
    let suggested = suggest(first);
    match rest {
        Some(rest) => format!("{suggested}\n{rest}"),
        None => suggested,
    }
}

fn suggest(message: &str) -> String {
    let Some((given, allowed)) = unknown_and_allowed(message) else {
        return message.to_string();
    };
    let nearest = allowed
        .iter()
        .map(|a| (distance(given, a), *a))
        .min_by_key(|(d, _)| *d);
    match nearest {
        Some((d, name)) if d > 0 && d <= given.len().max(3) / 3 => {
            format!("{message}; did you mean `{name}`?")
        }
        _ => message.to_string(),
    }
}

/// The name in "unknown field `x`" (or variant) and the names after
/// "expected one of".
fn unknown_and_allowed(message: &str) -> Option<(&str, Vec<&str>)> {
    let rest = message
        .strip_prefix("unknown field `")
        .or_else(|| message.strip_prefix("unknown variant `"))?;
    let (given, rest) = rest.split_once('`')?;
    let list = rest.split_once("expected one of ")?.1;
    let allowed = list.split('`').skip(1).step_by(2).collect();
    Some((given, allowed))
}

/// Levenshtein distance (insertions, deletions, substitutions).
#[doc(hidden)] // white-box tests (tests/suite)
pub fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut previous = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (previous + usize::from(ca != cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            previous = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}
