//! The eight-node hexahedron (one-point, Flanagan–Belytschko hourglass control) against
//! closed forms:
//! - a bar with ν = 0 carries a pulse at the rod speed √(E/ρ), a laterally confined
//!   column at the dilatational speed √((λ + 2μ)/ρ) (Graff, *Wave Motion in Elastic
//!   Solids*, §1.1 and §5.1);
//! - the patch test (Irons; Belytschko, Liu & Moran §8.3 and Flanagan & Belytschko 1981
//!   §4: the mean-strain element passes it): a linear velocity field on a distorted mesh
//!   gives one and the same stress in every element and no force on an interior node;
//! - objectivity: a rigid rotation of 90° turns a uniaxial stress with the body, σ′ = RσRᵀ
//!   (the Hughes–Winget update is exact for it: the chord velocities at the mid-step
//!   configuration give D = 0 and the Cayley transform of the rotation);
//! - bad input: an inside-out hexahedron, a yield stress ≤ 0, a Johnson–Cook exponent out
//!   of range, a room temperature at or above melt, each refused naming what is wrong.

use weft::generate::block::hex_block;
use weft::model::{ElementKind, Load, Model, PartProps, TimeLaw};
use weft::solver::family::{Build, Family, ForceCtx, SlowStep};
use weft::solver::rotations::Rotations;
use weft::solver::run_in_memory;
use weft::solver::solid::hex::HexGroup;

mod common;
use common::solid::{on_threads, steel, struck_block, STEEL_E as E, STEEL_RHO as RHO};

/// A bar of `n` cubes of side h along x (one element across), nodes at
/// (i h, j h, k h), j, k ∈ {0, 1}; node index 4i + 2j + k.
fn bar(n: usize, h: f64, nu: f64) -> Model {
    let mut m = Model::default();
    for i in 0..=n {
        for j in 0..2 {
            for k in 0..2 {
                m.add_node(
                    (4 * i + 2 * j + k + 1) as i64,
                    [i as f64 * h, j as f64 * h, k as f64 * h],
                );
            }
        }
    }
    let p = m.add_part(1, "bar", ElementKind::Hex, steel(nu));
    let id = |i: usize, j: usize, k: usize| 4 * i + 2 * j + k;
    for i in 0..n {
        // n1–n4 on the face x = i h counter-clockwise seen from +x, n5–n8 at x = (i+1) h.
        let face = |ii: usize| [id(ii, 0, 0), id(ii, 1, 0), id(ii, 1, 1), id(ii, 0, 1)];
        let (a, b) = (face(i), face(i + 1));
        m.add_element(
            i as i64 + 1,
            p,
            &[a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]],
        );
    }
    m
}

/// The arrival time of the pulse at output node j: the first time |vx| reaches half of
/// its peak there, interpolated linearly between samples.
fn arrival(t: &[f64], vx: &[f64]) -> f64 {
    let peak = vx.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let level = 0.5 * peak;
    for k in 1..t.len() {
        if vx[k].abs() >= level {
            let (a, b) = (vx[k - 1].abs(), vx[k].abs());
            return t[k - 1] + (level - a) / (b - a) * (t[k] - t[k - 1]);
        }
    }
    f64::NAN
}

/// A sine pulse of force on the end face x = 0 (4 N on 1 mm²: a strain of 2·10⁻⁵, the
/// small-strain wave the closed forms describe), run until the front has crossed 3/4 of
/// the bar; the speed between the stations at ¼ and ¾ of the bar.
fn pulse_speed(m: &mut Model, n: usize, h: f64) -> (f64, f64) {
    let c_guess = (E / RHO).sqrt();
    let l = n as f64 * h;
    let duration = 20.0 * h / c_guess;
    for k in 0..4 {
        m.loads.push(Load {
            id: k as i64 + 1,
            node: k,
            force: [-1.0, 0.0, 0.0], // 4 N on the face
            law: TimeLaw::SinePulse {
                start: 0.0,
                duration,
            },
        });
    }
    let (s1, s2) = (n / 4, 3 * n / 4);
    m.node_sets.insert("stations".into(), vec![4 * s1, 4 * s2]);
    m.analysis.history_sets = vec!["stations".into()];
    m.analysis.end_time = (0.8 * l) / c_guess + duration;
    m.analysis.output_interval = 0.02 * h / c_guess;
    let (_s, out, st) = run_in_memory(m).unwrap();
    let v1 = out.velocity_series(0, 0);
    let v2 = out.velocity_series(1, 0);
    let (t1, t2) = (arrival(&out.t, &v1), arrival(&out.t, &v2));
    (
        (s2 - s1) as f64 * h / (t2 - t1),
        st.max_balance_error_relative,
    )
}

