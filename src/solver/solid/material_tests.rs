//! Unit tests of the solid materials (`material.rs`): each against its closed form.

use super::*;
use crate::random::Stream;

/// Steel-like bilinear J2: E = 200 GPa, ν = 0.3, σ_y0 = 250 MPa, E_t = 2 GPa.
fn bilinear() -> Material {
    let h = Hardening::from_tangent_modulus(200e9, 2e9).unwrap();
    Material::new(
        200e9,
        0.3,
        7850.0,
        Model::J2 {
            yield_stress: 250e6,
            hardening: h,
        },
        None,
    )
    .unwrap()
}

/// OFHC copper, Johnson & Cook (1983) Table 1: A = 90 MPa, B = 292 MPa, n = 0.31,
/// C = 0.025, m = 1.09, T_melt = 1356 K, c_p = 383 J/(kg K), ρ = 8960 kg/m³
/// (ε̇₀ = 1/s, T_room = 294 K as in their tests); E = 124 GPa, ν = 0.34 (handbook).
fn copper() -> Material {
    let jc = JohnsonCook {
        a: 90e6,
        b: 292e6,
        n: 0.31,
        c: 0.025,
        reference_rate: 1.0,
        m: 1.09,
        room_temperature: 294.0,
        melt_temperature: 1356.0,
        specific_heat: 383.0,
        taylor_quinney: TAYLOR_QUINNEY,
    };
    Material::new(124e9, 0.34, 8960.0, Model::JohnsonCook(jc), None).unwrap()
}

fn jc(m: &Material) -> JohnsonCook {
    match m.model {
        Model::JohnsonCook(j) => j,
        _ => unreachable!(),
    }
}

/// One increment of uniaxial stress: the axial increment `de`, the lateral increments
/// found by a secant iteration so that σ_yy = σ_zz = 0 after the update (by symmetry
/// one unknown). Returns the lateral increment.
fn uniaxial_step(mat: &Material, st: &mut PointState, de: f64, dt: f64) -> f64 {
    let g = |dl: f64| {
        let mut s = *st;
        update(mat, &mut s, &[de, dl, dl, 0.0, 0.0, 0.0], dt);
        (s.stress[1], s)
    };
    let nu = mat.poisson_ratio;
    let (mut a, mut b) = (-nu * de, -0.5 * de);
    let (mut ga, mut gb) = (g(a).0, g(b).0);
    for _ in 0..60 {
        if gb.abs() <= 1e-7 || gb == ga {
            break;
        }
        let c = b - gb * (b - a) / (gb - ga);
        (a, ga) = (b, gb);
        b = c;
        gb = g(b).0;
    }
    let (r, s) = g(b);
    assert!(
        r.abs() <= 1e-6 && s.stress[2].abs() <= 1e-6,
        "lateral stress {r}"
    );
    *st = s;
    b
}

