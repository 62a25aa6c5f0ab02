//! `woven-reduced`: the reduced woven model of the paper's §5. Warp and weft yarns as
//! truss chains on the crossing lines, joined at every crossing by a link (springs,
//! dashpots, an optional friction slider), inside the graded equivalent membrane of
//! [`super::surround`] whose properties follow from the yarns by the paper's §3 ratios,
//! tied to the yarns on the patch's boundary; a rigid projectile at the centre. A
//! pretensioned model starts balanced, relaxed or unbalanced ([`PretensionStart`]).
//!
//! Here the model is built; its parameters and their checks are in `params`, the relaxed
//! start in `relax`.

mod params;
mod relax;

pub use crate::generate::surround::SurroundParams;
pub use params::{Interface, PretensionStart, WovenParams};
use relax::relax_start;

use crate::error::Result;
use crate::generate::reduced_failure::{fail_rods, tag_layer};
use crate::generate::surround::{
    centre_line_sets, coarse_membrane, fail_membranes, graded_lines, hold_outer_edge, tie_to_hole,
    Coarse, MembraneProps,
};
use crate::model::{Analysis, ElementKind, Model, PartProps, ProjectileSpec};

/// The reduced woven model: the patch's yarns and links inside the graded membrane tied
/// to the patch's boundary, the projectile, the node sets and the analysis; relaxed
/// before the start when [`PretensionStart::Relaxed`].
pub fn woven_reduced(p: &WovenParams) -> Result<Model> {
    p.check()?;
    let membrane = p.membrane();
    let layout = Layout::new(p);
    let pos = graded_lines(layout.c, layout.hc, 0.5 * p.length, p.growth)?;
    let mut m = Model::default();
    let yarns = add_yarn_nodes(&mut m, p, &layout);
    let parts = add_parts(&mut m, p);
    let yarn_of = add_yarns_and_links(&mut m, p, &layout, &yarns, &parts);
    let coarse = coarse_membrane(&mut m, &pos, p.quarter, layout.c, &membrane, 1_000_000);
    tag_layer(&mut m, &yarn_of);
    if p.pretension_strain != 0.0 && p.pretension_start == PretensionStart::Balanced {
        prestress_membrane(&mut m, p, &membrane);
    }
    let interface = tie_boundary(&mut m, &layout, &yarns, &coarse)?;
    hold_outer_edge(&mut m, &coarse, p.quarter, p.length);
    if p.bullet.is_none() {
        add_projectile(&mut m, p);
    }
    m.node_sets.insert("reference".into(), yarns.warp.clone());
    m.node_sets.insert("interface".into(), interface);
    centre_line_sets(&mut m, &yarns.warp, layout.c);
    m.analysis = Analysis {
        end_time: p.end_time,
        output_interval: p.output_interval,
        dt_safety: p.dt_safety,
        stop_on_outcome: p.stop_on_outcome,
        ..Default::default()
    };
    m.validate()?;
    if p.pretension_strain != 0.0 && p.pretension_start == PretensionStart::Relaxed {
        relax_start(&mut m, p)?;
    }
    let delay = p
        .failure
        .delay_for(p.spacing, p.yarn_modulus, p.yarn_density);
    if p.failure.strain > 0.0 {
        fail_rods(
            &mut m,
            &[parts.yarn, parts.half_yarn],
            p.failure.strain,
            delay,
        );
    }
    if let Some(e) = p.surround.failure_strain {
        fail_membranes(&mut m, e, delay);
    }
    if let Some(b) = &p.bullet {
        add_bullet(&mut m, p, b, &parts)?;
    }
    Ok(m)
}

/// The deformable bullet at the centre (after the relaxed start, which it takes no part
/// in), its tip 0.1 mm above the yarns' contact surface (the crimp plus the trusses'
/// contact radius √(A/π)), in contact with both yarn parts.
fn add_bullet(
    m: &mut Model,
    p: &WovenParams,
    b: &crate::generate::bullet::BulletParams,
    parts: &ReducedParts,
) -> Result<()> {
    let b = crate::generate::bullet::BulletParams {
        diameter: 2.0 * p.projectile_radius,
        mass: p.projectile_mass,
        ..b.clone()
    };
    let top = p.crimp + (p.yarn_area / std::f64::consts::PI).sqrt();
    crate::generate::bullet::add_to(
        m,
        &b,
        [0.0, 0.0, top + 1e-4],
        p.projectile_velocity,
        p.quarter,
        p.projectile_friction,
        &[parts.yarn, parts.half_yarn],
    )?;
    m.analysis.variable_time_step = true;
    m.validate()
}

