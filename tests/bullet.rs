//! The deformable 9 mm bullet in the yarn-level patch (`weft-weave woven --projectile
//! deformable`): lead hexahedra meeting aramid chains both ways through the general
//! contact, the yarns failing.
//!
//! Oracles:
//! - energy conservation: the ledger's balance (the issue asks ≤ 1 %);
//! - the lead's volume: its pressure is hypoelastic, dp = −K tr D dt, and plasticity is
//!   deviatoric (J2 and Johnson–Cook return along the deviator), so each hexahedron's
//!   pressure is −K ln(V/V₀) (tr D dt sums to ln V/V₀ for the mid-step gradient, to
//!   O(Δt²)); K = E/(3(1 − 2ν)) (Simo & Hughes, *Computational Inelasticity*, §9.1 for the
//!   split, Belytschko, Liu & Moran §5.6 for hypoelastic rates);
//! - mass: the meshed bullet is the NIJ round's 8.0 g (a quarter, 2 g), to round-off;
//! - the same bits on one and two threads.

mod common;
use common::solid::on_threads;
use weft::generate::bullet::{BulletKind, BulletParams};
use weft::generate::woven::{woven, WovenBandParams, YarnFailure, YarnModel};
use weft::generate::woven_reduced::{woven_reduced, WovenParams};
use weft::material::pressure;
use weft::model::Model;
use weft::shape::hex8::hex_geometry;
use weft::solver::{run_in_memory, RunStats, Solver};

fn patch(kind: BulletKind, velocity: f64, end_time: f64) -> Model {
    let p = WovenBandParams {
        yarns: 10,
        yarn_model: YarnModel::Chain,
        failure: YarnFailure {
            strain: 0.036,
            ..Default::default()
        },
        projectile_velocity: velocity,
        end_time,
        output_interval: end_time / 20.0,
        bullet: Some(BulletParams {
            kind,
            ..Default::default()
        }),
        ..Default::default()
    };
    woven(&p).unwrap().0
}

/// (length along z, diameter) of the bullet at positions `x`.
fn bullet_shape(m: &Model, x: &[[f64; 3]]) -> (f64, f64) {
    let nodes = m.bullet_nodes().unwrap();
    let (mut lo, mut hi, mut r) = (f64::MAX, f64::MIN, 0.0f64);
    for &i in nodes {
        lo = lo.min(x[i][2]);
        hi = hi.max(x[i][2]);
        r = r.max(x[i][0].hypot(x[i][1]));
    }
    (hi - lo, 2.0 * r)
}

fn run(m: &Model) -> (Solver, RunStats) {
    let (s, _, st) = run_in_memory(m).unwrap();
    (s, st)
}

#[test]
fn a_lead_bullet_in_a_chain_patch_balances_energy_and_keeps_its_volume_law() {
    let m = patch(BulletKind::Lead, 400.0, 1.5e-5);
    let bullet_mass: f64 = {
        let s = weft::solver::Solver::new(&m).unwrap();
        m.bullet_nodes()
            .unwrap()
            .iter()
            .map(|&i| s.masses()[i])
            .sum()
    };
    // A quarter of 8.0 g (the mesh's exact volume times ρ; lumped masses sum to it).
    assert!((bullet_mass - 2e-3).abs() < 1e-15, "{bullet_mass}");
    let (s, st) = run(&m);
    let (len0, dia0) = bullet_shape(&m, &m.coords);
    let (len, dia) = bullet_shape(&m, &s.state().xn);
    // The stress is that of x^n, the last sample's positions (`xn`; `x` is a step ahead).
    let (worst, pmax) = pressure_law(&s);
    let e = st.final_energies;
    eprintln!(
        "lead bullet at 400 m/s, 15 µs: length {:.4} mm, diameter {:.4} mm ({:.4}, {:.4} at rest); balance {:.2e}; hourglass {:.2e} J; pressure against −K ln(V/V₀): {worst:.3e} Pa of {pmax:.3e} Pa; {} steps, smallest step {:.3} of the first",
        len * 1e3,
        dia * 1e3,
        len0 * 1e3,
        dia0 * 1e3,
        st.max_balance_error_relative,
        e.hourglass,
        st.steps,
        s.time_step().dt_min / s.time_step().dt
    );
    // Measured 1.53e-4 (the issue asks ≤ 1 %; 1.38e-3 before solid faces stopped
    // catching nodes deep behind them).
    assert!(st.max_balance_error_relative < 4e-4);
    // Measured 7.0 Pa of 22 MPa (3.2e-7): the mid-step rule's Σ tr D Δt differs from
    // ln V/V₀ by O(Δt²) a step; tolerance 8e-7.
    assert!(worst < 8e-7 * pmax, "{worst} of {pmax}");
    // The nose has started to flatten on the yarns: shorter and wider than at rest.
    assert!(dia > dia0 && len < len0, "{len0} {dia0} -> {len} {dia}");
}

