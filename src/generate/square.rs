//! The paper's §4 models on a square L × L: a girder of rods and a membrane on the same
//! nodes, clamped along x = 0, loaded along x = L.
//!
//! Load cases (total force F spread over the loaded edge's nodes, half at the two
//! corners, so that the traction is uniform): `tension` (along +x), `shear` (along +y),
//! `transverse` (along +z at the centre node, an impact-like pulse). Time law: the pulse
//! F·sin(πt/T_F) on [0, T_F] with T_F = T/2 and T = L√(ρ/E) (the time a longitudinal
//! wave needs to cross the square; `period` sets T, so that two models compared sample by
//! sample share it); a static solve uses the amplitude F.
//!
//! Node sets: `reference` (every node), `axis_x` (y = 0, ordered by x), `diagonal`
//! (x = y, ordered by x), `loaded_edge` (x = L, ordered by y), `centre` (the nodes of
//! the central L/2 × L/2 zone, |x − L/2| ≤ L/4 and |y − L/2| ≤ L/4: the reference nodes
//! of the paper's combined model, Fig. 5b; N ≥ 2).

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::generate::grid::rectangle;
use crate::generate::pulse::resolve_pulse;
pub use crate::generate::pulse::STEPS_PER_PULSE;
use crate::generate::surround::{tie_to_hole, Coarse};
use crate::model::{Analysis, ElementKind, Load, Model, PartProps, TimeLaw};

/// Where the square is loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum LoadCase {
    Tension,
    Shear,
    Transverse,
}

/// Common parameters of the square models.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Square {
    /// Side L [m].
    pub length: f64,
    /// Cells (rods or elements) per side N.
    pub cells: usize,
    pub load_case: LoadCase,
    /// Total force F [N].
    pub force: f64,
    /// The time scale T [s] (pulse T_F = T/2, default end time T); `None`: L√(ρ/E) of the
    /// model's own material. Give a girder and its membrane the same T to compare them.
    pub period: Option<f64>,
    /// End time [s]; `None`: T = L√(ρ/E).
    pub end_time: Option<f64>,
    /// Output interval [s]; `None`: end time / 100.
    pub output_interval: Option<f64>,
}

impl Default for Square {
    /// The paper's §4 square: L = 0.1 m, N = 10 cells per side, a tension of F = 100 N
    /// (the times from the model's own material).
    fn default() -> Self {
        Square {
            length: 0.1,
            cells: 10,
            load_case: LoadCase::Tension,
            force: 100.0,
            period: None,
            end_time: None,
            output_interval: None,
        }
    }
}

/// The square's side and cell count: --length > 0, --cells ≥ 1.
fn check_square(sq: &Square) -> Result<()> {
    positive("length", sq.length, "in m")?;
    if sq.cells == 0 {
        return Err(WeftError::input("--cells = `0`").expected("at least 1 cell per side"));
    }
    Ok(())
}

fn positive(name: &str, v: f64, unit: &str) -> Result<()> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(WeftError::input(format!("--{name} = `{v}`")).expected(format!("a value > 0 {unit}")))
    }
}

/// Nodes of the (cells+1)² grid, clamps, loads, sets and analysis shared by both models.
/// `rotations` clamps the rotations at x = 0 too (beams).
fn frame(m: &mut Model, sq: &Square, e: f64, rho: f64, rotations: bool) -> Result<()> {
    let n = sq.cells;
    let id = |i: usize, j: usize| j * (n + 1) + i;
    clamp_load_analysis(m, sq, e, rho, rotations, &id, id(n / 2, n / 2))?;
    m.node_sets
        .insert("reference".into(), (0..(n + 1) * (n + 1)).collect());
    m.node_sets
        .insert("axis_x".into(), (0..=n).map(|i| id(i, 0)).collect());
    m.node_sets
        .insert("diagonal".into(), (0..=n).map(|i| id(i, i)).collect());
    m.node_sets
        .insert("loaded_edge".into(), (0..=n).map(|j| id(n, j)).collect());
    // Index test with integers: 4i ∈ [N, 3N] ⇔ |x − L/2| ≤ L/4 exactly. (N = 1 has no
    // node there, and no `centre` set.)
    let centre: Vec<usize> = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| (i, j)))
        .filter(|&(i, j)| (n..=3 * n).contains(&(4 * i)) && (n..=3 * n).contains(&(4 * j)))
        .map(|(i, j)| id(i, j))
        .collect();
    if !centre.is_empty() {
        m.node_sets.insert("centre".into(), centre);
    }
    Ok(())
}