/// Where the reduced patch's crossing lines and the membrane's hole lie.
struct Layout {
    /// The last crossing line's index n: crossing lines k = 0 … n each way (n = N/2 in a
    /// quarter, N in a full model).
    n: usize,
    /// The first crossing line's coordinate x₀ (0 in a quarter, −Np/2 in a full model);
    /// line k lies at x₀ + kp.
    x0: f64,
    /// Band ends ([`Interface::BandEnds`]): the yarns run on past the last crossing line
    /// to their ends on the membrane's edge.
    ends: bool,
    /// The membrane's hole: its half-size c and the size h_c of the membrane's first cells.
    c: f64,
    hc: f64,
}

impl Layout {
    fn new(p: &WovenParams) -> Layout {
        let ends = p.interface == Interface::BandEnds;
        let (n, x0) = if p.quarter {
            (p.yarns / 2, 0.0)
        } else {
            (p.yarns, -0.5 * p.yarns as f64 * p.spacing)
        };
        // The membrane's hole: the last crossing line, or half a spacing past it (band ends,
        // where the membrane's first cells are p/2 wide, as around the yarn-level patch).
        let (c, hc) = if ends {
            ((n as f64 + 0.5) * p.spacing, 0.5 * p.spacing)
        } else {
            (0.5 * p.yarns as f64 * p.spacing, p.spacing)
        };
        Layout { n, x0, ends, c, hc }
    }

    /// Crossings per line, n + 1.
    fn w(&self) -> usize {
        self.n + 1
    }

    /// The along-index at which a yarn's last element ends: the last crossing n, or with
    /// band ends n + 1 (the yarn's end on the membrane's edge).
    fn last(&self) -> usize {
        if self.ends {
            self.n + 1
        } else {
            self.n
        }
    }

    /// Halved: the yarns on a symmetry plane, and (crossing interface) those on the
    /// interface lines; with band ends the last crossing line is a full yarn.
    fn on_line(&self, k: usize) -> bool {
        k == 0 || (k == self.n && !self.ends)
    }
}

/// The warp lies over the weft where (i + j) is even (plain weave).
fn warp_on_top(i: usize, j: usize) -> bool {
    (i + j).is_multiple_of(2)
}

/// The yarns' nodes: warp and weft at each crossing (i, j), index j(n + 1) + i, and with
/// band ends the warp j's end at (c, jp) and the weft i's at (ip, c).
struct YarnNodes {
    warp: Vec<usize>,
    weft: Vec<usize>,
    warp_end: Vec<usize>,
    weft_end: Vec<usize>,
    /// The last crossing line's index n.
    n: usize,
}

impl YarnNodes {
    /// The warp j's node at i (i = n + 1: its end).
    fn warp_at(&self, i: usize, j: usize) -> usize {
        if i > self.n {
            self.warp_end[j]
        } else {
            self.warp[j * (self.n + 1) + i]
        }
    }

    /// The weft i's node at j (j = n + 1: its end).
    fn weft_at(&self, i: usize, j: usize) -> usize {
        if j > self.n {
            self.weft_end[i]
        } else {
            self.weft[j * (self.n + 1) + i]
        }
    }
}

/// The warp and weft nodes at every crossing, crimped ±a alternately, and the band ends.
fn add_yarn_nodes(m: &mut Model, p: &WovenParams, l: &Layout) -> YarnNodes {
    let (n, w, c, ends, x0) = (l.n, l.w(), l.c, l.ends, l.x0);
    let mut warp = vec![];
    let mut weft = vec![];
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (x0 + i as f64 * p.spacing, x0 + j as f64 * p.spacing);
            let boundary = !ends && ((x.abs() - c).abs() < 1e-12 || (y.abs() - c).abs() < 1e-12);
            // Plain weave: the warp passes over and under alternately; flat on the boundary.
            let z = if boundary {
                0.0
            } else if warp_on_top(i, j) {
                p.crimp
            } else {
                -p.crimp
            };
            warp.push(m.add_node((2 * (j * w + i) + 1) as i64, [x, y, z]));
            weft.push(m.add_node((2 * (j * w + i) + 2) as i64, [x, y, -z]));
        }
    }
    // Band ends: the warp on y = jp ends at (c, jp), the weft on x = ip at (ip, c), on the
    // membrane's plane z = 0 (where the yarn-level bands' crimp cos(πx/p) is zero).
    let (mut warp_end, mut weft_end) = (vec![], vec![]);
    if ends {
        let first = 2 * (w * w) as i64;
        for k in 0..=n {
            let t = k as f64 * p.spacing;
            warp_end.push(m.add_node(first + 1 + k as i64, [c, t, 0.0]));
            weft_end.push(m.add_node(first + 1 + (w + k) as i64, [t, c, 0.0]));
        }
    }
    YarnNodes {
        warp,
        weft,
        warp_end,
        weft_end,
        n,
    }
}

