//! The Taylor test (`weft-weave taylor`): a flat-ended metal rod on a rigid wall, in
//! hexahedra with the variable step.
//!
//! Oracles:
//! - Taylor's one-dimensional theory (G. I. Taylor, *The use of flat-ended projectiles for
//!   determining dynamic yield stress. I. Theoretical considerations*, Proc. R. Soc. A 194
//!   (1948) 289–299): a rigid-perfectly plastic rod of yield stress Y; its undeformed
//!   length ℓ moving at u decelerates as ρℓ u̇ = −Y, the plastic front runs into it at v
//!   from the wall with Y = ρ v (u + v) (mass and momentum across the front, the crushed
//!   part at rest), ℓ̇ = −(u + v), the crushed length h grows as ḣ = v; integrated here
//!   (RK4 in u) until u = 0, the final length is ℓ + h. For a rod of elastic–perfectly
//!   plastic material the finite elements must approach it as the mesh is refined (the
//!   theory leaves out elasticity and radial inertia, a few per cent at these speeds:
//!   Wilkins & Guinan, J. Appl. Phys. 44 (1973) 1200, their Fig. 9);
//! - convergence: the final length and foot diameter of Johnson & Cook's (1983) OFHC
//!   copper and 2024-T351 aluminium rods settle as the mesh is refined (differences
//!   shrinking from one mesh to the next);
//! - energy conservation (the ledger's balance), and hourglass energy a small part of the
//!   internal energy;
//! - the same bits on one and two threads.

mod common;
use common::solid::on_threads;
use weft::generate::metals::Metal;
use weft::generate::taylor::{taylor, TaylorParams};
use weft::model::Model;
use weft::solver::{run_in_memory, RunStats, Solver};

/// What a Taylor run ends with.
#[derive(Debug, Clone, Copy)]
struct Shape {
    /// Final length (axis, rear to wall side) [m].
    length: f64,
    /// Foot diameter (twice the impact edge's largest radius) [m].
    foot: f64,
    hourglass_share: f64,
    balance: f64,
    steps: u64,
    dt_ratio: f64,
}

fn shape(m: &Model, s: &Solver, st: &RunStats) -> Shape {
    let x = &s.state().x;
    let axis = &m.node_sets["axis"];
    let (lo, hi) = axis.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &i| {
        (lo.min(x[i][2]), hi.max(x[i][2]))
    });
    let foot = m.node_sets["impact_edge"]
        .iter()
        .fold(0.0f64, |r, &i| r.max(x[i][0].hypot(x[i][1])));
    let e = st.final_energies;
    Shape {
        length: hi - lo,
        foot: 2.0 * foot,
        hourglass_share: e.hourglass / e.internal,
        balance: st.max_balance_error_relative,
        steps: st.steps,
        dt_ratio: s.time_step().dt_min / s.time_step().dt,
    }
}

fn run(p: &TaylorParams) -> Shape {
    let m = taylor(p).unwrap();
    let (s, _, st) = run_in_memory(&m).unwrap();
    let r = shape(&m, &s, &st);
    eprintln!(
        "{} N = {}: U {} m/s, L₁ {:.4} mm, foot {:.4} mm, hourglass {:.2} % of internal, balance {:.2e}, {} steps, smallest step {:.3} of the first",
        p.material.name(),
        p.radial,
        p.velocity,
        r.length * 1e3,
        r.foot * 1e3,
        100.0 * r.hourglass_share,
        r.balance,
        r.steps,
        r.dt_ratio
    );
    r
}

/// Taylor's (1948) one-dimensional final length of a rigid-perfectly plastic rod of
/// length L, density ρ and yield stress Y striking a rigid wall at U: the equations of the
/// module doc integrated by RK4 in u from U to 0 (t, ℓ, h as functions of u, with
/// dt/du = −ρℓ/Y), n steps.
fn taylor_final_length(l: f64, u0: f64, rho: f64, y: f64, n: usize) -> f64 {
    let rates = |u: f64, ell: f64| {
        let v = 0.5 * (-u + (u * u + 4.0 * y / rho).sqrt());
        let dtdu = -rho * ell / y;
        (-(u + v) * dtdu, v * dtdu)
    };
    let (mut ell, mut h, mut u) = (l, 0.0, u0);
    let du = -u0 / n as f64;
    for _ in 0..n {
        let k1 = rates(u, ell);
        let k2 = rates(u + 0.5 * du, ell + 0.5 * du * k1.0);
        let k3 = rates(u + 0.5 * du, ell + 0.5 * du * k2.0);
        let k4 = rates(u + du, ell + du * k3.0);
        ell += du * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0) / 6.0;
        h += du * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1) / 6.0;
        u += du;
    }
    ell + h
}

