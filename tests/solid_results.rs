//! A hexahedron's path-dependent state in `elements.parquet` (`weft-simulate
//! --element-results`): `plastic_strain`, `temperature`, `pressure`, `von_mises_stress`.
//!
//! One cube, held on its three symmetry planes x = 0, y = 0, z = 0 (each face along its
//! normal only) and pulled along x by four equal forces on its face x = h, ramped slowly
//! (mass damping for the dynamics): a homogeneous uniaxial stress, free to contract
//! sideways. The oracles use the kinematics of the history alone, the logarithmic strain
//! ε = ln(L/h) of the cube's length L (the integral of the rate of deformation along a
//! fixed axis), and the closed forms of the material:
//! - J2 bilinear (Hill, *The Mathematical Theory of Plasticity*, §2; Simo & Hughes,
//!   *Computational Inelasticity*, §2.2, uniaxial elastoplastic tangent E_t = EH/(E + H)):
//!   monotone loading past yield gives σ = σ_y + E_t(ε − σ_y/E), ε_p = ε − σ/E
//!   (= (σ − σ_y)/H); uniaxial stress has p = −σ/3 and σ̄ = |σ|;
//! - Johnson–Cook with adiabatic heating (Johnson & Cook 1983; the Taylor–Quinney
//!   fraction β): T − T₀ = β/(ρ c_p) ∫ σ̄ dε_p, integrated here by the trapezoid over the
//!   output samples of the table's own σ̄ and ε_p (the material integrates it step by
//!   step), and ε_p = ε − σ̄/E against the kinematics.
//!
//! Also: a block of 1210 Johnson–Cook hexahedra (the family's parallel path) writes
//! bit-identical element results on one and on two threads; an eroded hexahedron's row;
//! the generic columns null on hex rows; an unknown part refused naming it.

use std::path::{Path, PathBuf};

mod common;
use common::solid::{copper, struck_block};
use weft::generate::block::hex_block;
use weft::model::io::write_model;
use weft::model::{Load, Model, PartProps, TimeLaw};
use weft::simulate::{run, Config};
use weft::table::{Provenance, Table};

const H: f64 = 1e-3;
const E: f64 = 200e9;
const SY: f64 = 250e6;
const ET: f64 = 2e9;

fn steel() -> PartProps {
    PartProps {
        youngs_modulus: Some(E),
        poisson_ratio: Some(0.3),
        density: Some(7850.0),
        yield_stress: Some(SY),
        tangent_modulus: Some(ET),
        ..Default::default()
    }
}

/// The cube of side H on its symmetry planes, pulled by `force` [N] in all (a ramp
/// over `duration`, the end time), mass damping `alpha` [1/s].
fn pulled_cube(props: PartProps, force: f64, duration: f64, alpha: f64) -> Model {
    let mut m = hex_block(1, 1, 1, H, "cube", props);
    for (i, x) in m.coords.clone().iter().enumerate() {
        m.constraints
            .push((i, [x[0] == 0.0, x[1] == 0.0, x[2] == 0.0]));
        if x[0] == H {
            m.loads.push(Load {
                id: m.loads.len() as i64 + 1,
                node: i,
                force: [0.25 * force, 0.0, 0.0],
                law: TimeLaw::Ramp {
                    start: 0.0,
                    duration,
                },
            });
        }
    }
    m.analysis.end_time = duration;
    m.analysis.output_interval = duration / 100.0;
    m.analysis.mass_damping = alpha;
    m
}

/// Write the model, run `simulate` with element results of `parts` on `threads`
/// threads; the output folder.
fn simulate(m: &Model, parts: &[&str], threads: usize, dir: &Path) -> weft::error::Result<PathBuf> {
    let model = dir.join("model");
    write_model(m, &model, &Provenance::new("test", serde_json::json!({})))?;
    let out = dir.join(format!("run{threads}"));
    run(
        &Config {
            model,
            out: out.clone(),
            threads: Some(threads),
            element_results: parts.iter().map(|s| s.to_string()).collect(),
            ..Default::default()
        },
        &mut |_| {},
    )?;
    Ok(out)
}

