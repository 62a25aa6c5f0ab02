//! `weft-ballistic`: ballistic limits from impact runs (`fit`), or by running the impacts
//! (`search`), the failed zone of impact runs (`zone`), the backing clay's drop
//! calibration (`clay-calibration`), and the armour test's verdicts on shots on the clay
//! (`nij`, `armour-test`).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use weft::ballistic::lambert_jonas::Bounds;
use weft::ballistic::limit::{self, Options};
use weft::ballistic::probability::Link;
use weft::ballistic::runs::{GroupBy, GroupType};
use weft::ballistic::{clay, runs, search, zone};
use weft::table::Provenance;

#[derive(Parser)]
#[command(
    name = "weft-ballistic",
    version,
    about = "Ballistic limits (V50, the Lambert–Jonas fit) from impact runs, or by running them; the failed zone of impact runs; the backing clay's drop calibration; the armour test's verdict on shots on the clay, one level or many packs",
    long_about = "The ballistic limit of a fabric from impacts at several striking velocities \
                  (docs/theory.md, \"Failure, perforation and the ballistic limit\").\n\n\
                  `fit` gathers impact runs (the weft-simulate output folders, or one table that \
                  `weft gather --table summary.parquet` made of them), groups them (by `layers`), \
                  and fits per group the Lambert–Jonas law V_r = a(V_s^p − V_bl^p)^(1/p) with \
                  bootstrap intervals and the probability of perforation (V50, V10, V90; a \
                  bracket when the outcomes are separated).\n\n`search` runs the impacts of one \
                  model itself, in parallel, narrowing the bracket of the limit to a tolerance.\n\n\
                  Both write ballistic_runs.parquet (one row per impact, with what it cost: \
                  steps, elements, wall time) and ballistic_limit.parquet (one row per group, \
                  with what its impacts cost) into --out (docs/tables.md).\n\n\
                  `zone` measures where the elements of impact runs failed: the failed zone's \
                  radius and diameter per run and layer (failure_zone.parquet).\n\n\
                  `clay-calibration` runs the armour test's clay drop (weft-weave clay-drop) \
                  and judges its indentation against NIJ Standard-0101.06's band \
                  (clay_calibration.parquet).\n\n\
                  `nij` judges shots of a pack on the clay as the standard does: no \
                  perforation and a back-face signature of at most 44 mm at the level's \
                  velocity (nij.parquet). `armour-test` judges many packs' shots at once, each \
                  at the level of its velocity (armour_test.parquet).\n\n\
                  Example:\n  weft-ballistic fit --runs runs/v300 runs/v350 runs/v400 --out runs/limit\n  \
                  weft-ballistic search --model runs/patch --lo 50 --hi 400 --tolerance 5 --out runs/search\n  \
                  weft-ballistic zone --run runs/v400 --model runs/patch --out runs/zone\n  \
                  weft-ballistic clay-calibration --model runs/drop --out runs/clay\n  \
                  weft-ballistic nij --run runs/pack-398 --level II --out runs/verdict\n  \
                  weft-ballistic armour-test --run runs/armour_test/shots --out runs/armour_test/verdict"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Fit the ballistic limit of impact runs (one limit per group).
    #[command(
        after_help = "Example:\n  weft-ballistic fit --runs runs/v60 runs/v80 runs/v100 runs/v120 --out runs/limit"
    )]
    Fit(FitArgs),
    /// Run impacts of one model, bracketing its limit to a tolerance, then fit it.
    #[command(
        after_help = "Example:\n  weft-weave woven --yarns 10 --layers 2 --failure-strain 0.036 --out runs/two\n  weft-ballistic search --model runs/two --lo 40 --hi 200 --tolerance 5 --out runs/two-limit"
    )]
    Search(SearchArgs),
    /// The failed zone of impact runs: how far from the projectile's axis elements failed.
    #[command(
        long_about = "The failed zone of impact runs: for each element that failed and left the \
                      model (failures.parquet, `eroded`), its centroid in the model's initial \
                      configuration and its distance r from the projectile's axis (the line \
                      through the projectile's initial position along its initial velocity). \
                      Per run and layer, failure_zone.parquet: the failed elements, the largest r \
                      (radius_max), its 90th percentile (radius_p90, nearest rank), the first and \
                      last failure times, and the diameter.\n\n\
                      The diameter is 2 × radius_max: the failed zone's diameter on the full \
                      fabric (a quarter model's zone is symmetric about the axis). A patch should \
                      be at least twice as large as the zone where yarns fail: compare the \
                      patch's width with 2 × diameter.",
        after_help = "Example:\n  weft-weave woven --yarns 10 --failure-strain 0.036 --stop-on-outcome --out runs/patch\n  weft-simulate --model runs/patch --projectile-velocity 400 --out runs/v400\n  weft-ballistic zone --run runs/v400 --model runs/patch --out runs/zone"
    )]
    Zone(ZoneArgs),
    /// The backing clay's drop calibration: runs drop models (weft-weave clay-drop) and
    /// says whether each indentation lies in NIJ Standard-0101.06's band (19 ± 3 mm).
    #[command(
        long_about = "The backing clay's drop calibration (NIJ Standard-0101.06): each model of \
                      `weft-weave clay-drop` (the standard's steel sphere, 63.5 mm and 1043 g, \
                      striking at the speed of a 2.0 m drop) is run to its end time, past the \
                      sphere's rebound; the indentation is the crater's depth on the axis then, \
                      as the standard measures it, and lies in the band when it is 19 ± 3 mm \
                      (docs/theory.md, \"The backing clay\").\n\n\
                      Writes clay_calibration.parquet (one row per model: the indentation, the \
                      band, the clay's constants, the run's cost and balance) and clay_drop.parquet \
                      (the crater's and the sphere's depth against time) into --out \
                      (docs/tables.md). Exits with 1 when an indentation lies outside the band.",
        after_help = "Example:\n  weft-weave clay-drop --out runs/drop\n  weft-ballistic clay-calibration --model runs/drop --out runs/clay"
    )]
    ClayCalibration(ClayArgs),
    /// The armour test's verdict (NIJ Standard-0101.06) on shots of packs on the clay:
    /// no perforation and a back-face signature ≤ 44 mm, at the level's velocity.
    #[command(
        long_about = "The armour test's verdict (NIJ Standard-0101.06) on shots of a pack on the clay \
                      (weft-simulate of weft-weave woven --backing clay): a shot at the level's \
                      velocity (9 mm FMJ RN: IIA 373 m/s, II 398 m/s, ± 9.1 m/s) passes when the \
                      bullet is arrested without perforating the pack and the back-face signature \
                      (the summary's bfs, the crater's depth in the clay) is at most 44 mm; the \
                      margin is 44 mm − BFS. A run that stopped, a shot outside the level's \
                      velocities or one whose bullet was not yet arrested at the run's end (the \
                      crater may still deepen) gets no verdict, with the reason.\n\n\
                      Writes nij.parquet (one row per run) into --out (docs/tables.md). Exits with \
                      1 unless every shot passes.",
        after_help = "Example:\n  weft-weave woven --layers 24 --backing clay --projectile-velocity 398 --out runs/pack\n  weft-simulate --model runs/pack --out runs/pack-398 --end-time 1e-3\n  weft-ballistic nij --run runs/pack-398 --level II --out runs/verdict"
    )]
    Nij(NijArgs),
    /// The armour test over packs and velocities: each shot judged at the level of its
    /// velocity, one table of plies, areal density, outcome, BFS and verdict.
    #[command(
        long_about = "The armour test over packs and velocities (pipelines/armour_test.toml): each \
                      shot of a pack on the clay (weft-simulate of weft-weave woven --backing clay) \
                      is judged as `nij` judges it, at the level whose velocity band its striking \
                      velocity lies in (IIA 373, II 398 ± 9.1 m/s; no verdict in neither). Prints \
                      per level the lightest pack that passes.\n\n\
                      Writes armour_test.parquet (one row per run: plies, areal_density, velocity, \
                      level, outcome, perforated, plies_perforated, bfs, bfs_margin, pass, reason) \
                      into --out (docs/tables.md).",
        after_help = "Example:\n  weft-ballistic armour-test --run runs/armour/shots/*/* --out runs/armour/verdict"
    )]
    ArmourTest(ArmourArgs),
}