#[test]
fn a_bar_of_hexahedra_with_no_poisson_effect_carries_a_pulse_at_the_rod_speed() {
    // ν = 0: the bar's lateral faces stay where they are, the wave is the rod's,
    // c₀ = √(E/ρ) (Graff §1.1).
    let (n, h) = (200, 1e-3);
    let mut m = bar(n, h, 0.0);
    let (c, balance) = pulse_speed(&mut m, n, h);
    let c0 = (E / RHO).sqrt();
    let err = (c - c0) / c0;
    eprintln!("rod speed: {c:.2} m/s against √(E/ρ) = {c0:.2} m/s ({err:+.2e}); energy balance {balance:.2e}");
    // Measured −4.2e-3: the lumped-mass central difference's dispersion at the Courant
    // number of the element's Gershgorin step (0.6 of h/c) delays the pulse's half-level
    // (the issue asks ≤ 1 %); tolerance 9e-3, 2.2×.
    assert!(err.abs() < 9e-3, "{c} vs {c0}");
    // Measured 1.4e-9 (the bulk viscosity's linear term, on at each unloading, booked by
    // the trapezoid of its own forces); tolerance 5e-9.
    assert!(balance < 5e-9, "balance {balance}");
}

#[test]
fn a_laterally_confined_column_carries_a_pulse_at_the_dilatational_speed() {
    // ν = 0.3, every node held in y and z: uniaxial strain, c_d = √((λ + 2μ)/ρ)
    // (Graff §5.1, the plane dilatational wave).
    let (n, h, nu) = (200, 1e-3, 0.3);
    let mut m = bar(n, h, nu);
    for i in 0..m.num_nodes() {
        m.constraints.push((i, [false, true, true]));
    }
    let (c, balance) = pulse_speed(&mut m, n, h);
    let (lam, mu) = (
        E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        E / (2.0 * (1.0 + nu)),
    );
    let cd = ((lam + 2.0 * mu) / RHO).sqrt();
    let err = (c - cd) / cd;
    eprintln!("dilatational speed: {c:.2} m/s against √((λ+2μ)/ρ) = {cd:.2} m/s ({err:+.2e}); energy balance {balance:.2e}");
    // Measured −2.9e-3 (dispersion, as the rod's); tolerance 7e-3, 2.4×.
    assert!(err.abs() < 7e-3, "{c} vs {cd}");
    // Measured 1.5e-15: the trapezoid of the element's own forces telescopes; a
    // round-off bound.
    assert!(balance < 1e-13, "balance {balance}");
}

/// A unit cube in 2 × 2 × 2 hexahedra whose 27 nodes are moved off the grid (all but
/// the corners), so that no element is a parallelepiped.
fn distorted_patch() -> (Model, usize) {
    let mut m = hex_block(2, 2, 2, 0.5, "patch", steel(0.3));
    let id = |i: usize, j: usize, k: usize| 9 * k + 3 * j + i;
    for k in 0..3 {
        for j in 0..3 {
            for i in 0..3 {
                let x = &mut m.coords[id(i, j, k)];
                // Deterministic, different offsets; the corners stay, faces stay planar
                // only where the offset is along the face.
                let s = (id(i, j, k) as f64 * 0.618_034).fract() - 0.5;
                let corner = [i, j, k].iter().all(|&c| c != 1);
                if !corner {
                    for (d, xd) in x.iter_mut().enumerate() {
                        let free = [i, j, k][d] == 1;
                        if free {
                            *xd += 0.12 * s * (1.0 + d as f64) / 3.0;
                        }
                    }
                }
            }
        }
    }
    m.validate().unwrap();
    (m, id(1, 1, 1))
}

fn family(m: &Model) -> HexGroup {
    let mut mass = vec![0.0; m.num_nodes()];
    let mut rot = Rotations::default();
    let mut b = Build {
        model: m,
        mass: &mut mass,
        rot: &mut rot,
    };
    HexGroup::build(&mut b).unwrap()
}

/// Sums the family's force slots onto the nodes.
fn nodal(g: &HexGroup, fe: &[[f64; 3]], nn: usize) -> Vec<[f64; 3]> {
    let mut f = vec![[0.0; 3]; nn];
    for (e, ns) in g.nodes.iter().enumerate() {
        for a in 0..8 {
            for d in 0..3 {
                f[ns[a] as usize][d] += fe[8 * e + a][d];
            }
        }
    }
    f
}

