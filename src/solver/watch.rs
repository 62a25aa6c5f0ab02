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
/// failure [s] (NaN: none yet), the time it was perforated [s] (NaN: not yet; see
/// [`Watch::perforated_at`]).
pub type LayerValues = [f64; 10];

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
    /// moving at `residual_velocity` [m/s]. A pack on a backing (clay): every ply
    /// perforated ([`PATH_FRACTION`]) at `time`, the projectile entering the backing at
    /// `residual_velocity`.
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

/// A cross-section of a yarn: its yarn, how many of its elements are live, and whether
/// it lies near the shot (an element's centroid within [`CUT_REACH`] radii of the shot's
/// line).
#[derive(Debug, Clone, Copy)]
struct Section {
    yarn: u32,
    live: u32,
    near: bool,
}

/// A ply is perforated once the projectile's tip has passed where the ply's back face
/// started and the nose has a hole through it, which is either of:
/// - **cut**: every yarn of the ply that crosses the projectile's path (its reference
///   line within [`PATH_FRACTION`] of the projectile's radius R of the shot's line) has
///   failed at a cross-section near the shot (within [`CUT_REACH`] R of the line);
/// - **cleared**: none of the ply's nodes still joined to the ply beyond [`CUT_REACH`] R
///   through live elements ([`super::plies::Around`]: a fragment cut free riding on the
///   nose is not the ply) lies on the nose's front cap: within [`PATH_FRACTION`] R of
///   the line and less than R behind the tip (the yarns there broken and slid off, or
///   pushed aside: windowing).
///
/// Either alone misses holes: cut ends whipping ahead of the nose can sit on the cap
/// (the outcome's note on [`FREE_SAMPLES`]), and a yarn on the path pushed aside intact
/// is never cut. An intact ply in front of the nose satisfies neither: its yarns are
/// whole and its nodes lie on the cap.
pub const PATH_FRACTION: f64 = 0.5;

/// How far from the shot's line, in projectile radii, a yarn's failure counts as a cut
/// of the ply's path ([`PATH_FRACTION`]): a yarn loaded by the nose fails where it
/// leaves the nose's contact, within a radius of the line or a little beyond.
pub const CUT_REACH: f64 = 2.0;

