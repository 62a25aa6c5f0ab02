//! CalculiX (ccx 2.20) input deck for explicit dynamics (`*DYNAMIC, EXPLICIT`).
//!
//! What CalculiX 2.20's explicit scheme runs correctly, measured with the Debian package
//! `calculix-ccx` (the facts of issue 15, and `tests/export_calculix.rs`):
//! - a truss as a `SPRINGA` element (an axial spring along the current axis, k = E·A/L₀)
//!   with the truss's mass lumped on its nodes as `MASS` elements; `T3D2` trusses are
//!   refused by ccx in explicit ("linear and nonlinear MPC's depend on each other");
//! - a prestrained or tension-only truss as a `NONLINEAR` `SPRINGA`: force against
//!   elongation e from the geometric length, F = k(e + L − L₀) (0 below −(L − L₀) when
//!   tension-only), a straight line through the range −0.9 L … L (ccx holds the force
//!   constant outside the points given);
//! - a link between nodes as one `SPRING2` per axis with a spring (the global-axis
//!   spring of weft's link, exact for coincident nodes);
//! - point masses as `MASS` elements;
//! - fixed translations and symmetry planes as `*BOUNDARY`, loads as `*CLOAD` with a
//!   tabulated `*AMPLITUDE` (a sine pulse sampled at every step), initial velocities as
//!   `*INITIAL CONDITIONS, TYPE=VELOCITY`;
//! - mass-proportional damping α as Rayleigh damping `*DAMPING, ALPHA=α` (applied to the
//!   whole model).
//!
//! Refused, with the reason: beams (`B31` runs in explicit but is expanded into `C3D8I`
//! bricks, which give wrong answers there), membranes (`M3D4` likewise; `S4R` shells run
//! correctly in-plane but add a bending stiffness weft's membranes do not have), link
//! dashpots (`DASHPOTA` is silently ignored in explicit), friction sliders, projectiles,
//! contacts, ties, formed models (initial displacement with its stresses), mass
//! scaling.
//!
//! The step: ccx in explicit with `DIRECT` needs the minimum and maximum increment on the
//! `*DYNAMIC` line (without them its time does not advance: the springs have no wave
//! speed, ccx prints "Wave Speed for mat. … −1"); numbers are at most 20 characters
//! (longer fields are refused by ccx's reader). `*NODE PRINT, FREQUENCY=n` prints every
//! n-th increment, so the step divides the output interval; `TIME POINTS` collides with
//! `DIRECT`. CalculiX's explicit scheme is not pure central difference: expect
//! differences of 10⁻⁴–10⁻³ of max|u| against weft on the same step.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::common::{fixed_translations, law_samples, node_lines, num, output_nodes, Report};
use super::unsupported::{check, Refusals, Unsupported};
use crate::error::Result;
use crate::model::{ElementKind, Model};

const FORMAT: &str = "CalculiX";

/// What this deck cannot reproduce, in the order looked for, with CalculiX's reasons.
const REFUSED: &Refusals = &[
    (Unsupported::Solids, "not mapped yet (C3D8R with its hourglass control and a plastic material would need checking against weft's one-point hexahedron first)"),
    (Unsupported::Beams, "CalculiX's B31 beams run in explicit dynamics but give wrong answers there (they are expanded into C3D8I bricks, which are wrong in explicit); measured with ccx 2.20"),
    (Unsupported::Membranes, "CalculiX's M3D membranes are expanded into C3D8I bricks, wrong in explicit dynamics; S4R shells run correctly in-plane but add a bending stiffness weft's membranes do not have (measured with ccx 2.20)"),
    (Unsupported::LinkDashpots, "CalculiX's DASHPOTA elements are silently ignored in explicit dynamics (measured with ccx 2.20)"),
    (Unsupported::LinkSlider, "CalculiX has no elastic-perfectly-plastic discrete element"),
    (Unsupported::LinkSliding, "a link whose ends move along its yarns has no discrete-element counterpart (it would be a contact between beams)"),
    (Unsupported::Projectiles, "a rigid projectile in penalty contact has no CalculiX explicit counterpart here"),
    (Unsupported::Contacts, "not exported (CalculiX's contact in explicit dynamics is not checked against weft's)"),
    (Unsupported::Ties, "they would be *EQUATION constraints; not exported"),
    (Unsupported::Formed, "CalculiX cannot start from displaced positions with the strains of that state"),
    (Unsupported::MassScaling, "the added masses are weft's; run without mass scaling"),
];

