//! General contact: slave nodes against master surfaces — membrane faces offset by
//! ± half their nodal thickness (LS-DYNA's shell contact thickness), truss and beam
//! segments with a radius, or a solid's boundary faces, one-sided ([`solid`]: their boxes
//! are those of a membrane face as thick as the depth the kernel looks behind them, so
//! every claim below holds for them) — with penalty forces and Coulomb friction.
//!
//! Glossary: s a slave node, x_s its position, t_s its contact thickness; F a master face
//! (2 nodes: a segment, 3: a triangle, 4: a quad), q = Σ_a w_a x_a the closest point of
//! its mid-surface to x_s, d = |x_s − q|, n = (x_s − q)/d the normal from the face to the
//! node, t_F = Σ_a w_a t_a the face thickness at q; g = (t_s + t_F)/2 − d − g₀ the
//! penetration (g₀: the depth at which a node started inside, see below); m* = min(m_s,
//! m_F) with m_F the faces' nodal masses interpolated at the feet (λ-weighted, below);
//! κ_c = 0.1 × penalty_scale.
//!
//! Phases, after `docs/theory.md`, "Contact", and LS-DYNA's contact:
//! - **thickness box** of a face: the bounding box of the balls of radius t_a/2 about its
//!   nodes, lo = min_a (x_a − t_a/2), hi = max_a (x_a + t_a/2) per component. It holds
//!   every ball of radius t_F/2 about a point q = Σ w_a x_a of the face (w_a ≥ 0, Σ w_a =
//!   1, t_F = Σ w_a t_a), so a slave farther than t_s/2 from it cannot penetrate the face.
//! - **broad phase** ([`grid`]): the faces' thickness boxes, inflated by
//!   r = t_s,max/2 + skin + η (η a 10⁻⁹ round-off allowance), in a dense uniform grid
//!   whose cell is half the largest inflated box (each face in ≤ 27 cells); each slave's
//!   candidates are the faces of its cell whose box contains it (never a face it belongs
//!   to), in face order.
//!   Rebuilt only when the displacements since the last build could have brought a pair
//!   within reach that is not a candidate: some node has moved more than 2 skins, or the
//!   displacements of the nodes near one another differ by more than the skin
//!   ([`super::staleness`]); a region that moves as a whole (the fabric under the nose)
//!   keeps its lists. A pair that can touch is never missed and the cost is amortised
//!   (Teschner et al., *Optimized spatial hashing for collision detection of deformable
//!   objects*, VMV 2003).
//! - **envelope bounds**: along a unit direction m, every such ball lies below
//!   h = max_a (m·x_a + t_a/2) (its support m·q + t_F/2 = Σ w_a (m·x_a + t_a/2)). Each
//!   face keeps two directions m± = (±n̂ − ½∇t_F)/|…|, the outward normals of the two
//!   sides of a flat face's envelope with a linear thickness, taken at each broad phase
//!   (any unit direction is sound), and its bounds h± every step: a lenticular band's
//!   quad thins to 0 at the band's edge, where the thickness box stays as high as the
//!   thick nodes.
//! - **narrow phase** (pure kernels [`closest_on_face`], [`pair_force`]): the faces'
//!   thickness boxes and envelope bounds once per step; a slave whose margin at the
//!   build (its distance beyond reach from all its candidates) exceeds how far the nodes
//!   around it have since moved apart is skipped, as no candidate can pass (`Side::margin`:
//!   the same results); per other slave, the candidates whose
//!   thickness box is within t_s/2 + η of it and that are not beyond either envelope
//!   bound by t_s/2 + η (branch-free passes), then the closest point on each of those;
//!   of the faces it penetrates, the one of largest penetration sets g, and all of
//!   them share the rest:
//!   the normal is their penetration-weighted mean, and the reaction −f goes to each
//!   penetrated face F in the share λ_F = g_F/Σg (to its nodes by the foot's weights), the
//!   foot's mass and velocity being the λ-weighted ones, so that a node over a vertex or
//!   in a crease, whose faces tie, pushes them all alike and nothing jumps as faces come
//!   and go; normal force
//!   f_n = k g with k = κ_c m*/Δt² (LS-DYNA's SOFT = 1 idea: the contact spring alone has
//!   ω Δt ≤ √(2κ_c), so it does not cut the step; the step is still reduced by
//!   √(s² − κ_c/2)/s as a guard, see `Solver::set_time_step`); one geometry evaluation gives the
//!   force and the stored energy ½ k g².
//! - **friction**: Coulomb with an elastic stick spring of the normal stiffness k
//!   (Wriggers, *Computational Contact Mechanics*, §5.2, return mapping): trial
//!   f_t* = P_t f_t^{old} − k Δu_t with Δu_t the tangential slip increment of the slave
//!   over the face over the last step; slip when |f_t*| > μ f_n, then f_t = μ f_n f_t*/|f_t*|
//!   and the dissipated work μ f_n (|f_t*| − μ f_n)/k; μ = μ_d + (μ_s − μ_d) e^{−d_c|v_t|}.
//!   The stored stick energy |f_t|²/(2k) is part of the contact energy; what is stored
//!   when a pair opens is dissipated.
//! - **initial penetration**: a slave inside at t = 0 (g > 0 with g₀ = 0) is recorded with
//!   its depth g₀ (the force acts only beyond it, and g₀ shrinks as the node leaves), or
//!   stops the run when the definition says `error`.
//! - **erosion** (docs/theory.md, "Failure, perforation and the ballistic limit"): the
//!   faces of a failed element leave the surface at the force evaluation of the step it
//!   fails; the pairs on them held ½ k g² and would have done a half step of work, which
//!   a second narrow phase with the faces still in measures and the ledger books as
//!   eroded energy (as `failure::taken_energy` does for the element itself). From the
//!   first failure on, each face a slave penetrates is a pair of its own, k_F g_F
//!   (n_F − ½∇t_F) on the slave and its reaction on the face, the exact gradient of the
//!   Σ ½ k_F g_F² booked; friction acts along the resultant (`Side::per_face`). The
//!   shared normal and reaction above are not a gradient, and broken yarn ends that
//!   slide through the crossings at hundreds of m/s gained energy by them.
//! - **determinism**: slaves are processed in parallel fixed chunks, each writing only its
//!   own result slot and its chunk's list of reaction shares; the results are gathered
//!   onto the nodes in chunk order (the slaves, then their reactions), so 1 and N threads
//!   give bit-identical forces.
//! - **oracle** (a check for tests, off unless the caller sets
//!   [`SurfaceContact::oracle`]): at every force evaluation each side is built again
//!   alone, in a grid of its own at its own reach, and its narrow phase run without
//!   skipping a slave; every result must be the same bits as the step's, which shares the
//!   master surfaces' boxes and grids among sides, computes only the boxes it needs,
//!   skips far slaves and runs every side in one parallel loop.
//!
//! Where things live: [`kernels`] (the pure kernels: thickness box and envelope bounds,
//! distance tests, the pair force with friction; the closest points are
//! [`super::closest`]'s), [`solid`] (a hexahedron part's boundary faces and nodes, and
//! its faces' one-sided kernel), [`side`] (a definition's side and its per-step data), [`grid`]
//! (the broad phase), [`narrow`] (the narrow phase), and this module: the driver
//! ([`SurfaceContact`]: setup, the step's phases in order, the report), `gather` (the
//! forces onto the nodes in a canonical order, in parallel) and `oracle`.

