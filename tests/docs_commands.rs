//! Docs that cannot rot: what the README and the docs tell a user to type, runs.
//!
//! - Every fenced block marked `sh` in README.md, CONTRIBUTING.md and docs/**/*.md runs:
//!   a file's blocks in order, in one `bash -euo pipefail` session, in a fresh scratch
//!   project holding copies of `pipelines/`, `data/` and `scripts/`, with the weft binaries
//!   on PATH; a `python` block runs there too (python3 with pandas, polars and pyarrow),
//!   after the blocks before it. A block preceded by the line
//!   `<!-- docs-test: skip (reason) -->` is not run (installs, cargo, Slurm, full sizes),
//!   nor are `console` or `text` blocks.
//! - Every relative link and image points at a file of the repository, and an anchor at a
//!   heading of its target (GitHub's slugs).
//! - The README's stage table is each binary's own `--help` summary (regenerate with
//!   `WEFT_BLESS=1 cargo test --release --test docs_commands`), and every binary and
//!   subcommand's `--help` has an example; a flag whose default shows several values
//!   takes them as shown (`weft-bench --threads 1 2`).
//!
//! Its own harness (libtest-mimic, as tests/common/optional.rs): a file with python blocks
//! is reported as ignored where python3 with pandas and polars is missing, unless
//! `WEFT_REQUIRE_PYTHON=1`.

use libtest_mimic::{Arguments, Failed, Trial};
use std::collections::BTreeSet;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");
const SKIP: &str = "<!-- docs-test: skip";
/// A documented run (small sizes) takes seconds; this only stops a hang.
const LIMIT: Duration = Duration::from_secs(600);

fn bin_dir() -> PathBuf {
    Path::new(env!("CARGO_BIN_EXE_weft"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// README.md, CONTRIBUTING.md and every Markdown file under docs/, sorted.
fn markdown_files() -> Vec<PathBuf> {
    let root = Path::new(ROOT);
    let mut v: Vec<PathBuf> = ["README.md", "CONTRIBUTING.md"]
        .iter()
        .map(|f| root.join(f))
        .filter(|p| p.exists())
        .collect();
    let mut stack = vec![root.join("docs")];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "md") {
                v.push(p);
            }
        }
    }
    v.sort();
    v
}

fn rel(p: &Path) -> String {
    p.strip_prefix(ROOT).unwrap_or(p).display().to_string()
}

/// A fenced block: its info string, first line number (1-based, of the fence), its text,
/// and whether the line before the fence asks the test to skip it.
struct Block {
    info: String,
    line: usize,
    text: String,
    skip: bool,
}

/// The fenced blocks of a Markdown text (``` or ~~~ fences, not indented more than 3).
fn blocks(text: &str) -> Vec<Block> {
    let lines: Vec<&str> = text.lines().collect();
    let mut v = vec![];
    let mut i = 0;
    while i < lines.len() {
        let t = lines[i].trim_start();
        let indent = lines[i].len() - t.len();
        let fence = if t.starts_with("```") {
            "```"
        } else if t.starts_with("~~~") {
            "~~~"
        } else {
            ""
        };
        if fence.is_empty() || indent > 3 {
            i += 1;
            continue;
        }
        let info = t.trim_start_matches(fence).trim().to_string();
        let skip = i > 0 && lines[i - 1].trim_start().starts_with(SKIP);
        let start = i;
        let mut body = vec![];
        i += 1;
        while i < lines.len() && !lines[i].trim_start().starts_with(fence) {
            body.push(lines[i]);
            i += 1;
        }
        v.push(Block {
            info,
            line: start + 1,
            text: body.join("\n"),
            skip,
        });
        i += 1;
    }
    v
}

/// The lines outside fenced blocks (links and headings are looked for there only).
fn prose(text: &str) -> Vec<(usize, String)> {
    let mut out = vec![];
    let mut fence: Option<&str> = None;
    for (i, l) in text.lines().enumerate() {
        let t = l.trim_start();
        match fence {
            Some(f) if t.starts_with(f) => fence = None,
            Some(_) => {}
            None if t.starts_with("```") => fence = Some("```"),
            None if t.starts_with("~~~") => fence = Some("~~~"),
            None => out.push((i + 1, l.to_string())),
        }
    }
    out
}