/// The clamp at x = 0, the load and the analysis, on the nodes `id(i, j)` of the N × N
/// grid's clamped (i = 0) and loaded (i = N) edges; a transverse load acts at `centre`.
fn clamp_load_analysis(
    m: &mut Model,
    sq: &Square,
    e: f64,
    rho: f64,
    rotations: bool,
    id: &dyn Fn(usize, usize) -> usize,
    centre: usize,
) -> Result<()> {
    check_square(sq)?;
    if !sq.force.is_finite() {
        return Err(
            WeftError::input(format!("--force = `{}`", sq.force)).expected("a finite force in N")
        );
    }
    let n = sq.cells;
    for j in 0..=n {
        m.constraints.push((id(0, j), [true, true, true]));
        if rotations {
            m.rot_constraints.push((id(0, j), [true, true, true]));
        }
    }
    let t = sq.period.unwrap_or(sq.length * (rho / e).sqrt());
    positive("period", t, "in s")?;
    let law = TimeLaw::SinePulse {
        start: 0.0,
        duration: 0.5 * t,
    };
    match sq.load_case {
        LoadCase::Tension | LoadCase::Shear => {
            let d = if sq.load_case == LoadCase::Tension {
                0
            } else {
                1
            };
            for j in 0..=n {
                let w = if j == 0 || j == n { 0.5 } else { 1.0 } / n as f64;
                let mut f = [0.0; 3];
                f[d] = sq.force * w;
                m.loads.push(Load {
                    id: j as i64 + 1,
                    node: id(n, j),
                    force: f,
                    law: law.clone(),
                });
            }
        }
        LoadCase::Transverse => {
            m.loads.push(Load {
                id: 1,
                node: centre,
                force: [0.0, 0.0, sq.force],
                law,
            });
        }
    }
    let end = sq.end_time.unwrap_or(t);
    m.analysis = Analysis {
        end_time: end,
        output_interval: sq.output_interval.unwrap_or(end / 100.0),
        ..Default::default()
    };
    Ok(())
}

/// `girder`: rods along x and y between the nodes of an N × N grid.
#[derive(Debug, Clone, Serialize)]
pub struct GirderParams {
    pub square: Square,
    pub youngs_modulus: f64,
    pub density: f64,
    /// Rod width b (in plane) [m]; `None`: L/(10N).
    pub rod_width: Option<f64>,
    /// Rod thickness h (out of plane) [m]; `None`: equal to b.
    pub rod_thickness: Option<f64>,
    /// Rigid joints (beams) or pinned joints (trusses).
    pub rigid: bool,
    /// Rods along the boundary with full properties instead of half the modulus and density.
    pub full_edge_rods: bool,
    /// Rigid joints: hold the rotations of the clamped nodes too (a built-in edge). Off, the
    /// clamp holds translations only, like the membrane's clamp (which has no rotations).
    pub clamp_rotations: bool,
}

impl Default for GirderParams {
    /// The paper's §4 steel girder on the default [`Square`]: E = 1.5·10¹¹ Pa,
    /// ρ = 7800 kg/m³, b = h = L/(10N), rigid joints, a built-in clamp, half edge rods.
    fn default() -> Self {
        GirderParams {
            square: Square::default(),
            youngs_modulus: 1.5e11,
            density: 7800.0,
            rod_width: None,
            rod_thickness: None,
            rigid: true,
            full_edge_rods: false,
            clamp_rotations: true,
        }
    }
}

impl GirderParams {
    pub fn b(&self) -> f64 {
        self.rod_width
            .unwrap_or(self.square.length / (10.0 * self.square.cells as f64))
    }
    pub fn h(&self) -> f64 {
        self.rod_thickness.unwrap_or(self.b())
    }
}