mod boxes;
mod gather;
pub mod grid;
pub mod kernels;
pub mod narrow;
mod oracle;
pub mod side;
pub mod solid;

pub use super::closest::{closest_on_face, closest_on_quad};
use super::projectile::PENALTY_FACTOR;
use super::staleness::Staleness;
use crate::error::{Result, WeftError};
use crate::model::contacts::{InitialPenetration, Slave};
use crate::model::{ElementKind, Model};
use boxes::MasterBoxes;
pub use kernels::{pair_force, thickness_gradient, Friction, SlaveState, MAX_THICKNESS_GRADIENT};
use side::{part_nodes, ChunkSums};
pub use side::{PairOut, Reaction, Side};

/// A recorded initial penetration.
#[derive(Debug, Clone)]
pub struct InitialPen {
    pub contact_id: i64,
    pub node: usize,
    pub element: i64,
    pub depth: f64,
}

/// What a run's contact did.
#[derive(Debug, Clone, Default)]
pub struct ContactReport {
    pub definitions: usize,
    /// Slave nodes and master faces over all sides (a two-way definition counts twice).
    pub slaves: usize,
    pub faces: usize,
    /// Sides (a two-way definition has two), and their distinct master surfaces: the
    /// sides of a surface share its thickness boxes and broad-phase grid.
    pub sides: usize,
    pub surfaces: usize,
    /// Broad-phase builds.
    pub builds: u64,
    /// Slaves in contact at the end.
    pub active: usize,
    pub initial_penetrations: usize,
    /// Deepest initial penetration: (contact id, node id, element id, depth [m]).
    pub deepest: Option<(i64, i64, i64, f64)>,
    /// Friction work dissipated [J].
    pub friction_work: f64,
    /// Broad-phase skin [m].
    pub skin: f64,
    /// Wall time of the broad phase (with the per-step face boxes and the staleness
    /// check) and of the narrow phase with the scatter [s].
    pub build_seconds: f64,
    pub narrow_seconds: f64,
    /// The same wall time by phase [s]: the faces' thickness boxes (every step), the
    /// staleness test (every step), the broad-phase builds, the narrow phase proper, and
    /// the scatter of the forces onto the nodes.
    pub phases: ContactPhases,
    /// Slave-steps (slaves × force evaluations), and over them: candidate faces whose
    /// box was tested, faces past the box and envelope filters (whose closest point was
    /// computed), and faces found penetrated.
    pub slave_steps: u64,
    pub tested: u64,
    pub evaluated: u64,
    pub penetrated: u64,
    /// Slave-steps skipped whole: the slave was farther from every candidate at the
    /// build than its neighbourhood's nodes have since moved apart (see `Side::margin`).
    pub skipped: u64,
    /// What the stale tests that triggered the builds (after the setup's) found.
    pub triggers: TriggerStats,
    /// Side-steps whose thickness boxes were computed only for the faces the narrow phase
    /// could read (see [`LAZY_BOXES_SKIPPED`]).
    pub lazy_boxes: u64,
}

