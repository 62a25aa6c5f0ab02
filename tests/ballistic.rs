//! Perforation and the ballistic limit: the woven patch with failing yarns against the
//! bullet, statistical strengths, the stopped run's tables, the fits of
//! `weft-ballistic`, and what its impacts cost.
//!
//! References: the impulse–momentum theorem (a perforating projectile loses the momentum
//! its contact force's impulse takes); the Weibull law of the strengths
//! (docs/theory.md, "Failure, perforation and the ballistic limit") checked by the
//! Kolmogorov–Smirnov test and the moments of ln ε (Weibull 1951); the Lambert–Jonas law
//! (BRL-R-1852, 1976) on synthetic data; the cost columns against the runs' own
//! summaries and weft-simulate runs of the same model (the same solver, the same steps).

mod common;
use common::woven::run_on;
use common::*;
use weft::ballistic::lambert_jonas::{self, Bounds, Law, Shot};
use weft::ballistic::probability::{self, Link};
use weft::generate::woven::{woven, StrengthPer, WovenBandParams, YarnFailure, YarnModel};
use weft::model::ElementKind;
use weft::random::Stream;
use weft::solver::run_in_memory;
use weft::solver::watch::Outcome;

/// A small chain patch of 8 × 8 yarns a quarter, failing at 3.6 %, its runs ending at the
/// outcome.
fn patch(layers: usize, failure: YarnFailure) -> WovenBandParams {
    WovenBandParams {
        yarns: 8,
        yarn_model: YarnModel::Chain,
        layers,
        failure,
        stop_on_outcome: true,
        end_time: 2e-4,
        output_interval: 2e-7,
        ..WovenBandParams::default()
    }
}

fn failing() -> YarnFailure {
    YarnFailure {
        strain: 0.036,
        ..YarnFailure::default()
    }
}

/// A perforating projectile loses the momentum that the impulse of the contact force on
/// it takes: m (v_end − v₀) = ∫ F dt (Newton's second law). The force is sampled every
/// 20 ns (a step is 26 ns) and integrated by the trapezoid rule.
#[test]
fn a_perforating_projectile_loses_the_impulse_of_its_contact_force() {
    let mut p = patch(1, failing());
    p.projectile_velocity = 400.0;
    p.output_interval = 2e-8;
    let (m, _) = woven(&p).unwrap();
    let (s, out, stats) = run_in_memory(&m).unwrap();
    let Outcome::Perforated {
        residual_velocity, ..
    } = s.watch().outcome
    else {
        panic!("not perforated: {:?}", s.watch().outcome);
    };
    let mass = m.projectiles[0].mass;
    let pr = &out.projectile;
    let dp = mass * (pr.last().unwrap().2[5] - pr[0].2[5]);
    let impulse: f64 = pr
        .windows(2)
        .map(|w| 0.5 * (w[1].0 - w[0].0) * (w[0].2[8] + w[1].2[8]))
        .sum();
    println!(
        "perforated at 400 m/s, residual {residual_velocity:.2} m/s: Δp {dp:.6e} N·s, impulse {impulse:.6e} N·s ({:.2e}); balance {:.2e}",
        rel(dp, impulse),
        stats.max_balance_error_relative
    );
    assert!(dp > 0.0, "the projectile (moving in −z) slows: Δp_z > 0");
    // Measured: 2.7·10⁻⁴ (the trapezoid over the force sampled every 20 ns; the issue
    // asks 1 %).
    assert!(rel(dp, impulse) < 1e-3, "{dp} vs {impulse}");
}

/// Failing impacts close their energy books: kinetic + internal + contact + friction +
/// eroded energy = the bullet's energy at the start (the central difference conserves
/// energy to O(Δt²) under forces that are the gradient of the energy stored, and the
/// contact after a failure is: each penetrated face its own pair, docs/theory.md,
/// "Contact"). Four plies of chains perforated near their limit (many failures in a
/// resting, squeezed stack), and the deformable FMJ perforating two plies. The issue
/// asks ≤ 0.5 %; under the deepest-face law before, the four plies measured 1.04e-3.
#[test]
fn failing_impacts_on_several_plies_and_a_perforating_bullet_close_their_energy_books() {
    let mut p = patch(4, failing());
    p.projectile_velocity = 150.0;
    let (m, _) = woven(&p).unwrap();
    let (s, _, plies) = run_in_memory(&m).unwrap();
    assert!(
        matches!(s.watch().outcome, Outcome::Perforated { .. }),
        "{:?}",
        s.watch().outcome
    );
    let mut b = patch(2, failing());
    b.yarns = 10;
    b.projectile_velocity = 400.0;
    b.end_time = 1.5e-4;
    b.bullet = Some(weft::generate::bullet::BulletParams {
        kind: weft::generate::bullet::BulletKind::Fmj,
        ..Default::default()
    });
    let (mb, _) = woven(&b).unwrap();
    let (sb, _, fmj) = run_in_memory(&mb).unwrap();
    assert!(
        matches!(sb.watch().outcome, Outcome::Perforated { .. }),
        "{:?}",
        sb.watch().outcome
    );
    println!(
        "4 plies at 150 m/s: balance {:.3e}; FMJ through 2 plies at 400 m/s: {:.3e}",
        plies.max_balance_error_relative, fmj.max_balance_error_relative
    );
    // Measured 2.67e-4 and 4.88e-5.
    assert!(plies.max_balance_error_relative < 8e-4);
    assert!(fmj.max_balance_error_relative < 1.5e-4);
}