/// The patch's parts: full and half yarns; the links, and in a quarter model those on a
/// symmetry plane (half) and the centre crossing (a quarter).
struct ReducedParts {
    yarn: usize,
    half_yarn: usize,
    link: usize,
    half_link: usize,
    quarter_link: usize,
}

impl ReducedParts {
    /// The link part of the crossing (i, j).
    fn link_at(&self, quarter: bool, i: usize, j: usize) -> usize {
        match (quarter && i == 0, quarter && j == 0) {
            (true, true) => self.quarter_link,
            (true, false) | (false, true) => self.half_link,
            _ => self.link,
        }
    }
}

fn add_parts(m: &mut Model, p: &WovenParams) -> ReducedParts {
    let yarn = m.add_part(
        1,
        "yarns",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(p.yarn_modulus),
            density: Some(p.yarn_density),
            area: Some(p.yarn_area),
            tension_only: Some(p.tension_only),
            prestrain: (p.pretension_strain != 0.0).then_some(p.pretension_strain),
            ..Default::default()
        },
    );
    let link = m.add_part(
        2,
        "crossings",
        ElementKind::Link,
        PartProps {
            kx: Some(p.k_xy),
            ky: Some(p.k_xy),
            kz: Some(p.k_z),
            cx: Some(p.c_xy),
            cy: Some(p.c_xy),
            cz: Some(p.c_z),
            slip_force: p.slip_force,
            friction: p.friction,
            unilateral: p.unilateral.then_some(true),
            local_frame: p.local_frame.then_some(true),
            sliding: p.sliding.then_some(true),
            ..Default::default()
        },
    );
    // The yarns on the lines that bound the patch carry half a yarn: on a symmetry plane
    // (x = 0, y = 0 of a quarter) the other half belongs to the neighbouring quarter; on
    // the interface (x = ±c, y = ±c) the membrane carries the other half (each yarn
    // stands for a strip of width p, and the membrane starts at the line). Half the
    // area halves the mass, the axial stiffness and the pretension force alike.
    let half_yarn = m.add_part(
        3,
        "half_yarns",
        ElementKind::Truss,
        PartProps {
            area: Some(0.5 * p.yarn_area),
            ..m.parts[yarn].props.clone()
        },
    );
    let (half_link, quarter_link) = if p.quarter {
        let lp = m.parts[link].props.clone();
        (
            m.add_part(
                4,
                "crossings_on_symmetry",
                ElementKind::Link,
                scaled_link(0.5, &lp),
            ),
            m.add_part(
                5,
                "centre_crossing",
                ElementKind::Link,
                scaled_link(0.25, &lp),
            ),
        )
    } else {
        (link, link)
    };
    ReducedParts {
        yarn,
        half_yarn,
        link,
        half_link,
        quarter_link,
    }
}

/// In a quarter model, what lies on a symmetry plane is shared with the neighbouring
/// quarter: the links on one plane get half, the centre link a quarter of their
/// stiffness, damping and slip force (the friction coefficient is a ratio: the halved
/// normal stiffness halves N and so the slip force).
fn scaled_link(f: f64, base: &PartProps) -> PartProps {
    PartProps {
        kx: base.kx.map(|v| v * f),
        ky: base.ky.map(|v| v * f),
        kz: base.kz.map(|v| v * f),
        cx: base.cx.map(|v| v * f),
        cy: base.cy.map(|v| v * f),
        cz: base.cz.map(|v| v * f),
        slip_force: base.slip_force.map(|v| v * f),
        ..base.clone()
    }
}

/// The yarns' trusses and the crossings' links, numbered crossing by crossing: the warp
/// element leaving (i, j), the weft element, the link. Returns each truss's yarn, its
/// index within its part from 1: the warp on y = jp is j + 1, the weft on x = ip is
/// n + 2 + i (a rod's part holds warp and weft alike).
fn add_yarns_and_links(
    m: &mut Model,
    p: &WovenParams,
    l: &Layout,
    y: &YarnNodes,
    parts: &ReducedParts,
) -> Vec<i64> {
    let (n, last) = (l.n, l.last());
    let mut yarn_of = vec![];
    let mut eid = 1;
    for j in 0..=n {
        for i in 0..=n {
            if i < last {
                m.add_element(
                    eid,
                    if l.on_line(j) {
                        parts.half_yarn
                    } else {
                        parts.yarn
                    },
                    &[y.warp_at(i, j), y.warp_at(i + 1, j)],
                );
                yarn_of.push(j as i64 + 1);
                eid += 1;
            }
            if j < last {
                m.add_element(
                    eid,
                    if l.on_line(i) {
                        parts.half_yarn
                    } else {
                        parts.yarn
                    },
                    &[y.weft_at(i, j), y.weft_at(i, j + 1)],
                );
                yarn_of.push((n + 2 + i) as i64);
                eid += 1;
            }
            add_link(m, p, l, y, eid, parts.link_at(p.quarter, i, j), (i, j));
            eid += 1;
        }
    }
    yarn_of
}

