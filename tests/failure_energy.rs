//! The energy balance through and after failures (docs/theory.md, "Failure, perforation
//! and the ballistic limit"): E_kin + E_int + contact + eroded = E₀ + W_ext, and what
//! breaks it when yarns break.
//!
//! Oracles, each independent of the code:
//! - energy conservation: no force of these models dissipates, so every joule the ledger
//!   loses or gains is an error;
//! - a contact spring that leaves with its face holds ½ k g² (k = κ_c m*/Δt², g its
//!   penetration): what the eroded energy must book when the face's element fails;
//! - the elastic collision of two masses along a line (momentum and energy kept):
//!   m hitting M at rest at u leaves at (m − M)/(m + M) u, M at 2m/(m + M) u.

mod common;
use common::rel;
use weft::generate::woven::{woven, Edge, WovenBandParams, YarnFailure, YarnModel};
use weft::model::contacts::{ContactDef, InitialPenetration, Slave};
use weft::model::{Analysis, ElementKind, Model, PartProps, ProjectileShape, ProjectileSpec};
use weft::solver::run_in_memory;
use weft::solver::watch::Outcome;

/// A point mass `mass` on node `n` (part and element ids `id`).
fn point_mass(m: &mut Model, n: usize, mass: f64, id: i64) {
    let p = m.add_part(
        id,
        &format!("mass_{id}"),
        ElementKind::PointMass,
        PartProps {
            mass: Some(mass),
            ..Default::default()
        },
    );
    m.add_element(id, p, &[n]);
}

/// The largest |balance error| over the samples, over the energy scale at the end.
fn worst_balance(out: &weft::solver::output::MemorySink) -> f64 {
    let e = out.energy.last().unwrap();
    out.energy
        .iter()
        .map(|x| x.balance_error.abs())
        .fold(0.0, f64::max)
        / e.scale
}

/// A truss pulled to failure while a node rests pressed into it.
///
/// ```text
///                 o  ball: fixed, g₀ into the segment (contact kept from the start)
///   A o===========|===========o-[M]-> V     A fixed; B moves along x only
/// ```
/// The ball and the segment's nodes do no work on each other (the ball is held, the
/// reaction on the segment is normal to it and its nodes move along it), so the spring
/// holds ½ k g₀² throughout, and takes exactly that when the segment fails.
#[test]
fn a_segment_that_fails_under_a_pressed_node_takes_the_contact_energy() {
    let (l, area, v, big) = (1e-3, 1e-8, 10.0, 1e-4);
    let (t_c, g0, m_ball, dt) = (1e-4, 2e-5, 1e-6, 1e-7);
    let mut m = Model::default();
    let a = m.add_node(1, [0.0, 0.0, 0.0]);
    let b = m.add_node(2, [l, 0.0, 0.0]);
    // The contact distance is (t_s + t_F)/2 = t_c.
    let ball = m.add_node(3, [0.5 * l, 0.0, t_c - g0]);
    let seg = m.add_part(
        1,
        "segment",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(80e9),
            density: Some(1440.0),
            area: Some(area),
            failure_strain: Some(0.036),
            ..Default::default()
        },
    );
    m.add_element(1, seg, &[a, b]);
    point_mass(&mut m, b, big, 10);
    point_mass(&mut m, ball, m_ball, 11);
    m.constraints.push((a, [true, true, true]));
    m.constraints.push((b, [false, true, true]));
    m.constraints.push((ball, [true, true, true]));
    m.initial_velocities.push((b, [v, 0.0, 0.0]));
    m.node_sets.insert("ball".into(), vec![ball]);
    let mut c = ContactDef::new(1, Slave::Set("ball".into()), seg);
    c.slave_thickness = Some(t_c);
    c.master_thickness = Some(t_c);
    c.initial_penetration = InitialPenetration::Keep;
    m.contacts.push(c);
    m.analysis = Analysis {
        end_time: 2e-5,
        output_interval: 1e-7,
        time_step: Some(dt),
        ..Analysis::default()
    };
    let (s, out, _) = run_in_memory(&m).unwrap();
    // The segment fails at 3.6 % (after 36 steps at 10⁴ s⁻¹).
    assert_eq!(s.failure_log().events.len(), 1);
    // m* = min(m_ball, the foot's mass ½(m_A + m_B)) = m_ball.
    let k = 0.1 * m_ball / (dt * dt);
    let want = 0.5 * k * g0 * g0;
    let got = s.operator().surfaces.eroded;
    let bal = worst_balance(&out);
    println!(
        "contact energy taken {got:.9e} J, ½ k g₀² {want:.9e} J ({:.1e}); element's {:.4e} J; worst balance {bal:.1e}",
        rel(got, want),
        s.failure_log().events[0].failure.energy
    );
    // Measured 1.7·10⁻¹⁵.
    assert!(rel(got, want) < 1e-14, "{got} against {want}");
    // Measured 7.4·10⁻¹⁶. Without the booking the ledger lost ½ k g₀² = 2·10⁻³ J at the
    // failure, 29 % of the 7·10⁻³ J the run starts with (the mass's 5·10⁻³, the
    // spring's 2·10⁻³), and the run stopped on the energy guard.
    assert!(bal < 5e-15, "balance {bal:e}");
}