/// Uniaxial stress, bilinear hardening (oracle: the hardening law itself,
/// σ = σ_y0 + H ε_p with ε = σ/E + ε_p, and the uniaxial tangent E_t = EH/(E + H);
/// Simo & Hughes §1.4 for the 1-D model the 3-D return must reduce to), then elastic
/// unloading with slope E.
#[test]
fn uniaxial_stress_follows_linear_hardening_and_unloads_elastically() {
    let mat = bilinear();
    let (e, sy0) = (200e9, 250e6);
    let h = match &mat.model {
        Model::J2 {
            hardening: Hardening::Linear { plastic_modulus },
            ..
        } => *plastic_modulus,
        _ => unreachable!(),
    };
    let mut st = mat.initial_state();
    let de = 2e-5;
    let mut eps = 0.0;
    let mut worst = 0.0f64;
    let mut yielded_at = None;
    for k in 0..1000 {
        uniaxial_step(&mat, &mut st, de, 1e-6);
        eps += de;
        let s = st.stress[0];
        if st.plastic_strain == 0.0 {
            worst = worst.max((s - e * eps).abs() / sy0);
            assert!(s <= sy0 * (1.0 + 1e-12));
        } else {
            yielded_at.get_or_insert(k);
            worst = worst.max((s - (sy0 + h * st.plastic_strain)).abs() / s);
            worst = worst.max((eps - (s / e + st.plastic_strain)).abs() / eps);
        }
        assert!(st.stress[3..].iter().all(|&v| v == 0.0));
    }
    // Yield at ε = σ_y0/E = 1.25e-3: increment 62 (0-based).
    assert_eq!(yielded_at, Some(62));
    assert!(worst < 1e-13, "worst relative error {worst}"); // measured 3.5e-14
    assert!(st.plastic_strain > 0.015);
    // Tangent after yield E_t = E H/(E + H) = 2 GPa.
    let s1 = st.stress[0];
    uniaxial_step(&mat, &mut st, de, 1e-6);
    let et = (st.stress[0] - s1) / de;
    // Δσ/Δε cancels ~4 digits of σ: 1e-12 expected, 1.2e-16 measured.
    assert!((et - 2e9).abs() < 1e-10 * 2e9, "E_t = {et}");
    // Unloading: slope E, no new plastic strain, until σ = −σ_y(ε_p) is reached.
    let (ep, s0) = (st.plastic_strain, st.stress[0]);
    for _ in 0..20 {
        let before = st.stress[0];
        uniaxial_step(&mat, &mut st, -de, 1e-6);
        assert!(((before - st.stress[0]) / de - e).abs() < 1e-6 * e);
        assert_eq!(st.plastic_strain, ep);
    }
    assert!((s0 - st.stress[0] - 20.0 * de * e).abs() < 1e-9 * s0);
}

/// Pure shear: τ = 2μ ε_xy until the von Mises yield τ = σ_y/√3, then τ stays there
/// (perfect plasticity: Hill, *Mathematical Theory of Plasticity*, ch. II; S&H §3.3).
#[test]
fn pure_shear_yields_at_sigma_y_over_root_3() {
    let sy = 250e6;
    let mat = Material::new(
        200e9,
        0.3,
        7850.0,
        Model::J2 {
            yield_stress: sy,
            hardening: Hardening::Linear {
                plastic_modulus: 0.0,
            },
        },
        None,
    )
    .unwrap();
    let mu = mat.shear_modulus();
    let mut st = mat.initial_state();
    let d = 1e-5; // tensor ε_xy per step
    let mut exy = 0.0;
    for _ in 0..300 {
        update(&mat, &mut st, &[0.0, 0.0, 0.0, d, 0.0, 0.0], 1e-6);
        exy += d;
        let tau = st.stress[3];
        let expect = (2.0 * mu * exy).min(sy / 3f64.sqrt());
        assert!((tau - expect).abs() <= 1e-14 * expect, "{tau} vs {expect}"); // 3.0e-15
        assert_eq!(&st.stress[..3], &[0.0; 3]);
    }
    assert!(st.plastic_strain > 0.0);
    // Plastic shear: Δε_p = (2/√3) Δε_xy^p (γ^p = 2ε^p_xy, ε_p = γ^p/√3).
    let ep_expect = 2.0 / 3f64.sqrt() * (exy - sy / 3f64.sqrt() / (2.0 * mu));
    assert!((st.plastic_strain - ep_expect).abs() < 1e-12 * ep_expect);
}