/// One hexahedron's rows: t, plastic_strain, temperature, pressure, von_mises_stress.
struct HexRows {
    t: Vec<f64>,
    q: [Vec<f64>; 4],
}

fn hex_rows(out: &Path) -> HexRows {
    let el = Table::read(&out.join("elements.parquet")).unwrap();
    let kind = el.str("kind", "").unwrap();
    assert!(kind.iter().all(|k| k == "hex"), "{kind:?}");
    // The generic columns are null on hex rows (energy included).
    for c in [
        "axial_strain",
        "force_x",
        "strain_11",
        "stress_11",
        "energy",
    ] {
        let v = el.f64_opt(c).unwrap().unwrap();
        assert!(v.iter().all(|x| x.is_none()), "{c} not null on a hex row");
    }
    let col = |c: &str| -> Vec<f64> {
        el.f64_opt(c)
            .unwrap()
            .unwrap()
            .into_iter()
            .map(|x| x.expect("a hex row's own column is not null"))
            .collect()
    };
    HexRows {
        t: el.f64("t", "").unwrap(),
        q: [
            col("plastic_strain"),
            col("temperature"),
            col("pressure"),
            col("von_mises_stress"),
        ],
    }
}

/// ε = ln(L/h) at each output time, L = h + u_x of the node at (h, h, h).
fn log_strain(out: &Path, m: &Model) -> Vec<f64> {
    let hist = Table::read(&out.join("history.parquet")).unwrap();
    let id = hist.i64("node_id", "").unwrap();
    let ux = hist.f64("ux", "").unwrap();
    let corner = m.coords.iter().position(|x| *x == [H, H, H]).unwrap();
    let cid = m.node_id[corner];
    id.iter()
        .zip(&ux)
        .filter(|(i, _)| **i == cid)
        .map(|(_, u)| ((H + u) / H).ln())
        .collect()
}

#[test]
fn a_j2_cube_pulled_past_yield_reports_the_bilinear_plastic_strain_pressure_and_von_mises_stress() {
    // 330 N on 1 mm²: ε_p about 0.048 at the end. The plastic axial mode of the lumped
    // cube, ω = √(E_t A/(h ρV/2)) = 7.1e5 1/s, damped with α = 1e5 1/s; the ramp lasts
    // 4 ms (the lateral stresses of the dynamics, which the uniaxial closed form leaves
    // out, fall as the square of the rate: 8e-4 of σ in p with a 1 ms ramp).
    let m = pulled_cube(steel(), 330.0, 4e-3, 1e5);
    let dir = tempfile::tempdir().unwrap();
    let out = simulate(&m, &["cube"], 1, dir.path()).unwrap();
    let r = hex_rows(&out);
    let eps = log_strain(&out, &m);
    assert_eq!(eps.len(), r.t.len());
    let (mut e_ep, mut e_p, mut e_vm, mut plastic) = (0.0f64, 0.0f64, 0.0f64, 0);
    for k in 0..r.t.len() {
        // Monotone loading: the closed form holds.
        if k > 0 {
            assert!(eps[k] >= eps[k - 1], "unloading at t = {}", r.t[k]);
        }
        let [ep, temp, p, vm] = [r.q[0][k], r.q[1][k], r.q[2][k], r.q[3][k]];
        assert_eq!(temp, 293.15, "a J2 part stays at the room temperature");
        let sigma = if eps[k] * E <= SY {
            E * eps[k]
        } else {
            plastic += 1;
            SY + ET * (eps[k] - SY / E)
        };
        let ep_oracle = (eps[k] - sigma / E).max(0.0);
        e_ep = e_ep.max((ep - ep_oracle).abs());
        e_vm = e_vm.max((vm - sigma).abs() / sigma.max(SY));
        e_p = e_p.max((p + sigma / 3.0).abs() / sigma.max(SY));
    }
    let ep_end = *r.q[0].last().unwrap();
    eprintln!(
        "J2 cube: {plastic} plastic samples of {}, final ε_p {ep_end:.4e} (ε {:.4e}); largest |Δε_p| {e_ep:.2e}, σ̄ relative {e_vm:.2e}, p relative {e_p:.2e}",
        r.t.len(),
        eps.last().unwrap()
    );
    assert!(plastic > 20 && ep_end > 0.04);
    // Measured 2.0e-8 absolute against ε_p = 0.048; tolerance 1e-7.
    assert!(e_ep < 1e-7, "plastic strain off by {e_ep:e}");
    // Measured 1.3e-6 relative; tolerance 5e-6.
    assert!(e_vm < 5e-6, "von Mises stress off by {e_vm:e}");
    // Measured 4.0e-5 relative (p = −σ/3, compression positive: the sign swapped is 2/3
    // off); tolerance 1.5e-4.
    assert!(e_p < 1.5e-4, "pressure off by {e_p:e}");
    // weft-vtk carries the new columns as cell data.
    let vtk = weft::vtk::run(&weft::vtk::Config {
        model: dir.path().join("model"),
        history: out.join("history.parquet"),
        out: dir.path().join("vtk"),
        every: 50,
        reference_points: false,
    })
    .unwrap();
    for c in [
        "plastic_strain",
        "temperature",
        "pressure",
        "von_mises_stress",
    ] {
        assert!(
            vtk.element_results.iter().any(|x| x == c),
            "{c} not in the VTK cell data"
        );
    }
}