#[test]
fn taylors_one_dimensional_theory_is_approached_by_an_elastic_perfectly_plastic_rod() {
    // Copper's density and elasticity, J2 with Y = 300 MPa and no hardening: Taylor's
    // material. RK4 with 2·10⁴ and 4·10⁴ steps agree to 1e-12 m: the oracle is exact.
    let y = 300e6;
    let base = TaylorParams {
        yield_stress: Some(y),
        ..Default::default()
    };
    let rho = Metal::Copper.constants().density;
    let theory = taylor_final_length(base.length, base.velocity, rho, y, 20_000);
    let fine = taylor_final_length(base.length, base.velocity, rho, y, 40_000);
    assert!((theory - fine).abs() < 1e-12, "{theory} vs {fine}");
    let err = |n: usize| {
        let r = run(&TaylorParams {
            radial: n,
            ..base.clone()
        });
        ((r.length - theory) / theory, r)
    };
    let (e4, r4) = err(4);
    let (e8, r8) = err(8);
    eprintln!(
        "Taylor (1948): L₁ {:.4} mm; N = 4: {:+.2} %, N = 8: {:+.2} %",
        theory * 1e3,
        100.0 * e4,
        100.0 * e8
    );
    // Measured +2.27 % (N = 4), +0.95 % (N = 8): closer on the finer mesh, within 2 %
    // (2 × the measured 0.95 %) on it.
    assert!(e8.abs() < e4.abs(), "N = 8 {e8} not closer than N = 4 {e4}");
    assert!(e8.abs() < 0.02, "N = 8: {e8} from Taylor's theory");
    // Measured 1.6e-4, 4.9e-5 (the issue asks ≤ 1 %).
    assert!(r4.balance < 5e-4 && r8.balance < 1.5e-4, "{r4:?} {r8:?}");
    // Measured 7.2 %, 2.3 %: the perfectly plastic foot spreads to 2.4 D, its corner
    // elements the most distorted; the finer mesh under the 5 % (tolerance 2 ×
    // measured).
    assert!(r8.hourglass_share < 0.046, "{r8:?}");
}

/// Final length and foot of a Johnson–Cook rod on three meshes: both settle (the change
/// from N = 4 to 8 smaller than from 2 to 4), energy balances, hourglass small.
fn converges(metal: Metal, velocity: f64) -> [Shape; 3] {
    let p = |n: usize| TaylorParams {
        material: metal,
        velocity,
        radial: n,
        ..Default::default()
    };
    let r = [run(&p(2)), run(&p(4)), run(&p(8))];
    let d = |f: fn(&Shape) -> f64| [f(&r[1]) - f(&r[0]), f(&r[2]) - f(&r[1])];
    let (dl, df) = (d(|s| s.length), d(|s| s.foot));
    eprintln!(
        "{}: L₁ changes {:+.3} then {:+.3} mm, foot {:+.3} then {:+.3} mm",
        metal.name(),
        dl[0] * 1e3,
        dl[1] * 1e3,
        df[0] * 1e3,
        df[1] * 1e3
    );
    assert!(dl[1].abs() < dl[0].abs(), "{}: length {dl:?}", metal.name());
    assert!(df[1].abs() < df[0].abs(), "{}: foot {df:?}", metal.name());
    r
}

#[test]
fn johnson_and_cooks_copper_rod_converges_with_the_mesh() {
    let r = converges(Metal::Copper, 190.0);
    // Measured: L₁ 17.37, 17.20, 17.19 mm; foot 13.43, 14.23, 14.67 mm. Balance 2.2e-4,
    // 1.6e-4, 3.9e-5 (≤ 1 % asked); hourglass 8.6 %, 4.0 %, 1.3 % of the internal energy
    // (under the 5 % from N = 4).
    assert!(r.iter().all(|s| s.balance < 5e-4), "{r:?}");
    assert!(
        r[1].hourglass_share < 0.05 && r[2].hourglass_share < 0.026,
        "{r:?}"
    );
    // A bracket from the theory of the test above: the rod hardens from Johnson–Cook's
    // A = 90 MPa to below its flow stress at ε_p = 1 and 10⁴ /s, 470 MPa, so its length
    // lies between the lengths of rigid-perfectly plastic rods of those two yield
    // stresses (8.9 and 19.3 mm; 17.2 mm measured, which the theory gives for 330 MPa).
    let y_lo = 90e6;
    let y_hi = (90e6 + 292e6 * 1.0f64.powf(0.31)) * (1.0 + 0.025 * 1e4f64.ln());
    let rho = Metal::Copper.constants().density;
    let l = |y: f64| taylor_final_length(25.4e-3, 190.0, rho, y, 20_000);
    assert!(r[2].length > l(y_lo) && r[2].length < l(y_hi), "{r:?}");
}

#[test]
fn the_aluminium_rod_converges_with_the_mesh() {
    // 2024-T351 at 200 m/s: L₁ 23.12, 23.08, 23.05 mm, foot 9.54, 9.80, 9.81 mm
    // (measured); balance 1.4e-4, 1.9e-5, 1.1e-5; hourglass 4.0 %, 1.5 %, 0.47 %.
    let r = converges(Metal::Aluminium, 200.0);
    assert!(r.iter().all(|s| s.balance < 4e-4), "{r:?}");
    assert!(
        r[1].hourglass_share < 0.03 && r[2].hourglass_share < 0.01,
        "{r:?}"
    );
}

#[test]
fn a_taylor_rod_runs_the_same_on_one_and_two_threads() {
    let m = taylor(&TaylorParams::default()).unwrap();
    let go = |threads: usize| on_threads(threads, || run_in_memory(&m).unwrap());
    let (s1, o1, st1) = go(1);
    let (s2, o2, st2) = go(2);
    assert!(o1.u == o2.u && o1.energy == o2.energy && st1.steps == st2.steps);
    assert_eq!(
        s1.time_step().dt_min.to_bits(),
        s2.time_step().dt_min.to_bits()
    );
    assert!(s1.operator().el.hex.state == s2.operator().el.hex.state);
}
