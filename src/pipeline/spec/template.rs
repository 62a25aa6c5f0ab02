//! Templates: `${name}` references in commands and paths rendered against an instance's
//! values, inputs and outputs, and the shell quoting of what they insert.

use std::collections::BTreeMap;

fn needs_quotes(s: &str) -> bool {
    s.is_empty()
        || !s
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-=,@+:%".contains(c))
}

/// Quote a path for `sh -c` when it holds shell-special characters.
pub fn shell_quote(s: &str) -> String {
    if needs_quotes(s) {
        format!("'{}'", s.replace('\'', r"'\''"))
    } else {
        s.to_string()
    }
}

/// What a template can refer to.
pub struct Ctx<'a> {
    pub values: &'a BTreeMap<String, String>,
    pub inputs: &'a [(String, String)],
    pub outputs: &'a [(String, String)],
    pub stage: &'a str,
    pub instance: &'a str,
}

/// Render `${...}` references. Returns the text and the plain names referenced.
pub fn render(t: &str, ctx: &Ctx) -> std::result::Result<(String, Vec<String>), String> {
    let mut out = String::with_capacity(t.len());
    let mut used = Vec::new();
    let mut rest = t;
    while let Some(i) = rest.find('$') {
        out.push_str(&rest[..i]);
        let after = &rest[i + 1..];
        if let Some(a) = after.strip_prefix('$') {
            out.push('$');
            rest = a;
            continue;
        }
        let Some(body) = after.strip_prefix('{') else {
            out.push('$');
            rest = after;
            continue;
        };
        let Some(end) = body.find('}') else {
            return Err(format!("unclosed `${{` in `{t}`"));
        };
        let name = body[..end].trim();
        let all = |v: &[(String, String)]| {
            v.iter()
                .map(|(_, p)| shell_quote(p))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let val = match name {
            "inputs" => all(ctx.inputs),
            "outputs" => all(ctx.outputs),
            "stage" => ctx.stage.to_string(),
            "instance" => ctx.instance.to_string(),
            n if n.starts_with("inputs.") || n.starts_with("outputs.") => {
                let (kind, key) = n.split_once('.').expect("has a dot");
                let list = if kind == "inputs" { ctx.inputs } else { ctx.outputs };
                match list.iter().find(|(k, _)| k == key) {
                    Some((_, p)) => shell_quote(p),
                    None => {
                        return Err(format!(
                            "`${{{n}}}` names no {kind} entry; the stage's {kind} are [{}]",
                            list.iter().map(|(k, _)| k.as_str()).collect::<Vec<_>>().join(", ")
                        ))
                    }
                }
            }
            n => match ctx.values.get(n) {
                Some(v) => {
                    used.push(n.to_string());
                    v.clone()
                }
                None => {
                    return Err(format!(
                        "unknown variable `${{{n}}}`; known: [{}] and inputs.*, outputs.*, stage, instance",
                        ctx.values.keys().map(|k| k.as_str()).collect::<Vec<_>>().join(", ")
                    ))
                }
            },
        };
        out.push_str(&val);
        rest = &body[end + 1..];
    }
    out.push_str(rest);
    Ok((out, used))
}