/// Strengths drawn per element with modulus m = 8 at the gauge length of the elements:
/// the factors ε/ε₀ follow the Weibull law of scale 1 and modulus 8. Kolmogorov–Smirnov:
/// D below its 1 % critical value 1.63/√n; the mean of ln(ε/ε₀) within four standard
/// errors of −γ/m (γ Euler's constant), its variance within four of π²/(6m²).
#[test]
fn strengths_follow_the_weibull_law_asked_for() {
    let modulus = 8.0;
    let mut p = patch(2, failing());
    p.yarns = 20;
    p.failure.weibull_modulus = Some(modulus);
    p.failure.per = StrengthPer::Element;
    // The gauge length of one element: the factors are then the Weibull law's own.
    p.failure.gauge_length = Some(p.spacing / p.per_spacing as f64);
    p.failure.seed = 12345;
    let (m, _) = woven(&p).unwrap();
    let mut f = m.elements[&ElementKind::Truss].failure_factor.clone();
    let n = f.len() as f64;
    assert!(n > 5000.0);
    f.sort_by(f64::total_cmp);
    let cdf = |x: f64| 1.0 - (-x.powf(modulus)).exp();
    let d = f
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            let c = cdf(x);
            (c - i as f64 / n).abs().max(((i + 1) as f64 / n - c).abs())
        })
        .fold(0.0, f64::max);
    let logs: Vec<f64> = f.iter().map(|x| x.ln()).collect();
    let mean = logs.iter().sum::<f64>() / n;
    let var = logs.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let euler = 0.577_215_664_901_532_9;
    let (mu, sig2) = (
        -euler / modulus,
        std::f64::consts::PI.powi(2) / (6.0 * modulus * modulus),
    );
    // ln X is Gumbel (of the minimum): kurtosis 5.4, so Var(s²) ≈ (5.4 − 1)σ⁴/n.
    println!(
        "{n} factors: KS D = {d:.4} (1 % critical {:.4}); mean ln {mean:.5} vs {mu:.5}, variance {var:.6} vs {sig2:.6}",
        1.63 / n.sqrt()
    );
    assert!(d < 1.63 / n.sqrt());
    assert!((mean - mu).abs() < 4.0 * (sig2 / n).sqrt());
    assert!((var - sig2).abs() < 4.0 * (4.4 * sig2 * sig2 / n).sqrt());
    // The same seed, the same strengths; another seed, others.
    let (m2, _) = woven(&p).unwrap();
    assert_eq!(
        m2.elements[&ElementKind::Truss].failure_factor,
        m.elements[&ElementKind::Truss].failure_factor
    );
    p.failure.seed = 12346;
    let (m3, _) = woven(&p).unwrap();
    assert_ne!(
        m3.elements[&ElementKind::Truss].failure_factor,
        m.elements[&ElementKind::Truss].failure_factor
    );
}

/// With statistical strengths and erosion active, 1 and 2 threads give the same bits
/// (the solver's chunks are fixed and failures are collected in element order).
#[test]
fn erosion_with_statistical_strengths_is_thread_independent() {
    let mut p = patch(2, failing());
    p.failure.weibull_modulus = Some(10.0);
    p.failure.seed = 7;
    p.projectile_velocity = 300.0;
    p.end_time = 3e-5;
    let (m, _) = woven(&p).unwrap();
    let (o1, _, s1) = run_on(&m, 1);
    let (o2, _, _) = run_on(&m, 2);
    let e1: Vec<[f64; 3]> = o1
        .energy
        .iter()
        .map(|e| [e.kinetic, e.internal, e.eroded])
        .collect();
    let e2: Vec<[f64; 3]> = o2
        .energy
        .iter()
        .map(|e| [e.kinetic, e.internal, e.eroded])
        .collect();
    let eroded = o1.energy.last().unwrap().eroded;
    println!(
        "two layers at 300 m/s to 30 µs: eroded {eroded:.4e} J, balance {:.2e}",
        s1.max_balance_error_relative
    );
    assert!(eroded > 0.0, "something failed");
    assert_eq!(e1, e2);
    assert_eq!(o1.u, o2.u);
    // Bit for bit, NaN (a layer with no failure yet) included.
    let bits = |o: &weft::solver::output::MemorySink| -> Vec<u64> {
        o.layers
            .iter()
            .flat_map(|(t, l)| {
                std::iter::once(t.to_bits()).chain(l.iter().flatten().map(|x| x.to_bits()))
            })
            .collect()
    };
    assert_eq!(bits(&o1), bits(&o2));
}