/// The stale tests that triggered a build (after the setup's).
#[derive(Debug, Clone, Copy, Default)]
pub struct TriggerStats {
    /// Tests that found the lists stale, and of them those where a node had gone past
    /// the absolute bound U (the others: a neighbourhood's spread past the skin).
    pub triggers: u64,
    pub far: u64,
}

/// Wall time of the contact's phases [s] (see [`ContactReport::phases`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct ContactPhases {
    pub boxes: f64,
    pub staleness: f64,
    pub builds: f64,
    pub narrow: f64,
    pub scatter: f64,
}

/// The broad phase's skin as a fraction of the mean face size of the finest surface: a
/// larger skin means fewer builds but more candidates per slave. Measured on the 60 × 60
/// woven quarter to 60 µs (2 threads, alternately): at ¼, 510 builds and 47.6, 48.6 s
/// (broad phase 11.9, 12.4 s; narrow 26.2, 26.6 s); at ½, 274 builds and 44.1, 42.6 s
/// (broad 8.2, 7.9 s; narrow 26.6, 25.7 s); at ¾, 181 builds and 49.1 s (narrow 30.8 s:
/// the candidates' box tests outgrow what the builds save).
const SKIN_PER_FACE: f64 = 0.5;

/// The fraction of a side's slaves that its last narrow phase skipped from which the next
/// step computes only the thickness boxes its narrow phase can read (`boxes::stamp_sides`;
/// on a master surface shared by several sides, when every one of them skipped so many).
/// Measured on the 60 × 60 quarter to 60 µs, 2 threads, alternately with every box
/// computed, each side with boxes of its own then: the band patch (43 % of its
/// slave-steps skipped) spent 1.8–1.9 s in the boxes against 1.4–1.7 s; the four-layer
/// chain patch (91 %, its sides between layers nearly all) 30.8 and 33.1 s against 37.2
/// and 38.6 s in all.
const LAZY_BOXES_SKIPPED: f64 = 0.75;

