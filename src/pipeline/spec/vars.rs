//! `[vars]`: scalars that templates name as `${name}`; a var may refer to other vars,
//! without cycles.

use std::collections::BTreeMap;

use toml::Spanned;

use super::raw::{value_str, Source};
use super::template::{render, Ctx};
use crate::error::Result;

/// A var as written, not yet rendered.
struct Pending {
    name: String,
    /// Its text, which may refer to other vars.
    text: String,
    line: usize,
}

/// The vars, each rendered against the others.
pub(super) fn resolve(
    raw: &BTreeMap<String, Spanned<toml::Value>>,
    at: &Source,
) -> Result<BTreeMap<String, String>> {
    let pending = scalars(raw, at)?;
    let (vars, left) = render_in_rounds(pending);
    match left.first() {
        Some(first) => Err(unresolved(first, &left, &vars, at)),
        None => Ok(vars),
    }
}

/// Each var's text: a string, number or boolean.
fn scalars(raw: &BTreeMap<String, Spanned<toml::Value>>, at: &Source) -> Result<Vec<Pending>> {
    let mut pending = Vec::new();
    for (k, v) in raw {
        let line = at.line(v.span().start);
        let s = value_str(v.get_ref()).ok_or_else(|| {
            at.err(
                format!("var `{k}` is not a string, number or boolean"),
                line,
                &format!("vars.{k}"),
            )
            .expected("a scalar value")
        })?;
        pending.push(Pending {
            name: k.clone(),
            text: s,
            line,
        });
    }
    Ok(pending)
}

/// A template context of vars alone (no inputs, outputs, stage or instance).
fn vars_only(vars: &BTreeMap<String, String>) -> Ctx<'_> {
    Ctx {
        values: vars,
        inputs: &[],
        outputs: &[],
        stage: "",
        instance: "",
    }
}

/// Render the vars whose references are all resolved, round after round, until none
/// is left or a round resolves nothing more. Returns the resolved vars and those left.
fn render_in_rounds(mut pending: Vec<Pending>) -> (BTreeMap<String, String>, Vec<Pending>) {
    let mut vars: BTreeMap<String, String> = BTreeMap::new();
    let rounds = pending.len();
    for _round in 0..=rounds {
        let mut next = Vec::new();
        for p in pending.drain(..) {
            match render(&p.text, &vars_only(&vars)) {
                Ok((r, _)) => {
                    vars.insert(p.name, r);
                }
                Err(_) => next.push(p),
            }
        }
        pending = next;
        if pending.is_empty() {
            break;
        }
    }
    (vars, pending)
}

/// Why the vars `left` could not be rendered: a cycle among them, or what rendering the
/// first one says.
fn unresolved(
    first: &Pending,
    left: &[Pending],
    vars: &BTreeMap<String, String>,
    at: &Source,
) -> crate::error::WeftError {
    let names: Vec<String> = left.iter().map(|p| format!("`{}`", p.name)).collect();
    let refers_pending = left
        .iter()
        .any(|p| first.text.contains(&format!("${{{}}}", p.name)));
    let what = if refers_pending {
        format!("vars {} refer to each other in a cycle", names.join(", "))
    } else {
        format!(
            "var `{}`: {}",
            first.name,
            render(&first.text, &vars_only(vars))
                .err()
                .unwrap_or_default()
        )
    };
    at.err(what, first.line, &format!("vars.{}", first.name))
        .hint("vars may refer to other vars, without cycles")
}