/// Lambert–Jonas on synthetic data: without noise the constants come back to round-off;
/// with noise (Gaussian, 3 m/s, seeded) the true constants lie in the bootstrap intervals.
#[test]
fn lambert_jonas_recovers_synthetic_laws() {
    let truth = Law {
        a: 0.9,
        p: 2.2,
        v_bl: 250.0,
    };
    let speeds: Vec<f64> = (0..20).map(|k| 200.0 + 15.0 * k as f64).collect();
    let exact: Vec<Shot> = speeds
        .iter()
        .map(|&v| Shot {
            striking: v,
            residual: truth.residual(v),
            perforated: v > truth.v_bl,
        })
        .collect();
    let f = lambert_jonas::fit(&exact, &Bounds::default(), 200, 1).unwrap();
    println!("exact: {:?}", f.law);
    // Measured: relative errors below 10⁻¹⁰.
    assert!(
        rel(f.law.v_bl, truth.v_bl) < 1e-8
            && rel(f.law.a, truth.a) < 1e-8
            && rel(f.law.p, truth.p) < 1e-8
    );
    let mut rng = Stream::new(99);
    let noisy: Vec<Shot> = exact
        .iter()
        .map(|s| Shot {
            residual: if s.perforated {
                (s.residual + 3.0 * rng.next_normal()).max(0.0)
            } else {
                0.0
            },
            ..*s
        })
        .collect();
    let f = lambert_jonas::fit(&noisy, &Bounds::default(), 1000, 2).unwrap();
    println!("noisy: {:?}", f);
    let inside = |v: f64, (lo, hi): (f64, f64)| lo <= v && v <= hi;
    assert!(inside(truth.v_bl, f.v_bl_interval), "{f:?}");
    assert!(inside(truth.a, f.a_interval), "{f:?}");
    assert!(inside(truth.p, f.p_interval), "{f:?}");
}

/// The probability of perforation on outcomes drawn from a known logistic law
/// (V50 = 300 m/s, scale 10 m/s): the fit's V50 interval holds the true V50, and V10, V90
/// are V50 ∓ 10 ln 9 within the interval's width.
#[test]
fn the_probability_fit_recovers_a_logistic_law() {
    let (v50, s) = (300.0, 10.0);
    let mut rng = Stream::new(5);
    let outcomes: Vec<(f64, bool)> = (0..400)
        .map(|i| {
            let v = 250.0 + 100.0 * (i as f64 + 0.5) / 400.0;
            (v, rng.next_uniform() < 1.0 / (1.0 + (-(v - v50) / s).exp()))
        })
        .collect();
    let f = probability::fit(&outcomes, Link::Logit).unwrap();
    println!("{f:?}");
    assert_eq!(f.method, "logit");
    assert!(f.v50_interval.0 <= v50 && v50 <= f.v50_interval.1, "{f:?}");
    let w = f.v50_interval.1 - f.v50_interval.0;
    let spread = s * 9f64.ln();
    assert!((f.v90 - f.v10 - 2.0 * spread).abs() < 2.0 * w, "{f:?}");
}

// ---------------------------------------------------------------------------------------
// Runs that stop, and bad input.

/// A run that stops keeps what it computed: the tables up to the last good output
/// sample, `status = stopped` with the reason in the summary, and an error (a non-zero
/// exit). The stop: an energy-balance limit far below this rod's O(Δt²) drift.
#[test]
fn a_stopped_run_keeps_its_tables_and_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let (model, out) = (dir.path().join("rod"), dir.path().join("out"));
    let rod = weft::generate::rod::build(&weft::generate::rod::RodParams::default()).unwrap();
    weft::model::io::write_model(
        &rod,
        &model,
        &weft::table::Provenance::new("t", serde_json::json!({})),
    )
    .unwrap();
    let c = weft::simulate::Config {
        model: model.clone(),
        out: out.clone(),
        max_energy_error: Some(1e-13),
        end_time: Some(4e-4),
        ..Default::default()
    };
    let err = weft::simulate::run(&c, &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("the run stopped") && err.contains("energy balance error"),
        "{err}"
    );
    let s = weft::table::Table::read(&out.join("summary.parquet")).unwrap();
    assert_eq!(s.str("status", "").unwrap(), vec!["stopped"]);
    let why = s.str_opt("stop_reason").unwrap().unwrap()[0]
        .clone()
        .unwrap();
    assert!(why.contains("energy balance error"), "{why}");
    let end = s.f64("end_time", "").unwrap()[0];
    let e = weft::table::Table::read(&out.join("energy.parquet")).unwrap();
    let t = e.f64("t", "").unwrap();
    let h = weft::table::Table::read(&out.join("history.parquet")).unwrap();
    println!(
        "stopped at {end:e} s: {} energy rows, {} history rows; {why}",
        t.len(),
        h.num_rows()
    );
    assert!(end > 0.0 && end < 4e-4);
    assert_eq!(
        *t.last().unwrap(),
        end,
        "the tables end at the last good sample"
    );
}

