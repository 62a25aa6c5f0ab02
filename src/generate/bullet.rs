//! The deformable 9 mm bullet: hexahedra, Johnson–Cook metals (`--projectile deformable`
//! of `weft-weave woven` and `woven-reduced`).
//!
//! The 9 × 19 mm Luger round of armour standards (NIJ Standard-0101.06, *Ballistic
//! Resistance of Body Armor* (2008), Table 2: "9 mm Full Metal Jacketed Round Nose
//! (FMJ RN), 8.0 g (124 gr)"; C.I.P. / SAAMI: bullet diameter 9.01 mm). Two kinds:
//! - `lead`: homogeneous lead, the paper's "homogeneous deformable bullet";
//! - `fmj`: a lead core in a copper-alloy jacket (the cells of the outermost ring and of
//!   the nose's first layer: about 0.6 mm thick for 4 cells to the rim; the base open, as
//!   a jacket drawn from a cup is).
//!
//! Shape: a cylinder of diameter D with a round nose, a hemisphere of radius D/2 cut by
//! a meplat (a flat tip) of 0.35 D, so that the O-grid's core stays a hexahedron at the
//! tip; the nose's stations are spaced evenly in the polar angle. The body's length is
//! what makes the mesh's mass the bullet's mass exactly (the facets of the polygonal
//! section included): 8.0 g of lead 9.0 mm across gives 12.68 mm overall (the real FMJ RN,
//! ogival and with its jacket, is 15.6 mm; the mass, diameter and presented area are what
//! the impact sees first).
//!
//! The bullet points along −z, its tip at `tip`; a quarter (x ≥ 0, y ≥ 0, on the
//! symmetry planes) or the whole.

use serde::Serialize;

use super::cylinder::{extrude, quarter_disk, Disk};
use super::metals::Metal;
use crate::error::{Result, WeftError};

/// What the bullet is made of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum BulletKind {
    /// Homogeneous lead (the paper's).
    Lead,
    /// Full metal jacket: a lead core in a brass jacket.
    Fmj,
}

/// The bullet's parameters.
#[derive(Debug, Clone, Serialize)]
pub struct BulletParams {
    pub kind: BulletKind,
    /// Diameter D [m].
    pub diameter: f64,
    /// Mass [kg] (of the whole bullet, also in a quarter model).
    pub mass: f64,
    /// Cells from the axis to the rim (even, ≥ 2).
    pub radial: usize,
    /// The core's metal (the whole bullet's for `lead`).
    pub core: Metal,
    /// The jacket's metal (`fmj`).
    pub jacket: Metal,
    /// Hourglass coefficient Q_hg.
    pub hourglass: f64,
    /// Erode a hexahedron at this equivalent plastic strain (None: never).
    pub erosion_plastic_strain: Option<f64>,
}

impl Default for BulletParams {
    fn default() -> Self {
        BulletParams {
            kind: BulletKind::Lead,
            diameter: 9.01e-3,
            mass: 8.0e-3,
            radial: 4,
            core: Metal::Lead,
            jacket: Metal::Brass,
            hourglass: 0.1,
            erosion_plastic_strain: None,
        }
    }
}

/// The meplat's diameter over the bullet's.
pub const MEPLAT: f64 = 0.35;

/// A meshed bullet: nodes, hexahedra with their part (0 core, 1 jacket), its overall
/// length and the mass of what was meshed (a quarter's in a quarter model).
#[derive(Debug, Clone)]
pub struct BulletMesh {
    pub nodes: Vec<[f64; 3]>,
    pub hexes: Vec<([usize; 8], usize)>,
    pub length: f64,
    pub mass: f64,
}

/// The whole disk from the quarter: the quarter turned by 90°, 180° and 270° (turns keep
/// the quads counter-clockwise), the shared points once.
fn full_disk(q: &Disk) -> Disk {
    let mut d = q.clone();
    for turn in 1..4 {
        let map: Vec<usize> = q
            .points
            .iter()
            .map(|p| {
                let mut p = *p;
                for _ in 0..turn {
                    p = [-p[1], p[0]];
                }
                d.point(p)
            })
            .collect();
        for quad in &q.quads {
            d.quads.push(quad.map(|k| map[k]));
        }
    }
    d
}