/// GitHub's anchor of a heading: lowercase, spaces to `-`, letters (any script), digits,
/// `-` and `_` kept, the rest dropped; repeated headings get `-1`, `-2`, ….
fn slugs(text: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    for (_, l) in prose(text) {
        let t = l.trim_start();
        if !t.starts_with('#') {
            continue;
        }
        let h = t.trim_start_matches('#');
        if !h.starts_with(' ') {
            continue;
        }
        let h = h.trim().replace('`', "");
        let base: String = h
            .to_lowercase()
            .chars()
            .filter_map(|c| match c {
                ' ' => Some('-'),
                c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
                _ => None,
            })
            .collect();
        let mut s = base.clone();
        let mut k = 1;
        while seen.contains(&s) {
            s = format!("{base}-{k}");
            k += 1;
        }
        seen.insert(s);
    }
    seen
}

/// The `(target)` of every inline link and image on a line: `[text](target)`.
fn link_targets(line: &str) -> Vec<String> {
    let mut v = vec![];
    let b = line.as_bytes();
    let mut i = 0;
    while let Some(k) = line[i..].find("](") {
        let start = i + k + 2;
        // Balanced parentheses inside the target.
        let mut depth = 1;
        let mut j = start;
        while j < b.len() {
            match b[j] {
                b'(' => depth += 1,
                b')' => {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                }
                _ => {}
            }
            j += 1;
        }
        if j >= b.len() {
            break;
        }
        let target = line[start..j].split_whitespace().next().unwrap_or("");
        v.push(target.trim_matches(['<', '>']).to_string());
        i = j + 1;
    }
    v
}

fn links_resolve() -> Result<(), Failed> {
    let mut bad = vec![];
    let mut n = 0;
    for f in markdown_files() {
        let text = std::fs::read_to_string(&f).unwrap();
        let dir = f.parent().unwrap();
        for (line, l) in prose(&text) {
            // Inline code is not a link.
            let l: String = l.split('`').step_by(2).collect::<Vec<_>>().join(" ");
            for t in link_targets(&l) {
                if t.is_empty() || t.contains("://") || t.starts_with("mailto:") {
                    continue;
                }
                n += 1;
                let (path, anchor) = match t.split_once('#') {
                    Some((p, a)) => (p, Some(a)),
                    None => (t.as_str(), None),
                };
                let target = if path.is_empty() {
                    f.clone()
                } else {
                    dir.join(path)
                };
                if !target.exists() {
                    bad.push(format!(
                        "{}:{line}: `{t}`: no file {}",
                        rel(&f),
                        rel(&target)
                    ));
                    continue;
                }
                if let Some(a) = anchor {
                    if target.extension().is_some_and(|x| x == "md") {
                        let s = slugs(&std::fs::read_to_string(&target).unwrap());
                        if !s.contains(a) {
                            bad.push(format!(
                                "{}:{line}: `{t}`: {} has no heading with the anchor `#{a}`",
                                rel(&f),
                                rel(&target)
                            ));
                        }
                    }
                }
            }
        }
    }
    eprintln!("{n} relative links checked");
    if bad.is_empty() {
        Ok(())
    } else {
        Err(format!("{} broken links:\n{}", bad.len(), bad.join("\n")).into())
    }
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let p = e.path();
        let q = to.join(e.file_name());
        if p.is_dir() {
            copy_dir(&p, &q);
        } else {
            std::fs::copy(&p, &q).unwrap();
        }
    }
}

/// Whether a file has blocks the test runs, and whether any of them is python.
fn runnable(text: &str) -> (usize, bool) {
    let b: Vec<Block> = blocks(text)
        .into_iter()
        .filter(|b| !b.skip && (b.info == "sh" || b.info == "python"))
        .collect();
    (b.len(), b.iter().any(|b| b.info == "python"))
}

