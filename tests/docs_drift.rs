//! The generated sections of `docs/tables.md` match what the code generates from its
//! single definitions (the part-property table of `src/model/props.rs`).
//!
//! Regenerate after changing a definition:
//!   WEFT_BLESS=1 cargo test --release --test docs_drift

use std::path::Path;

/// The text between `<!-- BEGIN generated: {name} ... -->` and `<!-- END generated: {name} -->`.
fn check_block(doc: &str, name: &str, generated: &str) -> Result<(), String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(doc);
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let begin = format!("<!-- BEGIN generated: {name}");
    let end = format!("<!-- END generated: {name} -->");
    let b = text
        .find(&begin)
        .ok_or_else(|| format!("{doc} has no `{begin}` marker"))?;
    let body_start = b + text[b..].find("-->\n").ok_or("unclosed BEGIN marker")? + 4;
    let e = text[body_start..]
        .find(&end)
        .map(|e| body_start + e)
        .ok_or_else(|| format!("{doc} has no `{end}` marker"))?;
    if &text[body_start..e] == generated {
        return Ok(());
    }
    if std::env::var_os("WEFT_BLESS").is_some() {
        let new = format!("{}{generated}{}", &text[..body_start], &text[e..]);
        std::fs::write(&path, new).map_err(|e| format!("{}: {e}", path.display()))?;
        eprintln!("rewrote the `{name}` section of {doc}");
        return Ok(());
    }
    Err(format!(
        "the `{name}` section of {doc} differs from what the code generates; \
         regenerate it with `WEFT_BLESS=1 cargo test --release --test docs_drift`.\n\
         --- in {doc}:\n{}\n--- generated:\n{generated}",
        &text[body_start..e]
    ))
}

#[test]
fn parts_table_in_docs_matches_the_property_table() {
    if let Err(e) = check_block(
        "docs/tables.md",
        "parts.parquet columns",
        &weft::model::props::parts_table_markdown(),
    ) {
        panic!("{e}");
    }
}

/// `weft-fit --help` lists the property aliases of the table.
#[test]
fn fit_help_lists_the_property_aliases() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_weft-fit"))
        .arg("--help")
        .output()
        .expect("weft-fit runs");
    let help = String::from_utf8_lossy(&o.stdout);
    let help = help.split_whitespace().collect::<Vec<_>>().join(" ");
    let aliases: Vec<&str> = weft::model::props::PROPERTIES
        .iter()
        .flat_map(|p| p.aliases.iter().copied())
        .collect();
    let want = format!("aliases {})", aliases.join(", "));
    assert!(
        help.contains(&want),
        "weft-fit --help does not list `{want}`:\n{help}"
    );
}
