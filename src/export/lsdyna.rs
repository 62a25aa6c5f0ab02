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

use super::common::{fixed_translations, law_samples, node_lines, num, output_nodes, Report};
use super::unsupported::{check, Refusals, Unsupported};
use crate::error::Result;
use crate::model::{ElementKind, Model, Part};

const FORMAT: &str = "LS-DYNA";

/// What this deck does not map, in the order looked for, with the reasons.
const REFUSED: &Refusals = &[
    (Unsupported::Solids, "not mapped yet (*SECTION_SOLID ELFORM 1 with *HOURGLASS IHQ 1 and *MAT_PLASTIC_KINEMATIC or *MAT_JOHNSON_COOK with its equation of state: a later step)"),
    (Unsupported::Beams, "not mapped yet (an LS-DYNA beam needs an orientation node and the section's torsion constant)"),
    (Unsupported::TrussPrestrain, "not mapped yet (LS-DYNA's cable, MAT_071, is a discrete beam with its own offset law)"),
    (Unsupported::TrussArea, "not mapped yet (*ELEMENT_BEAM_THICKNESS)"),
    (Unsupported::LinkSliding, "a link whose ends move along its yarns has no discrete-element counterpart (it would be a contact between beams)"),
    (Unsupported::LinkSlider, "weft's slider couples x and y; LS-DYNA's elastoplastic springs act per axis"),
    (Unsupported::NoCompression, "not mapped yet (a fabric material, MAT_034)"),
    (Unsupported::InitialStress, "not mapped yet (*INITIAL_STRESS_SHELL)"),
    (Unsupported::Projectiles, "not mapped yet (a rigid body and its contact)"),
    (Unsupported::Contacts, "not mapped yet (*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE with SOFT = 1 is the analogue, unchecked)"),
    (Unsupported::Ties, "not mapped yet"),
    (Unsupported::Formed, "LS-DYNA would need the formed state's stresses too"),
    (Unsupported::MassScaling, "weft's added masses are not LS-DYNA's (DT2MS)"),
];

/// Lines of at most `per` ids.
fn id_lines(s: &mut String, ids: &[i64], per: usize) {
    for c in ids.chunks(per) {
        let v: Vec<String> = c.iter().map(|i| i.to_string()).collect();
        let _ = writeln!(s, "{}", v.join(", "));
    }
}

/// The deck being written, and what it holds so far.
struct Deck {
    s: String,
    /// Cards written and their counts (the report's list, in name order).
    counts: BTreeMap<&'static str, usize>,
    /// The next free part id (a link part's discrete parts come after weft's parts).
    next_part: i64,
    /// The next free element id (discrete elements come after weft's elements).
    next_eid: i64,
    /// The next id of what weft does not number: sections, materials, hourglass sets,
    /// orientations, curves, the node set.
    next_id: i64,
}

impl Deck {
    /// A fresh id for a section, material, curve, ….
    fn take(&mut self) -> i64 {
        self.next_id += 1;
        self.next_id - 1
    }
}

/// The deck and what it holds: a list of sections, in deck order.
pub fn deck(m: &Model, dt: f64, provenance: &str) -> Result<(String, Report)> {
    check(m, FORMAT, REFUSED)?;
    let a = &m.analysis;
    let mut r = Report {
        dt,
        increments_per_output: (a.output_interval / dt).round() as u64,
        end_time: a.end_time,
        nodes: m.num_nodes(),
        ..Default::default()
    };
    // Ids for what weft does not number: sections, materials, extra parts, curves.
    let mut d = Deck {
        s: String::new(),
        counts: BTreeMap::new(),
        next_part: m.parts.iter().map(|p| p.id).max().unwrap_or(0) + 1,
        next_eid: m
            .elements
            .values()
            .flat_map(|b| b.id.iter().copied())
            .max()
            .unwrap_or(0)
            + 1,
        next_id: 1,
    };
    header_and_controls(m, provenance, &mut d.s);
    d.s.push_str("*NODE\n$ nid, x, y, z\n");
    node_lines(&mut d.s, m);
    parts(m, &mut d);
    truss_elements(m, &mut d);
    shell_elements(m, &mut d);
    discrete_links(m, &mut d);
    point_masses(m, &mut d);
    boundary(m, &mut d);
    loads(m, dt, &mut d);
    initial_velocities(m, &mut d);
    r.output_nodes = history_nodes(m, &mut d);
    d.s.push_str("*END\n");
    r.written = d
        .counts
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
    Ok((d.s, r))
}