/// Johnson–Cook at two plastic strain rates and a raised temperature: the returned
/// stress equals (A + B ε_pⁿ)(1 + C ln ε̇*)(1 − T*ᵐ) written out here (Johnson & Cook
/// 1983, eq. (1)) at the converged ε_p, ε̇_p = Δε_p/Δt, T_n, to 1e-10 and, tighter,
/// to the return's own bound: |r| ≤ 1e-14 σ̄_tr, i.e. 1e-14 σ̄_tr/σ_y relative (×2 for
/// round-off); measured 4.8e-14 with σ̄_tr/σ_y ≈ 5.
#[test]
fn johnson_cook_matches_the_formula() {
    let mat = copper();
    let j = jc(&mat);
    let formula = |ep: f64, rate: f64, t: f64| {
        let ts: f64 = ((t - 294.0) / (1356.0 - 294.0)).clamp(0.0, 1.0);
        (90e6 + 292e6 * ep.powf(0.31))
            * (1.0 + 0.025 * (rate / 1.0).max(1.0).ln())
            * (1.0 - ts.powf(1.09))
    };
    let mut results = vec![];
    for (dt, t) in [
        (1e-3, 294.0),
        (1e-6, 294.0),
        (1e-3, 700.0),
        (1e-6, 700.0),
        (100.0, 294.0),
    ] {
        for ep0 in [0.0, 0.2] {
            let mut st = mat.initial_state();
            st.plastic_strain = ep0;
            st.temperature = t;
            // An isochoric increment well past yield.
            let de = 0.01;
            update(
                &mat,
                &mut st,
                &[de, -0.5 * de, -0.5 * de, 0.0, 0.0, 0.0],
                dt,
            );
            let d = st.plastic_strain - ep0;
            assert!(d > 0.0);
            let rate = d / dt;
            let expect = formula(st.plastic_strain, rate, t);
            let got = von_mises(&st.stress);
            assert!(
                (got - expect).abs() < 1e-10 * expect
                    && (got - expect).abs()
                        < 2.0 * RETURN_TOLERANCE * (got + 3.0 * mat.shear_modulus() * d),
                "dt {dt} T {t}: {got} vs {expect}"
            );
            assert_eq!(expect, j.flow_stress(st.plastic_strain, rate, t));
            assert!(pressure(&st.stress).abs() < 1e-6);
            results.push((dt, t, ep0, rate, got));
        }
    }
    // The rate factor raised the stress at the fast rate (≈ 1e4/s vs ≈ 10/s: ×(1 + C ln 1e3)
    // ≈ 1.17 at equal strain, nearly), the temperature lowered it, and ε̇_p < ε̇₀ (dt =
    // 100 s) gives the quasi-static curve (rate factor 1).
    let (slow, fast, hot) = (results[0], results[2], results[4]);
    assert!(
        slow.3 > 5.0 && fast.3 > 5e3 && results[8].3 < 1.0,
        "{results:?}"
    );
    assert!(fast.4 > 1.1 * slow.4 && hot.4 < 0.8 * slow.4);
    let qs = results[8];
    assert!((qs.4 - formula(qs.2 + qs.3 * 100.0, 0.0, 294.0)).abs() < 1e-13 * qs.4); // 5.7e-16
                                                                                     // Melted: no deviatoric stress.
    let mut st = mat.initial_state();
    st.temperature = 1400.0;
    update(&mat, &mut st, &[0.01, -0.005, -0.005, 0.0, 0.0, 0.0], 1e-6);
    assert!(von_mises(&st.stress) < 1e-6, "{:?}", st.stress);
}

