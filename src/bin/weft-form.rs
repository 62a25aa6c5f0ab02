//! `weft-form`: form a yarn-level woven patch by contact equilibrium (the paper's §2).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::Parser;
use weft::cli::Progress;
use weft::form::{run, Config, Params, Report, StartMode};

#[derive(Parser)]
#[command(
    name = "weft-form",
    version,
    about = "Form a woven patch by contact equilibrium: yarns pulled with their residual tension settle by dynamic relaxation; the formed model starts an impact run at rest and in equilibrium",
    long_about = "Reads a model from `weft-weave woven`. The yarn ends held at the patch edge are let go along their \
                  yarn and pulled outwards with the residual tension (N per yarn; warp: parts named `warp…`, along x; \
                  weft: `weft…`, along y); the projectile is set aside; the weave settles by frictionless contact under \
                  dynamic relaxation with local damping (each force component loses half its size against the motion; \
                  Cundall) until the \
                  largest kinetic energy of a test window is below --kinetic-tolerance of the energy removed, the \
                  largest residual nodal force below --force-tolerance of the largest contact force, and then, left \
                  alone at rest (a free, undamped test run), no node moves more than --creep-tolerance of the yarn \
                  thickness within --creep-time (the pretensioned patch's slow drum mode settles last; \
                  --creep-tolerance 1000 turns the test off).\n\n\
                  By default (--start cell) the patch is not relaxed whole: a plain weave is mirror-symmetric about \
                  every yarn's centre line, so its periodic cell (four half yarns between two neighbouring crossings \
                  each way, symmetry planes on its four sides) is formed alone, its planes moved until the force \
                  across them is the residual tension, and reflected over the whole patch; the patch is then left \
                  alone at rest (the same free test) and relaxed further only if it moves. Forming the 60 × 60 \
                  quarter takes about 1 min this way (the cell in under a second, the rest of it the test run). \
                  --start geometry relaxes the generated geometry whole instead; --start-from starts from a formed \
                  smaller patch.\n\n\
                  A patch tied into a membrane (`weft-weave woven --membrane-length`, the paper's §3 combined model) \
                  is formed the same way as a patch alone, then its ties come back with the membrane pre-stressed \
                  (s0_11, s0_22 of its quads) and the whole model settles again, S₀ corrected until the bands carry \
                  the requested tension (30 s for the 10 × 10 in a 29.5 mm membrane).\n\n\
                  Writes the formed model (the reference geometry unchanged, the formed positions as the nodes' initial \
                  displacement ux0, uy0, uz0 in nodes.parquet, the yarn ends held where they came to rest, contacts \
                  `keep` with their friction, the projectile raised by as much as the fabric rose) and form.parquet \
                  (steps, residual force, crimp and crimp amplitude before and after, the tension measured in the bands \
                  and at the ends). Nothing is written when forming fails to converge or leaves a yarn through another.\n\n\
                  Example:\n  weft-weave woven --yarns 10 --out runs/patch\n  \
                  weft-form --model runs/patch --out runs/patch-formed --warp-tension 0.5 --weft-tension 0.5\n  \
                  weft-simulate --model runs/patch-formed --out runs/impact"
)]
struct Cli {
    /// Model folder (from `weft-weave woven`: edge clamped, or tied into a membrane).
    #[arg(long)]
    model: PathBuf,
    /// Formed model folder to write.
    #[arg(long)]
    out: PathBuf,
    /// Residual tension per warp yarn [N] (0: the weave settles stress-free).
    #[arg(long, default_value_t = Params::default().warp_tension)]
    warp_tension: f64,
    /// Residual tension per weft yarn [N].
    #[arg(long, default_value_t = Params::default().weft_tension)]
    weft_tension: f64,
    /// Step budget; forming that has not converged by then is an error.
    #[arg(long, default_value_t = Params::default().max_steps)]
    max_steps: u64,
    /// No convergence test before this many steps.
    #[arg(long, default_value_t = Params::default().min_steps)]
    min_steps: u64,
    /// Converged when the largest kinetic energy of a test window is ≤ this × the energy
    /// removed so far ...
    #[arg(long, default_value_t = Params::default().kinetic_tolerance)]
    kinetic_tolerance: f64,
    /// ... and the largest residual nodal force is ≤ this × the largest contact force.
    #[arg(long, default_value_t = Params::default().force_tolerance)]
    force_tolerance: f64,
    /// ... and then, left alone at rest (a free run), no node moves more than this × the
    /// largest yarn thickness within --creep-time.
    #[arg(long, default_value_t = Params::default().creep_tolerance)]
    creep_tolerance: f64,
    /// Length of the free rest test [s].
    #[arg(long, default_value_t = Params::default().creep_time)]
    creep_time: f64,
    /// Largest contact penetration allowed after forming, as a fraction of the contact
    /// distance of the thickest slave and face, (t_s,max + t_F,max)/2.
    #[arg(long, default_value_t = Params::default().penetration_limit)]
    penetration_limit: f64,
    /// Keep the contacts' friction while forming (default: frictionless, so that each
    /// yarn's tension is uniform and the impact run starts in equilibrium).
    #[arg(long)]
    friction: bool,
    /// Normal contact damping while forming, as a fraction of critical (≥ 0).
    #[arg(long, default_value_t = Params::default().contact_damping)]
    contact_damping: f64,
    /// Local damping α of the relaxation, 0 < α < 1.
    #[arg(long, default_value_t = Params::default().damping)]
    damping: f64,
    /// Start from a formed smaller quarter patch of the same weave (a `weft-form` output
    /// folder) instead of the generated geometry: its displacement, periodic in two
    /// spacings plus its mean stretch, is laid over this patch, its edges over this
    /// patch's edges, and the relaxation goes on from there (for patches whose forming
    /// from the generated geometry would take hours, like the 60 × 60 reference).
    #[arg(long, value_name = "FORMED_MODEL", conflicts_with = "start")]
    start_from: Option<PathBuf>,
    /// Where forming starts: `cell`, the formed periodic cell reflected over the patch
    /// (then tested at rest, relaxed only if it moves), or `geometry`, the generated
    /// geometry relaxed whole.
    #[arg(long, value_enum, default_value = "cell")]
    start: StartMode,
    /// Worker threads [default: all cores]. Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

fn main() -> ExitCode {
    weft::cli::main(run_cli)
}

fn run_cli() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    if let Some(n) = cli.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n.max(1))
            .build_global()
            .context("cannot set up the worker threads")?;
    }
    let params = cli.params();
    let progress = Progress::new(
        cli.quiet,
        params.max_steps,
        "{spinner} form [{bar:40}] {pos}/{len} steps {elapsed_precise} {msg}",
    );
    let max = params.max_steps as f64;
    let res = run(
        &Config {
            model: cli.model.clone(),
            out: cli.out.clone(),
            params,
            start_from: cli.start_from.clone(),
            start: cli.start,
        },
        &mut |s| {
            if progress.protocol() {
                progress.line(s.steps as f64 / max);
            } else {
                progress.bar().set_position(s.steps);
                let rest = if s.creep.is_finite() {
                    format!(", last rest test moved {:.2e} m", s.creep)
                } else {
                    String::new()
                };
                progress.bar().set_message(format!(
                    "K {:.2e} J, residual {:.2e} N, contact {:.2e} N{rest}",
                    s.kinetic, s.residual, s.contact_force
                ));
            }
        },
    );
    progress.finish();
    let r = res.with_context(|| {
        format!(
            "form `{}` failed; nothing was written to `{}`",
            cli.model.display(),
            cli.out.display()
        )
    })?;
    print_report(&r);
    eprintln!("  wrote {} (formed model, form.parquet)", cli.out.display());
    Ok(ExitCode::SUCCESS)
}

