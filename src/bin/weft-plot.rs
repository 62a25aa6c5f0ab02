//! `weft-plot`: figures from weft tables, as PNG or SVG (by the output's extension), with
//! a bundled font (DejaVu Sans) so that no system font package is needed. The figures
//! are [`weft::plot`]'s; this parses the flags and prints the summary.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use weft::plot;

#[derive(Parser)]
#[command(
    name = "weft-plot",
    version,
    about = "Figures from weft tables (PNG or SVG, chosen by the output's extension)",
    long_about = "Figures a paper needs, from the tables the stages write: displacement time laws of chosen nodes \
                  for several models side by side (the paper's Figs. 3, 10, 11), wave speeds along a line \
                  (weft-wavespeed), the per-node error along a node set (weft-error) and a fit's convergence \
                  (weft-fit), a woven patch's section, and colour maps of a nodal quantity over the mesh (the paper's \
                  Fig. 4), several models side by side on one colour scale. The output's extension picks the format: .png (raster, --width × --height pixels) or \
                  .svg. The font is bundled (DejaVu Sans); nothing is needed from the system.\n\nExamples:\n  \
                  weft-plot history --model g --history go/history.parquet --label girder \\\n    \
                  --model m --history mo/history.parquet --label membrane \\\n    \
                  --nodes 121,61 --component ux --out fig3.png\n  \
                  weft-plot fit --trace runs/fit/fit_trace.parquet --out convergence.svg\n  \
                  weft-plot field --model runs/patch --history runs/impact/history.parquet --component uz \\\n    \
                  --time 1e-5 --deformed --out uz.png"
)]
struct Cli {
    #[command(subcommand)]
    figure: Figure,
}

