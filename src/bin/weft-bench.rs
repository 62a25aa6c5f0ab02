//! `weft-bench`: element-updates per second of the explicit solver and stage wall times.
//!
//! Not a test: numbers depend on the machine. Run `cargo run --release --bin weft-bench`.

use std::time::Instant;

use clap::Parser;
use weft::model::{ElementKind, Load, Model, PartProps, TimeLaw};
use weft::solver::output::MemorySink;
use weft::solver::Solver;

#[derive(Parser)]
#[command(
    name = "weft-bench",
    version,
    about = "Measure solver throughput (element-updates/s) and stage wall times",
    long_about = "Measure solver throughput (element-updates/s) and stage wall times on this \
machine. By default: a net of trusses and links of each of --sizes elements, stepped for \
--updates element-updates on each of --threads thread counts. --pipeline times the pipeline \
engine (a no-op `weft run`, `weft status` over sweeps); --contact, the contact search on two \
pressed layers of bands; --woven, the yarn-level woven patch hit by the bullet (wall time, \
contact share). Prints its tables and writes nothing. Not a test: numbers depend on the \
machine; compare two builds alternately in the same sitting.\n\n\
Example:\n  \
weft-bench --sizes 100000 --threads 1 2 --updates 3e8\n  \
weft-bench --woven --woven-yarns 30 --woven-end-time 4e-5 --threads 2"
)]
struct Cli {
    /// Element counts to measure (several: `--sizes 1000 10000` or `--sizes 1000,10000`).
    #[arg(long, num_args = 1.., value_delimiter = ',', default_values_t = vec![10_000usize, 100_000, 1_000_000])]
    sizes: Vec<usize>,
    /// Thread counts to measure (several: `--threads 1 2` or `--threads 1,2`).
    #[arg(long, num_args = 1.., value_delimiter = ',', default_values_t = vec![1usize, 2])]
    threads: Vec<usize>,
    /// Element updates per measurement (sets the number of steps).
    #[arg(long, default_value_t = 3e8)]
    updates: f64,
    /// Benchmark the pipeline engine instead: a no-op `weft run` of a 20-stage pipeline,
    /// and `weft status` over sweeps of the sizes in --instances.
    #[arg(long)]
    pipeline: bool,
    /// Benchmark contact instead: two crossing layers of bands pressed together, at the
    /// node counts in --contact-nodes; prints the contact cost per node per step.
    #[arg(long)]
    contact: bool,
    /// Node counts for the contact benchmark.
    #[arg(long, num_args = 1.., value_delimiter = ',', default_values_t = vec![1000usize, 10_000, 100_000])]
    contact_nodes: Vec<usize>,
    /// Node-steps per contact measurement (sets the repetitions of the 300-step run).
    #[arg(long, default_value_t = 9e7)]
    node_steps: f64,
    /// Benchmark the solid instead: a block of about --sizes hexahedra (J2 steel, its top
    /// struck at 20 m/s, base held) for --updates element-updates on each thread count;
    /// prints hex updates per second (e.g. `--solid --sizes 10000 100000 --updates 2e7`).
    #[arg(long)]
    solid: bool,
    /// Benchmark the yarn-level woven patch instead: the quarter patch of
    /// --woven-yarns yarns per side (60: the paper's 120 × 120 reference) hit by the
    /// default projectile, simulated to --woven-end-time on each thread count.
    #[arg(long)]
    woven: bool,
    /// Yarns per side of the woven benchmark's quarter patch (60: the paper's 120 × 120
    /// reference).
    #[arg(long, default_value_t = 60)]
    woven_yarns: usize,
    /// End time of the woven benchmark's impact [s].
    #[arg(long, default_value_t = 6e-5)]
    woven_end_time: f64,
    /// The yarns of the woven benchmark: `band` (the reference) or `chain` (truss chains;
    /// `weft-weave woven --yarn-model`).
    #[arg(long, value_enum, default_value_t = weft::generate::woven::YarnModel::Band)]
    woven_yarn_model: weft::generate::woven::YarnModel,
    /// Layers of the woven benchmark's patch (`weft-weave woven --layers`): each layer's
    /// warp against its weft, and each pair of adjacent layers, in contact.
    #[arg(long, default_value_t = 1)]
    woven_layers: usize,
    /// Sweep sizes for the pipeline benchmark.
    #[arg(long, num_args = 1.., value_delimiter = ',', default_values_t = vec![1000usize, 10_000])]
    instances: Vec<usize>,
}