/// Runs a file's `sh` and `python` blocks in order in a scratch project.
fn run_documented(file: &Path) -> Result<(), Failed> {
    let text = std::fs::read_to_string(file).unwrap();
    let mut script = String::new();
    for b in blocks(&text) {
        if b.skip || !(b.info == "sh" || b.info == "python") {
            continue;
        }
        script.push_str(&format!("echo '@@ {}:{}' >&2\n", rel(file), b.line));
        if b.info == "sh" {
            script.push_str(&b.text);
            script.push('\n');
        } else {
            script.push_str("python3 - <<'WEFT_DOCS_PYTHON'\n");
            script.push_str(&b.text);
            script.push_str("\nWEFT_DOCS_PYTHON\n");
        }
    }
    let dir = tempfile::tempdir().unwrap();
    for d in ["pipelines", "data", "scripts"] {
        let from = Path::new(ROOT).join(d);
        if from.exists() {
            copy_dir(&from, &dir.path().join(d));
        }
    }
    std::fs::write(dir.path().join("docs-commands.sh"), &script).unwrap();
    let path = format!(
        "{}:{}",
        bin_dir().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let start = Instant::now();
    let mut child = Command::new("bash")
        .args(["-euo", "pipefail", "docs-commands.sh"])
        .current_dir(dir.path())
        .env("PATH", path)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (mut so, mut se) = (child.stdout.take().unwrap(), child.stderr.take().unwrap());
    let out = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = so.read_to_string(&mut s);
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = se.read_to_string(&mut s);
        s
    });
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let (out, err) = (out.join().unwrap(), err.join().unwrap());
    let secs = start.elapsed().as_secs_f64();
    let at = err
        .lines()
        .filter_map(|l| l.strip_prefix("@@ "))
        .next_back()
        .unwrap_or("(before the first block)")
        .to_string();
    let tail = |s: &str| {
        let l: Vec<&str> = s.lines().collect();
        l[l.len().saturating_sub(30)..].join("\n")
    };
    match status {
        Some(s) if s.success() => {
            eprintln!("{}: its commands ran in {secs:.1} s", rel(file));
            Ok(())
        }
        Some(s) => Err(format!(
            "the documented commands of {} failed ({s}) in the block at {at}:\n--- stdout (tail):\n{}\n--- stderr (tail):\n{}",
            rel(file),
            tail(&out),
            tail(&err)
        )
        .into()),
        None => Err(format!(
            "the documented commands of {} ran over {} s, in the block at {at}",
            rel(file),
            LIMIT.as_secs()
        )
        .into()),
    }
}

/// The binaries of the project, from src/bin/: `NAME.rs` and `NAME/main.rs` (cargo's
/// two layouts).
fn binaries() -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(Path::new(ROOT).join("src/bin"))
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            if p.is_dir() && p.join("main.rs").is_file() {
                return Some(p.file_name().unwrap().to_string_lossy().to_string());
            }
            (p.extension()? == "rs").then(|| p.file_stem().unwrap().to_string_lossy().to_string())
        })
        .collect();
    v.sort();
    v
}

fn help(bin: &str, sub: Option<&str>, long: bool) -> String {
    let o = Command::new(bin_dir().join(bin))
        .args(sub)
        .arg(if long { "--help" } else { "-h" })
        .output()
        .unwrap();
    assert!(o.status.success(), "{bin} {sub:?} --help failed");
    String::from_utf8_lossy(&o.stdout).to_string()
}

/// The subcommands a help lists under `Commands:` (`help` aside).
fn subcommands(help: &str) -> Vec<String> {
    let mut v = vec![];
    let mut inside = false;
    for l in help.lines() {
        if l.starts_with("Commands:") {
            inside = true;
            continue;
        }
        if inside {
            if !l.starts_with("  ") || l.trim().is_empty() {
                if !l.starts_with(' ') {
                    break;
                }
                continue;
            }
            // `  name  description`: a command line has exactly two leading spaces.
            if l.starts_with("   ") {
                continue;
            }
            if let Some(name) = l.split_whitespace().next() {
                if name != "help" {
                    v.push(name.to_string());
                }
            }
        }
    }
    v
}

