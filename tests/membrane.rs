//! Membrane elements (constant-strain triangle, one-point quad with hourglass control).
//!
//! References: plane waves in an elastic plate (Graff, *Wave Motion in Elastic Solids*,
//! §8.1): with the lateral strain suppressed a longitudinal wave runs at
//! √(E/(ρ(1−ν²))) and a shear wave at √(G/ρ); an orthotropic sheet along its axes at
//! √(E₁/(ρ(1−ν₁₂ν₂₁))) and √(E₂/(ρ(1−ν₁₂ν₂₁))). The patch test (Irons; Zienkiewicz &
//! Taylor, *The Finite Element Method*, vol. 1, §9): an affine displacement field is
//! reproduced exactly. Objectivity and force = −∂W/∂x (Belytschko, Liu, Moran §4.6).
//!
//! ```text
//!   y=W  o---o---o---o-- ... --o        strip 0.2 m × 1.5 mm, 400 × 3 elements
//!        |   |   |   |         |        pulse on the edge x = 0,
//!   y=0  o---o---o---o-- ... --o        arrival times at x = 0.25 L and 0.75 L
//!       x=0                   x=L
//! ```

mod common;
use common::*;
use weft::generate::grid::rectangle;
use weft::model::{ElementKind, Load, Model, PartProps, TimeLaw};
use weft::solver::{run_in_memory, Solver};

const RHO: f64 = 1440.0;
const S: f64 = 2e-4;

fn props(e1: f64, e2: f64, nu: f64, g: f64, angle: f64) -> PartProps {
    PartProps {
        youngs_modulus_1: Some(e1),
        youngs_modulus_2: Some(e2),
        poisson_ratio_12: Some(nu),
        shear_modulus_12: Some(g),
        thickness: Some(S),
        density: Some(RHO),
        material_angle: Some(angle),
        ..Default::default()
    }
}

/// A strip along x; `dir` is the loaded direction (0: longitudinal, 1: shear); every node
/// keeps only that direction free, so that the wave is plane.
fn strip(kind: ElementKind, p: PartProps, dir: usize, c_expect: f64) -> (Model, f64) {
    let (nx, ny, lx, ly) = (400, 3, 0.2, 1.5e-3);
    let (nodes, elems) = rectangle(nx, ny, lx, ly, kind);
    let mut m = Model::default();
    for (i, x) in nodes.iter().enumerate() {
        m.add_node(i as i64 + 1, *x);
    }
    let part = m.add_part(1, "sheet", kind, p);
    for (e, ns) in elems.iter().enumerate() {
        m.add_element(e as i64 + 1, part, ns);
    }
    let mut fixed = [true; 3];
    fixed[dir] = false;
    for i in 0..nodes.len() {
        m.constraints.push((i, fixed));
    }
    let t_f = 0.1 * lx / c_expect; // the pulse spans a tenth of the strip
    for j in 0..=ny {
        let w = if j == 0 || j == ny { 0.5 } else { 1.0 };
        let mut f = [0.0; 3];
        f[dir] = 10.0 * w;
        m.loads.push(Load {
            id: j as i64 + 1,
            node: j * (nx + 1),
            force: f,
            law: TimeLaw::SinePulse {
                start: 0.0,
                duration: t_f,
            },
        });
    }
    m.analysis.end_time = 0.8 * lx / c_expect + t_f;
    m.analysis.output_interval = m.analysis.end_time / 2000.0;
    (m, t_f)
}