/// A stopped impact's tables end at one sample, and its runs stay out of the fits. The
/// stop: an energy limit just below the balance error the same impact reaches at one of
/// its samples, chosen (by runs in memory) so that the solver stops while yarns fail
/// between its last sample and the stop. Its history, projectile, energy, per-ply and
/// failures tables then end at the summary's `end_time`; its failures are those of the
/// solver's log up to that time, value by value, and the summary counts those.
/// `weft-ballistic fit` refuses it, naming the run and its reason, and `--skip-stopped`
/// leaves it out (and says so).
#[test]
fn a_stopped_impact_ends_its_tables_at_one_sample_and_stays_out_of_fits() {
    use weft::table::Table;
    let dir = tempfile::tempdir().unwrap();
    let mut p = patch(1, failing());
    p.projectile_velocity = 400.0;
    p.output_interval = 1e-6;
    let (m, _) = woven(&p).unwrap();
    let model = dir.path().join("patch");
    let prov = weft::table::Provenance::new("t", serde_json::json!({}));
    weft::model::io::write_model(&m, &model, &prov).unwrap();
    let simulate = |name: &str, limit: Option<f64>| {
        let out = dir.path().join(name);
        let c = weft::simulate::Config {
            model: model.clone(),
            out: out.clone(),
            max_energy_error: limit,
            ..Default::default()
        };
        (out.clone(), weft::simulate::run(&c, &mut |_| {}))
    };
    let (full, r) = simulate("full", None);
    r.unwrap();
    let read = |run: &std::path::Path, table: &str| Table::read(&run.join(table)).unwrap();
    // The limits to try: just below the balance error (relative to the scale so far) of
    // each sample, largest first; kept: the first whose stop falls after a failure that
    // is not yet in the last sample.
    let e = read(&full, "energy.parquet");
    let (b, scale) = (
        e.f64("balance_error", "").unwrap(),
        e.f64("energy_scale", "").unwrap(),
    );
    let mut limits: Vec<f64> = b
        .iter()
        .zip(&scale)
        .map(|(b, s)| 0.999 * b.abs() / s)
        .collect();
    limits.sort_by(|a, b| b.total_cmp(a));
    let stop_in_memory = |limit: f64| {
        let mut m = m.clone();
        m.analysis.max_energy_error = limit;
        let mut s = weft::solver::Solver::new(&m).unwrap();
        let mut sink = weft::solver::output::MemorySink::default();
        let stopped = s.run(&mut sink, &mut |_| {}).is_err();
        let end = s.stats_so_far().end_time;
        let log: Vec<f64> = s.failure_log().events.iter().map(|e| e.time).collect();
        (stopped, end, log)
    };
    let (limit, log) = limits
        .iter()
        .find_map(|&l| {
            let (stopped, end, log) = stop_in_memory(l);
            (stopped && log.iter().any(|&t| t <= end) && log.iter().any(|&t| t > end))
                .then_some((l, log))
        })
        .expect("no limit stops the run while yarns fail between its last sample and the stop");
    let (stopped, r) = simulate("stopped", Some(limit));
    let err = r.unwrap_err().to_string();
    assert!(err.contains("energy balance error"), "{err}");
    let s = read(&stopped, "summary.parquet");
    assert_eq!(s.str("status", "").unwrap(), vec!["stopped"]);
    let end = s.f64("end_time", "").unwrap()[0];
    let last = |run: &std::path::Path, table: &str| {
        read(run, table)
            .f64("t", "")
            .unwrap()
            .into_iter()
            .fold(f64::NEG_INFINITY, f64::max)
    };
    for table in [
        "history.parquet",
        "projectile.parquet",
        "energy.parquet",
        "ballistic.parquet",
    ] {
        assert_eq!(
            last(&stopped, table),
            end,
            "{table} ends at the last sample"
        );
    }
    let kept = read(&stopped, "failures.parquet").f64("t", "").unwrap();
    let before_end: Vec<f64> = log.iter().copied().filter(|&t| t <= end).collect();
    println!(
        "stopped at the sample {end:e} s (limit {limit:.3e}): {} failures in the table, {} in the solver's log by the stop; {err}",
        kept.len(),
        log.len()
    );
    assert!(before_end.len() < log.len(), "nothing to cut");
    assert_eq!(
        kept, before_end,
        "a stopped run's failures: those up to its last sample"
    );
    assert_eq!(
        s.i64("failed_elements", "").unwrap()[0] as usize,
        kept.len(),
        "the summary counts the failures of its table"
    );
    // The fit: refused, or left out with --skip-stopped.
    let runs =
        weft::ballistic::runs::read_folders(&[stopped.clone(), full.clone()], "layers").unwrap();
    let e = weft::ballistic::runs::leave_out_stopped(runs.clone(), false, &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&stopped.display().to_string())
            && e.contains("energy balance error")
            && e.contains("--skip-stopped"),
        "{e}"
    );
    let mut noted = vec![];
    let kept =
        weft::ballistic::runs::leave_out_stopped(runs, true, &mut |r| noted.push(r.source.clone()))
            .unwrap();
    assert_eq!(noted, vec![stopped.display().to_string()]);
    assert_eq!(kept.len(), 1);
    assert_eq!(kept[0].source, full.display().to_string());
    let fit = |extra: &[&str]| {
        let mut args = vec![
            "fit",
            "--runs",
            stopped.to_str().unwrap(),
            full.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let out = dir.path().join("limit");
        args.extend_from_slice(&["--out", out.to_str().unwrap()]);
        let o = std::process::Command::new(BALLISTIC)
            .args(&args)
            .output()
            .unwrap();
        assert!(!o.status.success());
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let refused = fit(&[]);
    assert!(
        refused.contains("stopped before its end") && refused.contains("--skip-stopped"),
        "{refused}"
    );
    // Left out, the one complete run perforated: no bracket to fit, said as such.
    let skipped = fit(&["--skip-stopped"]);
    assert!(
        skipped.contains("left out") && skipped.contains("every run perforated"),
        "{skipped}"
    );
}

/// Bad input, each named: a negative or non-finite failure strain (parts.parquet), a
/// Weibull modulus ≤ 0 (the generator), velocities that cannot bracket a limit, runs of
/// two models in one group.
#[test]
fn bad_failure_input_is_named() {
    let (mut m, _) = woven(&patch(1, failing())).unwrap();
    let warp = m.parts.iter().position(|p| p.name == "warp_1").unwrap();
    m.parts[warp].props.failure_strain = Some(-0.01);
    let e = m.validate().unwrap_err().to_string();
    assert!(
        e.contains("failure_strain") && e.contains("-0.01") && e.contains("warp_1"),
        "{e}"
    );
    m.parts[warp].props.failure_strain = Some(f64::INFINITY);
    let e = m.validate().unwrap_err().to_string();
    assert!(e.contains("failure_strain") && e.contains("inf"), "{e}");
    for bad in [0.0, -3.0, f64::NAN] {
        let mut p = patch(1, failing());
        p.failure.weibull_modulus = Some(bad);
        let e = woven(&p).unwrap_err().to_string();
        assert!(
            e.contains("--weibull-modulus") && e.contains("m > 0"),
            "{e}"
        );
    }
    let run = |v: f64, perforated: bool, nodes: f64| weft::ballistic::runs::Run {
        source: format!("runs/{v}"),
        group: "2".into(),
        striking_velocity: v,
        residual_velocity: if perforated { 0.5 * v } else { 0.0 },
        perforated,
        outcome: if perforated { "perforated" } else { "arrested" }.into(),
        energy_absorbed: f64::NAN,
        signature: vec![("layers", 2.0), ("nodes", nodes)],
        cost: Default::default(),
        stopped: None,
    };
    let fit = |runs: Vec<weft::ballistic::runs::Run>| -> String {
        match weft::ballistic::runs::group(runs) {
            Err(e) => e.to_string(),
            Ok(groups) => {
                match weft::ballistic::limit::fit_groups(&groups, "layers", &Default::default()) {
                    Err(e) => e.to_string(),
                    Ok(_) => String::new(),
                }
            }
        }
    };
    let all = fit(vec![run(300.0, true, 1.0), run(350.0, true, 1.0)]);
    assert!(
        all.contains("every run perforated")
            && all.contains("300, 350")
            && all.contains("layers = 2"),
        "{all}"
    );
    let none = fit(vec![run(30.0, false, 1.0), run(35.0, false, 1.0)]);
    assert!(none.contains("no run perforated"), "{none}");
    let mixed = fit(vec![run(30.0, false, 1.0), run(300.0, true, 2.0)]);
    assert!(
        mixed.contains("different models")
            && mixed.contains("nodes = 1 and 2")
            && mixed.contains("runs/30"),
        "{mixed}"
    );
}

// ---------------------------------------------------------------------------------------
// What an impact costs: `ballistic_runs.parquet`'s steps, simulated time, elements,
// element cycles and wall time, and `ballistic_limit.parquet`'s sums.

const WEAVE: &str = env!("CARGO_BIN_EXE_weft-weave");
const SIMULATE: &str = env!("CARGO_BIN_EXE_weft-simulate");
const BALLISTIC: &str = env!("CARGO_BIN_EXE_weft-ballistic");

/// A 4 × 4 chain patch (112 trusses) failing at 3.6 %, its runs ending at the outcome
/// within 1 ms: at 40 and 80 m/s it stops, at 250 and 400 m/s it is perforated.
fn small_patch(dir: &std::path::Path) -> std::path::PathBuf {
    small_patch_ending(dir, "patch", "1e-3")
}

/// The same patch in `dir/name`, its runs ending at `end` [s] at the latest.
fn small_patch_ending(dir: &std::path::Path, name: &str, end: &str) -> std::path::PathBuf {
    let m = dir.join(name);
    run_ok(
        WEAVE,
        &[
            "woven",
            "--yarns",
            "4",
            "--yarn-model",
            "chain",
            "--failure-strain",
            "0.036",
            "--stop-on-outcome",
            "--end-time",
            end,
            "--out",
            m.to_str().unwrap(),
        ],
    );
    m
}

/// The arguments of one round of `weft-ballistic search` on `model`, its two impacts at
/// 40 and 400 m/s (the bracket's ends, --per-round 2), into `out`, then `extra`.
fn search_args<'a>(
    model: &'a std::path::Path,
    out: &'a std::path::Path,
    extra: &[&'a str],
) -> Vec<&'a str> {
    let mut a = vec![
        "search",
        "--model",
        model.to_str().unwrap(),
        "--lo",
        "40",
        "--hi",
        "400",
        "--tolerance",
        "1000",
        "--per-round",
        "2",
        "--max-rounds",
        "1",
        "--threads",
        "1",
        "--bootstrap",
        "10",
        "--out",
        out.to_str().unwrap(),
    ];
    a.extend_from_slice(extra);
    a
}

