//! The woven patch's second representation (`weft-weave woven --yarn-model chain`): each
//! yarn a chain of trusses along the band's centre line, of the band's section and mass,
//! with the band's centre thickness t_c as contact thickness.
//!
//! Oracles:
//! - the band model of the same weave (an independent element formulation: membrane quads
//!   with the lenticular nodal thickness): the same mass to round-off, node for node on
//!   the centre lines the same geometry; a plain weave's areal density 2ρA(1 + c)/p;
//! - contact geometry: two cylinders of diameter t_c whose axes lie 2a ≥ t_c apart do not
//!   overlap; a sphere of radius R touches a cylinder of radius r where a sphere of radius
//!   R + r touches its axis (the Minkowski sum);
//! - energy conservation with yarn–yarn contact and friction in an impact; the same bits
//!   on 1 and 2 threads;
//! - Smith's kink speed with the fabric's mass per yarn (Smith, McCrackin, Schiefer,
//!   Textile Res. J. 28, 1958; Cunniff, Textile Res. J. 62, 1992), as for the bands
//!   (`tests/woven.rs`). Smith's strain and kink speed for a single straight truss chain
//!   are `tests/projectile.rs`' `smith_transverse_impact_strain_and_kink_speed`.

mod common;
use std::collections::HashMap;

use common::rel;
use common::woven::run_on;
use weft::generate::woven::{woven, Lenticular, WovenBandParams, YarnModel};
use weft::model::ElementKind;
use weft::solver::{run_in_memory, Solver};

fn params(yarns: usize, yarn_model: YarnModel) -> WovenBandParams {
    WovenBandParams {
        yarns,
        yarn_model,
        ..WovenBandParams::default()
    }
}

#[test]
fn a_chain_patch_has_the_bands_mass_section_and_contact_geometry() {
    let p = params(8, YarnModel::Chain);
    let (c, info) = woven(&p).unwrap();
    // The bands of the same crimp (the chains' default amplitude is 0.5 % larger: see
    // below).
    let (b, _) = woven(&WovenBandParams {
        crimp_amplitude: Some(info.crimp_amplitude),
        ..params(8, YarnModel::Band)
    })
    .unwrap();
    let lens = Lenticular::new(p.width, p.thickness);
    let (sc, sb) = (Solver::new(&c).unwrap(), Solver::new(&b).unwrap());
    let side = (p.yarns as f64 - 0.5) * p.spacing;
    let closed = 2.0 * p.density * lens.area() * (1.0 + info.crimp) / p.spacing * side * side;
    println!(
        "8×8 quarter: chains {:.6e} kg, bands {:.6e} kg ({:.1e}), closed form {:.6e} kg ({:.1e})",
        sc.physical_mass(),
        sb.physical_mass(),
        rel(sc.physical_mass(), sb.physical_mass()),
        closed,
        rel(sc.physical_mass(), closed)
    );
    // The same chords along the same crimped path: measured 2e-16.
    assert!(rel(sc.physical_mass(), sb.physical_mass()) < 1e-12);
    // Chords 4 per spacing under the cosine: measured 8.2e-4 (the bands' too).
    assert!(rel(sc.physical_mass(), closed) < 2e-3);
    // Sections: A, half of it for the yarns on the symmetry planes x = 0 and y = 0.
    let t = &c.elements[&ElementKind::Truss];
    for e in 0..t.len() {
        let (n1, n2) = (t.nodes[2 * e], t.nodes[2 * e + 1]);
        let on_plane = (0..2).any(|d| c.coords[n1][d] == 0.0 && c.coords[n2][d] == 0.0);
        let want = if on_plane { 0.5 } else { 1.0 } * lens.area();
        assert!(
            rel(t.truss_area(&c.parts, e), want) < 1e-15,
            "truss {}",
            t.id[e]
        );
    }
    // Contact thickness t_c, the bands' centre thickness; the centre lines at every
    // crossing 2a apart, a little more than t_c (measured 0.48 %: so that the chords
    // rising from the lower node stay t_c from the upper one, which the run below checks:
    // no initial penetration).
    let t_c = info.contact_thickness;
    let q = &b.elements[&ElementKind::Quad];
    assert_eq!(t_c, q.thickness.iter().cloned().fold(0.0, f64::max));
    assert_eq!(c.contacts.len(), 1);
    assert_eq!(c.contacts[0].slave_thickness, Some(t_c));
    assert_eq!(c.contacts[0].master_thickness, Some(t_c));
    for (&w, &f) in c.node_sets["diagonal"]
        .iter()
        .zip(&c.node_sets["diagonal_weft"])
    {
        let gap = (c.coords[w][2] - c.coords[f][2]).abs();
        assert!(gap > t_c && gap < 1.01 * t_c, "gap {gap} against t_c {t_c}");
    }
    // The centre lines' nodes are the bands' centre-line nodes.
    let centre = |m: &weft::model::Model| {
        let mut v: Vec<[i64; 3]> = m.node_sets["axis_x"]
            .iter()
            .map(|&n| m.coords[n].map(|x| (x * 1e12).round() as i64))
            .collect();
        v.sort();
        v
    };
    assert_eq!(centre(&c), centre(&b));
    // The projectile's nose: the same centre, radius R + t_c/2 against the chains' axes.
    let (pc, pb) = (&c.projectiles[0], &b.projectiles[0]);
    assert!(rel(pc.radius, pb.radius + 0.5 * t_c) < 1e-15);
    let centre_z = |pr: &weft::model::ProjectileSpec| pr.tip[2] + pr.radius;
    assert!((centre_z(pc) - centre_z(pb)).abs() < 1e-15);
    // No initial penetration anywhere.
    let mut short = c.clone();
    short.analysis.end_time = 1e-7;
    short.analysis.output_interval = 1e-7;
    let (s, _, _) = run_in_memory(&short).unwrap();
    assert_eq!(
        s.operator()
            .surfaces
            .report(&s.node_ids())
            .initial_penetrations,
        0
    );
}