/// The first paragraph of a binary's short help, on one line.
fn summary(bin: &str) -> String {
    let h = help(bin, None, false);
    h.split("\n\n")
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// The stages in the order a study uses them (the README's table follows it).
const STAGE_ORDER: &[&str] = &[
    "weft-weave",
    "weft-form",
    "weft-simulate",
    "weft-wavespeed",
    "weft-error",
    "weft-energy",
    "weft-fit",
    "weft-surrogate",
    "weft-ballistic",
    "weft-plot",
    "weft-vtk",
    "weft-export",
    "weft",
    "weft-bench",
];

fn stage_table() -> String {
    let mut s = String::from("| stage | what it does |\n|---|---|\n");
    let mut all = binaries();
    all.sort_by_key(|b| {
        STAGE_ORDER
            .iter()
            .position(|x| x == b)
            .unwrap_or(usize::MAX)
    });
    for b in all {
        let subs = subcommands(&help(&b, None, false));
        let name = if subs.is_empty() {
            format!("`{b}`")
        } else {
            format!("`{b} {}`", subs.join("\\|"))
        };
        s.push_str(&format!(
            "| {name} | {} |\n",
            summary(&b).replace('|', "\\|")
        ));
    }
    s
}

fn the_stage_table_is_the_binaries_own_words() -> Result<(), Failed> {
    let missing: Vec<String> = binaries()
        .into_iter()
        .filter(|b| !STAGE_ORDER.contains(&b.as_str()))
        .collect();
    if !missing.is_empty() {
        return Err(format!(
            "binaries not in STAGE_ORDER (add them where a study uses them): {missing:?}"
        )
        .into());
    }
    let path = Path::new(ROOT).join("README.md");
    let text = std::fs::read_to_string(&path).unwrap();
    let begin = "<!-- BEGIN generated: stages";
    let end = "<!-- END generated: stages -->";
    let b = text
        .find(begin)
        .ok_or(format!("README.md has no `{begin}` marker"))?;
    let body = b + text[b..].find("-->\n").ok_or("unclosed BEGIN marker")? + 4;
    let e = body
        + text[body..]
            .find(end)
            .ok_or(format!("README.md has no `{end}` marker"))?;
    let generated = stage_table();
    if text[body..e] == generated {
        return Ok(());
    }
    if std::env::var_os("WEFT_BLESS").is_some() {
        std::fs::write(&path, format!("{}{generated}{}", &text[..body], &text[e..])).unwrap();
        eprintln!("rewrote the README's stage table");
        return Ok(());
    }
    Err(format!(
        "the README's stage table differs from the binaries' --help; regenerate it with \
         `WEFT_BLESS=1 cargo test --release --test docs_commands`\n--- README.md:\n{}\n--- generated:\n{generated}",
        &text[body..e]
    )
    .into())
}

fn every_help_has_an_example_and_takes_its_defaults_as_shown() -> Result<(), Failed> {
    let mut bad = vec![];
    let (mut n, mut n_examples) = (0, 0);
    let bins = binaries();
    for b in &bins {
        let top = help(&b, None, true);
        let mut pages = vec![(None, top.clone())];
        for s in subcommands(&top) {
            let h = help(&b, Some(&s), true);
            pages.push((Some(s), h));
        }
        for (sub, h) in &pages {
            n += 1;
            let who = format!(
                "{b}{}",
                sub.as_ref().map(|s| format!(" {s}")).unwrap_or_default()
            );
            // The binary's own page or the subcommand's shows one example.
            if !h.to_lowercase().contains("example") {
                bad.push(format!("`{who} --help` shows no example"));
            }
            // Each example's weft command parses: run with --help at its end, every flag
            // and value before it is checked (not what it would read or write).
            for cmd in examples(h) {
                let Some((prog, args)) = cmd.split_first() else {
                    continue;
                };
                if !bins.contains(prog) {
                    continue;
                }
                n_examples += 1;
                let scratch = tempfile::tempdir().unwrap();
                let o = Command::new(bin_dir().join(prog))
                    .args(args)
                    .arg("--help")
                    .current_dir(scratch.path())
                    .output()
                    .unwrap();
                if !o.status.success() {
                    bad.push(format!(
                        "`{who} --help`'s example `{}` does not parse: {}",
                        cmd.join(" "),
                        String::from_utf8_lossy(&o.stderr)
                            .lines()
                            .next()
                            .unwrap_or("")
                    ));
                }
            }
            // `--flag <X>` … `[default: a b c]`: written as the help reads, it must parse.
            let flat = h.split_whitespace().collect::<Vec<_>>().join(" ");
            let mut rest = flat.as_str();
            while let Some(k) = rest.find("[default: ") {
                let before = &rest[..k];
                let after = &rest[k + 10..];
                let Some(close) = after.find(']') else { break };
                let values: Vec<&str> = after[..close].split(' ').collect();
                let last_flag = before
                    .split(' ')
                    .rfind(|w| w.starts_with("--") && w.len() > 2)
                    .map(|w| w.trim_end_matches(',').to_string());
                if values.len() > 1 && values.iter().all(|v| v.parse::<f64>().is_ok()) {
                    if let Some(f) = &last_flag {
                        let o = Command::new(bin_dir().join(&b))
                            .args(sub.iter())
                            .arg(f)
                            .args(&values)
                            .arg("--help")
                            .output()
                            .unwrap();
                        if !o.status.success() {
                            bad.push(format!(
                                "`{who} {f} {}` (its default as --help shows it) is refused: {}",
                                values.join(" "),
                                String::from_utf8_lossy(&o.stderr)
                                    .lines()
                                    .next()
                                    .unwrap_or("")
                            ));
                        }
                    }
                }
                rest = &after[close..];
            }
        }
    }
    eprintln!("{n} help pages, {n_examples} example commands checked");
    if bad.is_empty() {
        Ok(())
    } else {
        Err(bad.join("\n").into())
    }
}

/// The commands of a help page's examples: the lines after one that says "Example", up
/// to a blank line, each from its first word `weft…`, `\` continuations joined, a `&&`
/// chain split, a comment after two spaces dropped, words split as a shell would (quotes
/// kept together).
fn examples(help: &str) -> Vec<Vec<String>> {
    let mut out = vec![];
    let mut after = false;
    let mut joined = String::new();
    for l in help.lines() {
        if l.to_lowercase().contains("example") {
            after = true;
            continue;
        }
        if l.trim().is_empty() && joined.is_empty() {
            after = false;
        }
        if !after {
            continue;
        }
        let t = l.trim();
        if joined.is_empty() && !t.starts_with("weft") {
            continue;
        }
        let t = t.split("  ").next().unwrap_or(t);
        if let Some(c) = t.strip_suffix('\\') {
            joined.push_str(c);
            joined.push(' ');
            continue;
        }
        joined.push_str(t);
        for part in joined.split("&&") {
            let w = shell_words(part.trim());
            if !w.is_empty() {
                out.push(w);
            }
        }
        joined.clear();
    }
    out
}

fn shell_words(s: &str) -> Vec<String> {
    let mut v = vec![];
    let mut cur = String::new();
    let mut quote: Option<char> = None;
    let mut any = false;
    for c in s.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => cur.push(c),
            (None, '\'' | '"') => {
                quote = Some(c);
                any = true;
            }
            (None, c) if c.is_whitespace() => {
                if any || !cur.is_empty() {
                    v.push(std::mem::take(&mut cur));
                }
                any = false;
            }
            (None, c) => cur.push(c),
        }
    }
    if any || !cur.is_empty() {
        v.push(cur);
    }
    v
}