/// One round of `weft-ballistic search` on `model` (`search_args`), into `out`.
fn search_once(model: &std::path::Path, out: &std::path::Path) {
    run_ok(BALLISTIC, &search_args(model, out, &[]));
}

fn simulate(model: &std::path::Path, out: &std::path::Path, v: f64) {
    run_ok(
        SIMULATE,
        &[
            "--model",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--projectile-velocity",
            &format!("{v}"),
            "--quiet",
        ],
    );
}

/// A column of a table as options (null: None); integers as i64, others as f64.
fn opt_f(t: &weft::table::Table, c: &str) -> Vec<Option<f64>> {
    t.f64_opt(c)
        .unwrap()
        .unwrap_or_else(|| panic!("no column {c}"))
}
fn opt_i(t: &weft::table::Table, c: &str) -> Vec<Option<i64>> {
    t.i64_opt(c)
        .unwrap()
        .unwrap_or_else(|| panic!("no column {c}"))
}

/// The fit's cost columns are the summaries' own: steps, end time and elements as
/// written, element cycles = steps × elements exactly, the wall time the sum of the five
/// wall-time columns; each group's sums are the sums of its rows (in the rows' order:
/// the same additions), the mean their sum over the impacts. A table of the same
/// summaries without their wall-time columns (an older summary) and with `steps` as
/// floats gives null wall times and null sums of them, the other columns as before.
#[test]
fn the_cost_columns_are_the_summaries_own() {
    use weft::table::Table;
    let dir = tempfile::tempdir().unwrap();
    let m = small_patch(dir.path());
    let speeds = [40.0, 80.0, 250.0, 400.0];
    let runs: Vec<std::path::PathBuf> = speeds
        .iter()
        .map(|v| {
            let r = dir.path().join(format!("v{v}"));
            simulate(&m, &r, *v);
            r
        })
        .collect();
    let out = dir.path().join("fit");
    let mut args = vec!["fit", "--bootstrap", "10", "--out", out.to_str().unwrap()];
    args.push("--runs");
    args.extend(runs.iter().map(|r| r.to_str().unwrap()));
    run_ok(BALLISTIC, &args);
    let t = Table::read(&out.join("ballistic_runs.parquet")).unwrap();
    let (src, vs) = (
        t.str("run", "").unwrap(),
        t.f64("striking_velocity", "").unwrap(),
    );
    let (steps, sim, elements) = (
        opt_i(&t, "steps"),
        opt_f(&t, "simulated_time"),
        opt_i(&t, "elements"),
    );
    let (cycles, wall) = (opt_i(&t, "element_cycles"), opt_f(&t, "wall_time"));
    assert_eq!(vs, speeds, "the group's runs in the order of their speeds");
    for i in 0..4 {
        assert_eq!(src[i], runs[i].to_str().unwrap());
        let s = Table::read(&runs[i].join("summary.parquet")).unwrap();
        let one = |c: &str| s.f64(c, "").unwrap()[0];
        let (n, e) = (
            s.i64("steps", "").unwrap()[0],
            s.i64("elements", "").unwrap()[0],
        );
        let w = one("wall_time_setup")
            + one("wall_time_loads")
            + one("wall_time_forces")
            + one("wall_time_update")
            + one("wall_time_output");
        println!(
            "{} m/s: {n} steps × {e} elements = {:?} cycles, {:?} s simulated, wall {:?} s",
            vs[i], cycles[i], sim[i], wall[i]
        );
        assert_eq!((steps[i], elements[i]), (Some(n), Some(e)));
        assert_eq!(cycles[i], Some(n * e));
        assert_eq!(e, 112, "the patch's 112 trusses");
        assert_eq!(sim[i], Some(one("end_time")));
        // The recorded wall times are copied, not measured here: the column must equal the
        // summary's five recorded phases exactly, whatever the machine's load was.
        assert_eq!(wall[i], Some(w));
    }
    let l = Table::read(&out.join("ballistic_limit.parquet")).unwrap();
    let sum_cycles: i64 = cycles.iter().map(|c| c.unwrap()).sum();
    let sum_wall: f64 = wall.iter().map(|w| w.unwrap()).sum();
    assert_eq!(opt_i(&l, "impacts_element_cycles"), vec![Some(sum_cycles)]);
    assert_eq!(opt_f(&l, "impacts_wall_time"), vec![Some(sum_wall)]);
    assert_eq!(
        opt_f(&l, "wall_time_per_impact"),
        vec![Some(sum_wall / 4.0)]
    );

    // The same four summaries gathered into one table, without the wall-time columns,
    // and with `steps` as floats (as pandas writes an integer column with nulls).
    let batches: Vec<arrow_array::RecordBatch> = runs
        .iter()
        .map(|r| {
            use arrow_schema::{DataType, Field, Schema};
            let s = Table::read(&r.join("summary.parquet")).unwrap();
            let (mut fields, mut cols) = (vec![], vec![]);
            for (f, c) in s.batch.schema().fields().iter().zip(s.batch.columns()) {
                if f.name().starts_with("wall_time") {
                    continue;
                }
                if f.name() == "steps" {
                    fields.push(Field::new("steps", DataType::Float64, false));
                    cols.push(arrow_cast::cast(c, &DataType::Float64).unwrap());
                } else {
                    fields.push(f.as_ref().clone());
                    cols.push(c.clone());
                }
            }
            // Without the summary's provenance (schema metadata), as a gathered table.
            arrow_array::RecordBatch::try_new(std::sync::Arc::new(Schema::new(fields)), cols)
                .unwrap()
        })
        .collect();
    let gathered = dir.path().join("gathered.parquet");
    weft::table::write_table(
        &gathered,
        &arrow_select::concat::concat_batches(&batches[0].schema(), &batches).unwrap(),
        &weft::table::Provenance::new("t", serde_json::json!({})),
    )
    .unwrap();
    let old = dir.path().join("old");
    run_ok(
        BALLISTIC,
        &[
            "fit",
            "--table",
            gathered.to_str().unwrap(),
            "--bootstrap",
            "10",
            "--out",
            old.to_str().unwrap(),
        ],
    );
    let t = Table::read(&old.join("ballistic_runs.parquet")).unwrap();
    assert_eq!(opt_f(&t, "wall_time"), vec![None; 4]);
    assert_eq!(opt_i(&t, "element_cycles"), cycles);
    assert_eq!(opt_i(&t, "steps"), steps);
    let l = Table::read(&old.join("ballistic_limit.parquet")).unwrap();
    assert_eq!(opt_f(&l, "impacts_wall_time"), vec![None]);
    assert_eq!(opt_f(&l, "wall_time_per_impact"), vec![None]);
    assert_eq!(opt_i(&l, "impacts_element_cycles"), vec![Some(sum_cycles)]);
}