impl Cli {
    /// The forming parameters the flags give (the rest at their defaults).
    fn params(&self) -> Params {
        Params {
            warp_tension: self.warp_tension,
            weft_tension: self.weft_tension,
            max_steps: self.max_steps,
            min_steps: self.min_steps,
            kinetic_tolerance: self.kinetic_tolerance,
            force_tolerance: self.force_tolerance,
            penetration_limit: self.penetration_limit,
            friction: self.friction,
            damping: self.damping,
            contact_damping: self.contact_damping,
            creep_tolerance: self.creep_tolerance,
            creep_time: self.creep_time,
            ..Params::default()
        }
    }
}

/// What forming did, on stderr.
fn print_report(r: &Report) {
    eprintln!(
        "weft-form: equilibrium after {} steps of {:.3e} s (local damping): kinetic energy {:.2e} of the forming work {:.3e} J; largest residual force {:.3e} N against contact forces up to {:.3e} N; left alone at rest, nodes moved ≤ {:.3e} m",
        r.steps, r.time_step, r.kinetic_over_work, r.forming_work, r.max_residual_force, r.max_contact_force, r.creep
    );
    eprintln!(
        "  warp: crimp {:.3} % → {:.3} %, amplitude {:.4e} → {:.4e} m; weft: crimp {:.3} % → {:.3} %, amplitude {:.4e} → {:.4e} m; a string over the crossings: {:.3} %",
        100.0 * r.crimp_warp_before,
        100.0 * r.crimp_warp_after,
        r.amplitude_warp_before,
        r.amplitude_warp_after,
        100.0 * r.crimp_weft_before,
        100.0 * r.crimp_weft_after,
        r.amplitude_weft_before,
        r.amplitude_weft_after,
        100.0 * r.crimp_target,
    );
    eprintln!(
        "  mean tension per yarn along the yarns: warp {:.4} N, weft {:.4} N (at the ends {:.4} N, {:.4} N); deepest contact {:.1} % of its contact distance; fabric top rose {:.3e} m; {:.1} s",
        r.warp_tension,
        r.weft_tension,
        r.warp_end_tension,
        r.weft_end_tension,
        100.0 * r.max_penetration_ratio,
        r.top_rise,
        r.wall_seconds
    );
    if r.start == "cell" {
        eprintln!(
            "  started from the periodic cell: {} relaxations ({} steps), its planes moved {:.4e} / {:.4e} m, {:.4} / {:.4} N across them per warp / weft yarn; the patch then moved ≤ {:.3e} m at rest",
            r.cell.rounds, r.cell.steps, r.cell.stretch[0], r.cell.stretch[1], r.cell.tension[0], r.cell.tension[1], r.creep
        );
    }
}