fn python_here() -> bool {
    Command::new("python3")
        .args(["-c", "import pandas, polars, pyarrow"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

fn main() -> std::process::ExitCode {
    let args = Arguments::from_args();
    let required = std::env::var("WEFT_REQUIRE_PYTHON").as_deref() == Ok("1");
    let mut trials = vec![
        Trial::test("relative_links_and_anchors_resolve", links_resolve),
        Trial::test(
            "the_readme_stage_table_is_the_binaries_own_words",
            the_stage_table_is_the_binaries_own_words,
        ),
        Trial::test(
            "every_help_has_an_example_and_takes_its_defaults_as_shown",
            every_help_has_an_example_and_takes_its_defaults_as_shown,
        ),
    ];
    let mut python: Option<bool> = None;
    let mut skipped = 0;
    for f in markdown_files() {
        let text = std::fs::read_to_string(&f).unwrap();
        let (n, py) = runnable(&text);
        if n == 0 {
            continue;
        }
        let missing = py && !*python.get_or_insert_with(python_here);
        skipped += usize::from(missing && !required);
        let name = format!("documented_commands_run::{}", rel(&f));
        let file = f.clone();
        trials.push(
            Trial::test(name, move || {
                if missing {
                    return Err("WEFT_REQUIRE_PYTHON=1 but python3 with pandas, polars and pyarrow is not available".into());
                }
                run_documented(&file)
            })
            .with_ignored_flag(missing && !required),
        );
    }
    if skipped > 0 {
        println!(
            "SKIPPED {skipped} documented-command file(s), shown as ignored: python3 with pandas, \
             polars and pyarrow not found (pip install pandas polars pyarrow); \
             WEFT_REQUIRE_PYTHON=1 makes them required"
        );
    }
    libtest_mimic::run(&args, trials).exit_code()
}