/// Wave speed from the half-peak arrival of the velocity at x = 0.25 L and 0.75 L (centre row).
fn measure(kind: ElementKind, p: PartProps, dir: usize, c_expect: f64) -> f64 {
    let (m, _t_f) = strip(kind, p, dir, c_expect);
    let (_s, out, _) = run_in_memory(&m).unwrap();
    let nx = 400;
    let row = nx + 1; // second row of nodes
    let at = |i: usize| out.nodes.iter().position(|&n| n == row + i).unwrap();
    let va = out.velocity_series(at(nx / 4), dir);
    let vb = out.velocity_series(at(3 * nx / 4), dir);
    let peak = va.iter().cloned().fold(0.0, f64::max);
    let ta = crossing(&out.t, &va, 0.5 * peak).unwrap();
    let tb = crossing(&out.t, &vb, 0.5 * peak).unwrap();
    let e = out.energy.last().unwrap();
    // Energy balance: measured at most 2.48·10⁻⁶ of the work done over the plane waves of
    // this file (longitudinal, orthotropic, shear); tolerance 4×.
    assert!(e.balance_error.abs() < 1e-5 * e.external_work, "{e:?}");
    0.1 / (tb - ta)
}

#[test]
fn longitudinal_plane_wave_speed() {
    let (e, nu) = (70e9, 0.3);
    let c = (e / (RHO * (1.0 - nu * nu))).sqrt();
    for kind in [ElementKind::Quad, ElementKind::Tri] {
        let v = measure(kind, props(e, e, nu, e / (2.0 * (1.0 + nu)), 0.0), 0, c);
        eprintln!(
            "{} longitudinal: {v:.1} m/s vs √(E/(ρ(1−ν²))) = {c:.1} m/s ({:.2e})",
            kind.name(),
            rel(v, c)
        );
        assert!(rel(v, c) < 0.01, "{}: {v} vs {c}", kind.name());
    }
}

#[test]
fn shear_plane_wave_speed() {
    let (e, nu) = (70e9, 0.3);
    let g = e / (2.0 * (1.0 + nu));
    let c = (g / RHO).sqrt();
    for kind in [ElementKind::Quad, ElementKind::Tri] {
        let v = measure(kind, props(e, e, nu, g, 0.0), 1, c);
        eprintln!(
            "{} shear: {v:.1} m/s vs √(G/ρ) = {c:.1} m/s ({:.2e})",
            kind.name(),
            rel(v, c)
        );
        assert!(rel(v, c) < 0.01, "{}: {v} vs {c}", kind.name());
    }
}

#[test]
fn orthotropic_plane_waves_along_each_axis() {
    let (e1, e2, nu12, g12) = (80e9, 20e9, 0.3, 5e9);
    let den = 1.0 - nu12 * nu12 * e2 / e1;
    for kind in [ElementKind::Quad, ElementKind::Tri] {
        // Material axis 1 along x, then turned by 90° so that axis 2 lies along x.
        for (angle, e) in [(0.0, e1), (std::f64::consts::FRAC_PI_2, e2)] {
            let c = (e / (RHO * den)).sqrt();
            let v = measure(kind, props(e1, e2, nu12, g12, angle), 0, c);
            eprintln!(
                "{} orthotropic, angle {angle:.3}: {v:.1} m/s vs {c:.1} m/s ({:.2e})",
                kind.name(),
                rel(v, c)
            );
            assert!(
                rel(v, c) < 0.01,
                "{} angle {angle}: {v} vs {c}",
                kind.name()
            );
        }
    }
}

/// A small irregular patch: 3 × 3 nodes with the interior node and edges moved off the grid.
fn patch(kind: ElementKind) -> Model {
    let mut m = Model::default();
    let xs = [
        [0.0, 0.0, 0.0],
        [0.011, 0.0, 0.0],
        [0.02, 0.0, 0.0],
        [0.0, 0.009, 0.0],
        [0.0087, 0.0112, 0.0],
        [0.02, 0.0105, 0.0],
        [0.0, 0.02, 0.0],
        [0.0093, 0.02, 0.0],
        [0.02, 0.02, 0.0],
    ];
    for (i, x) in xs.iter().enumerate() {
        m.add_node(i as i64 + 1, *x);
    }
    let p = m.add_part(1, "sheet", kind, props(80e9, 20e9, 0.3, 5e9, 0.4));
    let quads = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]];
    let mut id = 1;
    for q in quads {
        if kind == ElementKind::Quad {
            m.add_element(id, p, &q);
            id += 1;
        } else {
            m.add_element(id, p, &[q[0], q[1], q[2]]);
            m.add_element(id + 1, p, &[q[0], q[2], q[3]]);
            id += 2;
        }
    }
    m
}