#[test]
fn a_chain_patch_impact_keeps_its_energy_and_is_thread_independent() {
    let p = WovenBandParams {
        end_time: 6e-6,
        output_interval: 2e-7,
        ..params(6, YarnModel::Chain)
    };
    let (m, _) = woven(&p).unwrap();
    let (o1, rep, stats) = run_on(&m, 1);
    let (o2, _, _) = run_on(&m, 2);
    let (e1, p1) = (&o1.energy, &o1.projectile);
    let last = e1.last().unwrap();
    println!(
        "chain 6×6 quarter, 6 µs: {} slaves in contact, friction work {:.3e} J, contact {:.3e} J, internal {:.3e} J, balance {:.2e}",
        rep.active, rep.friction_work, last.contact, last.internal, stats.max_balance_error_relative
    );
    assert!(
        o1.u == o2.u && o1.energy == o2.energy && o1.projectile == o2.projectile,
        "1 and 2 threads differ"
    );
    // Measured 1.9e-5 (the same bits on 1 and 2 threads); tolerance 6e-5, 3.1× (users
    // are promised ≤ 1 % with contact and friction).
    assert!(
        stats.max_balance_error_relative < 6e-5,
        "balance {:.2e}",
        stats.max_balance_error_relative
    );
    assert!(rep.friction_work > 0.0 && rep.active > 0);
    let vz = p1.last().unwrap().2[5];
    assert!(
        vz > -p.projectile_velocity && vz < 0.0,
        "projectile vz {vz}"
    );
}