#[test]
fn the_patch_test_a_linear_velocity_field_on_a_distorted_mesh_gives_one_stress_and_no_interior_force(
) {
    let (m, centre) = distorted_patch();
    let mut g = family(&m);
    // v = A X, A with all nine entries (stretch, shear, spin); tr A > 0 so that no bulk
    // viscosity acts (it depends on each element's length, which the patch test is not
    // about).
    let a = [[3.0, 1.0, -0.5], [0.2, 2.0, 0.7], [-0.4, 0.3, 1.5]];
    let dt = 1e-7;
    let v: Vec<[f64; 3]> = m
        .coords
        .iter()
        .map(|x| std::array::from_fn(|i| (0..3).map(|j| a[i][j] * x[j]).sum()))
        .collect();
    let x: Vec<[f64; 3]> = m
        .coords
        .iter()
        .zip(&v)
        .map(|(x, v)| std::array::from_fn(|i| x[i] + dt * v[i]))
        .collect();
    let ctx = ForceCtx {
        x: &x,
        v: &v,
        rot_r: &[],
        dt_prev: dt,
        slow: SlowStep::NONE,
    };
    let mut fe = vec![[0.0; 3]; 8 * g.len()];
    g.forces(&ctx, &mut fe);
    let s0 = g.state[0].stress;
    let scale = s0.iter().fold(0.0f64, |a, s| a.max(s.abs()));
    let spread = g
        .state
        .iter()
        .flat_map(|st| (0..6).map(move |i| (st.stress[i] - s0[i]).abs()))
        .fold(0.0f64, f64::max)
        / scale;
    let f = nodal(&g, &fe, m.num_nodes());
    let fmax = f.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    let fc = f[centre].iter().fold(0.0f64, |a, v| a.max(v.abs())) / fmax;
    // The stress a homogeneous D gives: σ = λ tr(D)Δt I + 2μ DΔt (the spin turns zero).
    let (e, nu) = (E, 0.3);
    let (lam, mu) = (
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        e / (2.0 * (1.0 + nu)),
    );
    let tr = a[0][0] + a[1][1] + a[2][2];
    let expect_xx = (lam * tr + 2.0 * mu * a[0][0]) * dt;
    let expect_xy = mu * (a[0][1] + a[1][0]) * dt;
    let (exx, exy) = (
        (s0[0] - expect_xx) / expect_xx,
        (s0[3] - expect_xy) / expect_xy,
    );
    eprintln!(
        "patch test: stress spread {spread:.2e} of {scale:.3e} Pa, interior node force {fc:.2e} of the largest, σ_xx {exx:+.1e}, σ_xy {exy:+.1e} from the closed form"
    );
    // Measured 7.2e-16 and 3.5e-14; round-off bounds, a few hundred ulps of the stress
    // and of the largest force.
    assert!(spread < 1e-12, "stress spread {spread}");
    assert!(fc < 1e-12, "interior force {fc}");
    // The mid-step geometry makes DΔt exact for v = AX only to O(Δt²) (the velocity
    // gradient at x^{n−½} is A(I + ½ΔtA)⁻¹): here |A|Δt ≈ 4e-7.
    assert!(exx.abs() < 2e-6 && exy.abs() < 2e-6, "{exx} {exy}");
}