/// Mutation tried (2026-11-23): the ν₁₂E₂ coupling terms of the material matrix set to
/// 0 in `solver/membrane/kernel.rs`: this test fails (its stiffness matrix is written out by
/// hand here, not taken from the code).
#[test]
fn patch_test_reproduces_a_uniform_strain_exactly() {
    // u = A·X: F = I + A uniform, so every element has the same Green strain; the interior
    // node is in equilibrium and the energy is A_total s ½ E:D:E.
    let a = [[1.2e-3, 3e-4], [-2e-4, -7e-4]];
    for kind in [ElementKind::Quad, ElementKind::Tri] {
        let m = patch(kind);
        let mut s = Solver::new(&m).unwrap();
        for i in 0..9 {
            let x0 = s.reference_positions()[i];
            s.state_mut().x[i] = [
                x0[0] + a[0][0] * x0[0] + a[0][1] * x0[1],
                x0[1] + a[1][0] * x0[0] + a[1][1] * x0[1],
                0.0,
            ];
        }
        let f = s.internal_forces();
        let fmax = f
            .iter()
            .map(|v| v[0].abs().max(v[1].abs()))
            .fold(0.0, f64::max);
        assert!(fmax > 0.0);
        assert!(
            f[4][0].abs() < 1e-9 * fmax && f[4][1].abs() < 1e-9 * fmax,
            "{}: interior force {:?} (boundary {fmax})",
            kind.name(),
            f[4]
        );
        // Energy against the closed form, in material axes turned by 0.4 rad.
        let (c, sn) = (0.4f64.cos(), 0.4f64.sin());
        let fm = [[1.0 + a[0][0], a[0][1]], [a[1][0], 1.0 + a[1][1]]];
        let g = [[c, sn], [-sn, c]]; // columns of F applied to the material axes g1, g2
        let col = |k: usize| {
            [
                fm[0][0] * g[k][0] + fm[0][1] * g[k][1],
                fm[1][0] * g[k][0] + fm[1][1] * g[k][1],
            ]
        };
        let (f1, f2) = (col(0), col(1));
        let e = [
            0.5 * (f1[0] * f1[0] + f1[1] * f1[1] - 1.0),
            0.5 * (f2[0] * f2[0] + f2[1] * f2[1] - 1.0),
            f1[0] * f2[0] + f1[1] * f2[1],
        ];
        // The plane-stress reduced stiffness of an orthotropic lamina, written out here
        // (Jones, *Mechanics of Composite Materials*, §2.6): Q₁₁ = E₁/Δ, Q₂₂ = E₂/Δ,
        // Q₁₂ = ν₁₂E₂/Δ, Q₆₆ = G₁₂, Δ = 1 − ν₁₂ν₂₁, ν₂₁ = ν₁₂E₂/E₁; e[2] is the
        // engineering shear strain.
        let (e1, e2, nu12, g12) = (80e9, 20e9, 0.3, 5e9);
        let delta = 1.0 - nu12 * nu12 * e2 / e1;
        let (q11, q22, q12) = (e1 / delta, e2 / delta, nu12 * e2 / delta);
        let st = [q11 * e[0] + q12 * e[1], q12 * e[0] + q22 * e[1], g12 * e[2]];
        let w = 0.5 * (0.02 * 0.02) * S * (st[0] * e[0] + st[1] * e[1] + st[2] * e[2]);
        let (ie, _, _, hg) = s.internal_energy();
        assert!(rel(ie, w) < 1e-10, "{}: energy {ie} vs {w}", kind.name());
        assert!(
            hg.abs() < 1e-12 * w,
            "{}: hourglass energy {hg} under an affine field",
            kind.name()
        );
    }
}