/// Build the girder; returns the model and warnings for the user.
///
/// Each rod is a prism of b × h between joint centres; the b × b crossings would be
/// counted twice, so the rods carry the density ρ(1 − b/(2a)), which gives the lattice's
/// areal density ρ·b·h·(2 − b/a)/a exactly (docs/theory.md, "Closed forms used as
/// oracles"). Rods on the boundary stand for half a cell: half the modulus and half the
/// density, unless `full_edge_rods`.
pub fn girder(p: &GirderParams) -> Result<(Model, Vec<String>)> {
    let (b, h, warnings) = girder_section(p)?;
    let mut m = Model::default();
    add_lattice(&mut m, p, b, h);
    frame(
        &mut m,
        &p.square,
        p.youngs_modulus,
        p.density,
        p.rigid && p.clamp_rotations,
    )?;
    // A plane girder under in-plane loads: hold the out-of-plane motion (pinned joints have
    // no stiffness there at all).
    if p.square.load_case != LoadCase::Transverse {
        for i in 0..m.num_nodes() {
            m.constraints.push((i, [false, false, true]));
            if p.rigid {
                m.rot_constraints.push((i, [true, true, false]));
            }
        }
    }
    m.validate()?;
    resolve_pulse(&mut m)?;
    Ok((m, warnings))
}

/// The girder's flags checked, its rods' width b < a = L/N and thickness h; a warning
/// where b lies outside the paper's range L/(20N) … L/(8N).
fn girder_section(p: &GirderParams) -> Result<(f64, f64, Vec<String>)> {
    positive("youngs-modulus", p.youngs_modulus, "in Pa")?;
    positive("density", p.density, "in kg/m³")?;
    // The square's own flags first: the rod's default width and thickness derive from
    // L/N, and a refusal should name the flag given, not what it made invalid.
    check_square(&p.square)?;
    let (b, h) = (p.b(), p.h());
    positive("rod-width", b, "in m")?;
    positive("rod-thickness", h, "in m")?;
    let (n, l) = (p.square.cells, p.square.length);
    let a = l / n as f64;
    if b >= a {
        return Err(WeftError::input(format!(
            "--rod-width = `{b}` m is not smaller than the cell size a = L/N = {a} m"
        ))
        .expected("b < a"));
    }
    let mut warnings = vec![];
    let (lo, hi) = (l / (20.0 * n as f64), l / (8.0 * n as f64));
    if b < lo * (1.0 - 1e-12) || b > hi * (1.0 + 1e-12) {
        warnings.push(format!(
            "rod width b = {b:.4e} m lies outside the paper's range L/(20N) … L/(8N) = {lo:.4e} … {hi:.4e} m (its eq. 3); the reduced membrane closed forms assume slender rods"
        ));
    }
    Ok((b, h, warnings))
}

/// The girder's joints (the square's grid nodes, row by row, ids from 1) and its rods of
/// section b × h between them, beams or trusses, those on the boundary in part 2.
fn add_lattice(m: &mut Model, p: &GirderParams, b: f64, h: f64) {
    let (n, l) = (p.square.cells, p.square.length);
    let a = l / n as f64;
    let (nodes, _) = rectangle(n, n, l, l, ElementKind::Quad);
    for (i, x) in nodes.iter().enumerate() {
        m.add_node(i as i64 + 1, *x);
    }
    let kind = if p.rigid {
        ElementKind::Beam
    } else {
        ElementKind::Truss
    };
    let rho = p.density * (1.0 - b / (2.0 * a));
    let props = |f: f64| {
        if p.rigid {
            PartProps {
                youngs_modulus: Some(f * p.youngs_modulus),
                density: Some(f * rho),
                width: Some(b),
                height: Some(h),
                poisson_ratio: Some(0.0),
                ..Default::default()
            }
        } else {
            PartProps {
                youngs_modulus: Some(f * p.youngs_modulus),
                density: Some(f * rho),
                area: Some(b * h),
                ..Default::default()
            }
        }
    };
    let part = m.add_part(1, "rods", kind, props(1.0));
    // Rods on the boundary stand for half a cell of the lattice: half the modulus and half
    // the density at the full section halve every stiffness and the mass, so that the
    // girder of side L matches the lattice (and its equivalent membrane of side L).
    let edge = if p.full_edge_rods {
        part
    } else {
        m.add_part(2, "edge_rods", kind, props(0.5))
    };
    let id = |i: usize, j: usize| j * (n + 1) + i;
    let mut eid = 1;
    for j in 0..=n {
        for i in 0..=n {
            if i < n {
                m.add_element(
                    eid,
                    if j == 0 || j == n { edge } else { part },
                    &[id(i, j), id(i + 1, j)],
                );
                eid += 1;
            }
            if j < n {
                m.add_element(
                    eid,
                    if i == 0 || i == n { edge } else { part },
                    &[id(i, j), id(i, j + 1)],
                );
                eid += 1;
            }
        }
    }
}