/// Plastic work and heating under a nonlinear law (Johnson–Cook, rising rate-free
/// curve with heating): (i) W_p = Σ σ̄_{n+1}Δε_p equals Σ σ_{n+1}:Δε^p with Δε^p
/// recovered independently from the total strain, Δε^p = dε − C⁻¹:Δσ (the elastic
/// compliance), to round-off; (ii) against the trapezoid ∫σ̄ dε_p on the recorded
/// curve, the difference is ½ Σ Δσ̄ Δε_p ≥ 0, bounded by ½ max Δε_p (σ̄_end − σ̄_start);
/// (iii) T − T₀ = χ W_p/(ρ c_p).
#[test]
fn plastic_work_and_adiabatic_heating() {
    let mat = copper();
    let j = jc(&mat);
    let (e, nu) = (mat.youngs_modulus, mat.poisson_ratio);
    let mut st = mat.initial_state();
    let t0 = st.temperature;
    let mut r = Stream::new(11);
    let mut w_tensor = 0.0;
    let mut curve = vec![(0.0, 0.0)];
    for _ in 0..400 {
        // A mostly deviatoric increment with some volume change and shear, ε̇ ~ 1e3/s.
        let de: [f64; 6] = [
            1e-3,
            -0.5e-3 + 1e-4 * (r.next_uniform() - 0.5),
            -0.5e-3 + 1e-4 * (r.next_uniform() - 0.5),
            2e-4 * (r.next_uniform() - 0.5),
            2e-4 * (r.next_uniform() - 0.5),
            2e-4 * (r.next_uniform() - 0.5),
        ];
        let before = st;
        update(&mat, &mut st, &de, 1e-6);
        let ds: [f64; 6] = std::array::from_fn(|k| st.stress[k] - before.stress[k]);
        // C⁻¹: ε_ii = (σ_ii − ν(σ_jj + σ_kk))/E, ε_ij = (1 + ν)σ_ij/E (tensor).
        let tr = ds[0] + ds[1] + ds[2];
        let dep: [f64; 6] = std::array::from_fn(|k| {
            if k < 3 {
                de[k] - ((1.0 + nu) * ds[k] - nu * tr) / e
            } else {
                de[k] - (1.0 + nu) * ds[k] / e
            }
        });
        let s = st.stress;
        w_tensor += s[0] * dep[0]
            + s[1] * dep[1]
            + s[2] * dep[2]
            + 2.0 * (s[3] * dep[3] + s[4] * dep[4] + s[5] * dep[5]);
        curve.push((st.plastic_strain, von_mises(&st.stress)));
    }
    // The first increment yields from zero; start the curve at yield (σ̄ = A).
    curve[0].1 = 90e6;
    let wp = st.plastic_work;
    assert!(
        st.plastic_strain > 0.3 && wp > 1e8,
        "{} {wp}",
        st.plastic_strain
    );
    // (i) Backward-Euler consistency: measured equal to the last bit; the bound is the
    // round-off of recovering Δε^p by subtraction (400 steps, ~1e-15 each).
    assert!(
        (wp - w_tensor).abs() < 1e-12 * wp,
        "W_p {wp} vs Σσ:Δε^p {w_tensor}"
    );
    // (ii) Trapezoid.
    let mut trap = 0.0;
    let mut half = 0.0;
    let mut max_dep = 0.0f64;
    for k in 1..curve.len() {
        let (d, s0, s1) = (curve[k].0 - curve[k - 1].0, curve[k - 1].1, curve[k].1);
        trap += 0.5 * (s0 + s1) * d;
        half += 0.5 * (s1 - s0) * d;
        max_dep = max_dep.max(d);
    }
    let bound = 0.5 * max_dep * (curve.last().unwrap().1 - curve[0].1).abs();
    assert!((wp - trap - half).abs() < 1e-12 * wp, "{wp} {trap} {half}");
    assert!(
        (wp - trap).abs() <= bound,
        "W_p − trapezoid = {}, bound {bound}",
        wp - trap
    );
    // Measured (W_p − trapezoid)/W_p = 9.8e-4 against the bound's 1.15e-3.
    assert!((wp - trap).abs() < 2e-3 * wp);
    // (iii) Heating.
    let dt_expect = j.taylor_quinney * wp / (mat.density * j.specific_heat);
    assert!((st.temperature - t0 - dt_expect).abs() < 1e-14 * dt_expect); // 3.1e-15
    assert!(dt_expect > 20.0, "{dt_expect}");
}