#[test]
fn rigid_rotation_gives_no_force() {
    for kind in [ElementKind::Quad, ElementKind::Tri] {
        let m = patch(kind);
        let mut s = Solver::new(&m).unwrap();
        // 60° about (1, 1, 1)/√3 plus a translation.
        let th = std::f64::consts::FRAC_PI_3;
        let (c, sn) = (th.cos(), th.sin());
        let k = 1.0 / 3f64.sqrt();
        let r = [
            [
                c + k * k * (1.0 - c),
                k * k * (1.0 - c) - k * sn,
                k * k * (1.0 - c) + k * sn,
            ],
            [
                k * k * (1.0 - c) + k * sn,
                c + k * k * (1.0 - c),
                k * k * (1.0 - c) - k * sn,
            ],
            [
                k * k * (1.0 - c) - k * sn,
                k * k * (1.0 - c) + k * sn,
                c + k * k * (1.0 - c),
            ],
        ];
        for i in 0..9 {
            let x = s.reference_positions()[i];
            s.state_mut().x[i] =
                std::array::from_fn(|d| r[d][0] * x[0] + r[d][1] * x[1] + r[d][2] * x[2] + 0.3);
        }
        let f = s.internal_forces();
        let scale = 80e9 * S; // force of a unit strain per unit width × 1 m
        for (i, v) in f.iter().enumerate() {
            assert!(
                v.iter().all(|c| c.abs() < 1e-9 * scale * 0.02),
                "{} node {i}: {v:?}",
                kind.name()
            );
        }
    }
}

#[test]
fn membrane_force_is_minus_energy_gradient() {
    use weft::solver::membrane::{energy, forces, Material, Reference};
    let mat = Material::orthotropic(80e9, 20e9, 0.3, 5e9, false).unwrap();
    let x0q = [
        [0.0, 0.0, 0.0],
        [1.1e-3, 0.1e-3, 0.0],
        [1.0e-3, 0.9e-3, 0.0],
        [-0.1e-3, 1.0e-3, 0.0],
    ];
    let rq = Reference::<4>::new(&x0q, 0.3).unwrap();
    let x0t = [x0q[0], x0q[1], x0q[2]];
    let rt = Reference::<3>::new(&x0t, 0.3).unwrap();
    let k_hg = 0.1 * mat.e_max() * S * rq.area * rq.grad2();
    let mut seed = 7u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e-5
    };
    for _ in 0..20 {
        let xq: [[f64; 3]; 4] = std::array::from_fn(|a| std::array::from_fn(|d| x0q[a][d] + rnd()));
        let f = forces(&xq, &rq, &mat, S, k_hg);
        let h = 1e-10;
        for a in 0..4 {
            for d in 0..3 {
                let (mut xp, mut xm) = (xq, xq);
                xp[a][d] += h;
                xm[a][d] -= h;
                let w = |x: &[[f64; 3]; 4]| {
                    let (m, hg) = energy(x, &rq, &mat, S, k_hg);
                    m + hg
                };
                let g = (w(&xp) - w(&xm)) / (2.0 * h);
                let scale = f.iter().flatten().map(|v| v.abs()).fold(0.0, f64::max);
                assert!(
                    (f[a][d] + g).abs() < 1e-5 * scale,
                    "quad node {a} dir {d}: {} vs {}",
                    f[a][d],
                    -g
                );
            }
        }
        let xt = [xq[0], xq[1], xq[2]];
        let f = forces(&xt, &rt, &mat, S, 0.0);
        for a in 0..3 {
            for d in 0..3 {
                let (mut xp, mut xm) = (xt, xt);
                xp[a][d] += 1e-10;
                xm[a][d] -= 1e-10;
                let g =
                    (energy(&xp, &rt, &mat, S, 0.0).0 - energy(&xm, &rt, &mat, S, 0.0).0) / 2e-10;
                let scale = f.iter().flatten().map(|v| v.abs()).fold(0.0, f64::max);
                assert!(
                    (f[a][d] + g).abs() < 1e-5 * scale,
                    "tri node {a} dir {d}: {} vs {}",
                    f[a][d],
                    -g
                );
            }
        }
    }
}