pub fn check(p: &BulletParams) -> Result<()> {
    // The generators set the diameter and mass from the projectile's flags.
    for (what, v, unit) in [
        ("diameter (2 × --projectile-radius)", p.diameter, "m"),
        ("mass (--projectile-mass)", p.mass, "kg"),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            return Err(WeftError::input(format!("bullet {what} = `{v}`"))
                .expected(format!("a value > 0 in {unit}")));
        }
    }
    if p.radial < 2 || p.radial % 2 != 0 {
        return Err(
            WeftError::input(format!("--bullet-radial = `{}`", p.radial))
                .expected("an even number ≥ 2 (half the cells in the core, half in the ring)"),
        );
    }
    if let Some(e) = p.erosion_plastic_strain {
        if !(e > 0.0 && e.is_finite()) {
            return Err(WeftError::input(format!("--bullet-erosion-strain = `{e}`"))
                .expected("an equivalent plastic strain > 0 (leave it out: no erosion)"));
        }
    }
    if !(p.hourglass > 0.0 && p.hourglass.is_finite()) {
        return Err(
            WeftError::input(format!("--bullet-hourglass = `{}`", p.hourglass))
                .expected("a coefficient > 0 (0.1, LS-DYNA's default)"),
        );
    }
    Ok(())
}

/// Mesh the bullet, tip at `tip`, pointing along −z; `quarter`: x ≥ 0, y ≥ 0 only.
pub fn mesh(p: &BulletParams, tip: [f64; 3], quarter: bool) -> Result<BulletMesh> {
    check(p)?;
    let r = 0.5 * p.diameter;
    let (n, m) = (p.radial / 2, p.radial / 2);
    let q = quarter_disk(r, n, m);
    let disk = if quarter { q } else { full_disk(&q) };
    // Per cell of the section: its area and whether it is in the outermost ring (the
    // jacket's). The ring's outer cells are the quads with two points on the rim.
    let on_rim = |k: usize| (disk.points[k][0].hypot(disk.points[k][1]) - r).abs() < 1e-9 * r;
    let cells: Vec<(f64, bool)> = disk
        .quads
        .iter()
        .map(|quad| {
            let pts = quad.map(|k| disk.points[k]);
            let a2: f64 = (0..4)
                .map(|a| pts[a][0] * pts[(a + 1) % 4][1] - pts[(a + 1) % 4][0] * pts[a][1])
                .sum();
            (0.5 * a2, quad.iter().filter(|&&k| on_rim(k)).count() >= 2)
        })
        .collect();
    let jacketed = p.kind == BulletKind::Fmj;
    let rho = |jacket: bool| {
        if jacket && jacketed {
            p.jacket.constants().density
        } else {
            p.core.constants().density
        }
    };
    // Nose stations: polar angle φ from asin(MEPLAT) to 90°, ζ = R(1 − cos φ) from the
    // tip, radius scale sin φ.
    let phi0 = MEPLAT.asin();
    let n_nose = p.radial;
    let mut zeta = Vec::new();
    let mut scale = Vec::new();
    for k in 0..=n_nose {
        let phi = phi0 + (std::f64::consts::FRAC_PI_2 - phi0) * k as f64 / n_nose as f64;
        zeta.push(r * (1.0 - phi.cos()) - r * (1.0 - phi0.cos()));
        scale.push(phi.sin());
    }
    // Mass of a layer between stations a and b: Σ ρ_cell A_cell ∫ s² dζ, s linear in ζ.
    let layer_mass = |a: usize, b: usize, first: bool, s: &[f64], z: &[f64]| -> f64 {
        let s2 = (s[a] * s[a] + s[a] * s[b] + s[b] * s[b]) / 3.0;
        cells
            .iter()
            .map(|&(area, ring)| rho(ring || first) * area * s2 * (z[b] - z[a]))
            .sum()
    };
    let nose_mass: f64 = (0..n_nose)
        .map(|k| layer_mass(k, k + 1, k == 0, &scale, &zeta))
        .sum();
    let share = if quarter { 0.25 } else { 1.0 };
    let target = share * p.mass;
    // The body: mass per length of the full section.
    let per_length: f64 = cells.iter().map(|&(a, ring)| rho(ring) * a).sum();
    let body = (target - nose_mass) / per_length;
    if !(body > 0.0) {
        return Err(WeftError::input(format!(
            "a {} g bullet of {} mm diameter",
            p.mass * 1e3,
            p.diameter * 1e3
        ))
        .expected(format!(
            "at least the mass of its nose, {:.3} g",
            nose_mass / share * 1e3
        ))
        .hint("raise --projectile-mass or lower --projectile-radius"));
    }
    let h = r / p.radial as f64;
    let n_body = ((body / h).round() as usize).max(1);
    let nose_len = *zeta.last().unwrap();
    for k in 1..=n_body {
        zeta.push(nose_len + body * k as f64 / n_body as f64);
        scale.push(1.0);
    }
    let z: Vec<f64> = zeta.iter().map(|zz| tip[2] + zz).collect();
    let (mut nodes, hexes) = extrude(&disk, &z, &scale);
    for x in nodes.iter_mut() {
        x[0] += tip[0];
        x[1] += tip[1];
    }
    let nq = disk.quads.len();
    let hexes = hexes
        .into_iter()
        .enumerate()
        .map(|(e, h)| {
            let (layer, cell) = (e / nq, e % nq);
            let jacket = jacketed && (layer == 0 || cells[cell].1);
            (h, usize::from(jacket))
        })
        .collect();
    Ok(BulletMesh {
        nodes,
        hexes,
        length: nose_len + body,
        mass: target,
    })
}