/// Groups elements with equal constants into one ELSET (ccx takes one constant per set).
#[derive(Default)]
struct Sets<K: Ord> {
    sets: BTreeMap<K, Vec<String>>,
}

impl<K: Ord> Sets<K> {
    fn add(&mut self, key: K, line: String) {
        self.sets.entry(key).or_default().push(line);
    }
}

/// Bit pattern of a float, for grouping equal values.
fn bits(x: f64) -> u64 {
    x.to_bits()
}

/// The float of a bit pattern from [`bits`] (the same value, bit for bit).
fn value(b: u64) -> f64 {
    f64::from_bits(b)
}

/// The deck being written, and what it holds so far.
struct Deck {
    s: String,
    r: Report,
    /// The next free element id (SPRING2 and MASS elements come after weft's own).
    next_id: i64,
    /// Lumped nodal masses [kg]: the trusses' halves and the point masses.
    mass: Vec<f64>,
}

/// The deck and what it holds: a list of sections, in deck order.
pub fn deck(m: &Model, dt: f64, nsub: u64, provenance: &str) -> Result<(String, Report)> {
    check(m, FORMAT, REFUSED)?;
    let mut d = Deck {
        s: String::new(),
        r: Report {
            dt,
            increments_per_output: nsub,
            end_time: m.analysis.end_time,
            nodes: m.num_nodes(),
            ..Default::default()
        },
        next_id: m
            .elements
            .values()
            .flat_map(|b| b.id.iter().copied())
            .max()
            .unwrap_or(0)
            + 1,
        mass: vec![0.0; m.num_nodes()],
    };
    header(&mut d.s, dt, provenance);
    d.s.push_str("*NODE, NSET=NALL\n");
    node_lines(&mut d.s, m);
    trusses(m, &mut d);
    links(m, &mut d);
    masses(m, &mut d);
    damping(m, &mut d.s);
    boundary(m, &mut d);
    initial_velocities(m, &mut d);
    amplitudes(m, dt, &mut d.s);
    output_set(m, &mut d);
    step(m, dt, nsub, &mut d);
    Ok((d.s, d.r))
}

/// Comment lines (what wrote the deck, the units and step, the provenance) and the
/// heading.
fn header(s: &mut String, dt: f64, provenance: &str) {
    let _ = writeln!(
        s,
        "** CalculiX deck written by weft {} (weft-export --format calculix)",
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(
        s,
        "** Units: SI (m, kg, s, N, Pa). Explicit dynamics, fixed step {} s;",
        num(dt)
    );
    let _ = writeln!(
        s,
        "** compare with: weft-simulate --time-step {} (same step).",
        num(dt)
    );
    let _ = writeln!(
        s,
        "** Trusses are SPRINGA with lumped MASS; links one SPRING2 per axis."
    );
    let _ = writeln!(s, "** weft.provenance: {provenance}");
    let _ = writeln!(s, "*HEADING\nweft model, explicit dynamics");
}

/// Trusses as SPRINGA elements: linear sets by k, nonlinear ones by (k, L, L − L₀,
/// tension-only); their masses lumped, half on each end.
fn trusses(m: &Model, d: &mut Deck) {
    let dist = |a: usize, b: usize| {
        let (p, q) = (m.coords[a], m.coords[b]);
        ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2)).sqrt()
    };
    let mut linear: Sets<u64> = Sets::default();
    let mut nonlinear: Sets<(u64, u64, u64, bool)> = Sets::default();
    if let Some(b) = m.block(ElementKind::Truss) {
        for e in 0..b.len() {
            let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
            let p = &m.parts[b.part[e]].props;
            let (ym, area, rho) = (
                p.youngs_modulus.unwrap_or(0.0),
                b.truss_area(&m.parts, e),
                p.density.unwrap_or(0.0),
            );
            let l = dist(a, c);
            let l0 = l / (1.0 + p.prestrain.unwrap_or(0.0));
            let k = ym * area / l0;
            d.mass[a] += 0.5 * rho * area * l;
            d.mass[c] += 0.5 * rho * area * l;
            let line = format!("{}, {}, {}", b.id[e], m.node_id[a], m.node_id[c]);
            let tension_only = p.tension_only.unwrap_or(false);
            if l != l0 || tension_only {
                nonlinear.add((bits(k), bits(l), bits(l - l0), tension_only), line);
            } else {
                linear.add(bits(k), line);
            }
        }
        d.r.written.push(("SPRINGA (trusses)".into(), b.len()));
    }
    let s = &mut d.s;
    for (n, (k, lines)) in linear.sets.iter().enumerate() {
        let _ = writeln!(s, "*ELEMENT, TYPE=SPRINGA, ELSET=TRUSS{}", n + 1);
        s.push_str(&lines.join("\n"));
        let _ = writeln!(s, "\n*SPRING, ELSET=TRUSS{}\n\n{}", n + 1, num(value(*k)));
    }
    for (n, (&(k, l, dl, tension_only), lines)) in nonlinear.sets.iter().enumerate() {
        let _ = writeln!(s, "*ELEMENT, TYPE=SPRINGA, ELSET=PRETRUSS{}", n + 1);
        s.push_str(&lines.join("\n"));
        let _ = writeln!(s, "\n*SPRING, ELSET=PRETRUSS{}, NONLINEAR\n", n + 1);
        nonlinear_law(s, value(k), value(l), value(dl), tension_only);
    }
}