/// `membrane`: the same square meshed with quads, orthotropic with E₁ = E₂ = E.
#[derive(Debug, Clone, Serialize)]
pub struct MembraneParams {
    pub square: Square,
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    pub shear_modulus: f64,
    pub thickness: f64,
    pub density: f64,
    /// The paper's combined model (Fig. 5b): a girder zone at the centre of the square.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub girder_zone: Option<GirderZone>,
}

/// A girder zone L_m × L_m at the centre of the membrane square (the paper's Fig. 5b):
/// the rods of the girder of N_g cells per side L inside it, the membrane (N_m cells per
/// side) around it with a hole there, the zone's boundary nodes tied to the hole's edges.
/// The rods on the zone's boundary stand for half a cell (the membrane carries the other
/// half): half the modulus and half the density, as the girder's edge rods.
#[derive(Debug, Clone, Serialize)]
pub struct GirderZone {
    /// Side of the zone L_m [m], centred on the square.
    pub length: f64,
    /// Girder cells per side of the whole square, N_g (the zone has N_g·L_m/L).
    pub cells: usize,
    /// The rods' E [Pa] and ρ [kg/m³] (the prism's; the crossings are not counted twice,
    /// as in `girder`).
    pub youngs_modulus: f64,
    pub density: f64,
    /// Rod width = thickness b [m].
    pub rod_width: f64,
    /// Rigid joints (beams) or pinned joints (trusses).
    pub rigid: bool,
}

impl GirderZone {
    /// The membrane that is the closed-form equivalent of this zone's girder
    /// (docs/theory.md, "Closed forms used as oracles"; b = h, rigid joints): s = b²/a,
    /// ρ = ρ_g(2 − b/a), G = E(b/a)²/2, a = L/N_g.
    pub fn equivalent(&self, length: f64) -> (f64, f64, f64) {
        let a = length / self.cells.max(1) as f64;
        let r = self.rod_width / a;
        (
            self.rod_width * r,
            self.density * (2.0 - r),
            self.youngs_modulus * r * r / 2.0,
        )
    }
}

impl MembraneParams {
    /// The closed-form equivalent of a rigid-jointed girder with b = h = a/10
    /// (docs/theory.md, "Closed forms used as oracles"): s = b²/a, ρ = ρ_g(2 − b/a),
    /// G = E(b/a)²/2, with E = 1.5·10¹¹ Pa, ρ_g = 7800 kg/m³, L = 0.1 m, N = 10.
    pub fn paper_default(square: Square) -> MembraneParams {
        let a = square.length / square.cells as f64;
        let r = 0.1;
        MembraneParams {
            youngs_modulus: 1.5e11,
            poisson_ratio: 0.0,
            shear_modulus: 1.5e11 * r * r / 2.0,
            thickness: (r * a) * (r * a) / a,
            density: 7800.0 * (2.0 - r),
            square,
            girder_zone: None,
        }
    }
}

/// `membrane` as asked for (the flags of `weft-weave membrane`): the membrane's properties
/// and the girder zone's left `None` follow from the others in [`MembraneOptions::resolve`].
#[derive(Debug, Clone, PartialEq)]
pub struct MembraneOptions {
    pub square: Square,
    /// E = E₁ = E₂ [Pa] and ν₁₂.
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    /// G [Pa], s [m], ρ [kg/m³]; `None`: those of the closed-form equivalent of the
    /// girder ([`MembraneParams::paper_default`], or with a girder zone
    /// [`GirderZone::equivalent`] of the zone's girder).
    pub shear_modulus: Option<f64>,
    pub thickness: Option<f64>,
    pub density: Option<f64>,
    /// The paper's combined model (Fig. 5b): a girder zone at the centre of the square.
    pub girder_zone: Option<GirderZoneOptions>,
}

impl Default for MembraneOptions {
    /// [`MembraneParams::paper_default`] on the default [`Square`].
    fn default() -> Self {
        let d = MembraneParams::paper_default(Square::default());
        MembraneOptions {
            square: d.square,
            youngs_modulus: d.youngs_modulus,
            poisson_ratio: d.poisson_ratio,
            shear_modulus: None,
            thickness: None,
            density: None,
            girder_zone: None,
        }
    }
}