/// A node that catches up with a resting cylinder from behind, on the axis at ρ = R/2:
/// it must meet the back face and bounce off it, an elastic collision.
fn hit_from_behind(shape: ProjectileShape) {
    let (r, len, mass_p) = (1e-3, 4e-3, 2e-6);
    let (m_node, u, k, dt) = (1e-6, 10.0, 1e3, 1e-8);
    let mut m = Model::default();
    // The projectile travels along −z from its tip at z = 0: its back face is at z = len.
    // The node reaches it at exactly ten steps.
    let n = m.add_node(1, [0.5 * r, 0.0, len + 10.0 * u * dt]);
    point_mass(&mut m, n, m_node, 1);
    m.initial_velocities.push((n, [0.0, 0.0, -u]));
    m.projectiles.push(ProjectileSpec {
        id: 1,
        shape,
        radius: r,
        length: len,
        mass: mass_p,
        tip: [0.0; 3],
        axis: [0.0, 0.0, -1.0],
        velocity: [0.0; 3],
        prescribed_velocity: false,
        contact_stiffness: Some(k),
        friction: 0.0,
        contact_damping: 0.0,
        segment_contact: false,
    });
    // Contact lasts π√(μ/k) = 81 µs (μ the reduced mass), its deepest u√(μ/k) = 0.26 mm,
    // within the 0.5 mm from the side.
    m.analysis = Analysis {
        end_time: 1.5e-4,
        output_interval: 1e-6,
        time_step: Some(dt),
        ..Analysis::default()
    };
    let (s, out, _) = run_in_memory(&m).unwrap();
    let v_node = out.v.last().unwrap()[0];
    let v_proj = s.operator().projectiles.projectiles[0].v_full;
    let tot = m_node + mass_p;
    let (want_node, want_proj) = (-u * (m_node - mass_p) / tot, -u * 2.0 * m_node / tot);
    let bal = worst_balance(&out);
    println!(
        "{shape:?}: node {:.6} m/s (closed form {want_node:.6}, {:.1e}), projectile {:.6} m/s ({want_proj:.6}, {:.1e}), worst balance {bal:.1e}",
        v_node[2],
        rel(v_node[2], want_node),
        v_proj[2],
        rel(v_proj[2], want_proj)
    );
    // The node leaves backwards (+z) as it came, nothing sideways: measured 0.
    assert!(v_node[0] == 0.0 && v_node[1] == 0.0, "{v_node:?}");
    // Measured 3.7·10⁻⁸ and 9.3·10⁻⁹ (both shapes): the penalty's release within a step.
    assert!(rel(v_node[2], want_node) < 1e-7, "{v_node:?}");
    assert!(rel(v_proj[2], want_proj) < 3e-8, "{v_proj:?}");
    // Measured 2.5·10⁻⁸. Without the back face the node went from no penetration to
    // R − ρ = 0.5 mm in one step: 1.25·10⁻⁴ J stored out of nothing, 2.5 × the 5·10⁻⁵ J
    // of the run (which stopped on the energy guard), pushing it out sideways.
    assert!(bal < 1e-7, "balance {bal:e}");
}

#[test]
fn a_node_from_behind_meets_a_flat_nosed_cylinders_back_face() {
    hit_from_behind(ProjectileShape::Flat);
}

#[test]
fn a_node_from_behind_meets_a_round_nosed_cylinders_back_face() {
    hit_from_behind(ProjectileShape::Round);
}

/// The issue's case: a chain patch (10 yarns per side of the quarter, clamped edges, no
/// friction, no contact damping) struck near its ballistic limit, at 30 m/s, run 500 µs:
/// its yarns break from 96 µs on, the broken ends recoil through the crossings at
/// 300–500 m/s, the projectile perforates at about 280 µs, and the fragments fly on.
#[test]
fn a_chain_patch_keeps_its_energy_long_after_its_yarns_break() {
    let p = WovenBandParams {
        yarns: 10,
        yarn_model: YarnModel::Chain,
        friction: 0.0,
        projectile_friction: 0.0,
        edge: Edge::Clamped,
        projectile_velocity: 30.0,
        failure: YarnFailure {
            strain: 0.036,
            contact_damping: Some(0.0),
            ..YarnFailure::default()
        },
        end_time: 5e-4,
        output_interval: 2e-6,
        dt_safety: 0.6,
        ..WovenBandParams::default()
    };
    let (m, _) = woven(&p).unwrap();
    let (s, out, stats) = run_in_memory(&m).unwrap();
    let first = s.failure_log().events.first().map(|e| e.time).unwrap();
    let bal = worst_balance(&out);
    println!(
        "{} failures from {:.1} µs, {:?}; worst balance {bal:.2e} ({:.2e} J), run's {:.2e}",
        s.failure_log().events.len(),
        first * 1e6,
        s.watch().outcome,
        bal * out.energy.last().unwrap().scale,
        stats.max_balance_error_relative
    );
    assert!(s.failure_log().events.len() >= 5);
    assert!(matches!(s.watch().outcome, Outcome::Perforated { .. }));
    assert!(first < 1.2e-4 && stats.end_time == 5e-4);
    // Measured 4.56·10⁻³ of the 0.9 J impact under the per-face law after a failure
    // (`Side::per_face`; 2.15·10⁻³ under the deepest-face law before it, whose kinked
    // potential cost 1.5·10⁻² in a squeezed stack of plies: `tests/ballistic.rs`; the
    // bound is the issue's 0.5 %). Before either (the shared law throughout) the error was 4.2·10⁻² when
    // the projectile perforated and the run stopped on the energy guard at 328 µs (23 %):
    // a slave's contact along the penetration-weighted normal of the faces it penetrates
    // is not the gradient of the ½ k g² the ledger books, and gained energy as broken
    // ends slid through the crossings.
    assert!(bal < 5e-3, "balance {bal:e}");
}