#[test]
fn a_johnson_cook_cube_heats_by_the_taylor_quinney_share_of_its_plastic_work() {
    // 245 N on 1 mm² of copper: ε_p about 0.2. Elastic axial mode ω = √(E A/(h ρV/2))
    // = 5.3e6 1/s; the hardening slope falls from ∞ at yield: α = 1e5 1/s, a 4 ms ramp.
    let p = copper();
    let (rho, cp, e) = (8960.0, 383.0, 124e9);
    let beta = 0.9; // weft's default Taylor–Quinney fraction (material::TAYLOR_QUINNEY)
    let m = pulled_cube(p, 245.0, 4e-3, 1e5);
    let dir = tempfile::tempdir().unwrap();
    let out = simulate(&m, &["cube"], 1, dir.path()).unwrap();
    let r = hex_rows(&out);
    let eps = log_strain(&out, &m);
    let [ep, temp, pr, vm] = &r.q;
    let (mut work, mut e_t, mut e_ep, mut e_p) = (0.0, 0.0f64, 0.0f64, 0.0f64);
    for k in 0..r.t.len() {
        if k > 0 {
            assert!(eps[k] >= eps[k - 1], "unloading at t = {}", r.t[k]);
            work += 0.5 * (vm[k] + vm[k - 1]) * (ep[k] - ep[k - 1]);
        }
        let dt_oracle = beta * work / (rho * cp);
        e_t = e_t.max((temp[k] - 293.15 - dt_oracle).abs());
        if ep[k] > 0.0 {
            e_ep = e_ep.max((ep[k] - (eps[k] - vm[k] / e)).abs());
        }
        e_p = e_p.max((pr[k] + vm[k] / 3.0).abs() / vm[k].max(90e6));
    }
    let rise = temp.last().unwrap() - 293.15;
    eprintln!(
        "Johnson–Cook cube: final ε_p {:.4e}, σ̄ {:.4e} Pa, T rise {rise:.4} K (oracle {:.4} K); largest |ΔT| {e_t:.2e} K, |Δε_p| {e_ep:.2e}, p relative {e_p:.2e}",
        ep.last().unwrap(),
        vm.last().unwrap(),
        beta * work / (rho * cp)
    );
    assert!(*ep.last().unwrap() > 0.1 && rise > 5.0);
    // Measured 8.6e-4 K against a rise of 7.89 K (the oracle's trapezoid over 100
    // samples against the material's step-by-step sum); tolerance 3e-3 K.
    assert!(e_t < 3e-3, "temperature off by {e_t:e} K");
    // Measured 1.7e-7 absolute against ε_p = 0.129; tolerance 6e-7.
    assert!(e_ep < 6e-7, "plastic strain off by {e_ep:e}");
    // Measured 2.4e-4 relative (the dynamics' lateral stress near yield, where the
    // hardening is steepest); tolerance 8e-4.
    assert!(e_p < 8e-4, "pressure off by {e_p:e}");
}