impl MembraneOptions {
    /// The membrane's parameters: what is `None` taken from the closed-form equivalent of
    /// the girder, the zone's girder where there is one (s = b²/a, ρ = ρ_g(2 − b/a),
    /// G = E(b/a)²/2 with a = L/N_g), the paper's default girder otherwise.
    pub fn resolve(&self) -> MembraneParams {
        let mut d = MembraneParams::paper_default(self.square.clone());
        let l = self.square.length;
        let zone = self
            .girder_zone
            .as_ref()
            .map(|z| z.resolve(l, self.youngs_modulus));
        if let Some(z) = &zone {
            (d.thickness, d.density, d.shear_modulus) = z.equivalent(l);
        }
        MembraneParams {
            youngs_modulus: self.youngs_modulus,
            poisson_ratio: self.poisson_ratio,
            shear_modulus: self.shear_modulus.unwrap_or(d.shear_modulus),
            thickness: self.thickness.unwrap_or(d.thickness),
            density: self.density.unwrap_or(d.density),
            girder_zone: zone,
            ..d
        }
    }
}

/// The girder zone as asked for (`membrane --girder-cells` and the zone's flags); what is
/// `None` follows from the square in [`GirderZoneOptions::resolve`].
#[derive(Debug, Clone, PartialEq)]
pub struct GirderZoneOptions {
    /// Girder cells per side of the whole square, N_g.
    pub cells: usize,
    /// Side of the zone L_m [m]; `None`: L/2.
    pub length: Option<f64>,
    /// The rods' E [Pa]; `None`: the membrane's.
    pub youngs_modulus: Option<f64>,
    /// The rods' ρ_g [kg/m³].
    pub density: f64,
    /// Rod width = thickness b [m]; `None`: L/(10 N_g).
    pub rod_width: Option<f64>,
    /// Rigid joints (beams) or pinned joints (trusses).
    pub rigid: bool,
}

impl GirderZoneOptions {
    /// A zone of N_g = `cells` girder cells per side, its rods the default girder's
    /// ([`GirderParams::default`]: ρ_g, rigid joints), the rest following the square.
    pub fn new(cells: usize) -> GirderZoneOptions {
        let g = GirderParams::default();
        GirderZoneOptions {
            cells,
            length: None,
            youngs_modulus: None,
            density: g.density,
            rod_width: None,
            rigid: g.rigid,
        }
    }

    /// The zone in a square of side `length` whose membrane has the modulus
    /// `youngs_modulus`.
    pub fn resolve(&self, length: f64, youngs_modulus: f64) -> GirderZone {
        GirderZone {
            length: self.length.unwrap_or(0.5 * length),
            cells: self.cells,
            youngs_modulus: self.youngs_modulus.unwrap_or(youngs_modulus),
            density: self.density,
            rod_width: self
                .rod_width
                .unwrap_or(length / (10.0 * self.cells.max(1) as f64)),
            rigid: self.rigid,
        }
    }
}

fn membrane_part(p: &MembraneParams) -> PartProps {
    PartProps {
        youngs_modulus_1: Some(p.youngs_modulus),
        youngs_modulus_2: Some(p.youngs_modulus),
        poisson_ratio_12: Some(p.poisson_ratio),
        shear_modulus_12: Some(p.shear_modulus),
        thickness: Some(p.thickness),
        density: Some(p.density),
        ..Default::default()
    }
}

pub fn membrane(p: &MembraneParams) -> Result<Model> {
    positive("youngs-modulus", p.youngs_modulus, "in Pa")?;
    positive("shear-modulus", p.shear_modulus, "in Pa")?;
    check_square(&p.square)?;
    positive("thickness", p.thickness, "in m")?;
    positive("density", p.density, "in kg/m³")?;
    let (n, l) = (p.square.cells, p.square.length);
    if let Some(z) = &p.girder_zone {
        return membrane_with_girder_zone(p, z);
    }
    let mut m = Model::default();
    let (nodes, elems) = rectangle(n, n, l, l, ElementKind::Quad);
    for (i, x) in nodes.iter().enumerate() {
        m.add_node(i as i64 + 1, *x);
    }
    let part = m.add_part(1, "membrane", ElementKind::Quad, membrane_part(p));
    for (e, ns) in elems.iter().enumerate() {
        m.add_element(e as i64 + 1, part, ns);
    }
    frame(&mut m, &p.square, p.youngs_modulus, p.density, false)?;
    if p.square.load_case != LoadCase::Transverse {
        for i in 0..m.num_nodes() {
            m.constraints.push((i, [false, false, true]));
        }
    }
    m.validate()?;
    resolve_pulse(&mut m)?;
    Ok(m)
}