/// The largest total penalty factor that can act on one node: Σ κ_c over the contact
/// roles it has (slave of a definition, node of a master surface, both in two-way
/// contact), plus 2 × 0.1 when the model has projectiles (their node and face contact).
/// The stable-step guard of `Solver::set_time_step` uses it.
pub fn guard_kappa(m: &Model) -> f64 {
    if m.contacts.is_empty() {
        return 0.0;
    }
    let mut k = vec![0.0; m.num_nodes()];
    for d in &m.contacts {
        let kappa = PENALTY_FACTOR * d.penalty_scale;
        let slaves: Vec<u32> = match &d.slave {
            Slave::Part(p) => part_nodes(m, *p),
            Slave::Set(s) => m
                .node_sets
                .get(s)
                .map(|v| v.iter().map(|&n| n as u32).collect())
                .unwrap_or_default(),
        };
        let roles = if d.two_way { 2.0 } else { 1.0 };
        for n in slaves {
            k[n as usize] += roles * kappa;
        }
        for n in part_nodes(m, d.master) {
            k[n as usize] += roles * kappa;
        }
    }
    let proj = if m.projectiles.is_empty() {
        0.0
    } else {
        2.0 * PENALTY_FACTOR
    };
    k.iter().cloned().fold(0.0, f64::max) + proj
}

/// The deepest penetration of a force evaluation ([`SurfaceContact::deepest`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Deepest {
    /// The penetration over the contact distance of the thickest slave and face of its
    /// side, (t_s,max + t_F,max)/2.
    pub ratio: f64,
    /// The penetration g (beyond a tracked initial one) [m].
    pub depth: f64,
    /// The contact definition's id.
    pub contact_id: i64,
    /// The slave node (index).
    pub node: usize,
    /// The id of the face's element.
    pub element: i64,
}

/// Every contact definition of a model, and the broad phase they share.
#[derive(Debug, Clone, Default)]
pub struct SurfaceContact {
    pub sides: Vec<Side>,
    /// Faces joined a surface (an erosion uncovered them): the next broad phase builds.
    force_build: bool,
    /// The distinct master surfaces of the sides: their faces' boxes and envelope
    /// directions, computed once per step for all the sides of each ([`MasterBoxes`]).
    masters: Vec<MasterBoxes>,
    /// Nodes that take part (slaves and face nodes), sorted.
    nodes: Vec<u32>,
    /// Their positions at the last broad phase, and the test of when the candidate lists
    /// go stale.
    motion: Staleness,
    /// The oracle (module docs; off by default, the same results either way): check
    /// every force evaluation against each side built alone, afresh, skipping nothing,
    /// and panic on a difference. Set by the caller (tests) once the contact is made,
    /// before the first force evaluation (`tests/contact_search.rs`); it costs a
    /// side's build and narrow phase per side and step.
    pub oracle: bool,
    /// Force evaluations so far (the oracle names the step of a difference).
    evaluations: u64,
    /// Side-steps with only the needed boxes computed.
    lazy_boxes: u64,
    /// Whether the narrow phase skips the slaves that no candidate can reach yet (see
    /// `Side::margin`; on by default, the same results either way).
    pub skip_far: bool,
    /// Skin of the broad phase [m].
    pub skin: f64,
    /// Largest κ_c of the definitions (stable-step guard).
    pub kappa_max: f64,
    /// Broad-phase builds so far, and the wall time of the builds and of the narrow
    /// phase with the scatter.
    pub builds: u64,
    pub build_time: std::time::Duration,
    pub narrow_time: std::time::Duration,
    /// The same by phase; slave-steps so far, and the chunks' counts summed over them
    /// (see [`ContactReport`]).
    phases: ContactPhases,
    slave_steps: u64,
    counts: ChunkSums,
    /// What the stale tests that triggered a build found (see [`TriggerStats`]).
    triggers: TriggerStats,
    /// Friction work dissipated so far [J].
    pub dissipated: f64,
    /// When asked ([`SurfaceContact::track_friction`]): the friction work so far by slave
    /// node [J] (a pair's work goes to its slave), for the energy absorbed per layer.
    pub node_friction: Option<Vec<f64>>,
    /// Stored energy at the last force evaluation [J].
    pub stored: f64,
    /// Energy the faces of failed elements took with them when they left [J]: what the
    /// pairs on them held, and the half step of work their forces would have done
    /// ([`Side::pair_energy`]); the ledger books it with the elements' eroded energy.
    pub eroded: f64,
    pub initial: Vec<InitialPen>,
}