/// Each hexahedron's pressure against −K ln(V/V₀) at the last sample: the worst
/// difference and the largest pressure [Pa].
fn pressure_law(s: &Solver) -> (f64, f64) {
    let hex = &s.operator().el.hex;
    let (mut worst, mut pmax) = (0.0f64, 0.0f64);
    for e in 0..hex.nodes.len() {
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| s.state().xn[hex.nodes[e][a] as usize]);
        let v = hex_geometry(&x).volume;
        let (lam, mu) = hex.materials[hex.material[e] as usize].lame();
        let p = pressure(&hex.state[e].stress);
        worst = worst.max((p + (lam + 2.0 * mu / 3.0) * (v / hex.v0[e]).ln()).abs());
        pmax = pmax.max(p.abs());
    }
    (worst, pmax)
}

#[test]
fn a_lead_bullet_in_the_reduced_girder_balances_energy_and_keeps_its_volume_law() {
    // The paper's §5 reduced model (trusses and links in the graded membrane) against
    // the lead bullet at 400 m/s, 30 µs.
    let m = woven_reduced(&WovenParams {
        end_time: 3e-5,
        bullet: Some(BulletParams::default()),
        ..Default::default()
    })
    .unwrap();
    let (s, st) = run(&m);
    let (len0, dia0) = bullet_shape(&m, &m.coords);
    let (len, dia) = bullet_shape(&m, &s.state().xn);
    let (worst, pmax) = pressure_law(&s);
    eprintln!(
        "lead bullet into the reduced model, 30 µs: length {:.4} mm, diameter {:.4} mm ({:.4}, {:.4} at rest); balance {:.2e}; pressure law {worst:.3e} Pa of {pmax:.3e} Pa",
        len * 1e3,
        dia * 1e3,
        len0 * 1e3,
        dia0 * 1e3,
        st.max_balance_error_relative
    );
    // Measured 3.4e-5 (the issue asks ≤ 1 %); the pressure law 12 Pa of 194 MPa (6.4e-8,
    // tolerance 2e-7); the nose 12.68 → 12.32 mm long, 9.00 → 9.28 mm across.
    assert!(st.max_balance_error_relative < 1e-4);
    assert!(worst < 2e-7 * pmax, "{worst} of {pmax}");
    assert!(dia > dia0 && len < len0, "{len0} {dia0} -> {len} {dia}");
}

#[test]
fn an_fmj_bullet_runs_the_same_on_one_and_two_threads() {
    let m = patch(BulletKind::Fmj, 400.0, 5e-6);
    let go = |threads: usize| on_threads(threads, || run_in_memory(&m).unwrap());
    let (s1, o1, st1) = go(1);
    let (s2, o2, st2) = go(2);
    assert!(o1.u == o2.u && o1.energy == o2.energy && st1.steps == st2.steps);
    assert!(s1.state().x == s2.state().x);
    assert!(s1.operator().el.hex.state == s2.operator().el.hex.state);
}