/// Per layer, what its perforation is judged by ([`PATH_FRACTION`]).
#[derive(Debug, Clone, Default)]
struct Plies {
    /// Per yarn: it crosses the projectile's path, and it has been cut near the shot.
    on_path: Vec<bool>,
    cut: Vec<bool>,
    /// Per layer (index 0 unused): yarns on the path, those of them cut, where its back
    /// face started along the strike, and when it was perforated (NaN: not yet).
    path_yarns: Vec<u32>,
    cut_yarns: Vec<u32>,
    back: Vec<f64>,
    at: Vec<f64>,
    /// Per layer: some node of it starts on the path (within [`PATH_FRACTION`] R of the
    /// line); a layer with none (a mesh coarser than the nose) cannot be judged cleared.
    path_nodes: Vec<bool>,
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
    /// its most advanced node as the tip, its mass-weighted velocity, the contact forces
    /// on its nodes (their mean over the last samples, [`Watch::bullet_force`]); empty
    /// with a rigid projectile or none.
    pub bullet: Vec<usize>,
    /// The bullet's radius about its axis (`striker::axis_point`) [m].
    pub bullet_radius: f64,
    /// The bullet's last samples (up to [`FREE_SAMPLES`] + 1, oldest first): their times
    /// and velocities (momentum over mass), from which [`Watch::bullet_force`] takes the
    /// mean force over the window.
    bullet_last: std::collections::VecDeque<(f64, [f64; 3])>,
    plies: Plies,
    /// The shot's line (a point on it, its unit direction) and the projectile's radius.
    shot: Option<([f64; 3], [f64; 3], f64)>,
    /// The ply's elements around the shot ([`Watch::cap_layers`]).
    around: super::plies::Around,
    /// A pack on a backing (the clay's `clay_profile`): the bullet that has perforated
    /// every ply is in the backing, whose contact force never lets it go free; the
    /// outcome is then decided by the plies ([`Outcome::Perforated`] once every ply is).
    backed: bool,
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
        // The shot's line (a point on it, its direction) and the projectile's radius.
        let shot = match (m.projectiles.first(), w.axis) {
            (Some(p), Some(a)) => Some((p.tip, a, p.radius)),
            (None, Some(a)) if !w.bullet.is_empty() => {
                let xs: Vec<[f64; 3]> = w.bullet.iter().map(|&i| m.coords[i]).collect();
                Some((
                    crate::model::striker::axis_point(&xs, a),
                    a,
                    w.bullet_radius,
                ))
            }
            _ => None,
        };
        w.shot = shot;
        let lateral = |x: &[f64; 3]| -> f64 {
            shot.map_or(f64::INFINITY, |(p, a, _)| lateral_distance(x, &p, &a))
        };
        let radius = shot.map_or(0.0, |s| s.2);
        if shot.is_some() {
            w.around = super::plies::Around::new(m, lateral, CUT_REACH * radius);
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
                            w.plies.on_path.push(false);
                            w.plies.cut.push(false);
                            w.yarns.len() as u32 - 1
                        });
                        let xs = &b.nodes[npe * e..npe * e + npe];
                        if xs
                            .iter()
                            .any(|&n| lateral(&m.coords[n]) <= PATH_FRACTION * radius)
                        {
                            w.plies.on_path[yi as usize] = true;
                        }
                        let centroid: [f64; 3] = std::array::from_fn(|d| {
                            xs.iter().map(|&n| m.coords[n][d]).sum::<f64>() / npe as f64
                        });
                        let near = lateral(&centroid) <= CUT_REACH * radius;
                        // A truss is a section of its own; a membrane's section is its
                        // station along the yarn (its material direction 1).
                        let station = if kind == ElementKind::Truss {
                            e as i64
                        } else {
                            station(m, kind, e)
                        };
                        let si = *section_index.entry((yi, station)).or_insert_with(|| {
                            w.sections.push(Section {
                                yarn: yi,
                                live: 0,
                                near: false,
                            });
                            w.sections.len() as u32 - 1
                        });
                        w.sections[si as usize].live += 1;
                        w.sections[si as usize].near |= near;
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
        w.count_paths(m);
        w.backed = m.node_sets.contains_key(super::crater::PROFILE_SET);
        w
    }

    /// Per layer: its yarns on the path, where its back face starts along the strike and
    /// whether a node of it starts on the path ([`PATH_FRACTION`]).
    fn count_paths(&mut self, m: &Model) {
        let n = self.n_layers + 1;
        let pl = &mut self.plies;
        (pl.path_yarns, pl.cut_yarns) = (vec![0; n], vec![0; n]);
        (pl.back, pl.at) = (vec![f64::NEG_INFINITY; n], vec![f64::NAN; n]);
        for (y, &(layer, _)) in self.yarns.iter().enumerate() {
            if pl.on_path[y] {
                pl.path_yarns[layer as usize] += 1;
            }
        }
        pl.path_nodes = vec![false; n];
        let Some(a) = self.axis else { return };
        for (i, x) in m.coords.iter().enumerate() {
            let l = self.node_layer[i] as usize;
            if l > 0 {
                pl.back[l] = pl.back[l].max(x[0] * a[0] + x[1] * a[1] + x[2] * a[2]);
                if let Some((p, a, r)) = self.shot {
                    pl.path_nodes[l] |= lateral_distance(x, &p, &a) <= PATH_FRACTION * r;
                }
            }
        }
    }

    /// When layer `l` (1 = the strike face) was perforated ([`PATH_FRACTION`]): NaN
    /// while it is not, and for a layer without yarns on the projectile's path.
    pub fn perforated_at(&self, l: usize) -> f64 {
        self.plies.at[l]
    }

    /// The layers perforated so far.
    pub fn plies_perforated(&self) -> usize {
        self.plies.at.iter().filter(|t| !t.is_nan()).count()
    }

    /// Per layer (1 first): whether a node of it at `x`, joined to the ply beyond the
    /// reach, lies on the nose's front cap ([`PATH_FRACTION`]), the projectile's tip at
    /// `tip_a` along the strike; all false without a shot.
    pub fn cap_layers(&self, x: &[[f64; 3]], tip_a: f64) -> Vec<bool> {
        let mut on = vec![false; self.n_layers];
        let Some((p, a, r)) = self.shot else {
            return on;
        };
        self.around.for_joined(|i| {
            let l = self.node_layer[i] as usize;
            if l > 0
                && !on[l - 1]
                && x[i][0] * a[0] + x[i][1] * a[1] + x[i][2] * a[2] > tip_a - r
                && lateral_distance(&x[i], &p, &a) <= PATH_FRACTION * r
            {
                on[l - 1] = true;
            }
        });
        on
    }

    /// Layers that the tip (`tip_a`, along the strike) has passed, with every yarn on the
    /// path cut or nothing left on the nose's cap (`on_cap[l - 1]`: an attached node of
    /// layer l on it), are perforated at t ([`PATH_FRACTION`]).
    fn follow_plies(&mut self, t: f64, tip_a: f64, on_cap: &[bool]) {
        let pl = &mut self.plies;
        for l in 1..pl.at.len() {
            let cut = pl.path_yarns[l] > 0 && pl.cut_yarns[l] == pl.path_yarns[l];
            let cleared = pl.path_nodes[l] && !on_cap.get(l - 1).copied().unwrap_or(true);
            if pl.at[l].is_nan() && tip_a > pl.back[l] && (cut || cleared) {
                pl.at[l] = t;
            }
        }
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
        self.around.on_erosion(kind, e);
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
                let yi = s.yarn as usize;
                if s.near && self.plies.on_path[yi] && !self.plies.cut[yi] {
                    self.plies.cut[yi] = true;
                    self.plies.cut_yarns[l] += 1;
                }
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

    /// The force on a deformable bullet as the free test reads it: its mass times its
    /// velocity's change over the last [`FREE_SAMPLES`] sample intervals (fewer at the
    /// start) over their time, the contact forces' mean over that window (its internal
    /// forces sum to zero, so its momentum changes by their impulse alone); `None` at
    /// the first sample.
    ///
    /// Why not the contact force at the sample, as for a rigid nose: fragments ride on
    /// the bullet's faces and ring against them, so that force never falls to
    /// [`FREE_FORCE_FRACTION`] of its peak (measured: 24 plies in air, every ply
    /// perforated by 60 µs, the bullet's speed steady at 329.6 m/s, undecided at the
    /// 400 µs end). Fragments that merely ride along exert no mean force; over one
    /// interval their exchanges still swing its velocity by ~0.1 m/s a 10 µs sample,
    /// near 1 % of the peak, hence the window.
    pub fn bullet_force(&mut self, t: f64, v: &[f64; 3], mass: f64) -> Option<[f64; 3]> {
        let q = &mut self.bullet_last;
        q.push_back((t, *v));
        if q.len() > FREE_SAMPLES as usize + 1 {
            q.pop_front();
        }
        let (t0, v0) = *q.front()?;
        let dt = t - t0;
        (dt > 0.0).then(|| std::array::from_fn(|d| mass * (v[d] - v0[d]) / dt))
    }

    /// Judges the outcome at time t from the first projectile's tip, velocity, contact
    /// force and radius (see [`Outcome`]), and the plies perforated so far (`on_cap`:
    /// per layer, whether an attached node of it lies on the nose's cap, [`Watch::on_cap`]).
    #[allow(clippy::too_many_arguments)]
    pub fn judge(
        &mut self,
        t: f64,
        tip: &[f64; 3],
        v: &[f64; 3],
        force: &[f64; 3],
        radius: f64,
        on_cap: &[bool],
    ) {
        let Some(a) = self.axis else { return };
        let f = (force[0] * force[0] + force[1] * force[1] + force[2] * force[2]).sqrt();
        self.peak_force = self.peak_force.max(f);
        let tip_a = tip[0] * a[0] + tip[1] * a[1] + tip[2] * a[2];
        self.follow_plies(t, tip_a, on_cap);
        if self.outcome.is_decided() {
            return;
        }
        let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let backed = self.backed && self.n_layers > 0;
        if backed && self.plies_perforated() == self.n_layers {
            self.outcome = Outcome::Perforated {
                time: t,
                residual_velocity: speed,
            };
            return;
        }
        let along = v[0] * a[0] + v[1] * a[1] + v[2] * a[2];
        let v0 = *self.strike_speed.get_or_insert(along);
        if along <= ARREST_FRACTION * v0 {
            self.outcome = Outcome::Arrested { time: t };
            return;
        }
        // On a backing only the plies say perforated: a nose nearly stopped in the pack
        // can feel almost no force and be past the fabric's starting back face, which
        // the free test takes for a perforation (measured: 24 plies at 150 m/s, 'free'
        // at 450 µs at 4.6 m/s, no ply perforated).
        let free = !backed
            && self.peak_force > 0.0
            && f <= FREE_FORCE_FRACTION * self.peak_force
            && tip_a > self.back_start + radius;
        self.free_run = if free { self.free_run + 1 } else { 0 };
        if self.free_run >= FREE_SAMPLES {
            self.outcome = Outcome::Perforated {
                time: t,
                residual_velocity: speed,
            };
        }
    }
}

/// The distance of `x` from the line through `p` along the unit `a`.
fn lateral_distance(x: &[f64; 3], p: &[f64; 3], a: &[f64; 3]) -> f64 {
    let d = [x[0] - p[0], x[1] - p[1], x[2] - p[2]];
    let s = d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
    let r = [d[0] - s * a[0], d[1] - s * a[1], d[2] - s * a[2]];
    (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt()
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