impl SurfaceContact {
    /// The definitions of `m`, sides built with the nodal masses `mass`.
    pub fn new(m: &Model, mass: &[f64]) -> SurfaceContact {
        let mut sides = Vec::new();
        for (row, d) in m.contacts.iter().enumerate() {
            sides.push(Side::new(m, row, &d.slave, d.master, mass));
            if d.two_way {
                if let Slave::Part(p) = d.slave {
                    sides.push(Side::new(m, row, &Slave::Part(d.master), p, mass));
                }
            }
        }
        let mut nodes: Vec<u32> = sides
            .iter()
            .flat_map(|s| {
                s.slaves
                    .iter()
                    .copied()
                    .chain(s.faces.iter().flat_map(|f| f[..s.nf].to_vec()))
            })
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        // Skin: [`SKIN_PER_FACE`] of the mean face size of the finest surface.
        let skin = sides
            .iter()
            .map(|s| s.mean_face_size(&m.coords))
            .filter(|&h| h > 0.0)
            .fold(f64::INFINITY, f64::min);
        let skin = if skin.is_finite() {
            SKIN_PER_FACE * skin
        } else {
            0.0
        };
        let kappa_max = sides.iter().map(|s| s.kappa).fold(0.0, f64::max);
        let masters = MasterBoxes::group(&mut sides);
        SurfaceContact {
            sides,
            masters,
            nodes,
            motion: Staleness::new(skin),
            oracle: false,
            skip_far: true,
            skin,
            kappa_max,
            builds: 0,
            dissipated: 0.0,
            stored: 0.0,
            eroded: 0.0,
            force_build: false,
            initial: vec![],
            ..Default::default()
        }
    }

    pub fn is_empty(&self) -> bool {
        self.sides.is_empty()
    }

    /// Keep the friction work by slave node from now on (`node_friction`), for `nodes`
    /// nodes.
    pub fn track_friction(&mut self, nodes: usize) {
        self.node_friction = Some(vec![0.0; nodes]);
    }

    /// Element `e` of kind `kind` has failed: its faces (or segments) leave every side
    /// whose master surface they belong to, at the next force evaluation (which books
    /// what they held into `eroded`); from now on each face a slave penetrates is a
    /// pair of its own (see [`Side::per_face`]).
    pub fn erode(&mut self, kind: ElementKind, e: usize) {
        for s in self.sides.iter_mut() {
            s.per_face = true;
            if s.master_kind == kind {
                s.erode(e);
            }
        }
    }

    /// The faces pending erosion at x^n leave their sides, and what they held is booked
    /// into `eroded`: per side with such faces, a narrow phase with them (its slaves'
    /// states restored after it) against the step's own without them
    /// ([`Side::pair_energy`]; the other slaves give the same terms in both). Returns
    /// the first phase's energy per side (NaN where there was nothing pending), for
    /// [`SurfaceContact::book_erosion`] once the step's narrow phase is done.
    fn probe_erosion(
        &mut self,
        x: &[[f64; 3]],
        v: &[[f64; 3]],
        dt: f64,
        dt_prev: f64,
        spread: Option<&[f64]>,
    ) -> Vec<f64> {
        let mut with = vec![f64::NAN; self.sides.len()];
        for (k, s) in self.sides.iter_mut().enumerate() {
            if s.pending.is_empty() {
                continue;
            }
            let kept = (s.state.clone(), s.held.clone(), s.out.clone());
            s.narrow(&self.masters[s.surface], x, v, dt, dt_prev, false, spread);
            with[k] = s.pair_energy(v, dt_prev);
            (s.state, s.held, s.out) = kept;
        }
        // (Only once every side has been probed: the sides of a surface share its boxes.)
        for s in &mut self.sides {
            s.drop_pending(&mut self.masters[s.surface]);
        }
        with
    }

    /// Books the energy the eroded faces took: per side probed, its energy with them
    /// (`with`) less the step's without them.
    fn book_erosion(&mut self, with: &[f64], v: &[[f64; 3]], dt_prev: f64) {
        for (s, w) in self.sides.iter().zip(with) {
            if !w.is_nan() {
                self.eroded += w - s.pair_energy(v, dt_prev);
            }
        }
    }

    /// Normal viscous damping ζ (fraction of critical) on every pair of every side.
    pub fn set_normal_damping(&mut self, zeta: f64) {
        for s in &mut self.sides {
            s.damping = zeta;
        }
    }

