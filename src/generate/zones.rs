//! Coupled zones: a dense centre (a girder or a fine membrane) inside the coarse graded
//! membrane of [`super::surround`], whose elements grow with distance from the centre,
//! joined by tied interfaces (the paper's §3–§4 models). The reduced woven patch of the
//! paper's §5, built on the same surround, is in [`super::woven_reduced`], re-exported
//! here under its old path.

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::generate::pulse::resolve_pulse;
use crate::generate::surround::{centre_line_sets, coarse_membrane, hold_outer_edge, tie_to_hole};
pub use crate::generate::surround::{graded_lines, MembraneProps};
pub use crate::generate::woven_reduced::{
    woven_reduced, Interface, PretensionStart, SurroundParams, WovenParams,
};
use crate::model::{Analysis, ElementKind, Load, Model, PartProps, TimeLaw};

/// The dense centre zone of [`combined`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Centre {
    /// A rigid-jointed girder.
    Girder,
    /// A fine membrane.
    Membrane,
}

/// `combined`: a dense centre zone (girder or fine membrane) in a graded coarse membrane.
#[derive(Debug, Clone, Serialize)]
pub struct CombinedParams {
    pub centre: Centre,
    /// Side of the dense centre zone L_m [m].
    pub centre_length: f64,
    /// Cells across the centre zone (even).
    pub centre_cells: usize,
    /// Side of the whole model L [m].
    pub length: f64,
    /// Coarse cell size at the centre, in centre cells.
    pub coarsening: usize,
    /// Growth ratio of the coarse cells.
    pub growth: f64,
    pub quarter: bool,
    /// Girder: E, ρ, b = h (rods) [Pa, kg/m³, m].
    pub youngs_modulus: f64,
    pub density: f64,
    pub rod_width: f64,
    /// The coarse membrane (and the fine one).
    pub membrane: MembraneProps,
    /// Transverse force at the centre [N], pulse T_F [s], end time [s], output [s].
    pub force: f64,
    pub pulse: f64,
    pub end_time: f64,
    pub output_interval: f64,
}

/// `combined` as asked for (the flags of `weft-weave combined`): the values left `None`
/// follow from the others in [`CombinedOptions::resolve`].
#[derive(Debug, Clone, PartialEq)]
pub struct CombinedOptions {
    pub centre: Centre,
    /// Side of the dense centre zone L_m [m].
    pub centre_length: f64,
    /// Cells across the centre zone (even).
    pub centre_cells: usize,
    /// Side of the whole model L [m].
    pub length: f64,
    /// Coarse cell size at the centre, in centre cells.
    pub coarsening: usize,
    /// Growth ratio of the coarse cells.
    pub growth: f64,
    pub quarter: bool,
    /// Girder: E [Pa] (also the membrane's) and ρ [kg/m³].
    pub youngs_modulus: f64,
    pub density: f64,
    /// Girder rod width = thickness b [m]; `None`: a/10, a = L_m/(cells) the centre cell.
    pub rod_width: Option<f64>,
    /// Membrane shear modulus G [Pa], thickness s [m], density [kg/m³]; `None`: those of
    /// the centre girder's closed-form equivalent, E(b/a)²/2, b²/a, ρ(2 − b/a).
    pub shear_modulus: Option<f64>,
    pub thickness: Option<f64>,
    pub membrane_density: Option<f64>,
    /// Transverse force at the centre [N] (the full model's).
    pub force: f64,
    /// Pulse duration T_F [s]; `None`: L_m·√(ρ/E).
    pub pulse: Option<f64>,
    /// End time [s]; `None`: L/2·√(ρ/E)·4.
    pub end_time: Option<f64>,
    /// Output interval [s]; `None`: end time / 100.
    pub output_interval: Option<f64>,
}

impl Default for CombinedOptions {
    /// A steel girder zone of 20 cells across 20 mm in a quarter of a 0.1 m square, the
    /// coarse cells two centre cells wide at the zone and growing by 1.25, a 1 N force.
    fn default() -> Self {
        CombinedOptions {
            centre: Centre::Girder,
            centre_length: 0.02,
            centre_cells: 20,
            length: 0.1,
            coarsening: 2,
            growth: 1.25,
            quarter: true,
            youngs_modulus: 1.5e11,
            density: 7800.0,
            rod_width: None,
            shear_modulus: None,
            thickness: None,
            membrane_density: None,
            force: 1.0,
            pulse: None,
            end_time: None,
            output_interval: None,
        }
    }
}