/// The transverse front along the principal yarn (the warp chain on y = 0, half a yarn),
/// against Smith's kink speed U_L = √(P/(ρ_eff (1 + ε))) at the strain measured just
/// behind it, with the fabric's mass per yarn ρ_eff = 2ρ (see `tests/woven.rs`' band
/// version for the argument). Same reading as the bands': 16 × 16 quarter, 2–8 µs, the
/// outermost centre-line node with −u_z > 0.2 mm fitted linearly in t, P = N/A_e and ε the
/// mean over the axis chain's trusses in the 2 mm behind it. Measured: front 752 m/s,
/// Smith's U_L 738 m/s at ε = 2.00 % (+1.8 %; the bands' +4.7 %); with ρ alone 1044 m/s
/// (−28 %). Tolerance 5 %: the front is read to a node (0.25 mm) per sample.
#[test]
fn the_chain_patch_front_runs_at_smiths_speed_with_the_fabrics_mass() {
    let p = WovenBandParams {
        end_time: 8e-6,
        output_interval: 1e-7,
        ..params(16, YarnModel::Chain)
    };
    let (m, _) = woven(&p).unwrap();
    // The axis warp's trusses (on y = 0): their centre x and area, and their nodes.
    let warp = m.parts.iter().position(|q| q.name == "warp_1").unwrap();
    let b = &m.elements[&ElementKind::Truss];
    let (mut centre, mut area) = (HashMap::new(), HashMap::new());
    let mut line: Vec<usize> = vec![];
    for e in 0..b.len() {
        let (n1, n2) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
        if b.part[e] != warp || m.coords[n1][1] != 0.0 {
            continue;
        }
        centre.insert(b.id[e], 0.5 * (m.coords[n1][0] + m.coords[n2][0]));
        area.insert(b.id[e], b.truss_area(&m.parts, e));
        line.extend([n1, n2]);
    }
    line.sort_by(|a, c| m.coords[*a][0].total_cmp(&m.coords[*c][0]));
    line.dedup();
    let (el, samples) = common::woven::front(&m, &line, &centre);
    let (eid, eps_col, n_col) = (
        el.i64("element_id", "").unwrap(),
        el.f64("axial_strain", "").unwrap(),
        el.f64("axial_force", "").unwrap(),
    );
    // Per sample: the mean nominal stress N/A and strain behind the front.
    let front: Vec<(f64, f64)> = samples
        .iter()
        .map(|f| {
            let n = f.rows.len() as f64;
            for &r in &f.rows {
                assert!(n_col[r].is_finite() && eps_col[r].is_finite(), "row {r}");
            }
            let sp: f64 = f.rows.iter().map(|&r| n_col[r] / area[&eid[r]]).sum();
            let se: f64 = f.rows.iter().map(|&r| eps_col[r]).sum();
            (sp / n, se / n)
        })
        .collect();
    let speed = common::woven::front_speed(&samples);
    let nf = front.len() as f64;
    // P and ε averaged over the samples, then U_L: behind a chain's front (point
    // crossings, every 0.25 mm a node) the strain rings, down to −2 % in one sample,
    // where U_L has no value.
    let pn = front.iter().map(|f| f.0).sum::<f64>() / nf;
    let eps = front.iter().map(|f| f.1).sum::<f64>() / nf;
    let smith = (pn / (2.0 * p.density * (1.0 + eps))).sqrt();
    println!(
        "chain patch front {speed:.0} m/s; Smith's U_L with the fabric's mass (2ρ) at the measured strain ({:.2} %): {smith:.0} m/s ({:+.3}); with the yarn's alone: {:.0} m/s",
        100.0 * eps,
        speed / smith - 1.0,
        smith * 2f64.sqrt()
    );
    assert!(
        rel(speed, smith) < 0.05,
        "front {speed} m/s vs Smith {smith} m/s"
    );
}

/// A per-element truss area that is not a positive finite number is refused, naming the
/// file, the column, the row and the element.
#[test]
fn a_bad_truss_area_is_refused_with_the_element_named() {
    let (m, _) = woven(&params(2, YarnModel::Chain)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let prov = weft::table::Provenance::new("test", serde_json::json!({}));
    weft::model::io::write_model(&m, dir.path(), &prov).unwrap();
    let back = weft::model::io::read_model(dir.path()).unwrap();
    assert_eq!(
        back.elements[&ElementKind::Truss].area,
        m.elements[&ElementKind::Truss].area
    );
    let mut bad = m.clone();
    let t = bad.elements.get_mut(&ElementKind::Truss).unwrap();
    t.area[3] = -1e-8;
    let id = t.id[3];
    let err = bad.validate().unwrap_err().to_string();
    println!("{err}");
    assert!(
        err.contains("elements_truss.parquet")
            && err.contains("area")
            && err.contains(&format!("truss `{id}`"))
            && err.contains("-0.00000001"),
        "{err}"
    );
}

/// Fitting a chain part's `area` would leave the half yarns' own areas as they are:
/// `weft-fit` refuses it, naming the truss.
#[test]
fn fitting_the_area_of_trusses_with_their_own_area_is_refused() {
    let (m, _) = woven(&params(2, YarnModel::Chain)).unwrap();
    let err = weft::fit::parse_param("warp_1.area:1e-8:1e-7", &m)
        .unwrap_err()
        .to_string();
    println!("{err}");
    assert!(
        err.contains("truss `1` of part `warp_1` has a cross-section area of its own"),
        "{err}"
    );
    // The part's modulus is fitted as usual.
    assert!(weft::fit::parse_param("warp_1.E:1e10:1e11", &m).is_ok());
}
