//! LS-DYNA keyword deck (`.k`), free format (comma-separated fields), SI units.
//!
//! Mapping (LS-DYNA Keyword User's Manual, R13):
//! - node → `*NODE`;
//! - truss part → `*PART` + `*SECTION_BEAM` (ELFORM = 3, truss; A) + `*MAT_ELASTIC`
//!   (MAT_001: ρ, E), elements `*ELEMENT_BEAM`;
//! - membrane part (tri, quad) → `*SECTION_SHELL` (ELFORM = 5, Belytschko–Tsay membrane,
//!   one point, as weft's quad; T1…T4 the part's thickness) + `*MAT_ORTHOTROPIC_ELASTIC`
//!   (MAT_002: EA = E₁, EB = E₂, PRBA = ν₂₁ = ν₁₂E₂/E₁, GAB = G₁₂; AOPT = 3 with v = (0, 1,
//!   0), so that direction a is v × n = global x projected on a flat x–y element, turned by
//!   BETA = the material angle in degrees) + `*HOURGLASS` (IHQ = 4, Flanagan–Belytschko
//!   stiffness, QM = κ), elements `*ELEMENT_SHELL_THICKNESS` with the nodal thicknesses
//!   (a triangle as a quad with n4 = n3);
//! - link part → per axis with a spring or dashpot, a part of `*ELEMENT_DISCRETE`
//!   (`*SECTION_DISCRETE`, DRO = 0) oriented by `*DEFINE_SD_ORIENTATION` along that
//!   global axis, with `*MAT_SPRING_ELASTIC` (k) or `*MAT_DAMPER_VISCOUS` (c);
//! - point mass → `*ELEMENT_MASS`;
//! - fixed translations and symmetry planes → `*BOUNDARY_SPC_NODE`; loads →
//!   `*LOAD_NODE_POINT` with a `*DEFINE_CURVE` each; initial velocities →
//!   `*INITIAL_VELOCITY_NODE`; mass damping α → `*DAMPING_GLOBAL` (VALDMP = α: f = −α m v,
//!   weft's law);
//! - `*CONTROL_TERMINATION` (ENDTIM), `*CONTROL_TIMESTEP` (TSSFAC = the safety factor),
//!   `*DATABASE_NODOUT` and `*DATABASE_GLSTAT` at the output interval,
//!   `*DATABASE_HISTORY_NODE_SET` of the history nodes.
//!
//! Refused (not mapped; the deck would be another model): beams (an orientation node and
//! the section's torsion constant), prestrained or tension-only trusses (MAT_071 cables),
//! friction sliders (weft's is coupled in x–y), no-compression membranes, initial
//! stress, projectiles, contacts, ties, formed models, mass scaling.
//!
//! Not run here: LS-DYNA is not available to weft's tests, which check the deck's
//! structure (keywords, counts, ids and references).

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::{law_samples, num, refuse, Report};
use crate::error::Result;
use crate::model::{ElementKind, Model};

const FORMAT: &str = "LS-DYNA";