#[derive(Subcommand)]
enum Figure {
    /// Displacement (or velocity) time laws of chosen nodes, one line style per model.
    #[command(
        after_help = "Example:\n  weft-plot history --model runs/rod --history runs/rod-out/history.parquet \\\n    --set free_end --component vx --out vx.png"
    )]
    History(HistoryArgs),
    /// Wave speed against position along the line, one series per table.
    #[command(
        after_help = "Example:\n  weft-plot wavespeed --table runs/speeds.parquet --label rod --out speeds.png"
    )]
    Wavespeed(WavespeedArgs),
    /// Per-node peak relative error along the compared node set (error.parquet).
    #[command(
        after_help = "Example:\n  weft-plot error --table runs/err/error.parquet --label membrane --out error.png"
    )]
    Error(ErrorArgs),
    /// Best T against evaluations (fit_trace.parquet), one series per trace.
    #[command(
        after_help = "Example:\n  weft-plot fit --trace runs/fit/fit_trace.parquet --label static --out fit.png"
    )]
    Fit(FitArgs),
    /// Test MSE of a network search against the hidden neurons, per activation
    /// (weft-surrogate's search.parquet; the paper's Fig. 6b).
    #[command(
        after_help = "Example:\n  weft-plot surrogate --search runs/net/search.parquet --surrogate runs/net/surrogate.json \\\n    --out search.png"
    )]
    Surrogate(SurrogateArgs),
    /// A ballistic limit (weft-ballistic's tables): residual against striking velocity
    /// with the Lambert–Jonas fits, energy absorbed, probability of perforation, or the
    /// limit against layers.
    #[command(
        after_help = "Example:\n  weft-plot ballistic --runs runs/limit/ballistic_runs.parquet \\\n    --limit runs/limit/ballistic_limit.parquet --kind residual --out residual.png"
    )]
    Ballistic(BallisticArgs),
    /// Section of a woven patch along y = y₀: the yarn along x (centre line and ± t/2
    /// envelope) and the sections of the yarns across it; reference dashed and formed
    /// solid for a model from weft-form.
    #[command(
        after_help = "Example:\n  weft-plot weave --model runs/woven-formed --y 0 --out weave.png"
    )]
    Weave(WeaveArgs),
    /// A deformable bullet's length and diameter (the mushroom) against time, from the
    /// history of its node set `bullet` (weft-weave woven --projectile deformable), one
    /// pair of lines per run.
    #[command(
        after_help = "Example:\n  weft-plot bullet --model runs/lead --history runs/lead-out/history.parquet --label lead \\\n    --out bullet.png"
    )]
    Bullet(BulletArgs),
    /// The backing clay's crater from bfs.parquet (weft-simulate of a pack on the clay,
    /// weft-weave woven --backing clay): its depth on the shot's axis against time, or its
    /// profile (the clay's surface height against the distance from the axis) at chosen
    /// times; one series per run (and time), with the back-face signature's limit.
    #[command(
        after_help = "Examples:\n  weft-plot crater --bfs runs/pack-out/bfs.parquet --kind depth --limit 0.044 --out bfs.png\n  weft-plot crater --bfs runs/pack-out/bfs.parquet --kind profile --time 2e-4 --time 4e-4 \\\n    --max-radius 0.06 --out crater.png"
    )]
    Crater(CraterArgs),
    /// The armour test (armour_test.parquet of weft-ballistic armour-test): each shot's
    /// back-face signature against its pack's areal density, per level, the perforated
    /// shots apart, and the standard's 44 mm limit.
    #[command(after_help = "Example:
  weft-plot armour --table runs/armour_test/verdict/armour_test.parquet --out bfs.png")]
    Armour(ArmourArgs),
    /// Colour map of a nodal quantity (uz, |u|, vx, ...) over the mesh at one output
    /// time, on the initial or deformed mesh, with a colour bar; several models side by
    /// side on one colour scale (the paper's Fig. 4).
    #[command(
        long_about = "Colour map of a nodal quantity over the mesh at one output time (the paper's Fig. 4: \
        z-displacement of the whole patch). Membrane faces are filled, trusses, links and beams drawn as \
        coloured lines, point masses as dots; each face is divided 3 × 3 with the nodal values interpolated. \
        Seen along the view axis (top view xy by default), the near layer hides the far one. The history must \
        hold the nodes to colour: a run with --history-set writes only that set (nodes without a value are grey). \
        Repeat --model/--history for panels side by side: one colour scale and one length scale for all.\n\n\
        Example (girder and its fitted membrane, shear wave at 0.5 ms):\n  \
        weft-plot field --model runs/girder --history runs/girder-out/history.parquet --label girder \\\n    \
        --model runs/membrane --history runs/membrane-out/history.parquet --label membrane \\\n    \
        --component uy --time 5e-4 --out field.png"
    )]
    Field(FieldArgs),
}