/// The keyword line, comments (what wrote the deck, the units, the provenance), the
/// title, termination, time step, output intervals and global damping.
fn header_and_controls(m: &Model, provenance: &str, s: &mut String) {
    let a = &m.analysis;
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
}

/// Parts of trusses and membranes: one *PART, section, material (and hourglass set)
/// each.
fn parts(m: &Model, d: &mut Deck) {
    for part in &m.parts {
        match part.kind {
            ElementKind::Truss => truss_part(part, d),
            ElementKind::Tri | ElementKind::Quad => membrane_part(part, d),
            _ => {}
        }
    }
}

/// A truss part: `*SECTION_BEAM` (ELFORM = 3, truss) and `*MAT_ELASTIC`.
fn truss_part(part: &Part, d: &mut Deck) {
    let p = &part.props;
    let (sec, mat) = (d.take(), d.take());
    let s = &mut d.s;
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

/// A membrane part: `*SECTION_SHELL` (ELFORM = 5), `*MAT_ORTHOTROPIC_ELASTIC` and
/// `*HOURGLASS` (see the module docs).
fn membrane_part(part: &Part, d: &mut Deck) {
    let p = &part.props;
    let (sec, mat, hg) = (d.take(), d.take(), d.take());
    let s = &mut d.s;
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

/// Trusses as `*ELEMENT_BEAM`.
fn truss_elements(m: &Model, d: &mut Deck) {
    if let Some(b) = m.block(ElementKind::Truss) {
        d.s.push_str("*ELEMENT_BEAM\n$ eid, pid, n1, n2\n");
        for e in 0..b.len() {
            let _ = writeln!(
                d.s,
                "{}, {}, {}, {}",
                b.id[e],
                m.parts[b.part[e]].id,
                m.node_id[b.nodes[2 * e]],
                m.node_id[b.nodes[2 * e + 1]]
            );
        }
        d.counts.insert("*ELEMENT_BEAM (trusses)", b.len());
    }
}

/// Membranes as `*ELEMENT_SHELL_THICKNESS` with their nodal thicknesses (a triangle as a
/// quad with n4 = n3).
fn shell_elements(m: &Model, d: &mut Deck) {
    let s = &mut d.s;
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
        d.counts
            .insert("*ELEMENT_SHELL_THICKNESS (membranes)", shells);
    }
}

/// Links: a discrete part per (link part, axis, spring or dashpot), oriented along its
/// global axis.
fn discrete_links(m: &Model, d: &mut Deck) {
    let Some(b) = m.block(ElementKind::Link) else {
        return;
    };
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
                    orient[axis] = orientation(axis, d);
                }
                let (pid, sec, mat) = (d.next_part, d.take(), d.take());
                d.next_part += 1;
                let s = &mut d.s;
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
                        "{}, {pid}, {}, {}, {}",
                        d.next_eid,
                        m.node_id[b.nodes[2 * e]],
                        m.node_id[b.nodes[2 * e + 1]],
                        orient[axis]
                    );
                    d.next_eid += 1;
                    discrete += 1;
                }
            }
        }
    }
    d.counts.insert("*ELEMENT_DISCRETE (link axes)", discrete);
}

/// A `*DEFINE_SD_ORIENTATION` along global axis `axis`: its id.
fn orientation(axis: usize, d: &mut Deck) -> i64 {
    let vid = d.take();
    let mut v = [0.0; 3];
    v[axis] = 1.0;
    let _ = writeln!(
        d.s,
        "*DEFINE_SD_ORIENTATION\n$ vid, iop, xt, yt, zt\n{}, 0, {}, {}, {}",
        vid,
        num(v[0]),
        num(v[1]),
        num(v[2])
    );
    vid
}