fn check(m: &Model) -> Result<()> {
    if m.block(ElementKind::Beam).is_some() {
        return Err(refuse(FORMAT, "beam elements", "not mapped yet (an LS-DYNA beam needs an orientation node and the section's torsion constant)"));
    }
    for (kind, b) in &m.elements {
        for e in 0..b.len() {
            let part = &m.parts[b.part[e]];
            let p = &part.props;
            let what = |w: &str| format!("{w} of {} part `{}`", kind.name(), part.name);
            if *kind == ElementKind::Truss
                && (p.prestrain.unwrap_or(0.0) != 0.0 || p.tension_only.unwrap_or(false))
            {
                return Err(refuse(FORMAT, &what("the prestrain or tension-only law"), "not mapped yet (LS-DYNA's cable, MAT_071, is a discrete beam with its own offset law)"));
            }
            if *kind == ElementKind::Truss && b.truss_area(&m.parts, e) != p.area.unwrap_or(0.0) {
                return Err(refuse(
                    FORMAT,
                    &what("a cross-section area of its own (elements_truss.parquet `area`)"),
                    "not mapped yet (*ELEMENT_BEAM_THICKNESS)",
                ));
            }
            if *kind == ElementKind::Link && p.sliding == Some(true) {
                return Err(refuse(
                    FORMAT,
                    &what("the sliding ends"),
                    "a link whose ends move along its yarns has no discrete-element counterpart (it would be a contact between beams)",
                ));
            }
            if *kind == ElementKind::Link && p.slip_force.is_some() {
                return Err(refuse(
                    FORMAT,
                    &what("the friction slider"),
                    "weft's slider couples x and y; LS-DYNA's elastoplastic springs act per axis",
                ));
            }
            if matches!(kind, ElementKind::Tri | ElementKind::Quad)
                && p.no_compression.unwrap_or(false)
            {
                return Err(refuse(
                    FORMAT,
                    &what("the no-compression law"),
                    "not mapped yet (a fabric material, MAT_034)",
                ));
            }
            if !b.stress0.is_empty() && b.stress0[e] != [0.0; 3] {
                return Err(refuse(
                    FORMAT,
                    &what("the initial stress"),
                    "not mapped yet (*INITIAL_STRESS_SHELL)",
                ));
            }
        }
    }
    if !m.projectiles.is_empty() {
        return Err(refuse(
            FORMAT,
            "projectiles",
            "not mapped yet (a rigid body and its contact)",
        ));
    }
    if !m.contacts.is_empty() {
        return Err(refuse(FORMAT, "contacts between parts", "not mapped yet (*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE with SOFT = 1 is the analogue, unchecked)"));
    }
    if !m.ties.is_empty() {
        return Err(refuse(FORMAT, "tied interfaces", "not mapped yet"));
    }
    if !m.initial_displacement.is_empty() {
        return Err(refuse(
            FORMAT,
            "a formed model (initial displacements ux0, uy0, uz0)",
            "LS-DYNA would need the formed state's stresses too",
        ));
    }
    if m.analysis.target_time_step.is_some() {
        return Err(refuse(
            FORMAT,
            "mass scaling (target_time_step)",
            "weft's added masses are not LS-DYNA's (DT2MS)",
        ));
    }
    Ok(())
}

/// Lines of at most `per` ids.
fn id_lines(s: &mut String, ids: &[i64], per: usize) {
    for c in ids.chunks(per) {
        let v: Vec<String> = c.iter().map(|i| i.to_string()).collect();
        let _ = writeln!(s, "{}", v.join(", "));
    }
}