    /// The deepest penetration at the last force evaluation, relative to the contact
    /// distance of the thickest slave and face of its side, (t_s,max + t_F,max)/2 (the
    /// centre-line distance of two crossing yarns; a thin band edge's own distance would
    /// make a sub-micrometre overlap look deep).
    pub fn deepest(&self) -> Option<Deepest> {
        let mut best: Option<Deepest> = None;
        for s in &self.sides {
            for (si, o) in s.out.iter().enumerate() {
                if o.face == u32::MAX || s.reach <= 0.0 {
                    continue;
                }
                let r = o.g / s.reach;
                if best.as_ref().is_none_or(|b| r > b.ratio) {
                    best = Some(Deepest {
                        ratio: r,
                        depth: o.g,
                        contact_id: s.contact_id,
                        node: s.slaves[si] as usize,
                        element: s.face_id[o.face as usize],
                    });
                }
            }
        }
        best
    }

    /// Broad phase for every side at `x` (whose thickness boxes are up to date): per
    /// master surface its envelope directions and one grid, inflated by the largest
    /// reach of its sides, in which each side lists its candidates with its own reach
    /// (the lists a grid of its own would give, see `grid::Lister`).
    fn rebuild(&mut self, x: &[[f64; 3]]) {
        let skin = self.skin;
        for mb in &mut self.masters {
            let sides = &mut self.sides;
            mb.set_directions_of(&sides[mb.sides[0]], x);
            let r = mb
                .sides
                .iter()
                .map(|&k| sides[k].build_reach(skin))
                .fold(0.0, f64::max);
            let sg = sides[mb.sides[0]].surface_grid(mb, r);
            for &k in &mb.sides {
                sides[k].build(x, skin, mb, &sg);
            }
        }
        // ρ + W of the staleness test: the farthest a slave can be from a thickness box
        // that the narrow phase evaluates, and the widest box.
        let widest: Vec<f64> = self.masters.iter().map(MasterBoxes::widest).collect();
        let rho_w = self
            .sides
            .iter()
            .map(|s| 0.5 * s.slave_t_max + s.box_margin + widest[s.surface])
            .fold(0.0, f64::max);
        self.motion.reset(&self.nodes, x, rho_w);
        let motion = &self.motion;
        for s in &mut self.sides {
            s.set_cells(x, |p| motion.cell(p));
        }
        self.builds += 1;
    }

    /// Every master surface's thickness boxes at `x`.
    fn update_all_boxes(&mut self, x: &[[f64; 3]]) {
        let sides = &self.sides;
        boxes::update_surfaces(
            self.masters.iter_mut().map(|mb| {
                let sd = &sides[mb.sides[0]];
                (mb, sd, None)
            }),
            x,
        );
    }

    /// The thickness boxes at `x` after the staleness test (`stale`: a build follows):
    /// every box at a build, and otherwise, on a surface all of whose sides' last narrow
    /// phases skipped most of their slaves, only the boxes of the candidates that this
    /// step's narrow phases will test (each side stamps its own, [`stamp_sides`](boxes::stamp_sides)).
    fn update_needed_boxes(&mut self, x: &[[f64; 3]], stale: bool) {
        // (The stamps wrap after 2³² evaluations: a face stamped then and not since would
        // be taken as needed, which costs a box, never a missed one.)
        let epoch = (self.evaluations as u32).max(1);
        // (Only where the last narrow phases skipped most slaves: marking the needed
        // faces costs more than it saves where half of them search.)
        let sides = &self.sides;
        let lazy: Vec<bool> = self
            .masters
            .iter()
            .map(|mb| {
                !stale
                    && mb.sides.iter().all(|&k| {
                        let s = &sides[k];
                        let skipped: u64 = s.chunk_sums.iter().map(|c| c.skipped).sum();
                        skipped as f64 >= LAZY_BOXES_SKIPPED * s.slaves.len() as f64
                    })
            })
            .collect();
        boxes::stamp_sides(
            self.masters
                .iter()
                .zip(&lazy)
                .filter(|(_, &l)| l)
                .flat_map(|(mb, _)| mb.sides.iter().map(|&k| (&sides[k], &mb.stamp))),
            self.motion.spread(),
            epoch,
        );
        for (mb, _) in self.masters.iter().zip(&lazy).filter(|(_, &l)| l) {
            self.lazy_boxes += mb.sides.len() as u64;
        }
        boxes::update_surfaces(
            self.masters.iter_mut().zip(&lazy).map(|(mb, &l)| {
                let sd = &sides[mb.sides[0]];
                (mb, sd, l.then_some(epoch))
            }),
            x,
        );
    }