#[derive(clap::Args)]
struct ArmourArgs {
    /// Shots' run folders (weft-simulate --out, their summary.parquet), or folders
    /// holding them (searched two levels down, as a pipeline's `shots/<plies>/<velocity>`).
    #[arg(long, required = true, num_args = 1..)]
    run: Vec<PathBuf>,
    /// Output folder for armour_test.parquet.
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct NijArgs {
    /// A shot's run folder (weft-simulate --out, its summary.parquet); repeat it for
    /// several.
    #[arg(long, required = true, num_args = 1..)]
    run: Vec<PathBuf>,
    /// The protection level: IIA (373 m/s) or II (398 m/s).
    #[arg(long, value_enum)]
    level: weft::ballistic::nij::Level,
    /// Output folder for nij.parquet.
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct ClayArgs {
    /// A drop model folder (weft-weave clay-drop); repeat it for several.
    #[arg(long, required = true, num_args = 1..)]
    model: Vec<PathBuf>,
    /// Worker threads [default: all cores]. Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Output folder for clay_calibration.parquet and clay_drop.parquet.
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct ZoneArgs {
    /// An impact run folder (weft-simulate --out) with its failures.parquet; repeat it for
    /// several runs of the one model.
    #[arg(long, required = true)]
    run: Vec<PathBuf>,
    /// The model folder the runs used (its nodes, elements and projectile).
    #[arg(long)]
    model: PathBuf,
    /// Output folder for failure_zone.parquet.
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct FitArgs {
    /// Impact run folders (weft-simulate --out), each with its summary.parquet.
    #[arg(long, num_args = 1.., required_unless_present = "table")]
    runs: Vec<PathBuf>,
    /// A table of run summaries instead (weft gather --table summary.parquet), one row
    /// per impact.
    #[arg(long, conflicts_with = "runs")]
    table: Option<PathBuf>,
    /// The column that tells the groups apart (one limit per group).
    #[arg(long, default_value = "layers")]
    by: String,
    /// Leave out the runs the solver stopped (`status = stopped` in their summary: NaN,
    /// instability, an energy error), each named on stderr. Without it such a run is
    /// refused: its outcome is not one to fit.
    #[arg(long)]
    skip_stopped: bool,
    #[command(flatten)]
    fit: FitOptions,
    /// Output folder for ballistic_runs.parquet and ballistic_limit.parquet.
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct FitOptions {
    /// The probability of perforation's link: logit or probit.
    #[arg(long, value_enum, default_value = "logit")]
    link: LinkArg,
    /// Bootstrap replicates of the Lambert–Jonas intervals.
    #[arg(long, default_value_t = Options::default().replicates)]
    bootstrap: usize,
    /// Seed of the bootstrap.
    #[arg(long, default_value_t = Options::default().seed)]
    seed: u64,
    /// Bounds of the Lambert–Jonas a [default: 0.1–2].
    #[arg(long, num_args = 2, value_names = ["LO", "HI"])]
    a_bounds: Option<Vec<f64>>,
    /// Bounds of the Lambert–Jonas p [default: 1.1–5].
    #[arg(long, num_args = 2, value_names = ["LO", "HI"])]
    p_bounds: Option<Vec<f64>>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum LinkArg {
    Logit,
    Probit,
}

#[derive(clap::Args)]
struct SearchArgs {
    /// The model folder (weft-weave woven with a failure strain): its projectile's speed is
    /// set for each impact, and each runs to its outcome.
    #[arg(long)]
    model: PathBuf,
    /// The first bracket [m/s]: the slower end should stop, the faster perforate.
    #[arg(long)]
    lo: f64,
    #[arg(long)]
    hi: f64,
    /// Stop once the bracket is at most this wide [m/s].
    #[arg(long, default_value_t = 5.0)]
    tolerance: f64,
    /// Impacts per round, run in parallel [default: the threads].
    #[arg(long)]
    per_round: Option<usize>,
    /// At most this many rounds.
    #[arg(long, default_value_t = 12)]
    max_rounds: usize,
    /// An impact still undecided at the model's end time (near the limit a nose can drag
    /// through the broken yarns for long) is run again with twice the end time, at most
    /// this many times.
    #[arg(long, default_value_t = 2)]
    extensions: usize,
    /// Worker threads [default: all cores]. Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    #[command(flatten)]
    fit: FitOptions,
    /// Output folder for ballistic_runs.parquet and ballistic_limit.parquet.
    #[arg(long)]
    out: PathBuf,
}

impl FitOptions {
    fn options(&self) -> anyhow::Result<Options> {
        let d = Options::default();
        let pair =
            |v: &Option<Vec<f64>>, dflt: (f64, f64), name: &str| -> anyhow::Result<(f64, f64)> {
                match v {
                    None => Ok(dflt),
                    Some(v) if v[0] > 0.0 && v[1] > v[0] && v[1].is_finite() => Ok((v[0], v[1])),
                    Some(v) => Err(weft::WeftError::input(format!(
                        "--{name}-bounds {} {}",
                        v[0], v[1]
                    ))
                    .expected("0 < LO < HI")
                    .into()),
                }
            };
        Ok(Options {
            bounds: Bounds {
                a: pair(&self.a_bounds, d.bounds.a, "a")?,
                p: pair(&self.p_bounds, d.bounds.p, "p")?,
            },
            link: match self.link {
                LinkArg::Logit => Link::Logit,
                LinkArg::Probit => Link::Probit,
            },
            replicates: self.bootstrap,
            seed: self.seed,
        })
    }
}

fn main() -> ExitCode {
    weft::cli::main(run_cli)
}

fn run_cli() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    match cli.command {
        Command::Fit(a) => fit(a),
        Command::Search(a) => search_cmd(a),
        Command::Zone(a) => zone_cmd(a),
        Command::ClayCalibration(a) => clay_cmd(a),
        Command::Nij(a) => nij_cmd(a),
        Command::ArmourTest(a) => armour_cmd(a),
    }
}

/// The run folders under `p`: itself when it holds a summary, else its sub-folders'
/// (two levels down), sorted.
fn shot_folders(p: &std::path::Path, depth: u32) -> anyhow::Result<Vec<PathBuf>> {
    if p.join("summary.parquet").is_file() {
        return Ok(vec![p.to_path_buf()]);
    }
    if depth == 0 || !p.is_dir() {
        return Ok(vec![]);
    }
    let mut subs: Vec<PathBuf> = std::fs::read_dir(p)
        .map_err(|e| weft::WeftError::io(p, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|q| q.is_dir())
        .collect();
    subs.sort();
    let mut out = vec![];
    for q in subs {
        out.extend(shot_folders(&q, depth - 1)?);
    }
    Ok(out)
}

fn armour_cmd(a: ArmourArgs) -> anyhow::Result<ExitCode> {
    use weft::ballistic::nij;
    let mut runs = vec![];
    for r in &a.run {
        let found = shot_folders(r, 2)?;
        if found.is_empty() {
            return Err(weft::WeftError::input(format!(
                "--run {}: no summary.parquet in it or in its sub-folders",
                r.display()
            ))
            .expected("a weft-simulate run folder of a shot on the clay, or a folder of them")
            .into());
        }
        runs.extend(found);
    }
    let mut prov = Provenance::new("ballistic", serde_json::json!({ "runs": runs }));
    let mut vs = vec![];
    for run in &runs {
        prov = prov.with_input(&run.join("summary.parquet"))?;
        vs.push(nij::judge(run, None)?);
    }
    vs.sort_by(|p, q| {
        p.plies
            .cmp(&q.plies)
            .then(p.striking_velocity.total_cmp(&q.striking_velocity))
    });
    for v in &vs {
        eprintln!(
            "{:>3} plies at {:.0} m/s ({}): {}, {} plies perforated, BFS {:.1} mm: {}",
            v.plies,
            v.striking_velocity,
            v.level.map_or("no level", |l| l.name()),
            v.outcome,
            v.plies_perforated.map_or("?".into(), |n| n.to_string()),
            1e3 * v.bfs,
            v.said()
        );
    }
    for level in [nij::Level::IIA, nij::Level::II] {
        let lightest = vs
            .iter()
            .filter(|v| v.level == Some(level) && v.pass == Some(true))
            .min_by_key(|v| v.plies);
        match lightest {
            Some(v) => eprintln!(
                "  level {}: the lightest pack that passes has {} plies ({})",
                level.name(),
                v.plies,
                v.areal_density
                    .map_or("areal density unknown".into(), |d| format!("{d:.2} kg/m²"))
            ),
            None => eprintln!("  level {}: no pack passes", level.name()),
        }
    }
    std::fs::create_dir_all(&a.out).map_err(|e| weft::WeftError::io(&a.out, e))?;
    nij::write_armour_test(&a.out.join("armour_test.parquet"), &vs, &prov)?;
    eprintln!("  wrote {}/armour_test.parquet", a.out.display());
    Ok(ExitCode::SUCCESS)
}

fn nij_cmd(a: NijArgs) -> anyhow::Result<ExitCode> {
    use weft::ballistic::nij;
    let mut prov = Provenance::new(
        "ballistic",
        serde_json::json!({ "runs": a.run, "level": a.level.name() }),
    );
    let mut verdicts = vec![];
    for run in &a.run {
        prov = prov.with_input(&run.join("summary.parquet"))?;
        let v = nij::judge(run, Some(a.level))?;
        eprintln!(
            "{}: {:.1} m/s, {}, BFS {:.1} mm (margin {:+.1} mm): {}",
            run.display(),
            v.striking_velocity,
            v.outcome,
            1e3 * v.bfs,
            1e3 * v.bfs_margin,
            v.said()
        );
        verdicts.push(v);
    }
    std::fs::create_dir_all(&a.out).map_err(|e| weft::WeftError::io(&a.out, e))?;
    nij::write(&a.out.join("nij.parquet"), a.level, &verdicts, &prov)?;
    eprintln!("  wrote {}/nij.parquet", a.out.display());
    Ok(if verdicts.iter().all(|v| v.pass == Some(true)) {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn clay_cmd(a: ClayArgs) -> anyhow::Result<ExitCode> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads.unwrap_or(0))
        .build()?;
    let mut drops = Vec::new();
    let mut prov = Provenance::new("ballistic", serde_json::json!({ "models": a.model }));
    for path in &a.model {
        let m = weft::model::io::read_model(path)?;
        prov = prov.with_input(&path.join("parts.parquet"))?;
        let d = pool
            .install(|| clay::run_drop(&m))
            .map_err(|e| e.context(format!("the drop of `{}`", path.display())))?;
        let (lo, hi) = weft::generate::clay::DROP_BAND;
        eprintln!(
            "{}: indentation {:.2} mm (deepest {:.2} mm, the sphere off at {:.2} ms, {:.3} m/s up): {} the band {:.0}–{:.0} mm; balance {:.1e}, {} steps",
            path.display(),
            1e3 * d.indentation,
            1e3 * d.indentation_max,
            1e3 * d.separation_time,
            d.rebound_velocity,
            if d.indentation >= lo && d.indentation <= hi { "within" } else { "OUTSIDE" },
            1e3 * lo,
            1e3 * hi,
            d.max_balance_error_relative,
            d.steps
        );
        drops.push((path.display().to_string(), d));
    }
    std::fs::create_dir_all(&a.out).map_err(|e| weft::WeftError::io(&a.out, e))?;
    clay::write_calibration(&a.out.join("clay_calibration.parquet"), &drops, &prov)?;
    clay::write_history(&a.out.join("clay_drop.parquet"), &drops, &prov)?;
    eprintln!(
        "  wrote {}/{{clay_calibration,clay_drop}}.parquet",
        a.out.display()
    );
    let (lo, hi) = weft::generate::clay::DROP_BAND;
    let all_in = drops
        .iter()
        .all(|(_, d)| d.indentation >= lo && d.indentation <= hi);
    Ok(if all_in {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn zone_cmd(a: ZoneArgs) -> anyhow::Result<ExitCode> {
    let rows = zone::failure_zone(&a.run, &a.model)?;
    std::fs::create_dir_all(&a.out).map_err(|e| weft::WeftError::io(&a.out, e))?;
    let mut prov = Provenance::new(
        "ballistic",
        serde_json::json!({ "runs": a.run, "model": a.model }),
    );
    for r in &a.run {
        prov = prov.with_input(&r.join("failures.parquet"))?;
    }
    let path = a.out.join("failure_zone.parquet");
    zone::write_zone(&path, &rows, &prov)?;
    for r in &rows {
        let mm = |x: Option<f64>| x.map_or("–".to_string(), |x| format!("{:.2} mm", 1e3 * x));
        eprintln!(
            "{} layer {}: {} failed elements, radius {} (p90 {}), diameter {}",
            r.run,
            r.layer,
            r.failed_elements,
            mm(r.radius_max),
            mm(r.radius_p90),
            mm(r.diameter)
        );
    }
    eprintln!("  wrote {}", path.display());
    Ok(ExitCode::SUCCESS)
}

fn fit(a: FitArgs) -> anyhow::Result<ExitCode> {
    let o = a.fit.options()?;
    let all = match &a.table {
        Some(t) => runs::read_table(t, &a.by, &|row| format!("{} row {row}", t.display()))?,
        None => runs::read_folders(&a.runs, &a.by)?,
    };
    let all = runs::leave_out_stopped(all, a.skip_stopped, &mut |r| {
        eprintln!(
            "  left out {} at {} m/s: the run stopped ({})",
            r.source,
            r.striking_velocity,
            r.stopped.as_deref().unwrap_or_default()
        )
    })?;
    let groups = runs::group(all)?;
    let limits = limit::fit_groups(&groups, &a.by, &o)?;
    let params = serde_json::json!({
        "runs": a.runs, "table": a.table, "by": a.by, "skip_stopped": a.skip_stopped,
        "bootstrap": o.replicates, "seed": o.seed,
        "a_bounds": o.bounds.a, "p_bounds": o.bounds.p, "link": o.link.name(),
    });
    let by = GroupBy {
        column: &a.by,
        kind: GroupType::Inferred,
    };
    write(&a.out, &groups, &limits, by, params)?;
    Ok(ExitCode::SUCCESS)
}

fn search_cmd(a: SearchArgs) -> anyhow::Result<ExitCode> {
    let o = a.fit.options()?;
    let m = weft::model::io::read_model(&a.model)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads.unwrap_or(0))
        .build()?;
    let per_round = a.per_round.unwrap_or(pool.current_num_threads()).max(1);
    let so = search::Options {
        lo: a.lo,
        hi: a.hi,
        tolerance: a.tolerance,
        per_round,
        max_rounds: a.max_rounds,
        extensions: a.extensions,
    };
    let impacts = pool.install(|| {
        search::search(&m, &so, |round, lo, hi| {
            eprintln!("round {round}: the limit lies in ({lo:.2}, {hi:.2}) m/s")
        })
    })?;
    let group = a
        .model
        .file_name()
        .map_or("model".to_string(), |n| n.to_string_lossy().to_string());
    let mut runs: Vec<runs::Run> = impacts
        .iter()
        .map(|i| runs::Run {
            group: group.clone(),
            ..i.run.clone()
        })
        .collect();
    runs.sort_by(|a, b| a.striking_velocity.total_cmp(&b.striking_velocity));
    let groups = vec![(group, runs)];
    let limits = limit::fit_groups(&groups, "model", &o)?;
    let params = serde_json::json!({
        "model": a.model, "lo": a.lo, "hi": a.hi, "tolerance": a.tolerance,
        "per_round": per_round, "max_rounds": a.max_rounds, "extensions": a.extensions, "bootstrap": o.replicates, "seed": o.seed,
        "a_bounds": o.bounds.a, "p_bounds": o.bounds.p, "link": o.link.name(),
    });
    // The model folder's name, as text whatever it reads like, so that every search's
    // table gathers into one (`weft gather`).
    let by = GroupBy {
        column: "model",
        kind: GroupType::Text,
    };
    write(&a.out, &groups, &limits, by, params)?;
    Ok(ExitCode::SUCCESS)
}

/// The two tables into `out`, and a line per limit on stderr.
fn write(
    out: &std::path::Path,
    groups: &[(String, Vec<runs::Run>)],
    limits: &[limit::Limit],
    by: GroupBy,
    params: serde_json::Value,
) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).map_err(|e| weft::WeftError::io(out, e))?;
    let prov = Provenance::new("ballistic", params);
    limit::write_runs(
        &out.join("ballistic_runs.parquet"),
        groups,
        limits,
        by,
        &prov,
    )?;
    limit::write_limits(&out.join("ballistic_limit.parquet"), limits, by, &prov)?;
    let col = by.column;
    for l in limits {
        let p = &l.probability;
        let lj = l.lambert_jonas.map_or(
            "Lambert–Jonas: fewer than 3 perforations".to_string(),
            |f| {
                format!(
                    "V_bl {:.1} m/s ({:.1}–{:.1}), a {:.3}, p {:.2}, rms {:.2} m/s",
                    f.law.v_bl, f.v_bl_interval.0, f.v_bl_interval.1, f.law.a, f.law.p, f.rms
                )
            },
        );
        eprintln!(
            "{col} {}: {} runs, {} perforated; V50 {:.1} m/s ({:.1}–{:.1}, {}); {lj}",
            l.group, l.runs, l.perforations, p.v50, p.v50_interval.0, p.v50_interval.1, p.method
        );
    }
    eprintln!(
        "  wrote {}/{{ballistic_runs,ballistic_limit}}.parquet",
        out.display()
    );
    Ok(())
}