/// The deck and what it holds.
pub fn deck(m: &Model, dt: f64, provenance: &str) -> Result<(String, Report)> {
    check(m)?;
    let a = &m.analysis;
    let mut r = Report {
        dt,
        increments_per_output: (a.output_interval / dt).round() as u64,
        end_time: a.end_time,
        nodes: m.num_nodes(),
        ..Default::default()
    };
    let mut s = String::new();
    s.push_str("*KEYWORD\n");
    let _ = writeln!(
        s,
        "$ LS-DYNA deck written by weft {} (weft-export --format lsdyna)",
        env!("CARGO_PKG_VERSION")
    );
    s.push_str("$ Units: SI (m, kg, s, N, Pa). Free format (comma-separated).\n");
    let _ = writeln!(s, "$ weft.provenance: {provenance}");
    s.push_str("*TITLE\nweft model\n");
    let _ = writeln!(s, "*CONTROL_TERMINATION\n$ endtim\n{}", num(a.end_time));
    let _ = writeln!(
        s,
        "*CONTROL_TIMESTEP\n$ dtinit, tssfac\n0., {}",
        num(a.dt_safety)
    );
    let _ = writeln!(s, "*DATABASE_NODOUT\n$ dt\n{}", num(a.output_interval));
    let _ = writeln!(s, "*DATABASE_GLSTAT\n$ dt\n{}", num(a.output_interval));
    if a.mass_damping != 0.0 {
        let _ = writeln!(
            s,
            "*DAMPING_GLOBAL\n$ lcid, valdmp\n0, {}",
            num(a.mass_damping)
        );
    }
    s.push_str("*NODE\n$ nid, x, y, z\n");
    for (i, x) in m.coords.iter().enumerate() {
        let _ = writeln!(
            s,
            "{}, {}, {}, {}",
            m.node_id[i],
            num(x[0]),
            num(x[1]),
            num(x[2])
        );
    }
    // Ids for what weft does not number: sections, materials, extra parts, curves.
    let mut next_part = m.parts.iter().map(|p| p.id).max().unwrap_or(0) + 1;
    let mut next_eid = m
        .elements
        .values()
        .flat_map(|b| b.id.iter().copied())
        .max()
        .unwrap_or(0)
        + 1;
    let mut next_id = 1i64;
    let mut take = || {
        next_id += 1;
        next_id - 1
    };
    // Parts of trusses and membranes: one *PART, section, material each.
    for part in &m.parts {
        let p = &part.props;
        match part.kind {
            ElementKind::Truss => {
                let (sec, mat) = (take(), take());
                let _ = writeln!(
                    s,
                    "*PART\n{}\n$ pid, secid, mid\n{}, {}, {}",
                    part.name, part.id, sec, mat
                );
                let _ = writeln!(
                    s,
                    "*SECTION_BEAM\n$ secid, elform (3: truss)\n{sec}, 3\n$ a\n{}",
                    num(p.area.unwrap_or(0.0))
                );
                let _ = writeln!(
                    s,
                    "*MAT_ELASTIC\n$ mid, ro, e, pr\n{mat}, {}, {}, 0.",
                    num(p.density.unwrap_or(0.0)),
                    num(p.youngs_modulus.unwrap_or(0.0))
                );
            }
            ElementKind::Tri | ElementKind::Quad => {
                let (sec, mat, hg) = (take(), take(), take());
                let _ = writeln!(
                    s,
                    "*PART\n{}\n$ pid, secid, mid, eosid, hgid\n{}, {}, {}, 0, {}",
                    part.name, part.id, sec, mat, hg
                );
                let t = num(p.thickness.unwrap_or(0.0));
                let _ = writeln!(s, "*SECTION_SHELL\n$ secid, elform (5: membrane), shrf, nip\n{sec}, 5, 1., 1\n$ t1, t2, t3, t4\n{t}, {t}, {t}, {t}");
                let (e1, e2) = (
                    p.youngs_modulus_1.unwrap_or(0.0),
                    p.youngs_modulus_2.unwrap_or(0.0),
                );
                let nu21 = p.poisson_ratio_12.unwrap_or(0.0) * e2 / e1;
                let g = num(p.shear_modulus_12.unwrap_or(0.0));
                let beta = p.material_angle.unwrap_or(0.0).to_degrees();
                let _ = writeln!(
                    s,
                    "*MAT_ORTHOTROPIC_ELASTIC\n$ mid, ro, ea, eb, ec, prba, prca, prcb\n{mat}, {}, {}, {}, {}, {}, 0., 0.\n$ gab, gbc, gca, aopt (3: from v x n, turned by beta)\n{g}, {g}, {g}, 3.\n$ xp, yp, zp, a1, a2, a3\n0., 0., 0., 0., 0., 0.\n$ v1, v2, v3, d1, d2, d3, beta\n0., 1., 0., 0., 0., 0., {}",
                    num(p.density.unwrap_or(0.0)),
                    num(e1),
                    num(e2),
                    num(e2),
                    num(nu21),
                    num(beta)
                );
                let _ = writeln!(
                    s,
                    "*HOURGLASS\n$ hgid, ihq (4: Flanagan-Belytschko stiffness), qm\n{hg}, 4, {}",
                    num(p.hourglass.unwrap_or(0.1))
                );
            }
            _ => {}
        }
    }
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    if let Some(b) = m.block(ElementKind::Truss) {
        s.push_str("*ELEMENT_BEAM\n$ eid, pid, n1, n2\n");
        for e in 0..b.len() {
            let _ = writeln!(
                s,
                "{}, {}, {}, {}",
                b.id[e],
                m.parts[b.part[e]].id,
                m.node_id[b.nodes[2 * e]],
                m.node_id[b.nodes[2 * e + 1]]
            );
        }
        counts.insert("*ELEMENT_BEAM (trusses)", b.len());
    }
    let mut shells = 0;
    for kind in [ElementKind::Tri, ElementKind::Quad] {
        let Some(b) = m.block(kind) else { continue };
        let npe = kind.nodes_per_element();
        s.push_str(
            "*ELEMENT_SHELL_THICKNESS\n$ eid, pid, n1, n2, n3, n4\n$ thic1, thic2, thic3, thic4\n",
        );
        for e in 0..b.len() {
            let p = &m.parts[b.part[e]];
            let mut n: Vec<i64> = b.nodes[npe * e..npe * (e + 1)]
                .iter()
                .map(|&i| m.node_id[i])
                .collect();
            let mut t: Vec<f64> = if b.thickness.is_empty() {
                vec![p.props.thickness.unwrap_or(0.0); npe]
            } else {
                b.thickness[npe * e..npe * (e + 1)].to_vec()
            };
            if npe == 3 {
                n.push(n[2]);
                t.push(t[2]);
            }
            let _ = writeln!(
                s,
                "{}, {}, {}, {}, {}, {}",
                b.id[e], p.id, n[0], n[1], n[2], n[3]
            );
            let _ = writeln!(
                s,
                "{}, {}, {}, {}",
                num(t[0]),
                num(t[1]),
                num(t[2]),
                num(t[3])
            );
        }
        shells += b.len();
    }
    if shells > 0 {
        counts.insert("*ELEMENT_SHELL_THICKNESS (membranes)", shells);
    }
    // Links: a discrete part per (link part, axis, spring or dashpot).
    if let Some(b) = m.block(ElementKind::Link) {
        let mut orient = [0i64; 3];
        let mut discrete = 0;
        for part in m.parts.iter().filter(|p| p.kind == ElementKind::Link) {
            let p = &part.props;
            let members: Vec<usize> = (0..b.len())
                .filter(|&e| m.parts[b.part[e]].id == part.id)
                .collect();
            for axis in 0..3 {
                for (value, mat_kw, field) in [
                    ([p.kx, p.ky, p.kz][axis], "*MAT_SPRING_ELASTIC", "k"),
                    ([p.cx, p.cy, p.cz][axis], "*MAT_DAMPER_VISCOUS", "dc"),
                ] {
                    let v = value.unwrap_or(0.0);
                    if v <= 0.0 || members.is_empty() {
                        continue;
                    }
                    if orient[axis] == 0 {
                        orient[axis] = take();
                        let mut d = [0.0; 3];
                        d[axis] = 1.0;
                        let _ = writeln!(
                            s,
                            "*DEFINE_SD_ORIENTATION\n$ vid, iop, xt, yt, zt\n{}, 0, {}, {}, {}",
                            orient[axis],
                            num(d[0]),
                            num(d[1]),
                            num(d[2])
                        );
                    }
                    let (pid, sec, mat) = (next_part, take(), take());
                    next_part += 1;
                    let _ = writeln!(
                        s,
                        "*PART\n{} {} {}\n$ pid, secid, mid\n{pid}, {sec}, {mat}",
                        part.name,
                        ["x", "y", "z"][axis],
                        field
                    );
                    let _ = writeln!(
                        s,
                        "*SECTION_DISCRETE\n$ secid, dro (0: translational)\n{sec}, 0"
                    );
                    let _ = writeln!(s, "{mat_kw}\n$ mid, {field}\n{mat}, {}", num(v));
                    s.push_str("*ELEMENT_DISCRETE\n$ eid, pid, n1, n2, vid\n");
                    for &e in &members {
                        let _ = writeln!(
                            s,
                            "{next_eid}, {pid}, {}, {}, {}",
                            m.node_id[b.nodes[2 * e]],
                            m.node_id[b.nodes[2 * e + 1]],
                            orient[axis]
                        );
                        next_eid += 1;
                        discrete += 1;
                    }
                }
            }
        }
        counts.insert("*ELEMENT_DISCRETE (link axes)", discrete);
    }
    if let Some(b) = m.block(ElementKind::PointMass) {
        s.push_str("*ELEMENT_MASS\n$ eid, nid, mass\n");
        for e in 0..b.len() {
            let _ = writeln!(
                s,
                "{}, {}, {}",
                b.id[e],
                m.node_id[b.nodes[e]],
                num(m.parts[b.part[e]].props.mass.unwrap_or(0.0))
            );
        }
        counts.insert("*ELEMENT_MASS (point masses)", b.len());
    }
    // Boundary conditions.
    let mut fixed = vec![[false; 3]; m.num_nodes()];
    for (i, f) in &m.constraints {
        for d in 0..3 {
            fixed[*i][d] |= f[d];
        }
    }
    for sp in &m.symmetry {
        for (i, x) in m.coords.iter().enumerate() {
            if (x[sp.normal] - sp.position).abs() <= sp.tolerance {
                fixed[i][sp.normal] = true;
            }
        }
    }
    let spc: Vec<usize> = (0..m.num_nodes())
        .filter(|&i| fixed[i].iter().any(|&f| f))
        .collect();
    if !spc.is_empty() {
        s.push_str("*BOUNDARY_SPC_NODE\n$ nid, cid, dofx, dofy, dofz, dofrx, dofry, dofrz\n");
        for &i in &spc {
            let f = fixed[i].map(|b| b as u8);
            let _ = writeln!(
                s,
                "{}, 0, {}, {}, {}, 0, 0, 0",
                m.node_id[i], f[0], f[1], f[2]
            );
        }
    }
    counts.insert("*BOUNDARY_SPC_NODE (nodes)", spc.len());
    // Loads: a curve each, one *LOAD_NODE_POINT line per non-zero component.
    let mut nload = 0;
    for l in &m.loads {
        let lcid = take();
        let _ = writeln!(s, "*DEFINE_CURVE\n$ lcid (load {})\n{lcid}\n$ a1, o1", l.id);
        for (t, g) in law_samples(&l.law, a.end_time, dt) {
            let _ = writeln!(s, "{}, {}", num(t), num(g));
        }
        s.push_str("*LOAD_NODE_POINT\n$ nid, dof, lcid, sf\n");
        for d in (0..3).filter(|&d| l.force[d] != 0.0) {
            let _ = writeln!(
                s,
                "{}, {}, {lcid}, {}",
                m.node_id[l.node],
                d + 1,
                num(l.force[d])
            );
            nload += 1;
        }
    }
    counts.insert("*LOAD_NODE_POINT (load components)", nload);
    if !m.initial_velocities.is_empty() {
        s.push_str("*INITIAL_VELOCITY_NODE\n$ nid, vx, vy, vz\n");
        for (i, v) in &m.initial_velocities {
            let _ = writeln!(
                s,
                "{}, {}, {}, {}",
                m.node_id[*i],
                num(v[0]),
                num(v[1]),
                num(v[2])
            );
        }
    }
    counts.insert("*INITIAL_VELOCITY_NODE", m.initial_velocities.len());
    // History nodes.
    let out: Vec<i64> = if a.history_sets.is_empty() {
        m.node_id.clone()
    } else {
        let mut v: Vec<usize> = a
            .history_sets
            .iter()
            .filter_map(|n| m.node_sets.get(n))
            .flatten()
            .copied()
            .collect();
        v.sort_unstable();
        v.dedup();
        v.iter().map(|&i| m.node_id[i]).collect()
    };
    r.output_nodes = out.len();
    let sid = take();
    let _ = writeln!(s, "*SET_NODE_LIST\n$ sid\n{sid}");
    id_lines(&mut s, &out, 8);
    let _ = writeln!(s, "*DATABASE_HISTORY_NODE_SET\n{sid}");
    s.push_str("*END\n");
    r.written = counts
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
    Ok((s, r))
}
