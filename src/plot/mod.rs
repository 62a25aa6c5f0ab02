//! The figures behind `weft-plot`: charts built from the tables the stages write
//! (displacement time laws, wave speeds, per-node errors, a fit's convergence), drawn with
//! plotters as PNG or SVG (by the output's extension) with a bundled font (DejaVu Sans),
//! and written atomically (beside the target, then renamed); and colour maps of a nodal
//! quantity over the mesh ([`field`]: the paper's Fig. 4).
//!
//! Errors are `anyhow` errors: problems with the input are [`WeftError`]s inside them;
//! the file system and the drawing backend fail with their own errors under a context.

pub mod armour;
pub mod ballistic;
pub mod bullet;
mod chart;
pub mod crater;
pub mod field;
mod history;
mod output;
mod tables;
mod weave;

pub use history::HistoryFigure;
pub use output::Output;
pub use tables::{ErrorFigure, FitFigure, SurrogateFigure, WavespeedFigure};
pub use weave::WeaveFigure;

use plotters::prelude::*;

use crate::error::WeftError;
use output::{save, Drawing};

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// One figure, as `weft-plot`'s flags give it.
#[derive(Debug, Clone)]
pub struct Config {
    pub figure: Figure,
    pub output: Output,
}

/// Which figure, with its settings.
#[derive(Debug, Clone)]
pub enum Figure {
    /// Displacement (or velocity) time laws of chosen nodes, one line style per model.
    History(HistoryFigure),
    /// Wave speed against position along the line, one series per table.
    Wavespeed(WavespeedFigure),
    /// Per-node peak relative error along the compared node set (error.parquet).
    Error(ErrorFigure),
    /// Best T against evaluations (fit_trace.parquet), one series per trace.
    Fit(FitFigure),
    /// Section of a woven patch along a line y = y₀: the centre line and envelope of
    /// the yarn along x there, and the sections of the yarns across it.
    Weave(WeaveFigure),
    /// A colour map of a nodal quantity over the mesh at one time, several models side
    /// by side on one colour scale (the paper's Fig. 4).
    Field(field::FieldFigure),
    /// Test MSE of a network search against the hidden neurons n₁, per activation
    /// (search.parquet; the paper's Fig. 6b).
    Surrogate(SurrogateFigure),
    /// A ballistic limit's figures (weft-ballistic's tables).
    Ballistic(ballistic::BallisticFigure),
    /// A deformable bullet's length and diameter against time.
    Bullet(bullet::BulletFigure),
    /// The backing clay's crater: its depth against time or its profile.
    Crater(crater::CraterFigure),
    /// The armour test: back-face signature against areal density.
    Armour(armour::ArmourFigure),
}

/// What drawing a figure reports back to the binary.
#[derive(Debug, Clone)]
pub struct Report {
    /// Series drawn (empty ones included; a field figure: its panels).
    pub series: usize,
    /// A field figure's times, missing nodes and colour range.
    pub field: Option<field::FieldReport>,
}

/// Build the figure and write it to `output.out`.
pub fn run(c: &Config) -> anyhow::Result<Report> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| anyhow::anyhow!("the bundled font could not be loaded"))?;
    let mut chart = match &c.figure {
        Figure::History(a) => history::history(a)?,
        Figure::Wavespeed(a) => tables::wavespeed(a)?,
        Figure::Error(a) => tables::error(a)?,
        Figure::Fit(a) => tables::fit(a)?,
        Figure::Surrogate(a) => tables::surrogate(a)?,
        Figure::Ballistic(a) => ballistic::ballistic(a)?,
        Figure::Bullet(a) => bullet::bullet(a)?,
        Figure::Crater(a) => crater::crater(a)?,
        Figure::Armour(a) => armour::armour(a)?,
        Figure::Weave(a) => weave::weave(a)?,
        Figure::Field(a) => {
            let (f, report) = field::build(a)?;
            let panels = a.model.len();
            save(&Drawing::Field(f, c.output.title.clone()), &c.output)?;
            return Ok(Report {
                series: panels,
                field: Some(report),
            });
        }
    };
    chart.title = c.output.title.clone();
    if chart.series.iter().all(|s| s.points.is_empty()) {
        return Err(WeftError::input("nothing to plot: every series is empty").into());
    }
    let series = chart.series.len();
    save(&Drawing::Chart(chart), &c.output)?;
    Ok(Report {
        series,
        field: None,
    })
}
