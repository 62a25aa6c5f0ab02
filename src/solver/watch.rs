//! What an armour engineer reads from an impact, watched while the run goes: per layer of
//! a fabric (the element tables' `layer` column), at every output sample, the kinetic
//! energy of its nodes, the strain energy of its elements (live, and taken by failures),
//! the friction work of the contacts whose slave node is in it, the energy it has absorbed
//! (their sum), its failed elements and broken yarns, and its largest displacement along
//! the strike direction; and the projectile's outcome: arrested, or perforated with its
//! residual velocity (docs/theory.md, "Failure, perforation and the ballistic limit").
//!
//! A yarn is broken when one of its cross-sections has failed whole: a truss (a chain's
//! or a rod's section is one truss), or every membrane element of the yarn whose centroid
//! lies at the same station along the yarn (a band's elements across its width).

use std::collections::HashMap;

use crate::model::{ElementKind, Model};

/// Values per layer at one time, in this order: kinetic, strain, eroded, friction,
/// absorbed [J], failed elements, broken yarns, deflection [m], the time of its first
/// failure [s] (NaN: none yet).
pub type LayerValues = [f64; 9];

/// How the projectile's impact ended.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Outcome {
    /// The run ended before the projectile was arrested or free of the fabric.
    #[default]
    Undecided,
    /// Its velocity along its initial direction fell to [`ARREST_FRACTION`] of its
    /// striking speed or below, at `time`.
    Arrested { time: f64 },
    /// Free of the fabric: its tip beyond where the fabric's back face started by more
    /// than its radius, and no contact force on it (below [`FREE_FORCE_FRACTION`] of the
    /// peak so far) at [`FREE_SAMPLES`] output samples in a row, the last at `time`,
    /// moving at `residual_velocity` [m/s].
    Perforated { time: f64, residual_velocity: f64 },
}

impl Outcome {
    pub fn name(&self) -> &'static str {
        match self {
            Outcome::Undecided => "undecided",
            Outcome::Arrested { .. } => "arrested",
            Outcome::Perforated { .. } => "perforated",
        }
    }
    pub fn is_decided(&self) -> bool {
        !matches!(self, Outcome::Undecided)
    }
}

/// The velocity along the strike, as a fraction of the striking speed, at or below which
/// a projectile counts as arrested (4 cm/s at 400 m/s): one held still by its fabric can
/// keep a mean drift of a few mm/s that never changes sign, fragments wedged under the
/// nose ringing against it (measured: a 4 × 4 chain patch, every yarn broken, held the
/// nose from 188 µs to the 1 ms end at −3.7 mm/s, its step-to-step velocity swinging
/// about that mean, while the run waited for a zero crossing).
pub const ARREST_FRACTION: f64 = 1e-4;

/// The contact force on a projectile below which it counts as free of the fabric, as a
/// fraction of the peak so far: fragments (nodes whose elements have all failed) that
/// ride on the nose keep a small oscillating penalty force that never vanishes.
pub const FREE_FORCE_FRACTION: f64 = 0.01;

/// Output samples in a row without contact force that make a projectile free: one
/// sample could fall in a moment when the penalty contact has let go while the yarns
/// still hold the nose; broken yarn ends that whip ahead of the nose keep the "beyond
/// every attached node" test of an earlier design from ever passing (measured: ends
/// 8 mm ahead of the tip of a bullet that left at 399 m/s).
pub const FREE_SAMPLES: u32 = 3;

/// An element's layer (0: none) and its cross-section (`u32::MAX`: none).
#[derive(Debug, Clone, Copy)]
struct Tag {
    layer: u16,
    section: u32,
}

/// A cross-section of a yarn: its yarn and how many of its elements are live.
#[derive(Debug, Clone, Copy)]
struct Section {
    yarn: u32,
    live: u32,
}