#[test]
fn membrane_mass_is_density_times_volume() {
    for kind in [ElementKind::Quad, ElementKind::Tri] {
        let m = patch(kind);
        let s = Solver::new(&m).unwrap();
        let mass: f64 = s.masses().iter().sum();
        assert!(rel(mass, RHO * S * 0.02 * 0.02) < 1e-12);
    }
}

/// A band (E₁ = 80 GPa along x, E₂ = 1.6 GPa, G = 0.8 GPa) pre-stretched uniformly along
/// x and held at both ends, at rest in equilibrium. The stable step is set from the
/// undeformed band; an St Venant–Kirchhoff band stretched to a Green strain E₁₁ has the
/// uniaxial tangent modulus dP/dλ = E₁(3λ² − 1)/2 = E₁(1 + 3E₁₁) (P = E₁λ(λ² − 1)/2 the
/// nominal stress; Bonet & Wood, *Nonlinear Continuum Mechanics for FEA*, §6), so its
/// stable step shrinks by √(1 + 3E₁₁); the step used leaves the margin
/// (Δt_stable/Δt)² = 1/dt_safety². The run must stop, naming the element and its strain,
/// once 1 + 3E₁₁ exceeds that margin, and run below it. Measured: the threshold at
/// dt_safety 0.9 is E₁₁ = 0.0782; 0.95 of it runs (energy drift 0), 1.05 of it stops at
/// t = 0. Without the check such a band blows up a few steps later (the yarn-level
/// impacts at 43–49 µs of 400 m/s variants, docs/solver.md, "Features").
#[test]
fn a_band_stretched_past_the_steps_margin_stops_with_its_strain_named() {
    let (nx, ny, lx, ly) = (40, 2, 0.02, 1e-3);
    let band = |e11: f64, safety: f64| {
        let (nodes, elems) = rectangle(nx, ny, lx, ly, ElementKind::Quad);
        let mut m = Model::default();
        for (i, x) in nodes.iter().enumerate() {
            m.add_node(i as i64 + 1, *x);
        }
        let part = m.add_part(
            1,
            "band",
            ElementKind::Quad,
            props(80e9, 1.6e9, 0.0, 0.8e9, 0.0),
        );
        for (e, ns) in elems.iter().enumerate() {
            m.add_element(e as i64 + 1, part, ns);
        }
        // λ from the Green strain E = (λ² − 1)/2; u₀ = (λ − 1) x.
        let lam = (1.0 + 2.0 * e11).sqrt();
        m.initial_displacement = nodes
            .iter()
            .map(|x| [(lam - 1.0) * x[0], 0.0, 0.0])
            .collect();
        for (i, x) in nodes.iter().enumerate() {
            let end = x[0] < 1e-12 || (x[0] - lx).abs() < 1e-12;
            m.constraints.push((i, [end, true, true]));
        }
        m.analysis.dt_safety = safety;
        m.analysis.end_time = 2e-6;
        m.analysis.output_interval = 1e-7;
        m
    };
    let safety = 0.9;
    let s = Solver::new(&band(0.0, safety)).unwrap();
    let margin = (s.time_step().dt_stable / s.time_step().dt).powi(2);
    let threshold = (margin - 1.0) / 3.0;
    eprintln!(
        "margin {margin:.5} (1/dt_safety² = {:.5}), threshold E11 = {threshold:.4}",
        1.0 / (safety * safety)
    );
    assert!((margin - 1.0 / (safety * safety)).abs() < 1e-9 * margin);
    let (_s, out, _) = run_in_memory(&band(0.95 * threshold, safety)).unwrap();
    let e = out.energy.last().unwrap();
    assert!(e.balance_error.abs() <= 1e-9 * e.internal, "{e:?}");
    let err = match run_in_memory(&band(1.05 * threshold, safety)) {
        Ok(_) => panic!("a band stretched past the margin ran"),
        Err(e) => e.to_string(),
    };
    eprintln!("{err}");
    assert!(
        err.contains("quad `") && err.contains("Green strain") && err.contains("t = 0"),
        "{err}"
    );
    // With a shorter step the same band runs.
    run_in_memory(&band(1.05 * threshold, 0.8)).unwrap();
}