/// The index k with k·a = x (to 10⁻⁹ L), if x lies on a grid line of spacing a.
fn grid_line(x: f64, a: f64, l: f64) -> Option<usize> {
    let k = (x / a).round();
    (k >= 0.0 && (k * a - x).abs() <= 1e-9 * l).then_some(k as usize)
}

/// `membrane --girder-cells`: the square of N_m membrane cells per side with the girder
/// zone at its centre (the paper's Fig. 5b). Node sets: `centre` (the zone's girder
/// nodes: the paper's reference nodes), `reference` (every node, the girder's where a
/// membrane node coincides with one on the zone's boundary), `axis_x`, `diagonal`,
/// `loaded_edge` as in the plain square.
fn membrane_with_girder_zone(p: &MembraneParams, z: &GirderZone) -> Result<Model> {
    check_zone(p, z)?;
    let zg = ZoneGrid::new(p, z)?;
    let mut m = Model::default();
    let mut ids = NextIds {
        node: 1,
        element: 1,
    };
    let grid = add_membrane_around_zone(&mut m, p, &zg, &mut ids);
    let zone = add_zone_girder(&mut m, z, &zg, &mut ids);
    tie_zone_to_membrane(&mut m, &zg, &grid, &zone)?;
    let nz = zg.nz;
    if p.square.load_case == LoadCase::Transverse && nz % 2 != 0 {
        return Err(WeftError::input(format!(
            "the girder zone has {nz} cells per side: no node at its centre for the transverse load"
        ))
        .expected("an even number of girder cells across the zone")
        .hint("choose --girder-cells (and --zone-length) so that N_g·L_m/L is even"));
    }
    let n = p.square.cells;
    let g = |i: usize, j: usize| grid[j * (n + 1) + i];
    clamp_load_analysis(
        &mut m,
        &p.square,
        p.youngs_modulus,
        p.density,
        false,
        &g,
        zone[nz / 2 * (nz + 1) + nz / 2],
    )?;
    insert_zone_sets(&mut m, &zg, &grid, &zone);
    if p.square.load_case != LoadCase::Transverse {
        for i in 0..m.num_nodes() {
            m.constraints.push((i, [false, false, true]));
        }
        if z.rigid {
            for &i in &zone {
                m.rot_constraints.push((i, [true, true, false]));
            }
        }
    }
    m.validate()?;
    resolve_pulse(&mut m)?;
    Ok(m)
}

/// The girder zone's own values, each named by its flag.
fn check_zone(p: &MembraneParams, z: &GirderZone) -> Result<()> {
    let l = p.square.length;
    positive("length", l, "in m")?;
    positive("zone-length", z.length, "in m")?;
    positive("rod-modulus", z.youngs_modulus, "in Pa")?;
    positive("rod-density", z.density, "in kg/m³")?;
    positive("rod-width", z.rod_width, "in m")?;
    if z.cells == 0 {
        return Err(WeftError::input("--girder-cells = `0`")
            .expected("at least 1 girder cell per side of the square"));
    }
    if z.length >= l {
        return Err(WeftError::input(format!(
            "--zone-length = `{}` m is not smaller than the square's side L = {l} m",
            z.length
        ))
        .expected("0 < L_m < L: the membrane surrounds the girder zone"));
    }
    Ok(())
}

/// Where the girder zone lies on the membrane's grid and on the girder's.
struct ZoneGrid {
    /// Membrane cells per side N_m.
    n: usize,
    /// The membrane's cell L/N_m and the girder's L/N_g [m].
    am: f64,
    ag: f64,
    /// The zone's lower edges x = y = z0 [m].
    z0: f64,
    /// The zone's edges on the membrane's grid lines i0 and i1.
    i0: usize,
    i1: usize,
    /// Girder cells across the zone.
    nz: usize,
}