/// The (force, elongation) pairs of a prestrained or tension-only truss, elongation
/// ascending: F = k(e + d), d = L − L₀ (0 below −d when tension-only), over −0.9 L … L.
fn nonlinear_law(s: &mut String, k: f64, l: f64, d: f64, tension_only: bool) {
    let f = |e: f64| {
        let v = k * (e + d);
        if tension_only {
            v.max(0.0)
        } else {
            v
        }
    };
    let mut es = vec![-0.9 * l];
    if tension_only && -d > -0.9 * l && -d < l {
        es.push(-d);
    }
    es.push(l);
    for e in es {
        let _ = writeln!(s, "{}, {}", num(f(e)), num(e));
    }
}

/// Links: one SPRING2 per axis with a spring, sets by (axis, k).
fn links(m: &Model, d: &mut Deck) {
    let mut springs: Sets<(usize, u64)> = Sets::default();
    if let Some(b) = m.block(ElementKind::Link) {
        let mut count = 0;
        for e in 0..b.len() {
            let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
            let p = &m.parts[b.part[e]].props;
            for (axis, k) in [p.kx, p.ky, p.kz].into_iter().enumerate() {
                let k = k.unwrap_or(0.0);
                if k > 0.0 {
                    springs.add(
                        (axis, bits(k)),
                        format!("{}, {}, {}", d.next_id, m.node_id[a], m.node_id[c]),
                    );
                    d.next_id += 1;
                    count += 1;
                }
            }
        }
        d.r.written.push(("SPRING2 (link axes)".into(), count));
    }
    let s = &mut d.s;
    for (n, ((axis, k), lines)) in springs.sets.iter().enumerate() {
        let _ = writeln!(s, "*ELEMENT, TYPE=SPRING2, ELSET=LINK{}", n + 1);
        s.push_str(&lines.join("\n"));
        let _ = writeln!(
            s,
            "\n*SPRING, ELSET=LINK{}\n{}, {}\n{}",
            n + 1,
            axis + 1,
            axis + 1,
            num(value(*k))
        );
    }
}

/// Masses: trusses' lumped halves and point masses, one MASS element per node, sets by
/// mass.
fn masses(m: &Model, d: &mut Deck) {
    if let Some(b) = m.block(ElementKind::PointMass) {
        for e in 0..b.len() {
            d.mass[b.nodes[e]] += m.parts[b.part[e]].props.mass.unwrap_or(0.0);
        }
    }
    let mut masses: Sets<u64> = Sets::default();
    let mut count = 0;
    for (i, &mi) in d.mass.iter().enumerate() {
        if mi > 0.0 {
            masses.add(bits(mi), format!("{}, {}", d.next_id, m.node_id[i]));
            d.next_id += 1;
            count += 1;
        }
    }
    d.r.written.push(("MASS (nodal masses)".into(), count));
    let s = &mut d.s;
    for (n, (mv, lines)) in masses.sets.iter().enumerate() {
        let _ = writeln!(s, "*ELEMENT, TYPE=MASS, ELSET=MASS{}", n + 1);
        s.push_str(&lines.join("\n"));
        let _ = writeln!(s, "\n*MASS, ELSET=MASS{}\n{}", n + 1, num(value(*mv)));
    }
}