#[test]
fn a_block_of_hexahedra_writes_the_same_element_results_on_one_and_two_threads() {
    // 1210 elements: more than one chunk of 1024, so the family runs in parallel.
    let m = struck_block();
    let dir = tempfile::tempdir().unwrap();
    let read = |threads: usize| {
        let out = simulate(&m, &["all"], threads, dir.path()).unwrap();
        Table::read(&out.join("elements.parquet")).unwrap()
    };
    let (a, b) = (read(1), read(2));
    assert_eq!(a.num_rows(), 31 * 1210);
    for c in [
        "plastic_strain",
        "temperature",
        "pressure",
        "von_mises_stress",
    ] {
        let (x, y) = (
            a.f64_opt(c).unwrap().unwrap(),
            b.f64_opt(c).unwrap().unwrap(),
        );
        let bits =
            |v: &Vec<Option<f64>>| v.iter().map(|x| x.unwrap().to_bits()).collect::<Vec<_>>();
        assert!(bits(&x) == bits(&y), "{c} differs on 1 and 2 threads");
    }
    assert_eq!(
        a.i64("element_id", "").unwrap(),
        b.i64("element_id", "").unwrap()
    );
    let ep = a.f64_opt("plastic_strain").unwrap().unwrap();
    let t = a.f64_opt("temperature").unwrap().unwrap();
    let top = ep.iter().fold(0.0f64, |m, x| m.max(x.unwrap()));
    let hot = t.iter().fold(0.0f64, |m, x| m.max(x.unwrap()));
    eprintln!("struck block: largest ε_p {top:.3e}, T {hot:.2} K");
    assert!(top > 0.0 && hot > 293.15);
}

#[test]
fn an_eroded_hexahedron_keeps_its_row_with_the_strain_it_eroded_with_and_no_stress() {
    let mut p = steel();
    p.erosion_plastic_strain = Some(0.02);
    let mut m = pulled_cube(p, 330.0, 4e-3, 1e5);
    m.analysis.end_time = 3.9e-3;
    let dir = tempfile::tempdir().unwrap();
    let out = simulate(&m, &["cube"], 1, dir.path()).unwrap();
    let r = hex_rows(&out);
    let [ep, _, pr, vm] = &r.q;
    let k = ep.iter().position(|&x| x >= 0.02).expect("it eroded");
    eprintln!("eroded at sample {k} of {}, ε_p {:.4e}", r.t.len(), ep[k]);
    assert!(k + 1 < r.t.len());
    for j in k..r.t.len() {
        assert_eq!((pr[j], vm[j], ep[j]), (0.0, 0.0, ep[k]), "sample {j}");
    }
    assert!(vm[k - 1] > SY);
}

#[test]
fn element_results_of_a_part_that_does_not_exist_are_refused_naming_it() {
    let m = pulled_cube(steel(), 100.0, 1e-5, 0.0);
    let dir = tempfile::tempdir().unwrap();
    let err = simulate(&m, &["cube", "nope"], 1, dir.path())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("no part `nope`") && err.contains("`cube`"),
        "{err}"
    );
}