/// The link `eid` of part `part` at the crossing (i, j), in the crossing's frame with
/// `local_frame`.
fn add_link(
    m: &mut Model,
    p: &WovenParams,
    l: &Layout,
    y: &YarnNodes,
    eid: i64,
    part: usize,
    (i, j): (usize, usize),
) {
    let k = j * l.w() + i;
    // Node 1 the lower yarn, node 2 the upper: the link's normal points from
    // node 1 to node 2, so that d_z < 0 presses them together (the unilateral
    // spring and Coulomb friction read it).
    let pair = if warp_on_top(i, j) {
        [y.weft[k], y.warp[k]]
    } else {
        [y.warp[k], y.weft[k]]
    };
    if !p.local_frame {
        m.add_element(eid, part, &pair);
        return;
    }
    // The frame: e₁ along the warp (the chord of its neighbours at i ∓ 1), the
    // normal ⟂ the weft (neighbours at j ∓ 1). At k = 0 (a symmetry plane, or
    // the interface of a full model) the chord to k + 2, at the same crimp
    // height: the mirrored neighbour's chord, level as symmetry asks (a
    // one-sided chord to k + 1 would tilt the normal by 2a/p and read the
    // crimp's pressure as a pull there, measured); at k = n the chord to n − 1
    // (those crossings are tied to the membrane), or with band ends the chord
    // from n − 1 to the band's end.
    let last = l.last();
    let chord = |k: usize| match k {
        0 => (0, 2.min(last)),
        k if k == last => (k - 1, k),
        k => (k - 1, k + 1),
    };
    let ((ia, ib), (ja, jb)) = (chord(i), chord(j));
    m.add_link_with_frame(
        eid,
        part,
        &pair,
        [
            y.warp_at(ia, j),
            y.warp_at(ib, j),
            y.weft_at(i, ja),
            y.weft_at(i, jb),
        ],
    );
}

/// The balanced start: the membrane carries the yarns' tension per unit width as a
/// uniform initial stress in both directions, in equilibrium with the yarn ends tied to
/// its hole (a yarn of tension E A ε₀ per strip of width p; half yarns on the lines).
fn prestress_membrane(m: &mut Model, p: &WovenParams, membrane: &MembraneProps) {
    let s0 = p.pretension_per_width() / membrane.thickness;
    let b = m
        .elements
        .get_mut(&ElementKind::Quad)
        .expect("the coarse membrane");
    b.stress0 = vec![[s0, s0, 0.0]; b.len()];
}

/// Every yarn node on the patch boundary (the yarn ends and the nodes of the yarns
/// that run along it) is tied to the membrane edge it lies on; returns the tied nodes.
fn tie_boundary(m: &mut Model, l: &Layout, y: &YarnNodes, coarse: &Coarse) -> Result<Vec<usize>> {
    let c = l.c;
    let on_boundary: Vec<usize> = y
        .warp
        .iter()
        .chain(y.weft.iter())
        .chain(y.warp_end.iter())
        .chain(y.weft_end.iter())
        .copied()
        .filter(|&n| {
            let x = m.coords[n];
            (x[0].abs() - c).abs() < 1e-12 || (x[1].abs() - c).abs() < 1e-12
        })
        .collect();
    tie_to_hole(m, coarse, &on_boundary)
}

/// The rigid projectile at the centre, its tip just above the crimp (a quarter of its
/// mass in a quarter model).
fn add_projectile(m: &mut Model, p: &WovenParams) {
    let share = if p.quarter { 0.25 } else { 1.0 };
    m.projectiles.push(ProjectileSpec {
        id: 1,
        shape: p.projectile_shape,
        radius: p.projectile_radius,
        length: 2.0 * p.projectile_radius,
        mass: share * p.projectile_mass,
        tip: [0.0, 0.0, p.crimp + 1e-5],
        axis: [0.0, 0.0, -1.0],
        velocity: [0.0, 0.0, -p.projectile_velocity],
        prescribed_velocity: false,
        contact_stiffness: None,
        friction: p.projectile_friction,
        contact_damping: p.failure.contact_damping(),
        segment_contact: true,
    });
}