impl CombinedOptions {
    /// The parameters, what is `None` derived: the rod width from the centre cell, the
    /// membrane as the centre girder's closed-form equivalent (ν = 0), the pulse and the
    /// times from the wave's transit.
    pub fn resolve(&self) -> CombinedParams {
        let cell = self.centre_length / self.centre_cells.max(1) as f64;
        let b = self.rod_width.unwrap_or(cell / 10.0);
        let c = self.length * 0.5 * (self.density / self.youngs_modulus).sqrt();
        let end = self.end_time.unwrap_or(4.0 * c);
        CombinedParams {
            centre: self.centre,
            centre_length: self.centre_length,
            centre_cells: self.centre_cells,
            length: self.length,
            coarsening: self.coarsening,
            growth: self.growth,
            quarter: self.quarter,
            youngs_modulus: self.youngs_modulus,
            density: self.density,
            rod_width: b,
            membrane: MembraneProps {
                youngs_modulus: self.youngs_modulus,
                poisson_ratio: 0.0,
                shear_modulus: self
                    .shear_modulus
                    .unwrap_or(self.youngs_modulus * (b / cell).powi(2) / 2.0),
                thickness: self.thickness.unwrap_or(b * b / cell),
                density: self
                    .membrane_density
                    .unwrap_or(self.density * (2.0 - b / cell)),
            },
            force: self.force,
            pulse: self
                .pulse
                .unwrap_or(self.centre_length * (self.density / self.youngs_modulus).sqrt()),
            end_time: end,
            output_interval: self.output_interval.unwrap_or(end / 100.0),
        }
    }
}

/// The combined model: the dense centre zone ([`Centre`]) on its grid, the graded coarse
/// membrane around it tied to the zone's boundary and pinned at its outer edge, the
/// force pulse at the centre, the node sets and the analysis.
pub fn combined(p: &CombinedParams) -> Result<Model> {
    check(p)?;
    let a = p.centre_length / p.centre_cells as f64;
    let c = 0.5 * p.centre_length;
    let pos = graded_lines(c, a * p.coarsening as f64, 0.5 * p.length, p.growth)?;
    let mut m = Model::default();
    let zone = CentreGrid::new(&mut m, p, a, c);
    match p.centre {
        Centre::Girder => add_centre_girder(&mut m, p, &zone, a),
        Centre::Membrane => add_fine_membrane(&mut m, p, &zone),
    }
    let fine = zone.nodes;
    let coarse = coarse_membrane(&mut m, &pos, p.quarter, c, &p.membrane, 100_000);
    let boundary: Vec<usize> = fine
        .iter()
        .copied()
        .filter(|&f| {
            let x = m.coords[f];
            (x[0].abs() - c).abs() < 1e-12 || (x[1].abs() - c).abs() < 1e-12
        })
        .collect();
    let tied = tie_to_hole(&mut m, &coarse, &boundary)?;
    hold_outer_edge(&mut m, &coarse, p.quarter, p.length);
    let centre = *fine
        .iter()
        .find(|&&f| m.coords[f][0].abs() < 1e-12 && m.coords[f][1].abs() < 1e-12)
        .expect("a centre node");
    let share = if p.quarter { 0.25 } else { 1.0 };
    m.loads.push(Load {
        id: 1,
        node: centre,
        force: [0.0, 0.0, share * p.force],
        law: TimeLaw::SinePulse {
            start: 0.0,
            duration: p.pulse,
        },
    });
    m.node_sets.insert("reference".into(), fine.clone());
    m.node_sets.insert("interface".into(), tied);
    centre_line_sets(&mut m, &fine, c);
    m.analysis = Analysis {
        end_time: p.end_time,
        output_interval: p.output_interval,
        ..Default::default()
    };
    m.validate()?;
    resolve_pulse(&mut m)?;
    Ok(m)
}