    /// Whether the candidate lists may miss a pair at `x` (see [`Staleness`]).
    fn stale(&mut self, x: &[[f64; 3]]) -> bool {
        self.motion.stale(x)
    }

    /// Counts the stale test that has just triggered a build.
    fn record_trigger(&mut self) {
        let t = &mut self.triggers;
        t.triggers += 1;
        t.far += u64::from(self.motion.last_far());
    }

    /// Setup at the start positions `x` (the reference plus any initial displacement):
    /// the broad phase, and the nodes that start inside a surface (recorded, or an error
    /// when their definition says so).
    pub fn start(&mut self, m: &Model, x: &[[f64; 3]]) -> Result<()> {
        self.update_all_boxes(x);
        self.rebuild(x);
        let zero = vec![[0.0; 3]; m.num_nodes()];
        for s in &mut self.sides {
            s.narrow(&self.masters[s.surface], x, &zero, 1.0, 0.0, true, None);
            for (si, o) in s.out.iter().enumerate() {
                if o.face == u32::MAX {
                    continue;
                }
                let node = s.slaves[si] as usize;
                if s.on_initial == InitialPenetration::Keep {
                    continue;
                }
                let pen = InitialPen {
                    contact_id: s.contact_id,
                    node,
                    element: s.face_id[o.face as usize],
                    depth: s.state[si].g0,
                };
                if s.on_initial == InitialPenetration::Error {
                    let kind = m.parts[m.contacts[s.row].master].kind;
                    return Err(WeftError::input(format!(
                        "node `{}` starts {:.3e} m inside the surface of {} `{}` (contact `{}`)",
                        m.node_id[node],
                        pen.depth,
                        kind.name(),
                        pen.element,
                        s.contact_id
                    ))
                    .in_file("contacts.parquet")
                    .in_column("initial_penetration")
                    .at_row(s.row)
                    .expected("no slave node closer to a face than half their thicknesses at t = 0")
                    .hint("move the node out, lower the thicknesses, or set initial_penetration to `track`"));
                }
                self.initial.push(pen);
            }
        }
        Ok(())
    }

    /// Contact forces at x^n added into `fcon` (which the caller has cleared); the stored
    /// energy and the dissipated work are booked. The step's phases in order: the broad
    /// phase ([`SurfaceContact::broad_phase`]), the erosion probe when faces leave, the
    /// narrow phase of every side ([`SurfaceContact::narrow_phase`]), the oracle when
    /// asked, the eroded energy, and the gather onto the nodes.
    pub fn forces(
        &mut self,
        x: &[[f64; 3]],
        v: &[[f64; 3]],
        dt: f64,
        dt_prev: f64,
        fcon: &mut [[f64; 3]],
    ) {
        let t0 = std::time::Instant::now();
        self.evaluations += 1;
        self.broad_phase(x, t0);
        let t1 = std::time::Instant::now();
        let probed = if self.sides.iter().any(|s| !s.pending.is_empty()) {
            let sp = self.skip_far.then(|| self.motion.spread().to_vec());
            Some(self.probe_erosion(x, v, dt, dt_prev, sp.as_deref()))
        } else {
            None
        };
        // Faces an erosion uncovered join the surface from the next step's build on.
        for s in &mut self.sides {
            if !s.waking.is_empty() && s.wake_uncovered() {
                self.force_build = true;
            }
        }
        let before = self.oracle.then(|| self.sides.clone());
        let stored = self.narrow_phase(x, v, dt, dt_prev);
        if let Some(before) = before {
            self.check_oracle(before, x, v, dt, dt_prev);
        }
        if let Some(with) = probed {
            self.book_erosion(&with, v, dt_prev);
        }
        let t_narrow = std::time::Instant::now();
        let ph = &mut self.phases;
        ph.narrow += (t_narrow - t1).as_secs_f64();
        // Gather onto the nodes in the canonical order (side, chunk, the chunk's slaves,
        // then their reactions' face nodes): bit-identical for any thread count.
        gather::gather(&self.sides, fcon);
        self.stored = stored;
        self.phases.scatter += t_narrow.elapsed().as_secs_f64();
        self.narrow_time += t1.elapsed();
    }