/// Point masses as `*ELEMENT_MASS`.
fn point_masses(m: &Model, d: &mut Deck) {
    if let Some(b) = m.block(ElementKind::PointMass) {
        d.s.push_str("*ELEMENT_MASS\n$ eid, nid, mass\n");
        for e in 0..b.len() {
            let _ = writeln!(
                d.s,
                "{}, {}, {}",
                b.id[e],
                m.node_id[b.nodes[e]],
                num(m.parts[b.part[e]].props.mass.unwrap_or(0.0))
            );
        }
        d.counts.insert("*ELEMENT_MASS (point masses)", b.len());
    }
}

/// Boundary conditions: fixed translations and symmetry planes as `*BOUNDARY_SPC_NODE`.
fn boundary(m: &Model, d: &mut Deck) {
    let fixed = fixed_translations(m);
    let spc: Vec<usize> = (0..m.num_nodes())
        .filter(|&i| fixed[i].iter().any(|&f| f))
        .collect();
    if !spc.is_empty() {
        d.s.push_str("*BOUNDARY_SPC_NODE\n$ nid, cid, dofx, dofy, dofz, dofrx, dofry, dofrz\n");
        for &i in &spc {
            let f = fixed[i].map(|b| b as u8);
            let _ = writeln!(
                d.s,
                "{}, 0, {}, {}, {}, 0, 0, 0",
                m.node_id[i], f[0], f[1], f[2]
            );
        }
    }
    d.counts.insert("*BOUNDARY_SPC_NODE (nodes)", spc.len());
}

/// Loads: a curve each, one *LOAD_NODE_POINT line per non-zero component.
fn loads(m: &Model, dt: f64, d: &mut Deck) {
    let mut nload = 0;
    for l in &m.loads {
        let lcid = d.take();
        let s = &mut d.s;
        let _ = writeln!(s, "*DEFINE_CURVE\n$ lcid (load {})\n{lcid}\n$ a1, o1", l.id);
        for (t, g) in law_samples(&l.law, m.analysis.end_time, dt) {
            let _ = writeln!(s, "{}, {}", num(t), num(g));
        }
        s.push_str("*LOAD_NODE_POINT\n$ nid, dof, lcid, sf\n");
        for dof in (0..3).filter(|&dof| l.force[dof] != 0.0) {
            let _ = writeln!(
                s,
                "{}, {}, {lcid}, {}",
                m.node_id[l.node],
                dof + 1,
                num(l.force[dof])
            );
            nload += 1;
        }
    }
    d.counts.insert("*LOAD_NODE_POINT (load components)", nload);
}

/// Initial velocities as `*INITIAL_VELOCITY_NODE`.
fn initial_velocities(m: &Model, d: &mut Deck) {
    if !m.initial_velocities.is_empty() {
        d.s.push_str("*INITIAL_VELOCITY_NODE\n$ nid, vx, vy, vz\n");
        for (i, v) in &m.initial_velocities {
            let _ = writeln!(
                d.s,
                "{}, {}, {}, {}",
                m.node_id[*i],
                num(v[0]),
                num(v[1]),
                num(v[2])
            );
        }
    }
    d.counts
        .insert("*INITIAL_VELOCITY_NODE", m.initial_velocities.len());
}

/// History nodes: the history sets' (or every node) as a node list written to
/// `*DATABASE_HISTORY_NODE_SET`; returns their number.
fn history_nodes(m: &Model, d: &mut Deck) -> usize {
    let out: Vec<i64> = output_nodes(m).iter().map(|&i| m.node_id[i]).collect();
    let sid = d.take();
    let _ = writeln!(d.s, "*SET_NODE_LIST\n$ sid\n{sid}");
    id_lines(&mut d.s, &out, 8);
    let _ = writeln!(d.s, "*DATABASE_HISTORY_NODE_SET\n{sid}");
    out.len()
}