impl ZoneGrid {
    /// The zone's edges must lie on both grids' lines, and its rods be narrower than the
    /// girder's cell.
    fn new(p: &MembraneParams, z: &GirderZone) -> Result<ZoneGrid> {
        let (n, l) = (p.square.cells, p.square.length);
        let (am, ag) = (l / n as f64, l / z.cells as f64);
        let z0 = 0.5 * (l - z.length);
        let (i0, i1) = match (grid_line(z0, am, l), grid_line(z0 + z.length, am, l)) {
            (Some(a), Some(b)) if a >= 1 && b < n => (a, b),
            _ => {
                return Err(WeftError::input(format!(
                "the girder zone's edges at x, y = {z0:.6} and {:.6} m are not on the membrane's \
                     grid lines (multiples of L/N_m = {am} m, N_m = --cells = {n})",
                z0 + z.length
            ))
                .expected("(L − L_m)/2 a multiple of L/N_m")
                .hint("with the default L_m = L/2, choose --cells a multiple of 4"))
            }
        };
        let (g0, g1) = match (grid_line(z0, ag, l), grid_line(z0 + z.length, ag, l)) {
            (Some(a), Some(b)) => (a, b),
            _ => {
                return Err(WeftError::input(format!(
                    "the girder zone's edges at x, y = {z0:.6} and {:.6} m are not on the girder's \
                     grid lines (multiples of L/N_g = {ag} m, N_g = --girder-cells = {})",
                    z0 + z.length,
                    z.cells
                ))
                .expected("(L − L_m)/2 a multiple of L/N_g")
                .hint("with the default L_m = L/2, choose --girder-cells a multiple of 4"))
            }
        };
        let b = z.rod_width;
        if b >= ag {
            return Err(WeftError::input(format!(
                "--rod-width = `{b}` m is not smaller than the girder's cell L/N_g = {ag} m"
            ))
            .expected("b < L/N_g"));
        }
        Ok(ZoneGrid {
            n,
            am,
            ag,
            z0,
            i0,
            i1,
            nz: g1 - g0,
        })
    }

    /// The membrane's grid node (i, j) lies strictly inside the zone.
    fn inside(&self, i: usize, j: usize) -> bool {
        let (i0, i1) = (self.i0, self.i1);
        i0 < i && i < i1 && i0 < j && j < i1
    }

    /// The membrane's grid node (i, j) lies on the zone's edge.
    fn on_zone_edge(&self, i: usize, j: usize) -> bool {
        let (i0, i1) = (self.i0, self.i1);
        (i0..=i1).contains(&i) && (i0..=i1).contains(&j) && !self.inside(i, j)
    }
}

/// The next node and element ids.
struct NextIds {
    node: i64,
    element: i64,
}

/// The membrane's nodes, none strictly inside the zone, and its quads around it; returns
/// the grid's node indices (`usize::MAX` inside the zone).
fn add_membrane_around_zone(
    m: &mut Model,
    p: &MembraneParams,
    zg: &ZoneGrid,
    ids: &mut NextIds,
) -> Vec<usize> {
    let (n, am, i0, i1) = (zg.n, zg.am, zg.i0, zg.i1);
    let mut grid = vec![usize::MAX; (n + 1) * (n + 1)];
    for j in 0..=n {
        for i in 0..=n {
            if !zg.inside(i, j) {
                grid[j * (n + 1) + i] = m.add_node(ids.node, [i as f64 * am, j as f64 * am, 0.0]);
                ids.node += 1;
            }
        }
    }
    let part = m.add_part(1, "membrane", ElementKind::Quad, membrane_part(p));
    for j in 0..n {
        for i in 0..n {
            if (i0..i1).contains(&i) && (i0..i1).contains(&j) {
                continue;
            }
            let g = |i: usize, j: usize| grid[j * (n + 1) + i];
            m.add_element(
                ids.element,
                part,
                &[g(i, j), g(i + 1, j), g(i + 1, j + 1), g(i, j + 1)],
            );
            ids.element += 1;
        }
    }
    grid
}