/// An even number of centre cells, and a coarsening that divides half of them.
fn check(p: &CombinedParams) -> Result<()> {
    if p.centre_cells == 0 || !p.centre_cells.is_multiple_of(2) {
        return Err(
            WeftError::input(format!("--centre-cells = `{}`", p.centre_cells))
                .expected("an even number of cells > 0 (a node at the centre)"),
        );
    }
    if p.coarsening == 0 || !(p.centre_cells / 2).is_multiple_of(p.coarsening) {
        return Err(
            WeftError::input(format!("--coarsening = `{}`", p.coarsening)).expected(format!(
                "a divisor of centre-cells/2 = {}",
                p.centre_cells / 2
            )),
        );
    }
    Ok(())
}

/// The dense zone's nodes: the centre grid of cell size a (ids from 1), (n + 1)² of them,
/// n the cells per side (half of them in a quarter), row by row.
struct CentreGrid {
    nodes: Vec<usize>,
    n: usize,
}

impl CentreGrid {
    /// The grid's nodes on the quarter [0, c]² or on the full [−c, c]².
    fn new(m: &mut Model, p: &CombinedParams, a: f64, c: f64) -> CentreGrid {
        let n = if p.quarter {
            p.centre_cells / 2
        } else {
            p.centre_cells
        };
        let x0 = if p.quarter { 0.0 } else { -c };
        let mut nodes = vec![];
        for j in 0..=n {
            for i in 0..=n {
                nodes.push(m.add_node(
                    (nodes.len() + 1) as i64,
                    [x0 + i as f64 * a, x0 + j as f64 * a, 0.0],
                ));
            }
        }
        CentreGrid { nodes, n }
    }

    /// The node at (i, j) of the grid.
    fn id(&self, i: usize, j: usize) -> usize {
        self.nodes[j * (self.n + 1) + i]
    }
}

/// The girder centre: beams along the grid lines (rigid joints), those on the zone's
/// boundary or on a symmetry plane half rods.
fn add_centre_girder(m: &mut Model, p: &CombinedParams, g: &CentreGrid, a: f64) {
    let rod = |f: f64| PartProps {
        youngs_modulus: Some(f * p.youngs_modulus),
        density: Some(f * p.density * (1.0 - p.rod_width / (2.0 * a))),
        width: Some(p.rod_width),
        height: Some(p.rod_width),
        poisson_ratio: Some(0.0),
        ..Default::default()
    };
    let part = m.add_part(1, "rods", ElementKind::Beam, rod(1.0));
    // Rods on the hole boundary (half a cell; the membrane carries the other half)
    // and on a symmetry plane (half belongs to the neighbouring quarter) carry half
    // of everything: half the modulus and half the density at the full section
    // halve every stiffness (axial, both bendings, torsion) and the mass alike.
    let half = m.add_part(2, "half_rods", ElementKind::Beam, rod(0.5));
    // k = 0 is a symmetry plane in a quarter and the hole's other boundary in a
    // full model: half rods either way.
    let n = g.n;
    let on_line = |k: usize| k == n || k == 0;
    let mut eid = 1;
    for j in 0..=n {
        for i in 0..=n {
            if i < n {
                m.add_element(
                    eid,
                    if on_line(j) { half } else { part },
                    &[g.id(i, j), g.id(i + 1, j)],
                );
                eid += 1;
            }
            if j < n {
                m.add_element(
                    eid,
                    if on_line(i) { half } else { part },
                    &[g.id(i, j), g.id(i, j + 1)],
                );
                eid += 1;
            }
        }
    }
}

/// The membrane centre: a quad on every cell of the grid, of the coarse membrane's
/// properties.
fn add_fine_membrane(m: &mut Model, p: &CombinedParams, g: &CentreGrid) {
    let part = m.add_part(1, "fine_membrane", ElementKind::Quad, p.membrane.part());
    let mut eid = 1;
    for j in 0..g.n {
        for i in 0..g.n {
            m.add_element(
                eid,
                part,
                &[
                    g.id(i, j),
                    g.id(i + 1, j),
                    g.id(i + 1, j + 1),
                    g.id(i, j + 1),
                ],
            );
            eid += 1;
        }
    }
}