/// The search runs the solver weft-simulate runs: each of its impacts took the steps,
/// the simulated time and the elements of a weft-simulate run of the model at the same
/// speed, exactly; the elements are the model's trusses (elements_truss.parquet's rows).
#[test]
fn the_search_costs_what_weft_simulate_runs_cost() {
    use weft::table::Table;
    let dir = tempfile::tempdir().unwrap();
    let m = small_patch(dir.path());
    let out = dir.path().join("search");
    search_once(&m, &out);
    let t = Table::read(&out.join("ballistic_runs.parquet")).unwrap();
    let vs = t.f64("striking_velocity", "").unwrap();
    let (steps, sim, elements) = (
        opt_i(&t, "steps"),
        opt_f(&t, "simulated_time"),
        opt_i(&t, "elements"),
    );
    let (cycles, wall) = (opt_i(&t, "element_cycles"), opt_f(&t, "wall_time"));
    let trusses = Table::read(&m.join("elements_truss.parquet"))
        .unwrap()
        .num_rows() as i64;
    assert_eq!(vs, vec![40.0, 400.0]);
    for i in 0..vs.len() {
        let r = dir.path().join(format!("v{}", vs[i]));
        simulate(&m, &r, vs[i]);
        let s = Table::read(&r.join("summary.parquet")).unwrap();
        let (n, e) = (
            s.i64("steps", "").unwrap()[0],
            s.i64("elements", "").unwrap()[0],
        );
        let end = s.f64("end_time", "").unwrap()[0];
        println!(
            "{} m/s: search {:?} steps, {:?} s, {:?} elements; weft-simulate {n}, {end:e} s, {e}",
            vs[i], steps[i], sim[i], elements[i]
        );
        assert_eq!(steps[i], Some(n));
        assert_eq!(sim[i], Some(end));
        assert_eq!(elements[i], Some(e));
        assert_eq!(e, trusses);
        assert_eq!(cycles[i], Some(n * e));
        assert!(wall[i].is_some_and(|w| w.is_finite() && w >= 0.0));
    }
    let l = Table::read(&out.join("ballistic_limit.parquet")).unwrap();
    assert_eq!(
        opt_i(&l, "impacts_element_cycles"),
        vec![Some(cycles.iter().map(|c| c.unwrap()).sum())]
    );
}