/// The girder's nodes and rods inside the zone, as `girder` builds them (the rods on the
/// zone's edges halved); returns the zone's nodes, row by row.
fn add_zone_girder(m: &mut Model, z: &GirderZone, zg: &ZoneGrid, ids: &mut NextIds) -> Vec<usize> {
    let (nz, ag, z0, b) = (zg.nz, zg.ag, zg.z0, z.rod_width);
    let w = nz + 1;
    let mut zone = Vec::with_capacity(w * w);
    for j in 0..=nz {
        for i in 0..=nz {
            zone.push(m.add_node(ids.node, [z0 + i as f64 * ag, z0 + j as f64 * ag, 0.0]));
            ids.node += 1;
        }
    }
    let (kind, rho) = (
        if z.rigid {
            ElementKind::Beam
        } else {
            ElementKind::Truss
        },
        z.density * (1.0 - b / (2.0 * ag)),
    );
    let props = |f: f64| {
        if z.rigid {
            PartProps {
                youngs_modulus: Some(f * z.youngs_modulus),
                density: Some(f * rho),
                width: Some(b),
                height: Some(b),
                poisson_ratio: Some(0.0),
                ..Default::default()
            }
        } else {
            PartProps {
                youngs_modulus: Some(f * z.youngs_modulus),
                density: Some(f * rho),
                area: Some(b * b),
                ..Default::default()
            }
        }
    };
    let rods = m.add_part(2, "rods", kind, props(1.0));
    let half = m.add_part(3, "half_rods", kind, props(0.5));
    let gid = |i: usize, j: usize| zone[j * w + i];
    for j in 0..=nz {
        for i in 0..=nz {
            let edge = |k: usize| k == 0 || k == nz;
            if i < nz {
                m.add_element(
                    ids.element,
                    if edge(j) { half } else { rods },
                    &[gid(i, j), gid(i + 1, j)],
                );
                ids.element += 1;
            }
            if j < nz {
                m.add_element(
                    ids.element,
                    if edge(i) { half } else { rods },
                    &[gid(i, j), gid(i, j + 1)],
                );
                ids.element += 1;
            }
        }
    }
    zone
}

/// Tie the zone's boundary to the hole's four sides.
fn tie_zone_to_membrane(
    m: &mut Model,
    zg: &ZoneGrid,
    grid: &[usize],
    zone: &[usize],
) -> Result<()> {
    let (n, am, i0, i1, nz) = (zg.n, zg.am, zg.i0, zg.i1, zg.nz);
    let side = |axis: usize, k: usize| -> (usize, f64, Vec<usize>) {
        let ns = (i0..=i1)
            .map(|t| {
                if axis == 0 {
                    grid[t * (n + 1) + k]
                } else {
                    grid[k * (n + 1) + t]
                }
            })
            .collect();
        (axis, k as f64 * am, ns)
    };
    let hole = Coarse {
        hole_sides: vec![side(0, i0), side(0, i1), side(1, i0), side(1, i1)],
        outer: vec![],
    };
    let gid = |i: usize, j: usize| zone[j * (nz + 1) + i];
    let boundary: Vec<usize> = (0..=nz)
        .flat_map(|j| (0..=nz).map(move |i| (i, j)))
        .filter(|&(i, j)| i == 0 || i == nz || j == 0 || j == nz)
        .map(|(i, j)| gid(i, j))
        .collect();
    tie_to_hole(m, &hole, &boundary)?;
    Ok(())
}

/// Sets: the zone's nodes win where a membrane node coincides with one.
fn insert_zone_sets(m: &mut Model, zg: &ZoneGrid, grid: &[usize], zone: &[usize]) {
    let (n, nz) = (zg.n, zg.nz);
    let g = |i: usize, j: usize| grid[j * (n + 1) + i];
    let gid = |i: usize, j: usize| zone[j * (nz + 1) + i];
    let mut reference: Vec<usize> = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| (i, j)))
        .filter(|&(i, j)| !zg.inside(i, j) && !zg.on_zone_edge(i, j))
        .map(|(i, j)| g(i, j))
        .collect();
    reference.extend(zone.iter().copied());
    m.node_sets.insert("reference".into(), reference);
    m.node_sets.insert("centre".into(), zone.to_vec());
    m.node_sets
        .insert("axis_x".into(), (0..=n).map(|i| g(i, 0)).collect());
    let mut diagonal: Vec<usize> = (0..=n)
        .filter(|&i| !zg.inside(i, i) && !zg.on_zone_edge(i, i))
        .map(|i| g(i, i))
        .chain((0..=nz).map(|i| gid(i, i)))
        .collect();
    diagonal.sort_by(|&a, &b| m.coords[a][0].total_cmp(&m.coords[b][0]));
    m.node_sets.insert("diagonal".into(), diagonal);
    m.node_sets
        .insert("loaded_edge".into(), (0..=n).map(|j| g(n, j)).collect());
}