/// The watch of one run.
#[derive(Debug, Clone, Default)]
pub struct Watch {
    /// Layers 1..=n.
    pub n_layers: usize,
    node_layer: Vec<u16>,
    tags: HashMap<ElementKind, Vec<Tag>>,
    sections: Vec<Section>,
    /// Per yarn: its layer and whether it is broken.
    yarns: Vec<(u16, bool)>,
    failed: Vec<u32>,
    broken: Vec<u32>,
    /// Per layer, the time of its first failure (NaN: none yet).
    pub first_failure: Vec<f64>,
    /// The strike direction: the first projectile's initial velocity, unit.
    axis: Option<[f64; 3]>,
    peak_force: f64,
    /// The projectile's speed along the strike at its first sample [m/s].
    strike_speed: Option<f64>,
    /// The fabric's back face at the start: the largest X·a over the layered nodes.
    back_start: f64,
    /// Samples in a row that found the projectile free.
    free_run: u32,
    pub outcome: Outcome,
    /// The largest deflection of the last layer so far [m].
    pub back_face_peak: f64,
    /// The layers' values at the last sample.
    pub last_rows: Vec<LayerValues>,
    /// A deformable bullet's nodes (`Model::bullet_nodes`), judged as the projectile is:
    /// its most advanced node as the tip, its mass-weighted velocity, the sum of the
    /// contact forces on its nodes; empty with a rigid projectile or none.
    pub bullet: Vec<usize>,
    /// The bullet's radius about its axis (`striker::axis_point`) [m].
    pub bullet_radius: f64,
}