/// Mass-proportional damping f = −α m v: Rayleigh damping C = αM (ccx applies it to
/// the whole model; it warns that the material has no elastic constants).
fn damping(m: &Model, s: &mut String) {
    if m.analysis.mass_damping != 0.0 {
        let _ = writeln!(
            s,
            "*MATERIAL, NAME=DAMPING\n*DAMPING, ALPHA={}, BETA=0.",
            num(m.analysis.mass_damping)
        );
    }
}

/// Boundary conditions: fixed translations and symmetry planes.
fn boundary(m: &Model, d: &mut Deck) {
    let mut bc = String::new();
    let mut nbc = 0;
    for (i, f) in fixed_translations(m).iter().enumerate() {
        for (dof, _) in f.iter().enumerate().filter(|p| *p.1) {
            let _ = writeln!(bc, "{}, {}, {}", m.node_id[i], dof + 1, dof + 1);
            nbc += 1;
        }
    }
    if nbc > 0 {
        d.s.push_str("*BOUNDARY\n");
        d.s.push_str(&bc);
    }
    d.r.written
        .push(("*BOUNDARY (fixed translations)".into(), nbc));
}

/// Initial velocities, one line per non-zero component.
fn initial_velocities(m: &Model, d: &mut Deck) {
    if !m.initial_velocities.is_empty() {
        d.s.push_str("*INITIAL CONDITIONS, TYPE=VELOCITY\n");
        for (i, v) in &m.initial_velocities {
            for (dof, vd) in v.iter().enumerate().filter(|p| *p.1 != 0.0) {
                let _ = writeln!(d.s, "{}, {}, {}", m.node_id[*i], dof + 1, num(*vd));
            }
        }
    }
    d.r.written
        .push(("initial velocities".into(), m.initial_velocities.len()));
}

/// Load amplitudes, one per load: the law's samples, four pairs a line.
fn amplitudes(m: &Model, dt: f64, s: &mut String) {
    let end = m.analysis.end_time;
    for l in &m.loads {
        let _ = writeln!(s, "*AMPLITUDE, NAME=A{}", l.id);
        let pts = law_samples(&l.law, end, dt);
        for chunk in pts.chunks(4) {
            let row: Vec<String> = chunk
                .iter()
                .map(|(t, g)| format!("{}, {}", num(*t), num(*g)))
                .collect();
            let _ = writeln!(s, "{}", row.join(", "));
        }
    }
}

/// The printed nodes as the node set NOUT: the history sets, or every node.
fn output_set(m: &Model, d: &mut Deck) {
    let out_nodes = output_nodes(m);
    d.r.output_nodes = out_nodes.len();
    d.s.push_str("*NSET, NSET=NOUT\n");
    for chunk in out_nodes.chunks(8) {
        let ids: Vec<String> = chunk.iter().map(|&i| m.node_id[i].to_string()).collect();
        let _ = writeln!(d.s, "{}", ids.join(", "));
    }
}

/// The explicit step: its increments, the loads, and the printing of U at NOUT every
/// `nsub` increments.
fn step(m: &Model, dt: f64, nsub: u64, d: &mut Deck) {
    let end = m.analysis.end_time;
    let s = &mut d.s;
    let steps = (end / dt).round() as u64;
    let _ = writeln!(s, "*STEP, NLGEOM, INC={}", steps + 10);
    let _ = writeln!(
        s,
        "*DYNAMIC, EXPLICIT, DIRECT\n{}, {}, {}, {}",
        num(dt),
        num(end),
        num(dt),
        num(dt)
    );
    for l in &m.loads {
        let lines: Vec<String> = (0..3)
            .filter(|&dof| l.force[dof] != 0.0)
            .map(|dof| format!("{}, {}, {}", m.node_id[l.node], dof + 1, num(l.force[dof])))
            .collect();
        if !lines.is_empty() {
            let _ = writeln!(s, "*CLOAD, AMPLITUDE=A{}\n{}", l.id, lines.join("\n"));
        }
    }
    d.r.written.push(("*CLOAD (loads)".into(), m.loads.len()));
    let _ = writeln!(s, "*NODE PRINT, NSET=NOUT, FREQUENCY={nsub}\nU\n*END STEP");
}