/// Run the `weft` binary next to this one; returns wall seconds.
fn weft(dir: &std::path::Path, args: &[&str]) -> anyhow::Result<f64> {
    let exe = std::env::current_exe()?.with_file_name("weft");
    let t = Instant::now();
    let o = std::process::Command::new(&exe)
        .args(args)
        .current_dir(dir)
        .output()?;
    let s = t.elapsed().as_secs_f64();
    if !o.status.success() {
        anyhow::bail!(
            "`weft {}` failed: {}",
            args.join(" "),
            String::from_utf8_lossy(&o.stderr)
        );
    }
    Ok(s)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn bench_pipeline(sizes: &[usize]) -> anyhow::Result<()> {
    let dir = std::env::temp_dir().join(format!("weft-bench-pipeline-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("pipelines"))?;
    // 20 stages: 4 chains of 5, each stage copying its predecessor's output.
    let mut s = String::new();
    for c in 0..4 {
        for k in 0..5 {
            let name = format!("s{c}_{k}");
            if k == 0 {
                s += &format!("[stages.{name}]\ncmd = \"echo {c} > ${{outputs.o}}\"\noutputs = {{ o = \"out/{name}.txt\" }}\n\n");
            } else {
                s += &format!(
                    "[stages.{name}]\ncmd = \"cp ${{inputs.i}} ${{outputs.o}}\"\ninputs = {{ i = \"out/s{c}_{}.txt\" }}\noutputs = {{ o = \"out/{name}.txt\" }}\n\n",
                    k - 1
                );
            }
        }
    }
    std::fs::write(dir.join("pipelines/twenty.toml"), s)?;
    let first = weft(&dir, &["run", "pipelines/twenty.toml", "-q"])?;
    let noop: Vec<f64> = (0..11)
        .map(|_| weft(&dir, &["run", "pipelines/twenty.toml", "-q"]))
        .collect::<anyhow::Result<_>>()?;
    let status: Vec<f64> = (0..11)
        .map(|_| weft(&dir, &["status", "pipelines/twenty.toml"]))
        .collect::<anyhow::Result<_>>()?;
    println!("pipeline,instances,operation,seconds");
    println!("chains,20,first_run,{first:.4}");
    println!("chains,20,noop_run_median,{:.4}", median(noop.clone()));
    println!("chains,20,status_median,{:.4}", median(status));
    eprintln!(
        "  20-stage pipeline: first run {first:.3} s; no-op `weft run` median {:.4} s (min {:.4} s)",
        median(noop.clone()),
        noop.iter().cloned().fold(f64::INFINITY, f64::min)
    );
    for &n in sizes {
        let f = format!("pipelines/sweep{n}.toml");
        let vals: Vec<String> = (0..n).map(|i| i.to_string()).collect();
        std::fs::write(
            dir.join(&f),
            format!(
                "[stages.point]\ncmd = \"echo ${{i}} > ${{outputs.o}}\"\nmatrix = {{ i = [{}] }}\noutputs = {{ o = \"sweep{n}/${{i}}.txt\" }}\n",
                vals.join(", ")
            ),
        )?;
        let never = weft(&dir, &["status", &f])?;
        let run = weft(&dir, &["run", &f, "-q"])?;
        let st: Vec<f64> = (0..3)
            .map(|_| weft(&dir, &["status", &f]))
            .collect::<anyhow::Result<_>>()?;
        let noop = weft(&dir, &["run", &f, "-q"])?;
        println!("sweep,{n},status_never_run,{never:.4}");
        println!("sweep,{n},first_run,{run:.4}");
        println!("sweep,{n},status_fresh_median,{:.4}", median(st.clone()));
        println!("sweep,{n},noop_run,{noop:.4}");
        eprintln!(
            "  sweep of {n:>6} instances: status {never:.3} s before any run, {:.3} s when all fresh; first run {run:.1} s; no-op run {noop:.3} s",
            median(st)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

/// A chain of `n` elements along x: trusses, or point masses joined by links.
fn chain(kind: ElementKind, n: usize) -> Model {
    let mut m = Model::default();
    let h = 1e-3;
    for i in 0..=n {
        m.add_node(i as i64 + 1, [i as f64 * h, 0.0, 0.0]);
    }
    let p = match kind {
        ElementKind::Truss => m.add_part(
            1,
            "rod",
            ElementKind::Truss,
            PartProps {
                youngs_modulus: Some(8e10),
                density: Some(1440.0),
                area: Some(1e-7),
                ..Default::default()
            },
        ),
        _ => {
            let pm = m.add_part(
                2,
                "mass",
                ElementKind::PointMass,
                PartProps {
                    mass: Some(1e-6),
                    ..Default::default()
                },
            );
            for i in 0..=n {
                m.add_element((n + 1 + i) as i64, pm, &[i]);
            }
            m.add_part(
                1,
                "link",
                ElementKind::Link,
                PartProps {
                    kx: Some(1e4),
                    ky: Some(1e4),
                    kz: Some(1e5),
                    cx: Some(1e-4),
                    cy: Some(1e-4),
                    cz: Some(1e-4),
                    slip_force: Some(1.0),
                    ..Default::default()
                },
            )
        }
    };
    for e in 0..n {
        m.add_element(e as i64 + 1, p, &[e, e + 1]);
    }
    m.constraints.push((0, [true, true, true]));
    m.loads.push(Load {
        id: 1,
        node: n,
        force: [1.0, 0.5, 0.2],
        law: TimeLaw::Step { start: 0.0 },
    });
    m.node_sets.insert("end".into(), vec![n]);
    m.analysis.history_sets = vec!["end".into()];
    m
}

/// Contact: two crossing layers of bands (`generate::layers`), two-way node-to-surface
/// contact with friction, every free node of the upper layer pressed down.
fn bench_contact(nodes: &[usize], threads: &[usize], node_steps: f64) -> anyhow::Result<()> {
    use weft::generate::layers::{crossing_bands, CrossingBands};
    println!("nodes,threads,node_steps_total,contact_seconds,total_seconds,contact_ns_per_node_step,builds,active_end,bit_identical");
    for &n in nodes {
        // The same physical time (300 steps) at every size, so that every size is in
        // the same contact state; small models are run several times.
        let mut m = crossing_bands(&CrossingBands::with_nodes(n));
        let nn = m.num_nodes();
        let dt = Solver::new(&m)?.time_step().dt;
        let steps = 300u64;
        let reps = ((node_steps / (nn as f64 * steps as f64)).ceil() as usize).max(1);
        m.analysis.end_time = dt * steps as f64;
        m.analysis.output_interval = m.analysis.end_time;
        let mut base: Option<(f64, Vec<[f64; 3]>)> = None;
        for &t in threads {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
            let (mut c, mut total) = (0.0, 0.0);
            let mut last = None;
            for _ in 0..reps {
                let mut s = Solver::new(&m)?;
                let mut sink = MemorySink::default();
                let stats = pool.install(|| s.run(&mut sink, &mut |_| {}))?;
                c += stats.times.contact.as_secs_f64();
                total +=
                    (stats.times.forces + stats.times.update + stats.times.loads).as_secs_f64();
                last = Some((s, stats));
            }
            let (s, stats) = last.expect("one run");
            let per = 1e9 * c / (nn as f64 * (stats.steps as usize * reps) as f64);
            let rep = s.operator().surfaces.report(&s.node_ids());
            let same = base.as_ref().map(|b| b.1 == s.state().x);
            let speedup = base
                .as_ref()
                .map(|b| format!(" (contact speed-up {:.2})", b.0 / c))
                .unwrap_or_default();
            println!(
                "{nn},{t},{},{c:.3},{total:.3},{per:.2},{},{},{}",
                stats.steps as usize * reps,
                rep.builds,
                rep.active,
                same.map_or("".into(), |b| b.to_string())
            );
            eprintln!(
                "  contact {nn:>7} nodes, {t} thread(s): {per:.1} ns per node per step (search + forces), {} steps × {reps}, {} builds, {} slaves in contact, contact {:.0} % of the step{speedup}{}",
                stats.steps,
                rep.builds,
                rep.active,
                100.0 * c / total,
                match same {
                    Some(true) => ", bit-identical to 1 thread",
                    Some(false) => ", DIFFERS from 1 thread",
                    None => "",
                }
            );
            if base.is_none() {
                base = Some((c, s.state().x.clone()));
            }
        }
    }
    Ok(())
}

/// The yarn-level patch: wall time, elements, step, element-cycles per second, the
/// contact's share.
fn bench_woven(
    yarns: usize,
    end_time: f64,
    yarn_model: weft::generate::woven::YarnModel,
    layers: usize,
    threads: &[usize],
) -> anyhow::Result<()> {
    use weft::generate::woven::{woven, WovenBandParams, YarnModel};
    let model = match yarn_model {
        YarnModel::Band => "band",
        YarnModel::Chain => "chain",
    };
    let p = WovenBandParams {
        yarns,
        end_time,
        yarn_model,
        layers,
        output_interval: end_time / 20.0,
        ..WovenBandParams::default()
    };
    let (m, _) = woven(&p)?;
    println!("yarn_model,yarns,threads,elements,nodes,steps,dt,wall_seconds,element_cycles_per_second,contact_seconds,contact_share,broad_phase_builds,max_balance_error_relative,finished");
    for &t in threads {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
        let t0 = Instant::now();
        let mut s = Solver::new(&m)?;
        let mut sink = MemorySink::default();
        let r = pool.install(|| s.run(&mut sink, &mut |_| {}));
        let wall = t0.elapsed().as_secs_f64();
        let rep = s.operator().surfaces.report(&s.node_ids());
        let (steps, bal, done) = match &r {
            Ok(st) => (st.steps, st.max_balance_error_relative, "yes".to_string()),
            Err(e) => (
                s.state().step,
                f64::NAN,
                format!("no: {}", e.to_string().replace(',', ";")),
            ),
        };
        let c = rep.build_seconds + rep.narrow_seconds;
        let cycles = steps as f64 * m.num_elements() as f64 / wall;
        println!(
            "{model},{yarns},{t},{},{},{steps},{:.4e},{wall:.2},{cycles:.3e},{c:.2},{:.3},{},{bal:.3e},{done}",
            m.num_elements(),
            m.num_nodes(),
            s.time_step().dt,
            c / wall,
            rep.builds
        );
        eprintln!(
            "  woven {yarns}×{yarns} quarter ({model}s, {layers} layer(s)), {t} thread(s): {} elements, {} nodes, {steps} steps of {:.3e} s in {wall:.1} s: {cycles:.3e} element-cycles/s; contact {c:.1} s ({:.0} %: broad phase {:.1} s in {} builds, narrow {:.1} s); finished: {done}",
            m.num_elements(),
            m.num_nodes(),
            s.time_step().dt,
            100.0 * c / wall,
            rep.build_seconds,
            rep.builds,
            rep.narrow_seconds
        );
        let (ph, n) = (&rep.phases, rep.slave_steps.max(1) as f64);
        eprintln!(
            "    contact phases ({} sides on {} master surfaces): thickness boxes {:.1} s, staleness test {:.1} s, builds {:.1} s ({:.1} ms each), narrow {:.1} s, scatter {:.1} s; per slave-step: {:.3} skipped whole, {:.2} candidate boxes tested, {:.3} faces evaluated, {:.3} penetrated ({} slave-steps)",
            rep.sides,
            rep.surfaces,
            ph.boxes,
            ph.staleness,
            ph.builds,
            1e3 * ph.builds / rep.builds.max(1) as f64,
            ph.narrow,
            ph.scatter,
            rep.skipped as f64 / n,
            rep.tested as f64 / n,
            rep.evaluated as f64 / n,
            rep.penetrated as f64 / n,
            rep.slave_steps
        );
        let tr = &rep.triggers;
        eprintln!(
            "    staleness triggers: {} ({} by a node past U)",
            tr.triggers, tr.far
        );
    }
    Ok(())
}

/// A block of k × k × nz hexahedra of 1 mm (k = ⌊n^⅓⌋, nz = n/k²), J2 steel, the base
/// held, the top face moving down at 20 m/s: every element updates its stress, most
/// yield near the top.
fn hex_block(n: usize) -> Model {
    let k = ((n as f64).cbrt().floor() as usize).max(1);
    let nz = (n / (k * k)).max(1);
    let h = 1e-3;
    let mut m = weft::generate::block::hex_block(
        k,
        k,
        nz,
        h,
        "block",
        PartProps {
            youngs_modulus: Some(200e9),
            poisson_ratio: Some(0.3),
            density: Some(7850.0),
            yield_stress: Some(250e6),
            tangent_modulus: Some(2e9),
            ..Default::default()
        },
    );
    let top = nz as f64 * h;
    for node in 0..m.num_nodes() {
        let z = m.coords[node][2];
        if z == 0.0 {
            m.constraints.push((node, [true, true, true]));
        } else if z == top {
            m.initial_velocities.push((node, [0.0, 0.0, -20.0]));
        }
    }
    m
}

fn bench_solid(sizes: &[usize], threads: &[usize], updates: f64) -> anyhow::Result<()> {
    println!("kind,elements,threads,steps,seconds,element_updates_per_second");
    for &n in sizes {
        let mut m = hex_block(n);
        let ne = m.num_elements();
        let dt = Solver::new(&m)?.time_step().dt;
        let steps = ((updates / ne as f64).ceil() as u64).max(20);
        m.analysis.end_time = dt * steps as f64;
        m.analysis.output_interval = m.analysis.end_time;
        let mut base = None;
        for &t in threads {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
            let mut s = Solver::new(&m)?;
            let mut sink = MemorySink::default();
            let stats = pool.install(|| s.run(&mut sink, &mut |_| {}))?;
            let secs = (stats.times.forces + stats.times.update + stats.times.loads).as_secs_f64();
            let rate = stats.element_updates_per_second();
            let speedup = base
                .map(|b: f64| format!(" (speed-up {:.2})", rate / b))
                .unwrap_or_default();
            base.get_or_insert(rate);
            println!("hex,{ne},{t},{},{secs:.3},{rate:.4e}", stats.steps);
            eprintln!(
                "  hex {ne:>8} elements, {t} thread(s): {rate:.3e} element-updates/s{speedup}"
            );
        }
    }
    Ok(())
}

fn main() -> anyhow::Result<()> {
    let cli: Cli = weft::cli::parse();
    if cli.woven {
        return bench_woven(
            cli.woven_yarns,
            cli.woven_end_time,
            cli.woven_yarn_model,
            cli.woven_layers,
            &cli.threads,
        );
    }
    if cli.pipeline {
        return bench_pipeline(&cli.instances);
    }
    if cli.solid {
        return bench_solid(&cli.sizes, &cli.threads, cli.updates);
    }
    if cli.contact {
        return bench_contact(&cli.contact_nodes, &cli.threads, cli.node_steps);
    }
    println!("kind,elements,threads,steps,seconds,element_updates_per_second");
    for kind in [ElementKind::Truss, ElementKind::Link] {
        for &n in &cli.sizes {
            let mut m = chain(kind, n);
            let dt = Solver::new(&m)?.time_step().dt;
            let steps = ((cli.updates / n as f64).ceil() as u64).max(20);
            m.analysis.end_time = dt * steps as f64;
            m.analysis.output_interval = m.analysis.end_time;
            let mut base = None;
            for &t in &cli.threads {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
                let mut s = Solver::new(&m)?;
                let mut sink = MemorySink::default();
                let stats = pool.install(|| s.run(&mut sink, &mut |_| {}))?;
                let secs =
                    (stats.times.forces + stats.times.update + stats.times.loads).as_secs_f64();
                let rate = stats.element_updates_per_second();
                let speedup = base
                    .map(|b: f64| format!(" (speed-up {:.2})", rate / b))
                    .unwrap_or_default();
                base.get_or_insert(rate);
                println!(
                    "{},{},{},{},{:.3},{:.4e}",
                    kind.name(),
                    n,
                    t,
                    stats.steps,
                    secs,
                    rate
                );
                eprintln!(
                    "  {:>10} {:>8} elements, {t} thread(s): {rate:.3e} element-updates/s{speedup}",
                    kind.name(),
                    n
                );
            }
        }
    }
    // Stage wall times: the canonical rod, generated, written, simulated, written.
    let dir = std::env::temp_dir().join(format!("weft-bench-{}", std::process::id()));
    let t0 = Instant::now();
    let p = weft::generate::rod::RodParams::default();
    let m = weft::generate::rod::build(&p)?;
    let prov = weft::table::Provenance::new("bench", serde_json::json!({}));
    weft::model::io::write_model(&m, &dir.join("rod"), &prov)?;
    let t_weave = t0.elapsed();
    let t1 = Instant::now();
    let cfg = weft::simulate::Config {
        model: dir.join("rod"),
        out: dir.join("out"),
        ..Default::default()
    };
    let r = weft::simulate::run(&cfg, &mut |_| {})?;
    let t_sim = t1.elapsed();
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!(
        "stage wall times: weave rod {:.3} s; simulate rod {:.3} s ({} steps; setup {:.3} s, forces {:.3} s, update {:.3} s, output {:.3} s)",
        t_weave.as_secs_f64(),
        t_sim.as_secs_f64(),
        r.stats.steps,
        r.stats.times.setup.as_secs_f64(),
        r.stats.times.forces.as_secs_f64(),
        r.stats.times.update.as_secs_f64(),
        r.stats.times.output.as_secs_f64()
    );
    Ok(())
}
