//! `weft-simulate`: run the explicit solver on a model folder.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::Parser;
use weft::cli::Progress;
use weft::simulate::{run, Config};

#[derive(Parser)]
#[command(
    name = "weft-simulate",
    version,
    about = "Run the explicit solver on a model folder and write history, energy and summary tables",
    long_about = "Run the explicit central-difference solver on a model folder (see docs/tables.md) and write \
                  history.parquet (displacements and velocities on the output time grid), energy.parquet \
                  (energy balance) and summary.parquet (time step, controlling element, wall times) into --out.\n\n\
                  Analysis settings come from the model's analysis.parquet; the flags below override them. \
                  A model whose elements can fail also gets failures.parquet (one row per failure); a model \
                  with fabric layers and a projectile gets ballistic.parquet (energies, failures and \
                  deflection per layer against time) and the outcome (perforated or arrested, the residual \
                  velocity) in summary.parquet. A NaN, an instability or an energy blow-up stops the run \
                  with the step, time, node and element: the tables up to the last good output sample are \
                  written with status = stopped in summary.parquet, and the exit code is 1.\n\nExample:\n  weft-weave rod --out runs/rod && weft-simulate --model runs/rod --out runs/rod-out"
)]
struct Cli {
    /// Model folder (from weft-weave or written by hand).
    #[arg(long)]
    model: PathBuf,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Worker threads [default: all cores]. Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Simulated time [s].
    #[arg(long)]
    end_time: Option<f64>,
    /// Output time-grid spacing [s].
    #[arg(long)]
    output_interval: Option<f64>,
    /// Safety factor on the stable time step, 0 < f ≤ 1 [model default 0.9].
    #[arg(long)]
    dt_safety: Option<f64>,
    /// Fixed time step [s] (must not exceed the stable step).
    #[arg(long)]
    time_step: Option<f64>,
    /// Target time step [s] reached by adding mass to the nodes that limit the step.
    #[arg(long)]
    target_time_step: Option<f64>,
    /// Mass-proportional damping α [1/s].
    #[arg(long)]
    mass_damping: Option<f64>,
    /// Node set to write to history.parquet (repeatable) [default: all nodes].
    #[arg(long = "history-set")]
    history_sets: Vec<String>,
    /// Write every node to history.parquet, whatever node sets the model's
    /// analysis.parquet names (for whole-mesh figures: weft-plot field, weft-vtk).
    #[arg(long, conflicts_with = "history_sets")]
    all_nodes: bool,
    /// Write element results of this part at the output times to elements.parquet
    /// (repeatable; `all`: every part): axial strain and force (trusses, beams), relative
    /// displacement and force (links), Green strain and stress (membranes), energy;
    /// plastic strain, temperature, pressure and von Mises stress (hexahedra, from the
    /// solver's state). The history must hold the parts' nodes (--all-nodes), but for
    /// hexahedra.
    #[arg(long = "element-results", value_name = "PART")]
    element_results: Vec<String>,
    /// Stop when the energy balance error exceeds this fraction [model default 0.1].
    #[arg(long)]
    max_energy_error: Option<f64>,
    /// Step budget: a run that would need more steps is refused before it starts, naming
    /// the element that sets the step (like LS-DYNA's minimum step DTMIN).
    #[arg(long, default_value_t = weft::simulate::DEFAULT_MAX_STEPS)]
    max_steps: u64,
    /// Striking speed of the projectile [m/s] along its direction: one model folder, many
    /// impacts (a ballistic-limit sweep).
    #[arg(long)]
    projectile_velocity: Option<f64>,
    /// End the run at the output sample where the projectile's outcome is decided
    /// (arrested, or perforated and free of the fabric) instead of at the end time.
    #[arg(long)]
    stop_on_outcome: bool,
    /// Subcycle the solids whose stable step is many times the step, `on` or `off` [model
    /// default: analysis `subcycle`]: they are updated every so many steps, their forces
    /// the impulse of that slow step (docs/theory.md, "Subcycling"; a clay block under a
    /// yarn-level pack). The summary reports the ratio and the slow elements.
    #[arg(long, value_parser = on_off)]
    subcycle: Option<bool>,
    /// Linear static solve (K u = F with the load amplitudes) instead of the explicit run:
    /// history.parquet gets one sample at t = 0.
    #[arg(long = "static")]
    static_solve: bool,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

/// `on` / `off` for a flag that overrides a model's setting either way.
fn on_off(s: &str) -> Result<bool, String> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("`{s}`: expected `on` or `off`")),
    }
}