    /// The step's broad phase at `x` (the force evaluation began at `t0`): the thickness
    /// boxes, the staleness test (a stale one booked, [`SurfaceContact::record_trigger`])
    /// and, when stale, the build; their wall times booked.
    fn broad_phase(&mut self, x: &[[f64; 3]], t0: std::time::Instant) {
        // Every box when the oracle reads them all (its builds) or when no slave is
        // skipped; else, after the staleness test, every box at a build and otherwise
        // those of the candidates that the narrow phase will test
        // (`SurfaceContact::update_needed_boxes`).
        let all_boxes = self.oracle || !self.skip_far;
        if all_boxes {
            self.update_all_boxes(x);
        }
        let t_boxes = std::time::Instant::now();
        let stale = self.stale(x) || std::mem::take(&mut self.force_build);
        if stale {
            self.record_trigger();
        }
        let t_stale = std::time::Instant::now();
        if !all_boxes {
            self.update_needed_boxes(x, stale);
        }
        let t_lazy = std::time::Instant::now();
        if stale {
            self.rebuild(x);
        }
        let t1 = std::time::Instant::now();
        self.build_time += t1 - t0;
        let ph = &mut self.phases;
        ph.boxes += (t_boxes - t0).as_secs_f64() + (t_lazy - t_stale).as_secs_f64();
        ph.staleness += (t_stale - t_boxes).as_secs_f64();
        ph.builds += (t1 - t_lazy).as_secs_f64();
    }

    /// The narrow phase of every side at x^n, in one parallel loop
    /// ([`narrow::narrow_sides`]; far slaves skipped when `skip_far`), then its chunks'
    /// sums booked: the friction work, the counts and, when kept, the friction work by
    /// node. Returns the stored energy.
    fn narrow_phase(&mut self, x: &[[f64; 3]], v: &[[f64; 3]], dt: f64, dt_prev: f64) -> f64 {
        let spread = self.skip_far.then(|| self.motion.spread());
        let masters = &self.masters;
        narrow::narrow_sides(
            self.sides.iter_mut().map(|s| {
                let mb = &masters[s.surface];
                (s, mb)
            }),
            x,
            v,
            dt,
            dt_prev,
            false,
            spread,
        );
        let mut stored = 0.0;
        for s in &self.sides {
            // Sums in side and chunk order: bit-identical for any thread count.
            for c in &s.chunk_sums {
                stored += c.stored;
                self.dissipated += c.dissipated;
                self.counts.skipped += c.skipped;
                self.counts.tested += c.tested;
                self.counts.evaluated += c.evaluated;
                self.counts.penetrated += c.penetrated;
            }
            self.slave_steps += s.slaves.len() as u64;
            if let Some(nf) = self.node_friction.as_mut() {
                // In side, chunk and slave order: the same sums for any thread count.
                for active in &s.chunk_active {
                    for &si in active {
                        nf[s.slaves[si as usize] as usize] += s.out[si as usize].dissipated;
                    }
                }
            }
        }
        stored
    }

    /// A summary for reports.
    pub fn report(&self, node_id: &[i64]) -> ContactReport {
        let deepest = self
            .initial
            .iter()
            .max_by(|a, b| a.depth.total_cmp(&b.depth));
        ContactReport {
            definitions: self
                .sides
                .iter()
                .map(|s| s.row)
                .collect::<std::collections::BTreeSet<_>>()
                .len(),
            slaves: self.sides.iter().map(|s| s.slaves.len()).sum(),
            faces: self.sides.iter().map(|s| s.faces.len()).sum(),
            sides: self.sides.len(),
            surfaces: self.masters.len(),
            builds: self.builds,
            active: self.active(),
            initial_penetrations: self.initial.len(),
            deepest: deepest.map(|p| (p.contact_id, node_id[p.node], p.element, p.depth)),
            friction_work: self.dissipated,
            skin: self.skin,
            build_seconds: self.build_time.as_secs_f64(),
            narrow_seconds: self.narrow_time.as_secs_f64(),
            phases: self.phases,
            slave_steps: self.slave_steps,
            skipped: self.counts.skipped,
            tested: self.counts.tested,
            evaluated: self.counts.evaluated,
            penetrated: self.counts.penetrated,
            triggers: self.triggers,
            lazy_boxes: self.lazy_boxes,
        }
    }

    /// Slaves in contact after the last force evaluation.
    pub fn active(&self) -> usize {
        self.sides
            .iter()
            .map(|s| s.chunk_active.iter().map(|a| a.len()).sum::<usize>())
            .sum()
    }
}
