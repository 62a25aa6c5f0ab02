//! Where a figure goes: its file (PNG or SVG by the extension), size and title, written
//! atomically (beside the target, then renamed).

use std::path::PathBuf;

use anyhow::Context as _;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::{draw, Chart};
use super::field;
use crate::error::WeftError;

/// Where and how large the figure is drawn.
#[derive(Debug, Clone)]
pub struct Output {
    /// Output file: .png or .svg.
    pub out: PathBuf,
    /// Figure title (none when `None`).
    pub title: Option<String>,
    /// Width [px] (at least 200).
    pub width: u32,
    /// Height [px] (at least 150).
    pub height: u32,
}

/// What `save` draws: a line chart, or a field figure with its title.
pub(super) enum Drawing {
    Chart(Chart),
    Field(field::Field, Option<String>),
}

fn draw_any<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, d: &Drawing) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    match d {
        Drawing::Chart(c) => draw(root, c),
        Drawing::Field(f, title) => field::draw(root, f, title.as_deref()),
    }
}

/// Draw `chart` into `c.out` (PNG or SVG by its extension), beside the target and then
/// renamed into place.
pub(super) fn save(chart: &Drawing, c: &Output) -> anyhow::Result<()> {
    let ext = c
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if c.width < 200 || c.height < 150 {
        return Err(WeftError::input(format!(
            "--width {} --height {}: expected at least 200 × 150 pixels",
            c.width, c.height
        ))
        .into());
    }
    if !matches!(ext.as_str(), "png" | "svg") {
        // Before any folder is made: a refusal leaves nothing behind.
        return Err(WeftError::input(format!(
            "--out `{}`: unknown figure format `{ext}` (expected a .png or .svg file name)",
            c.out.display()
        ))
        .into());
    }
    if let Some(dir) = c.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create `{}`", dir.display()))?;
    }
    // Written beside the target, then renamed: an interrupted run leaves no half figure.
    let name = c
        .out
        .file_name()
        .ok_or_else(|| WeftError::input("--out has no file name"))?
        .to_string_lossy()
        .to_string();
    let tmp = c
        .out
        .with_file_name(format!(".{name}.tmp-{}.{ext}", std::process::id()));
    let size = (c.width, c.height);
    let r = match ext.as_str() {
        "png" => draw_any(BitMapBackend::new(&tmp, size).into_drawing_area(), chart),
        "svg" => draw_any(SVGBackend::new(&tmp, size).into_drawing_area(), chart),
        other => {
            return Err(WeftError::input(format!(
                "--out `{}`: unknown figure format `{other}` (expected a .png or .svg file name)",
                c.out.display()
            ))
            .into())
        }
    };
    if let Err(e) = r {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, &c.out)
        .with_context(|| format!("cannot move the figure to `{}`", c.out.display()))?;
    Ok(())
}