/// An impact undecided at the model's end time is run again with twice the end time.
/// The 4 × 4 patch woven to end at 30 µs: at 400 m/s it is perforated at 24 µs, within
/// the end time; at 40 m/s it is arrested at 98 µs (weft-simulate with a 1 ms end time),
/// so the search runs it to 30 µs, to 60 µs (both undecided) and to 120 µs, where it
/// decides. Its outcome and simulated time are those of weft-simulate on the patch woven
/// to end at 120 µs, its steps the sum of weft-simulate's to 30 µs, to 60 µs and to the
/// outcome. With `--extensions 1` the search stops at 60 µs, naming the impact.
#[test]
fn an_undecided_impact_is_run_again_with_twice_the_end_time() {
    use weft::table::Table;
    let dir = tempfile::tempdir().unwrap();
    let weave = |name: &str, end: &str| small_patch_ending(dir.path(), name, end);
    let short = weave("short", "3e-5");
    let out = dir.path().join("search");
    let search = |extensions: &str| {
        std::process::Command::new(BALLISTIC)
            .args(search_args(&short, &out, &["--extensions", extensions]))
            .output()
            .unwrap()
    };
    let o = search("1");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.contains(
            "the impact at 40 m/s was neither arrested nor free of the fabric by 6.000e-5 s"
        ),
        "{err}"
    );
    assert!(!out.join("ballistic_runs.parquet").exists());

    let o = search("2");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let t = Table::read(&out.join("ballistic_runs.parquet")).unwrap();
    assert_eq!(t.f64("striking_velocity", "").unwrap(), vec![40.0, 400.0]);
    let outcome = t.str("outcome", "").unwrap();
    let (steps, sim) = (opt_i(&t, "steps"), opt_f(&t, "simulated_time"));
    let summary = |model: &std::path::Path, v: f64, name: &str| {
        let r = dir.path().join(name);
        simulate(model, &r, v);
        let s = Table::read(&r.join("summary.parquet")).unwrap();
        (
            s.i64("steps", "").unwrap()[0],
            s.f64("end_time", "").unwrap()[0],
            s.str("outcome", "").unwrap()[0].clone(),
        )
    };
    let double = weave("double", "6e-5");
    let long = weave("long", "1.2e-4");
    let (n1, t1, o1) = summary(&short, 40.0, "s40");
    let (n2, t2, o2) = summary(&double, 40.0, "d40");
    let (n4, t4, o4) = summary(&long, 40.0, "l40");
    println!("40 m/s: {n1} steps to {t1:e} s ({o1}), {n2} to {t2:e} ({o2}), {n4} to {t4:e} ({o4}); search {:?} steps, {:?} s", steps[0], sim[0]);
    assert_eq!(
        (o1.as_str(), o2.as_str(), o4.as_str()),
        ("undecided", "undecided", "arrested")
    );
    assert_eq!(outcome[0], "arrested");
    assert_eq!(sim[0], Some(t4));
    assert_eq!(steps[0], Some(n1 + n2 + n4));
    // The perforation at 400 m/s decided within the model's own end time: one attempt.
    let (n, end, o400) = summary(&short, 400.0, "s400");
    assert_eq!(
        (outcome[1].as_str(), o400.as_str()),
        ("perforated", "perforated")
    );
    assert_eq!((steps[1], sim[1]), (Some(n), Some(end)));
}

/// A search names its group by the model folder, as text whatever the name reads like:
/// a search over `models/6` and one over `models/reference` gather into one table
/// (`weft gather` refuses instances whose columns differ in type), so `model` is a string
/// column holding "6", not an integer.
#[test]
fn a_search_names_its_model_as_text() {
    use weft::table::Table;
    let dir = tempfile::tempdir().unwrap();
    let m = dir.path().join("6");
    std::fs::rename(small_patch(dir.path()), &m).unwrap();
    let out = dir.path().join("search");
    search_once(&m, &out);
    for table in ["ballistic_runs.parquet", "ballistic_limit.parquet"] {
        let t = Table::read(&out.join(table)).unwrap();
        let model = t.str_opt("model").unwrap();
        assert!(model.is_some(), "{table}: `model` is not a string column");
        assert!(model.unwrap().iter().all(|m| m.as_deref() == Some("6")));
    }
}