#[test]
fn a_rigid_rotation_of_ninety_degrees_turns_a_uniaxial_stress_with_the_body() {
    let (m, _) = distorted_patch();
    let mut g = family(&m);
    let sigma = 250e6;
    for st in &mut g.state {
        st.stress = [sigma, 0.0, 0.0, 0.0, 0.0, 0.0];
    }
    // About z by π/2 in 400 steps of the angle (each step 0.2°), the nodes exactly on
    // the rotated positions, v^{n−½} the chords.
    let steps = 400;
    let dt = 1e-7;
    let rot = |th: f64, x: &[f64; 3]| {
        [
            th.cos() * x[0] - th.sin() * x[1],
            th.sin() * x[0] + th.cos() * x[1],
            x[2],
        ]
    };
    let mut prev: Vec<[f64; 3]> = m.coords.clone();
    let mut fe = vec![[0.0; 3]; 8 * g.len()];
    for n in 1..=steps {
        let th = std::f64::consts::FRAC_PI_2 * n as f64 / steps as f64;
        let x: Vec<[f64; 3]> = m.coords.iter().map(|x| rot(th, x)).collect();
        let v: Vec<[f64; 3]> = x
            .iter()
            .zip(&prev)
            .map(|(a, b)| std::array::from_fn(|i| (a[i] - b[i]) / dt))
            .collect();
        let ctx = ForceCtx {
            x: &x,
            v: &v,
            rot_r: &[],
            dt_prev: dt,
            slow: SlowStep::NONE,
        };
        g.forces(&ctx, &mut fe);
        prev = x;
    }
    // Turned by 90° about z: σ_xx → σ_yy.
    let worst = g
        .state
        .iter()
        .map(|st| {
            let want = [0.0, sigma, 0.0, 0.0, 0.0, 0.0];
            (0..6)
                .map(|i| (st.stress[i] - want[i]).abs())
                .fold(0.0f64, f64::max)
        })
        .fold(0.0f64, f64::max)
        / sigma;
    eprintln!("rigid rotation by 90° in {steps} steps: stress off the rotated uniaxial state by {worst:.2e} of σ");
    // Measured 1.5e-13: the angle's own round-off over 400 steps (cos, sin of n·Δθ,
    // chords); tolerance 1e-12. (The Jaumann rate's σ += (Wσ − σW)Δt would be off by
    // O(θ·Δθ), ~10⁻³ here.)
    assert!(worst < 1e-12, "{worst}");
}

#[test]
fn bad_solids_are_refused_naming_what_is_wrong() {
    // An inside-out hexahedron: the faces n1–n4 and n5–n8 swapped.
    let mut m = bar(1, 1e-3, 0.3);
    if let Some(b) = m.elements.get_mut(&ElementKind::Hex) {
        let n = b.nodes.clone();
        b.nodes = [&n[4..8], &n[0..4]].concat();
    }
    let err = m.validate().unwrap_err().to_string();
    eprintln!("{err}");
    assert!(
        err.contains("hexahedron `1`") && err.contains("Jacobian") && err.contains("n5–n8"),
        "{err}"
    );

    let refused = |props: PartProps, what: &str| {
        let mut m = bar(1, 1e-3, 0.3);
        m.parts[0].props = props;
        let err = m.validate().unwrap_err().to_string();
        eprintln!("{err}");
        assert!(err.contains(what), "expected `{what}` in: {err}");
    };
    refused(
        PartProps {
            yield_stress: Some(0.0),
            ..steel(0.3)
        },
        "yield_stress",
    );
    refused(
        PartProps {
            jc_a: Some(90e6),
            jc_b: Some(292e6),
            jc_n: Some(1.31),
            ..steel(0.3)
        },
        "hardening exponent n = 1.31",
    );
    refused(
        PartProps {
            jc_a: Some(90e6),
            jc_m: Some(1.09),
            room_temperature: Some(1400.0),
            melt_temperature: Some(1356.0),
            ..steel(0.3)
        },
        "T_room = 1400 K",
    );
    refused(
        PartProps {
            yield_stress: Some(300e6),
            tangent_modulus: Some(E),
            ..steel(0.3)
        },
        "tangent",
    );
    refused(
        PartProps {
            solid_formulation: Some("fully_integrated".into()),
            ..steel(0.3)
        },
        "solid_formulation `fully_integrated`",
    );
}

#[test]
fn a_solid_crushed_below_its_fixed_step_stops_the_run_naming_the_element() {
    // One aluminium cube of 1 mm, one face driven at 100 m/s into a yield stress of
    // 1 MPa: it crushes almost freely (1 N against 100 m/s of 1.35 mg: 6 m/s lost in
    // 8 µs). The step is set from the undeformed cube; as it flattens its Gershgorin rows
    // grow (as 1/h² for the driven direction), past the margin of dt_safety 0.9 (1/0.81)
    // well before it would invert: the run must stop with a message naming the
    // element, not blow up.
    let mut m = bar(1, 1e-3, 0.3);
    m.parts[0].props = PartProps {
        youngs_modulus: Some(70e9),
        density: Some(2700.0),
        poisson_ratio: Some(0.3),
        yield_stress: Some(1e6),
        ..Default::default()
    };
    // bar(1, …): node 4i + 2j + k at (i, j, k) h. The face x = 0 slides on a plane held
    // in x, the faces y = 0 and z = 0 are symmetry planes: the cube flows out freely in
    // +y and +z (isochoric plastic flow, uniaxial stress at the yield stress), the face
    // x = h driven along −x.
    for (n, x) in m.coords.clone().iter().enumerate() {
        m.constraints
            .push((n, [x[0] == 0.0, x[1] == 0.0, x[2] == 0.0]));
        if x[0] > 0.0 {
            m.initial_velocities.push((n, [-100.0, 0.0, 0.0]));
        }
    }
    m.analysis.end_time = 8e-6;
    m.analysis.output_interval = 1e-7;
    let err = run_in_memory(&m)
        .err()
        .expect("the run must stop")
        .to_string();
    eprintln!("{err}");
    assert!(
        err.contains("hex `1` has been compressed") && err.contains("dt_safety"),
        "{err}"
    );
}

