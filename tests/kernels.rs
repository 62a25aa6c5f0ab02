//! Element kernels: internal force equals minus the gradient of the stored energy
//! (checked by central finite differences), no force under rigid rotation, and
//! objectivity (a rotated deformed element gives the rotated force).
//!
//! Reference: Belytschko, Liu, Moran, *Nonlinear Finite Elements*, §2.8 (corotational
//! rod), §4.6 (objectivity); Crisfield, *Non-linear Finite Element Analysis of Solids and
//! Structures*, vol. 1, §3.3 (the rod's internal force as the energy gradient).

mod common;
use weft::generate::rod::{build, RodParams};
use weft::model::{ElementKind, Model, PartProps};
use weft::solver::link::{self, LinkProps};
use weft::solver::truss;

/// A deterministic pseudo-random sequence (xorshift), so failures reproduce.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
    fn vec(&mut self, s: f64) -> [f64; 3] {
        [s * self.next(), s * self.next(), s * self.next()]
    }
}

fn rotation(axis: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let [x, y, z] = [axis[0] / n, axis[1] / n, axis[2] / n];
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

fn rot(r: &[[f64; 3]; 3], v: &[f64; 3]) -> [f64; 3] {
    [
        r[0][0] * v[0] + r[0][1] * v[1] + r[0][2] * v[2],
        r[1][0] * v[0] + r[1][1] * v[1] + r[1][2] * v[2],
        r[2][0] * v[0] + r[2][1] * v[1] + r[2][2] * v[2],
    ]
}

#[test]
fn truss_force_is_minus_energy_gradient() {
    let mut rng = Rng(0x9e3779b97f4a7c15);
    for case in 0..200 {
        let x1 = rng.vec(1.0);
        let x2 = rng.vec(1.0);
        let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        // Reference lengths from 20 % compression to 20 % extension.
        let l0 = l * (1.0 + 0.2 * rng.next());
        let k = 1e3 * (1.5 + rng.next());
        let tension_only = case % 2 == 1;
        let f2 = truss::force(&x1, &x2, k, l0, tension_only);
        let h = 1e-6 * l;
        for c in 0..3 {
            let mut xp = x2;
            let mut xm = x2;
            xp[c] += h;
            xm[c] -= h;
            let g = (truss::energy(&x1, &xp, k, l0, tension_only)
                - truss::energy(&x1, &xm, k, l0, tension_only))
                / (2.0 * h);
            let scale = k * (l - l0).abs() + 1e-9 * k * l;
            assert!(
                (f2[c] + g).abs() < 1e-6 * scale,
                "case {case} dir {c}: f = {} vs −∂W/∂x = {}",
                f2[c],
                -g
            );
        }
        // Node 1 carries the opposite force (momentum balance).
        let f1 = [-f2[0], -f2[1], -f2[2]];
        let mut x1p = x1;
        x1p[0] += h;
        let mut x1m = x1;
        x1m[0] -= h;
        let g = (truss::energy(&x1p, &x2, k, l0, tension_only)
            - truss::energy(&x1m, &x2, k, l0, tension_only))
            / (2.0 * h);
        assert!((f1[0] + g).abs() < 1e-6 * (k * (l - l0).abs() + 1e-9 * k * l));
    }
}

/// The link's spring law written out here, independently of the code (the paper's §5 links: springs
/// along x, y, z on the relative displacement d = x₂ − x₁ − d₀, a slider's slip s taken
/// off the tangential part): W = ½[k_x (d_x − s_x)² + k_y (d_y − s_y)² + k_z e_z²], with
/// e_z = d_z, or min(d_z, 0) for a unilateral (push-only) normal spring.
fn link_energy_closed_form(
    x1: &[f64; 3],
    x2: &[f64; 3],
    d0: &[f64; 3],
    k: &[f64; 3],
    slip: &[f64; 2],
    unilateral: bool,
) -> f64 {
    let d: Vec<f64> = (0..3).map(|i| x2[i] - x1[i] - d0[i]).collect();
    let ez = if unilateral { d[2].min(0.0) } else { d[2] };
    0.5 * (k[0] * (d[0] - slip[0]).powi(2) + k[1] * (d[1] - slip[1]).powi(2) + k[2] * ez * ez)
}

/// The link's force on each node is minus the gradient of the closed-form energy above
/// (central differences of that energy, not of the code's `link::energy`), through both
/// the solver's path (`force_update_law` at rest, no slider limit) and `elastic_force_law`;
/// and the code's stored energy is the closed form. Comparing the code's force with the
/// code's energy (the test this one replaces) cannot catch a law wrong in both. Mutations
/// tried, each applied to force and energy alike: k_x and k_y swapped (in
/// `force_update_parts`, `elastic_force_law` and `energy_law`), and a unilateral spring
/// that pulls instead of pushing (`dz >= 0.0` → `dz <= 0.0` in `normal_spring`,
/// `min` → `max` in `energy_law`): both fail here, both passed the old test.
#[test]
fn link_force_is_minus_the_gradient_of_the_closed_form_energy() {
    use weft::solver::link::{LinkLaw, LinkState};
    let mut rng = Rng(12345);
    let mut checked = [0usize; 2];
    let mut worst: f64 = 0.0;
    for case in 0..200 {
        let p = LinkProps {
            k: [
                1e3 * (1.5 + rng.next()),
                2e3 * (1.5 + rng.next()),
                5e4 * (1.5 + rng.next()),
            ],
            c: [0.0; 3],
            slip_force: f64::INFINITY,
        };
        let unilateral = case % 2 == 1;
        let law = LinkLaw {
            friction: None,
            unilateral,
        };
        let slip = [1e-3 * rng.next(), 1e-3 * rng.next()];
        let x1 = rng.vec(1e-2);
        let x2 = rng.vec(1e-2);
        let d0 = rng.vec(1e-3);
        let h = 1e-7;
        let d = link::rel_disp(&x1, &x2, &d0);
        if d[2].abs() < 1e3 * h {
            continue; // the unilateral spring's kink
        }
        checked[unilateral as usize] += 1;
        let w = |a: &[f64; 3], b: &[f64; 3]| {
            link_energy_closed_form(a, b, &d0, &p.k, &slip, unilateral)
        };
        // The code's stored energy is the closed form.
        let e = link::energy_law(&d, &p, &law, &slip);
        assert!(
            (e - w(&x1, &x2)).abs() <= 1e-12 * w(&x1, &x2).max(1e-30),
            "case {case}: energy {e} vs closed form {}",
            w(&x1, &x2)
        );
        let mut st = LinkState {
            slip,
            ..Default::default()
        };
        let f_run = link::force_update_law(&d, &[0.0; 3], &p, &law, &mut st, 0.0);
        let f_el = link::elastic_force_law(&d, &p, &law, &slip);
        let scale = p.k[2] * 1e-2;
        for c in 0..3 {
            let (mut xp, mut xm) = (x2, x2);
            xp[c] += h;
            xm[c] -= h;
            let g2 = (w(&x1, &xp) - w(&x1, &xm)) / (2.0 * h);
            let (mut yp, mut ym) = (x1, x1);
            yp[c] += h;
            ym[c] -= h;
            let g1 = (w(&yp, &x2) - w(&ym, &x2)) / (2.0 * h);
            // Measured: |f + ∂W/∂x| ≤ 2.8e-11 of the scale k_z·1 cm (round-off of the
            // differences); a wrong stiffness is off by percents of it.
            for (name, f) in [("force_update_law", f_run), ("elastic_force_law", f_el)] {
                worst = worst.max((f[c] + g2).abs().max((-f[c] + g1).abs()) / scale);
                assert!(
                    (f[c] + g2).abs() < 1e-9 * scale,
                    "case {case} ({name}) dir {c}: node 2 force {} vs −∂W/∂x₂ = {}",
                    f[c],
                    -g2
                );
                // Node 1 carries −f (the code gives node 2's force; momentum balance).
                assert!(
                    (-f[c] + g1).abs() < 1e-9 * scale,
                    "case {case} ({name}) dir {c}: node 1 force {} vs −∂W/∂x₁ = {}",
                    -f[c],
                    -g1
                );
            }
        }
    }
    eprintln!("link: {checked:?} cases, worst |f + ∂W/∂x| = {worst:.1e} of k_z·1 cm");
    assert!(checked[0] > 50 && checked[1] > 50, "{checked:?}");
}

#[test]
fn truss_gives_no_force_under_rigid_rotation_and_rotates_its_force() {
    let mut rng = Rng(777);
    for _ in 0..100 {
        let x1 = rng.vec(1.0);
        let x2 = rng.vec(1.0);
        let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
        let l0 = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let k = 1e6;
        let r = rotation(rng.vec(1.0), 3.0 * rng.next());
        let shift = rng.vec(5.0);
        let y1 = rot(&r, &x1);
        let y2 = rot(&r, &x2);
        let (y1, y2) = (
            [y1[0] + shift[0], y1[1] + shift[1], y1[2] + shift[2]],
            [y2[0] + shift[0], y2[1] + shift[1], y2[2] + shift[2]],
        );
        // Unstressed element rigidly moved: no force (round-off only).
        let f = truss::force(&y1, &y2, k, l0, false);
        let fmag = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
        assert!(fmag < 1e-9 * k * l0, "force {fmag} N under rigid rotation");
        // Stretched element rotated: the force rotates with it.
        let f_ref = truss::force(&x1, &x2, k, 0.9 * l0, false);
        let f_rot = truss::force(&y1, &y2, k, 0.9 * l0, false);
        let expect = rot(&r, &f_ref);
        for c in 0..3 {
            assert!((f_rot[c] - expect[c]).abs() < 1e-9 * k * l0);
        }
    }
}

#[test]
fn rigidly_rotated_truss_frame_stays_unstressed_in_a_run() {
    // A triangle of trusses spinning about z with ω, free in space: a rigid rotation.
    // The corotational truss carries only the centripetal tension; the energy balances.
    let mut m = Model::default();
    let r = 0.1;
    for i in 0..3 {
        let a = 2.0 * std::f64::consts::PI * i as f64 / 3.0;
        m.add_node(i as i64 + 1, [r * a.cos(), r * a.sin(), 0.0]);
    }
    let p = m.add_part(
        1,
        "frame",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(2e11),
            density: Some(7800.0),
            area: Some(1e-6),
            ..Default::default()
        },
    );
    m.add_element(1, p, &[0, 1]);
    m.add_element(2, p, &[1, 2]);
    m.add_element(3, p, &[2, 0]);
    let w = 50.0; // rad/s: a quarter turn in π/(2ω)
    for i in 0..3 {
        let x = m.coords[i];
        m.initial_velocities.push((i, [-w * x[1], w * x[0], 0.0]));
    }
    m.analysis.end_time = std::f64::consts::FRAC_PI_2 / w;
    m.analysis.output_interval = m.analysis.end_time / 50.0;
    let (s, out, stats) = weft::solver::run_in_memory(&m).unwrap();
    // Positions at t = π/(2ω) (the last output sample): node i at angle a_i + π/2; the
    // radius grows only by the centripetal stretch (strain ~ ρω²r²/E ~ 1e-10).
    for i in 0..3 {
        let a = 2.0 * std::f64::consts::PI * i as f64 / 3.0 + std::f64::consts::FRAC_PI_2;
        let u = out.u.last().unwrap()[i];
        let x = [
            s.reference_positions()[i][0] + u[0],
            s.reference_positions()[i][1] + u[1],
        ];
        assert!(
            (x[0] - r * a.cos()).abs() < 1e-5 * r && (x[1] - r * a.sin()).abs() < 1e-5 * r,
            "node {i}: {x:?}"
        );
    }
    // Centripetal tension: each node (mass m = ρAL) needs mω²r inwards from two trusses at
    // 30° to the radius, so N = mω²r/√3, and the static strain energy is 3·N²L/(2EA).
    // Released unstrained, the strain overshoots to at most twice the static value
    // (dynamic amplification of a suddenly applied load), so W ≤ 4·W_static.
    let l = r * 3f64.sqrt();
    let (ea, mnode) = (2e11 * 1e-6, 7800.0 * 1e-6 * l);
    let n = mnode * w * w * r / 3f64.sqrt();
    let w_static = 3.0 * n * n * l / (2.0 * ea);
    let ke0 = 0.5 * s.masses().iter().sum::<f64>() * (w * r).powi(2);
    let w_max = out.energy.iter().map(|e| e.internal).fold(0.0, f64::max);
    eprintln!(
        "spinning frame: max strain energy {w_max:.3e} J, static centripetal {w_static:.3e} J"
    );
    assert!(
        w_max <= 4.0 * w_static * 1.01 && w_max > 0.5 * w_static,
        "strain energy {w_max} J"
    );
    // The ledger's kinetic energy is the central difference's ½m v^{n−½}·v^{n+½}, which
    // in a rotation differs from ½m|v|² by O((ωΔt)²)·KE (v^{n±½} = v ∓ aΔt/2 with a ⊥ v,
    // |a| = ω|v|: the dot product is (ωΔt)²/4 below). The balance closes to that order:
    // measured −7.6e-8 J = 0.64 (ωΔt)²·KE₀ (Δt 3.07e-5 s).
    let dt = stats.end_time / stats.steps as f64;
    let order = (w * dt).powi(2) * ke0;
    let e = out.energy.last().unwrap();
    eprintln!(
        "balance error {:.4e} J against (ωΔt)²·KE₀ = {order:.4e} J",
        e.balance_error
    );
    assert!(e.balance_error.abs() < order, "{e:?}");
}

#[test]
fn rod_generator_mass_and_counts() {
    // Total mass = ρ·A·L; n + 1 nodes and n elements.
    let p = RodParams::default();
    let m = build(&p).unwrap();
    assert_eq!(m.num_nodes(), p.elements + 1);
    assert_eq!(m.num_elements(), p.elements);
    let s = weft::solver::Solver::new(&m).unwrap();
    let mass: f64 = s.masses().iter().sum();
    let exact = p.density * p.width * p.thickness * p.length;
    assert!(common::rel(mass, exact) < 1e-12, "{mass} vs {exact}");
}