#[derive(Args)]
struct BulletArgs {
    /// Model folder (repeat, one per run).
    #[arg(long, required = true)]
    model: Vec<PathBuf>,
    /// Its history.parquet (repeat, in the same order).
    #[arg(long, required = true)]
    history: Vec<PathBuf>,
    /// Legend label of each run (default: the folder name).
    #[arg(long)]
    label: Vec<String>,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct ArmourArgs {
    /// armour_test.parquet (weft-ballistic armour-test).
    #[arg(long)]
    table: PathBuf,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct CraterArgs {
    /// bfs.parquet of a run (repeat).
    #[arg(long, required = true)]
    bfs: Vec<PathBuf>,
    /// Legend label of each run (default: its folder's name).
    #[arg(long)]
    label: Vec<String>,
    /// depth (on the axis, against time) or profile (at --time).
    #[arg(long, value_enum, default_value = "depth")]
    kind: plot::crater::CraterKind,
    /// profile: the output time [s] to draw (repeat; the nearest sample of each run)
    /// [default: each run's last].
    #[arg(long)]
    time: Vec<f64>,
    /// A limit on the depth [m] drawn as a line (NIJ Standard-0101.06's back-face
    /// signature: 0.044).
    #[arg(long)]
    limit: Option<f64>,
    /// profile: only points that started within this distance of the axis [m].
    #[arg(long)]
    max_radius: Option<f64>,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct FieldArgs {
    /// Model folder (repeat, one per panel).
    #[arg(long, required = true)]
    model: Vec<PathBuf>,
    /// Its history.parquet (repeat, in the same order).
    #[arg(long, required = true)]
    history: Vec<PathBuf>,
    /// Panel title of each model (default: the folder name).
    #[arg(long)]
    label: Vec<String>,
    /// Quantity: ux, uy, uz, vx, vy, vz, or u, v (magnitudes).
    #[arg(long, default_value = "uz")]
    component: String,
    /// Output time [s]; the nearest sample of each history is drawn (its time is in the
    /// panel title).
    #[arg(long)]
    time: f64,
    /// Draw on the deformed mesh (initial positions + scale × displacement) instead of
    /// the initial one.
    #[arg(long)]
    deformed: bool,
    /// Displacement magnification on the deformed mesh.
    #[arg(long, default_value_t = 1.0, requires = "deformed")]
    scale: f64,
    /// Projection: xy (seen from +z), xz (seen from -y) or yz (seen from +x).
    #[arg(long, default_value = "xy")]
    view: String,
    /// Colour range MIN:MAX in the quantity's SI unit (default: the values' range over
    /// all panels).
    #[arg(long, value_parser = parse_range, allow_hyphen_values = true)]
    range: Option<(f64, f64)>,
    #[command(flatten)]
    common: Common,
}

fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("`{s}`: expected MIN:MAX, e.g. -2e-3:0"))?;
    let num = |x: &str| {
        x.trim()
            .parse::<f64>()
            .map_err(|_| format!("`{x}` in `{s}` is not a number"))
    };
    Ok((num(a)?, num(b)?))
}

#[derive(Args)]
struct WeaveArgs {
    /// Model folder (weft-weave woven or weft-form).
    #[arg(long)]
    model: PathBuf,
    /// The section's y [m] (a warp centre line: a multiple of the spacing).
    #[arg(long, default_value_t = 0.0)]
    y: f64,
    /// Part of the yarn along x.
    #[arg(long, default_value = "warp_1")]
    along_part: String,
    /// Part of the yarns across the section.
    #[arg(long, default_value = "weft_1")]
    across_part: String,
    /// Only x ≤ this [m].
    #[arg(long)]
    x_max: Option<f64>,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct Common {
    /// Output file: .png or .svg.
    #[arg(long)]
    out: PathBuf,
    /// Figure title (default: none).
    #[arg(long)]
    title: Option<String>,
    /// Width [px].
    #[arg(long, default_value_t = 1000)]
    width: u32,
    /// Height [px].
    #[arg(long, default_value_t = 650)]
    height: u32,
}

#[derive(Args)]
struct HistoryArgs {
    /// Model folder (repeat, one per model).
    #[arg(long, required = true)]
    model: Vec<PathBuf>,
    /// Its history.parquet (repeat, in the same order).
    #[arg(long, required = true)]
    history: Vec<PathBuf>,
    /// Legend name of each model (default: the folder name).
    #[arg(long)]
    label: Vec<String>,
    /// Node ids, comma-separated (matched by position in the other models).
    #[arg(long, conflicts_with = "set")]
    nodes: Option<String>,
    /// A node set of the first model (at most 8 nodes) instead of --nodes.
    #[arg(long)]
    set: Option<String>,
    /// Component: ux, uy, uz, vx, vy, vz.
    #[arg(long, default_value = "uz")]
    component: String,
    /// Position matching tolerance across models [m].
    #[arg(long, default_value_t = 1e-9)]
    tolerance: f64,
    /// Read the other models at the nodes' positions through their elements' shape
    /// functions (a membrane beyond a tied interface, a coarser mesh); --tolerance then
    /// bounds a position's distance from the element.
    #[arg(long)]
    interpolate: bool,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct WavespeedArgs {
    /// wavespeeds.parquet (repeat).
    #[arg(long, required = true)]
    table: Vec<PathBuf>,
    #[arg(long)]
    label: Vec<String>,
    /// Plot segment speeds instead of node speeds.
    #[arg(long)]
    segments: bool,
    /// A closed-form speed to draw as a dashed line, `LABEL=SPEED` in m/s (signed like
    /// the table's speeds; repeat), e.g. `--expected 'lattice √(E/ρ(2 − b/a))=-3181'`.
    #[arg(long, value_parser = parse_expected)]
    expected: Vec<(String, f64)>,
    #[command(flatten)]
    common: Common,
}

fn parse_expected(s: &str) -> Result<(String, f64), String> {
    let (l, v) = s
        .rsplit_once('=')
        .ok_or_else(|| format!("`{s}`: expected LABEL=SPEED, e.g. 'closed form=-3181'"))?;
    let v: f64 = v
        .trim()
        .parse()
        .map_err(|_| format!("`{v}` in `{s}` is not a number (a speed in m/s)"))?;
    if !v.is_finite() {
        return Err(format!("`{s}`: the speed must be finite"));
    }
    Ok((l.trim().to_string(), v))
}

#[derive(Args)]
struct ErrorArgs {
    /// error.parquet (repeat).
    #[arg(long, required = true)]
    table: Vec<PathBuf>,
    #[arg(long)]
    label: Vec<String>,
    /// Abscissa: `distance` along the set's order, or the `x` or `y` coordinate.
    #[arg(long, default_value = "distance")]
    along: String,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct FitArgs {
    /// fit_trace.parquet (repeat).
    #[arg(long, required = true)]
    trace: Vec<PathBuf>,
    #[arg(long)]
    label: Vec<String>,
    /// Also plot every evaluation's T as points.
    #[arg(long)]
    all: bool,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct BallisticArgs {
    /// ballistic_runs.parquet from weft-ballistic.
    #[arg(long)]
    runs: PathBuf,
    /// ballistic_limit.parquet from weft-ballistic.
    #[arg(long)]
    limit: PathBuf,
    /// Which figure: residual, energy, probability or limit.
    #[arg(long, value_enum)]
    kind: plot::ballistic::BallisticKind,
    /// The grouping column of the tables (weft-ballistic --by).
    #[arg(long, default_value = "layers")]
    by: String,
    /// `limit`: the abscissa is the grouping value times this factor (e.g. 0.1946, the
    /// areal density of one layer in kg/m²) ...
    #[arg(long, default_value_t = 1.0)]
    x_factor: f64,
    /// ... under this label (e.g. 'areal density [kg/m²]').
    #[arg(long)]
    x_label: Option<String>,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct SurrogateArgs {
    /// search.parquet from weft-surrogate train.
    #[arg(long)]
    search: PathBuf,
    /// Its surrogate.json: draws the regression's test MSE as a dashed line.
    #[arg(long)]
    surrogate: Option<PathBuf>,
    /// A point to mark, `LABEL=N1:MSE` (repeat), e.g. `--mark 'paper, 11 tansig=11:0.0333'`.
    #[arg(long, value_parser = parse_mark)]
    mark: Vec<(String, f64, f64)>,
    #[command(flatten)]
    common: Common,
}

fn parse_mark(s: &str) -> Result<(String, f64, f64), String> {
    let bad = || format!("`{s}`: expected LABEL=N1:MSE, e.g. 'paper=11:0.0333'");
    let (l, v) = s.rsplit_once('=').ok_or_else(bad)?;
    let (a, b) = v.split_once(':').ok_or_else(bad)?;
    let (a, b): (f64, f64) = (
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    );
    if !(a.is_finite() && b.is_finite() && b > 0.0) {
        return Err(bad());
    }
    Ok((l.trim().to_string(), a, b))
}

fn main() -> ExitCode {
    weft::cli::main(|| run().map(|()| ExitCode::SUCCESS))
}

fn output(c: Common) -> plot::Output {
    plot::Output {
        out: c.out,
        title: c.title,
        width: c.width,
        height: c.height,
    }
}

fn run() -> anyhow::Result<()> {
    let cli: Cli = weft::cli::parse();
    let (figure, common) = match cli.figure {
        Figure::History(a) => (
            plot::Figure::History(plot::HistoryFigure {
                model: a.model,
                history: a.history,
                label: a.label,
                nodes: a.nodes,
                set: a.set,
                component: a.component,
                tolerance: a.tolerance,
                interpolate: a.interpolate,
            }),
            a.common,
        ),
        Figure::Wavespeed(a) => (
            plot::Figure::Wavespeed(plot::WavespeedFigure {
                table: a.table,
                label: a.label,
                segments: a.segments,
                expected: a.expected,
            }),
            a.common,
        ),
        Figure::Error(a) => (
            plot::Figure::Error(plot::ErrorFigure {
                table: a.table,
                label: a.label,
                along: a.along,
            }),
            a.common,
        ),
        Figure::Weave(a) => (
            plot::Figure::Weave(plot::WeaveFigure {
                model: a.model,
                y: a.y,
                along_part: a.along_part,
                across_part: a.across_part,
                x_max: a.x_max,
            }),
            a.common,
        ),
        Figure::Field(a) => (
            plot::Figure::Field(plot::field::FieldFigure {
                model: a.model,
                history: a.history,
                label: a.label,
                component: a.component,
                time: a.time,
                deformed: a.deformed,
                scale: a.scale,
                view: a.view,
                range: a.range,
            }),
            a.common,
        ),
        Figure::Surrogate(a) => (
            plot::Figure::Surrogate(plot::SurrogateFigure {
                search: a.search,
                mark: a.mark,
                regression: match &a.surrogate {
                    Some(p) => Some(weft::surrogate::Surrogate::read(p)?.regression_test_mse),
                    None => None,
                },
            }),
            a.common,
        ),
        Figure::Ballistic(a) => (
            plot::Figure::Ballistic(plot::ballistic::BallisticFigure {
                runs: a.runs,
                limit: a.limit,
                by: a.by,
                kind: a.kind,
                x_factor: a.x_factor,
                x_label: a.x_label,
            }),
            a.common,
        ),
        Figure::Bullet(a) => (
            plot::Figure::Bullet(plot::bullet::BulletFigure {
                model: a.model,
                history: a.history,
                label: a.label,
            }),
            a.common,
        ),
        Figure::Crater(a) => (
            plot::Figure::Crater(plot::crater::CraterFigure {
                bfs: a.bfs,
                label: a.label,
                kind: a.kind,
                times: a.time,
                limit: a.limit,
                max_radius: a.max_radius,
            }),
            a.common,
        ),
        Figure::Armour(a) => (
            plot::Figure::Armour(plot::armour::ArmourFigure { table: a.table }),
            a.common,
        ),
        Figure::Fit(a) => (
            plot::Figure::Fit(plot::FitFigure {
                trace: a.trace,
                label: a.label,
                all: a.all,
            }),
            a.common,
        ),
    };
    let c = plot::Config {
        figure,
        output: output(common),
    };
    let r = plot::run(&c)?;
    if let Some(f) = &r.field {
        let times: Vec<String> = f.times.iter().map(|t| format!("{t:e}")).collect();
        eprintln!(
            "weft-plot: t = [{}] s, colour range {:e} .. {:e}",
            times.join(", "),
            f.range.0,
            f.range.1
        );
        for (k, m) in f.missing_nodes.iter().enumerate().filter(|p| *p.1 > 0) {
            eprintln!(
                "weft-plot: panel {}: {m} nodes have no value in the history (grey)",
                k + 1
            );
        }
    }
    eprintln!(
        "weft-plot: {} series -> {}",
        r.series,
        c.output.out.display()
    );
    Ok(())
}