#[test]
fn a_solid_model_round_trips_through_its_tables_and_runs_from_them_as_in_memory() {
    use weft::model::io::{read_model, write_model};
    use weft::table::Provenance;
    // A J2 bar with a pulse: written, read back, the same model; the run from the read
    // model gives the same bits as the run of the model in memory (the tables lose
    // nothing the solver uses).
    let (n, h) = (20, 1e-3);
    let mut m = bar(n, h, 0.3);
    m.parts[0].props.yield_stress = Some(250e6);
    m.parts[0].props.tangent_modulus = Some(2e9);
    for k in 0..4 {
        m.loads.push(Load {
            id: k as i64 + 1,
            node: k,
            force: [-300.0, 0.0, 0.0],
            law: TimeLaw::SinePulse {
                start: 0.0,
                duration: 2e-6,
            },
        });
    }
    m.analysis.end_time = 4e-6;
    m.analysis.output_interval = 2e-7;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bar");
    write_model(&m, &path, &Provenance::new("test", serde_json::json!({}))).unwrap();
    assert!(path.join("elements_hex.parquet").exists());
    let back = read_model(&path).unwrap();
    let (_, a, _) = run_in_memory(&m).unwrap();
    let (s, b, _) = run_in_memory(&back).unwrap();
    assert!(
        a.u == b.u && a.energy == b.energy,
        "the read model runs differently"
    );
    // It yielded: 1.2 kN on 1 mm² is 1.2 GPa against 250 MPa.
    let ep = s.operator().el.hex.state[0].plastic_strain;
    eprintln!("plastic strain of the loaded element: {ep:.3e}");
    assert!(ep > 0.0);
}

#[test]
fn a_copper_block_struck_on_a_corner_region_balances_energy_and_runs_the_same_on_one_and_two_threads(
) {
    // 11 × 11 × 10 = 1210 hexahedra (two chunks of 1024): every element path at once,
    // Johnson–Cook plasticity with heating, bulk viscosity, hourglass forces, on one and
    // on two threads. Energy: the explicit scheme conserves it to round-off plus
    // what the ledger books (internal with the plastic work, bulk viscosity as damping,
    // hourglass), so the balance must stay near round-off.
    // The block and its velocity field: `common::solid::struck_block`.
    let m = struck_block();
    let run = |threads: usize| on_threads(threads, || run_in_memory(&m).unwrap());
    let (s1, o1, st) = run(1);
    let (s2, o2, _) = run(2);
    assert!(
        o1.u == o2.u && o1.energy == o2.energy,
        "1 and 2 threads differ"
    );
    assert!(s1.operator().el.hex.state == s2.operator().el.hex.state);
    let e = o1.energy.last().unwrap();
    let ep = s1
        .operator()
        .el
        .hex
        .state
        .iter()
        .fold(0.0f64, |a, p| a.max(p.plastic_strain));
    let t = s1
        .operator()
        .el
        .hex
        .state
        .iter()
        .fold(0.0f64, |a, p| a.max(p.temperature));
    eprintln!(
        "copper block: {} steps; kinetic {:.4e} J, internal {:.4e} J, bulk viscosity {:.3e} J, hourglass {:.3e} J ({:.2e} of internal); largest ε_p {ep:.3}, T {t:.1} K; balance {:.2e}",
        st.steps,
        e.kinetic,
        e.internal,
        e.damping,
        e.hourglass,
        e.hourglass / e.internal,
        st.max_balance_error_relative
    );
    assert!(ep > 0.0 && t > 293.15);
    // Measured 1.0e-5 (the issue asks ≤ 1 %); tolerance 3e-5.
    assert!(
        st.max_balance_error_relative < 3e-5,
        "balance {}",
        st.max_balance_error_relative
    );
    // Measured 5.3 % of the internal energy (the cone's kinks at its axis and rim, on a
    // 1 mm grid); tolerance 11 %.
    assert!(e.hourglass < 0.11 * e.internal, "hourglass {}", e.hourglass);
}