impl Watch {
    /// The layers of `m`'s trusses and membranes, and its first projectile's direction.
    pub fn new(m: &Model) -> Watch {
        let mut w = Watch {
            node_layer: vec![0; m.num_nodes()],
            axis: m.projectiles.first().and_then(|p| {
                let v = p.velocity;
                let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                (n > 0.0).then(|| [v[0] / n, v[1] / n, v[2] / n])
            }),
            ..Default::default()
        };
        if w.axis.is_none() {
            if let (Some(nodes), Some(a)) = (m.bullet_nodes(), m.bullet_direction()) {
                let along = |x: &[f64; 3]| x[0] * a[0] + x[1] * a[1] + x[2] * a[2];
                let xs: Vec<[f64; 3]> = nodes.iter().map(|&i| m.coords[i]).collect();
                if !xs.is_empty() {
                    let tip = crate::model::striker::axis_point(&xs, a);
                    w.bullet_radius = nodes
                        .iter()
                        .map(|&i| {
                            let x = m.coords[i];
                            let d = [x[0] - tip[0], x[1] - tip[1], x[2] - tip[2]];
                            let s = along(&d);
                            let r = [d[0] - s * a[0], d[1] - s * a[1], d[2] - s * a[2]];
                            (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt()
                        })
                        .fold(0.0, f64::max);
                    w.bullet = nodes.to_vec();
                    w.axis = Some(a);
                }
            }
        }
        let mut yarn_index: HashMap<(usize, i64), u32> = HashMap::new();
        let mut section_index: HashMap<(u32, i64), u32> = HashMap::new();
        for kind in [ElementKind::Truss, ElementKind::Tri, ElementKind::Quad] {
            let Some(b) = m.block(kind) else { continue };
            let npe = kind.nodes_per_element();
            let mut tags = Vec::with_capacity(b.len());
            for e in 0..b.len() {
                let layer = b
                    .layer_of(e)
                    .map_or(0, |l| l.clamp(0, u16::MAX as i64) as u16);
                let mut tag = Tag {
                    layer,
                    section: u32::MAX,
                };
                if layer > 0 {
                    w.n_layers = w.n_layers.max(layer as usize);
                    for &n in &b.nodes[npe * e..npe * e + npe] {
                        if w.node_layer[n] == 0 {
                            w.node_layer[n] = layer;
                        }
                    }
                    if let Some(yarn) = b.yarn_of(e) {
                        let yi = *yarn_index.entry((b.part[e], yarn)).or_insert_with(|| {
                            w.yarns.push((layer, false));
                            w.yarns.len() as u32 - 1
                        });
                        // A truss is a section of its own; a membrane's section is its
                        // station along the yarn (its material direction 1).
                        let station = if kind == ElementKind::Truss {
                            e as i64
                        } else {
                            station(m, kind, e)
                        };
                        let si = *section_index.entry((yi, station)).or_insert_with(|| {
                            w.sections.push(Section { yarn: yi, live: 0 });
                            w.sections.len() as u32 - 1
                        });
                        w.sections[si as usize].live += 1;
                        tag.section = si;
                    }
                }
                tags.push(tag);
            }
            w.tags.insert(kind, tags);
        }
        if let Some(a) = w.axis {
            w.back_start = (0..m.num_nodes())
                .filter(|&i| w.node_layer[i] > 0)
                .map(|i| {
                    let x = m.coords[i];
                    x[0] * a[0] + x[1] * a[1] + x[2] * a[2]
                })
                .fold(f64::NEG_INFINITY, f64::max);
        }
        w.failed = vec![0; w.n_layers + 1];
        w.broken = vec![0; w.n_layers + 1];
        w.first_failure = vec![f64::NAN; w.n_layers + 1];
        w
    }

    /// Whether the run has anything to watch: layers or a moving projectile.
    pub fn is_active(&self) -> bool {
        self.n_layers > 0 || self.axis.is_some()
    }

    /// The layer of node i (0: none).
    pub fn node_layer(&self, i: usize) -> u16 {
        self.node_layer[i]
    }

    /// The layer of element e of kind `kind` (0: none).
    pub fn element_layer(&self, kind: ElementKind, e: usize) -> u16 {
        self.tags
            .get(&kind)
            .and_then(|t| t.get(e))
            .map_or(0, |t| t.layer)
    }

    /// Element e of kind `kind` has left the model at time t.
    pub fn on_erosion(&mut self, kind: ElementKind, e: usize, t: f64) {
        let Some(tag) = self.tags.get(&kind).and_then(|t| t.get(e)).copied() else {
            return;
        };
        let l = tag.layer as usize;
        if l == 0 {
            return;
        }
        self.failed[l] += 1;
        if self.first_failure[l].is_nan() {
            self.first_failure[l] = t;
        }
        if tag.section != u32::MAX {
            let s = &mut self.sections[tag.section as usize];
            s.live = s.live.saturating_sub(1);
            if s.live == 0 {
                let y = &mut self.yarns[s.yarn as usize];
                if !y.1 {
                    y.1 = true;
                    self.broken[l] += 1;
                }
            }
        }
    }

    /// Per layer 1..=n: failed elements and broken yarns so far.
    pub fn counts(&self, layer: usize) -> (u32, u32) {
        (self.failed[layer], self.broken[layer])
    }

    /// The strike direction, when a projectile moves.
    pub fn axis(&self) -> Option<[f64; 3]> {
        self.axis
    }

    /// Judges the outcome at time t from the first projectile's tip, velocity, contact
    /// force and radius (see [`Outcome`]).
    pub fn judge(&mut self, t: f64, tip: &[f64; 3], v: &[f64; 3], force: &[f64; 3], radius: f64) {
        let Some(a) = self.axis else { return };
        let f = (force[0] * force[0] + force[1] * force[1] + force[2] * force[2]).sqrt();
        self.peak_force = self.peak_force.max(f);
        if self.outcome.is_decided() {
            return;
        }
        let along = v[0] * a[0] + v[1] * a[1] + v[2] * a[2];
        let v0 = *self.strike_speed.get_or_insert(along);
        if along <= ARREST_FRACTION * v0 {
            self.outcome = Outcome::Arrested { time: t };
            return;
        }
        let tip_a = tip[0] * a[0] + tip[1] * a[1] + tip[2] * a[2];
        let free = self.peak_force > 0.0
            && f <= FREE_FORCE_FRACTION * self.peak_force
            && tip_a > self.back_start + radius;
        self.free_run = if free { self.free_run + 1 } else { 0 };
        if self.free_run >= FREE_SAMPLES {
            self.outcome = Outcome::Perforated {
                time: t,
                residual_velocity: (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt(),
            };
        }
    }
}

/// A membrane element's station along its yarn: its centroid's coordinate along the
/// part's material direction 1 (the projected global x turned by `material_angle` about
/// z, for a fabric in the x–y plane), in units of 10⁻⁹ m.
fn station(m: &Model, kind: ElementKind, e: usize) -> i64 {
    let b = &m.elements[&kind];
    let npe = kind.nodes_per_element();
    let angle = m.parts[b.part[e]].props.material_angle.unwrap_or(0.0);
    let (c, s) = (angle.cos(), angle.sin());
    let mut along = 0.0;
    for &n in &b.nodes[npe * e..npe * e + npe] {
        along += c * m.coords[n][0] + s * m.coords[n][1];
    }
    (along / npe as f64 / 1e-9).round() as i64
}