/// The radial return leaves the pressure of the trial state (J2 flow is deviatoric):
/// p_{n+1} = p_n − K tr(dε), bilinear, tabulated and Johnson–Cook, random increments.
#[test]
fn radial_return_keeps_the_pressure() {
    let table =
        Hardening::table(vec![0.0, 0.01, 0.05, 0.2], vec![250e6, 300e6, 340e6, 360e6]).unwrap();
    let tab = Material::new(
        200e9,
        0.3,
        7850.0,
        Model::J2 {
            yield_stress: 250e6,
            hardening: table,
        },
        None,
    )
    .unwrap();
    for mat in [bilinear(), tab, copper()] {
        let k = mat.bulk_modulus();
        let mut st = mat.initial_state();
        let mut r = Stream::new(3);
        let mut plastic = 0;
        for _ in 0..200 {
            let de: [f64; 6] = std::array::from_fn(|_| 2e-3 * (r.next_uniform() - 0.5));
            let p_expect = pressure(&st.stress) - k * (de[0] + de[1] + de[2]);
            let ep = st.plastic_strain;
            update(&mat, &mut st, &de, 1e-6);
            plastic += (st.plastic_strain > ep) as usize;
            assert!(
                (pressure(&st.stress) - p_expect).abs() < 2e-14 * k * 1e-3, // 3.7e-15
                "{:?}",
                mat.model
            );
        }
        assert!(plastic > 100);
    }
}

/// Tabulated hardening: σ̄ = σ_y(ε_p) by linear interpolation, across break points and
/// on the flat part beyond the last point.
#[test]
fn tabulated_hardening_follows_the_table() {
    let (es, ss) = (vec![0.0, 0.01, 0.05, 0.2], vec![250e6, 300e6, 340e6, 360e6]);
    let table = Hardening::table(es.clone(), ss.clone()).unwrap();
    let mat = Material::new(
        200e9,
        0.3,
        7850.0,
        Model::J2 {
            yield_stress: 250e6,
            hardening: table,
        },
        None,
    )
    .unwrap();
    let interp = |ep: f64| {
        if ep >= 0.2 {
            return 360e6;
        }
        let i = (0..3).rev().find(|&i| es[i] <= ep).unwrap();
        ss[i] + (ss[i + 1] - ss[i]) * (ep - es[i]) / (es[i + 1] - es[i])
    };
    let mut st = mat.initial_state();
    let mut segs = [false; 4];
    for _ in 0..300 {
        update(&mat, &mut st, &[1e-3, -5e-4, -5e-4, 0.0, 0.0, 0.0], 1e-6);
        if st.plastic_strain > 0.0 {
            let expect = interp(st.plastic_strain);
            assert!((von_mises(&st.stress) - expect).abs() < 2e-15 * expect); // 3.9e-16
            segs[es.iter().filter(|&&e| e <= st.plastic_strain).count() - 1] = true;
        }
    }
    assert_eq!(segs, [true; 4]);
}

#[test]
fn elastic_law_and_moduli() {
    let mat = Material::new(200e9, 0.25, 7800.0, Model::Elastic, None).unwrap();
    let (l, m) = mat.lame();
    assert!((l - 80e9).abs() < 1e-3 && (m - 80e9).abs() < 1e-3);
    assert!((mat.bulk_modulus() - (l + 2.0 * m / 3.0)).abs() < 1e-3);
    assert!((mat.dilatational_wave_speed() - (240e9f64 / 7800.0).sqrt()).abs() < 1e-9);
    let mut st = mat.initial_state();
    update(&mat, &mut st, &[1e-3, 0.0, 0.0, 2e-3, 0.0, 0.0], 1e-6);
    // Confined compression and tensor shear: σ_xx = (λ + 2μ)ε, σ_yy = λε, σ_xy = 2με_xy.
    assert_eq!(
        st.stress,
        [
            (l + 2.0 * m) * 1e-3,
            l * 1e-3,
            l * 1e-3,
            2.0 * m * 2e-3,
            0.0,
            0.0
        ]
    );
    assert_eq!(st.plastic_strain, 0.0);
}

#[test]
fn erosion_flag() {
    let mut mat = bilinear();
    mat.erosion_plastic_strain = Some(0.01);
    let mut st = mat.initial_state();
    let mut n = 0;
    while !st.eroded {
        update(&mat, &mut st, &[1e-3, -5e-4, -5e-4, 0.0, 0.0, 0.0], 1e-6);
        n += 1;
        assert!(n < 100);
    }
    assert!(st.plastic_strain >= 0.01 && st.plastic_strain < 0.0111);
    update(&mat, &mut st, &[1e-3, 0.0, 0.0, 0.0, 0.0, 0.0], 1e-6);
    assert_eq!(st.stress, [0.0; 6]);
}