/// The penalty scale of each of the bullet's contacts with `n` yarn parts: 1/n (at most
/// 1). The step's contact guard adds, on each of the bullet's nodes, 0.2 × scale per
/// two-way definition it is in (it cannot know that a bullet meets one or two layers at a
/// time): with the default scale, four layers (8 parts, κ = 1.6) cut the step to 0.1 of
/// the stable one and eight left none. With 1/n the bullet's nodes carry κ = 0.2 as a
/// rigid projectile's do; the yarns, their own definitions' (measured, four layers of
/// chains: the step back at 0.55 of the stable one, the rigid nose's 0.46).
pub fn penalty_scale(n: usize) -> f64 {
    1.0 / n.max(1) as f64
}

/// Where the bullet went in a model: its parts (core, then the jacket when it has one)
/// and its node set.
#[derive(Debug, Clone)]
pub struct Placed {
    pub parts: Vec<usize>,
    pub length: f64,
    pub mass: f64,
}

/// Add the bullet to `m`, tip at `tip`, moving at `velocity` along −z: nodes and
/// hexahedra after the model's largest ids, parts `bullet` (core) and `bullet_jacket`
/// (FMJ), node set `bullet`, and a two-way contact with friction `friction` between
/// each of its parts and each part of `targets` (the yarns: their nodes against the
/// bullet's faces, the bullet's nodes against theirs), penalty scale [`penalty_scale`].
pub fn add_to(
    m: &mut crate::model::Model,
    p: &BulletParams,
    tip: [f64; 3],
    velocity: f64,
    quarter: bool,
    friction: f64,
    targets: &[usize],
) -> Result<Placed> {
    use crate::model::contacts::{ContactDef, Slave};
    use crate::model::ElementKind;
    let mesh = mesh(p, tip, quarter)?;
    let next_node = m.node_id.iter().max().copied().unwrap_or(0) + 1;
    let next_el = m
        .elements
        .values()
        .flat_map(|b| b.id.iter())
        .max()
        .copied()
        .unwrap_or(0)
        + 1;
    let next_part = m.parts.iter().map(|p| p.id).max().unwrap_or(0) + 1;
    let first = m.node_id.len();
    for (i, x) in mesh.nodes.iter().enumerate() {
        let k = m.add_node(next_node + i as i64, *x);
        m.initial_velocities.push((k, [0.0, 0.0, -velocity]));
    }
    if !m.initial_displacement.is_empty() {
        // A formed or relaxed model's start: the bullet starts where it is meshed.
        m.initial_displacement.resize(m.num_nodes(), [0.0; 3]);
    }
    let mut parts = vec![m.add_part(
        next_part,
        "bullet",
        ElementKind::Hex,
        p.core.part_props(p.hourglass, p.erosion_plastic_strain),
    )];
    if p.kind == BulletKind::Fmj {
        parts.push(m.add_part(
            next_part + 1,
            "bullet_jacket",
            ElementKind::Hex,
            p.jacket.part_props(p.hourglass, p.erosion_plastic_strain),
        ));
    }
    for (e, (h, part)) in mesh.hexes.iter().enumerate() {
        let ns: Vec<usize> = h.iter().map(|&k| first + k).collect();
        m.add_element(next_el + e as i64, parts[*part], &ns);
    }
    m.node_sets
        .insert("bullet".into(), (first..first + mesh.nodes.len()).collect());
    let mut cid = m.contacts.iter().map(|c| c.id).max().unwrap_or(0) + 1;
    for &t in targets {
        for &b in &parts {
            let mut c = ContactDef::new(cid, Slave::Part(t), b).with_friction(friction);
            c.two_way = true;
            c.penalty_scale = penalty_scale(targets.len());
            m.contacts.push(c);
            cid += 1;
        }
    }
    Ok(Placed {
        parts,
        length: mesh.length,
        mass: mesh.mass,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mesh's mass is the bullet's: Σ ρ V over the hexahedra, each volume the exact
    /// one of a trilinear hexahedron (the divergence theorem over its faces, computed
    /// here independently of the generator's layer sums), equals 8.0 g to round-off.
    fn hex_volume(x: &[[f64; 3]; 8]) -> f64 {
        // Split into 6 tetrahedra along the diagonal 0–6 (exact for planar faces; the
        // extruded, radially scaled cells have planar faces).
        let tet = |a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]| {
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
            (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                + u[2] * (v[0] * w[1] - v[1] * w[0]))
                / 6.0
        };
        [
            [1, 2, 6],
            [2, 3, 6],
            [3, 7, 6],
            [7, 4, 6],
            [4, 5, 6],
            [5, 1, 6],
        ]
        .iter()
        .map(|t| tet(x[0], x[t[0]], x[t[1]], x[t[2]]))
        .sum()
    }

    #[test]
    fn the_meshed_bullets_weigh_what_they_should() {
        for (kind, quarter) in [
            (BulletKind::Lead, true),
            (BulletKind::Lead, false),
            (BulletKind::Fmj, true),
        ] {
            let p = BulletParams {
                kind,
                ..Default::default()
            };
            let b = mesh(&p, [0.0; 3], quarter).unwrap();
            let mass: f64 = b
                .hexes
                .iter()
                .map(|(h, part)| {
                    let x = h.map(|k| b.nodes[k]);
                    let rho = if *part == 1 { 8520.0 } else { 11340.0 };
                    rho * hex_volume(&x)
                })
                .sum();
            let want = if quarter { 2e-3 } else { 8e-3 };
            // The nose layers' faces are ruled, not planar, where the scale changes: the
            // tetrahedra and the layer formula then differ by O(Δs²); measured 3e-4.
            assert!(
                (mass - want).abs() < 1e-3 * want,
                "{kind:?} {quarter}: {mass}"
            );
            assert!(b
                .hexes
                .iter()
                .all(|(h, _)| hex_volume(&h.map(|k| b.nodes[k])) > 0.0));
            let jacket = b.hexes.iter().filter(|h| h.1 == 1).count();
            assert_eq!(jacket > 0, kind == BulletKind::Fmj);
        }
    }
}