fn main() -> ExitCode {
    weft::cli::main(run_cli)
}

fn run_cli() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    let cfg = Config {
        model: cli.model.clone(),
        out: cli.out.clone(),
        threads: cli.threads,
        end_time: cli.end_time,
        output_interval: cli.output_interval,
        dt_safety: cli.dt_safety,
        time_step: cli.time_step,
        target_time_step: cli.target_time_step,
        mass_damping: cli.mass_damping,
        // An empty list overrides the model's sets: every node.
        history_sets: if cli.all_nodes {
            Some(vec![])
        } else {
            (!cli.history_sets.is_empty()).then_some(cli.history_sets.clone())
        },
        max_energy_error: cli.max_energy_error,
        max_steps: Some(cli.max_steps),
        static_solve: cli.static_solve,
        element_results: cli.element_results.clone(),
        projectile_velocity: cli.projectile_velocity,
        stop_on_outcome: cli.stop_on_outcome.then_some(true),
        subcycle: cli.subcycle,
    };
    let progress = Progress::new(
        cli.quiet,
        1000,
        "{spinner} simulate [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}",
    );
    let res = run(&cfg, &mut progress.fraction());
    progress.finish();
    let r = res.with_context(|| format!("simulate `{}` failed", cli.model.display()))?;
    if cli.static_solve {
        eprintln!("  wrote {}/{{history,summary}}.parquet", r.out.display());
        return Ok(ExitCode::SUCCESS);
    }
    let s = &r.stats;
    eprintln!(
        "weft-simulate: {} steps of dt = {:.4e} s (stable {:.4e} s, controlled by {}), {} nodes, {} elements, {} threads",
        s.steps, r.dt, r.dt_stable, r.controlling, s.nodes, s.elements, s.threads
    );
    if r.added_mass > 0.0 {
        eprintln!(
            "  mass scaling added {:.4e} kg ({:.3} % of the model mass)",
            r.added_mass,
            100.0 * r.added_fraction
        );
    }
    eprintln!(
        "  max energy balance error {:.3e} (relative); wall: setup {:.3} s, forces {:.3} s, update {:.3} s, output {:.3} s; {:.3e} element-updates/s",
        s.max_balance_error_relative,
        s.times.setup.as_secs_f64(),
        s.times.forces.as_secs_f64(),
        s.times.update.as_secs_f64(),
        s.times.output.as_secs_f64(),
        s.element_updates_per_second()
    );
    if let Some(line) = &r.subcycle {
        eprintln!("  {line}");
    }
    if let Some(c) = &r.contact {
        eprintln!(
            "  contact: {} definitions ({} sides on {} master surfaces), {} slave nodes against {} faces or segments; {} broad-phase builds (skin {:.3e} m) {:.3} s, narrow phase {:.3} s; {} slaves in contact at the end, friction work {:.4e} J",
            c.definitions, c.sides, c.surfaces, c.slaves, c.faces, c.builds, c.skin, c.build_seconds, c.narrow_seconds, c.active, c.friction_work
        );
        if let Some((cid, node, el, depth)) = c.deepest {
            eprintln!(
                "  contact: {} nodes started inside a surface and are tracked, not pushed out; deepest node `{node}` by {depth:.3e} m (element `{el}`, contact `{cid}`)",
                c.initial_penetrations
            );
        }
    }
    if let Some(b) = &r.ballistic {
        eprintln!("  {b}");
    }
    eprintln!(
        "  wrote {}/{{history,energy,summary}}.parquet{}",
        r.out.display(),
        r.ballistic
            .as_ref()
            .map_or("", |_| " and the failures and ballistic tables")
    );
    Ok(ExitCode::SUCCESS)
}