/// Each bad constant is refused, and the message names it.
#[test]
fn bad_input_is_refused_by_name() {
    let msg = |r: Result<Material>| format!("{}", r.unwrap_err());
    let j2 = |sy: f64, h: Hardening| Model::J2 {
        yield_stress: sy,
        hardening: h,
    };
    let lin = Hardening::Linear {
        plastic_modulus: 1e9,
    };
    assert!(msg(Material::new(0.0, 0.3, 1.0, Model::Elastic, None)).contains("Young"));
    assert!(msg(Material::new(1e9, 0.5, 1.0, Model::Elastic, None)).contains("Poisson"));
    assert!(msg(Material::new(1e9, -1.0, 1.0, Model::Elastic, None)).contains("Poisson"));
    assert!(msg(Material::new(1e9, 0.3, 0.0, Model::Elastic, None)).contains("density"));
    assert!(msg(Material::new(1e9, 0.3, 1.0, Model::Elastic, Some(0.0))).contains("erosion"));
    assert!(msg(Material::new(1e9, 0.3, 1.0, j2(0.0, lin.clone()), None)).contains("yield stress"));
    assert!(msg(Material::new(1e9, 0.3, 1.0, j2(-1e6, lin), None)).contains("yield stress"));
    assert!(
        format!("{}", Hardening::from_tangent_modulus(1e9, 1e9).unwrap_err()).contains("tangent")
    );
    assert!(format!(
        "{}",
        Hardening::from_tangent_modulus(1e9, -1.0).unwrap_err()
    )
    .contains("tangent"));
    assert!(format!(
        "{}",
        Hardening::table(vec![0.0, 0.1, 0.1], vec![1.0, 2.0, 3.0]).unwrap_err()
    )
    .contains("strictly"));
    assert!(format!(
        "{}",
        Hardening::table(vec![0.01, 0.1], vec![1.0, 2.0]).unwrap_err()
    )
    .contains("ε_p = 0"));
    assert!(format!(
        "{}",
        Hardening::table(vec![0.0, 0.1], vec![2.0, 1.0]).unwrap_err()
    )
    .contains("non-decreasing"));
    assert!(format!(
        "{}",
        Hardening::table(vec![0.0], vec![1.0, 2.0]).unwrap_err()
    )
    .contains("as many"));
    let t = Hardening::table(vec![0.0, 0.1], vec![2e8, 3e8]).unwrap();
    assert!(msg(Material::new(1e9, 0.3, 1.0, j2(2.5e8, t.clone()), None)).contains("table starts"));
    assert!(Material::new(1e9, 0.3, 1.0, j2(2e8, t), None).is_ok());
    let ok = jc(&copper());
    let cases: [(fn(&mut JohnsonCook), &str); 11] = [
        (|j| j.a = 0.0, "A ="),
        (|j| j.b = -1.0, "B ="),
        (|j| j.n = 0.0, "exponent n"),
        (|j| j.n = 1.5, "exponent n"),
        (|j| j.c = -0.1, "constant C"),
        (|j| j.reference_rate = 0.0, "reference strain rate"),
        (|j| j.m = 0.0, "exponent m"),
        (|j| j.melt_temperature = j.room_temperature, "T_melt"),
        (|j| j.specific_heat = 0.0, "specific heat"),
        (|j| j.taylor_quinney = 1.1, "Taylor–Quinney"),
        (|j| j.taylor_quinney = -0.1, "Taylor–Quinney"),
    ];
    for (f, name) in cases {
        let mut j = ok;
        f(&mut j);
        let m = msg(Material::new(
            124e9,
            0.34,
            8960.0,
            Model::JohnsonCook(j),
            None,
        ));
        assert!(m.contains(name), "{m} lacks {name}");
    }
    assert!(ok.check_temperature(1000.0).is_ok());
    assert!(format!("{}", ok.check_temperature(1356.0).unwrap_err()).contains("melting"));
}
