//! A side of a contact definition: its slaves against a master surface ([`Side`]), built
//! from the model, and the per-step data its phases share: the candidate lists of the
//! last broad phase, and the slaves' history and results ([`PairOut`], [`Reaction`],
//! `ChunkSums`). The faces' thickness boxes and envelope directions belong to the master
//! surface, shared by its sides (`super::boxes::MasterBoxes`).

use super::kernels::{bbox, Friction, SlaveState};
use super::solid::{boundary_nodes, solid_faces};
use crate::model::contacts::{ContactDef, InitialPenetration, Slave};
use crate::model::{ElementKind, Model};
use crate::solver::contact::projectile::PENALTY_FACTOR;
use crate::solver::vec3::dot;

/// Slaves per parallel chunk of the narrow phase.
pub(super) const SLAVE_CHUNK: usize = 256;

/// Round-off allowance of the thickness-box tests relative to the largest coordinate of a
/// side's nodes: its foot and box are computed within ~10⁻¹⁵ of that.
const BOX_MARGIN: f64 = 1e-9;

/// What one slave's contact gives at one step.
#[derive(Debug, Clone, Copy, Default)]
pub struct PairOut {
    /// Face of largest penetration (u32::MAX: no contact).
    pub face: u32,
    /// Force on the slave [N] (the nodes of each penetrated face F get −λ_F w_{F,a} f,
    /// see [`Reaction`]).
    pub f: [f64; 3],
    /// Stored energy ½ k g² + |f_t|²/(2k) [J].
    pub stored: f64,
    /// Friction work dissipated this step [J].
    pub dissipated: f64,
    /// Penetration g (beyond a tracked initial one) [m].
    pub g: f64,
}

/// A share of a slave's reaction: the nodes of `face` get −w_a f_slave (w already
/// multiplied by the face's share λ_F = g_F/Σg of the penetrations), or, under the
/// per-face law ([`Side::per_face`]), −w_a f_F with f_F the face's `own` force on the
/// slave (w its foot's weights).
#[derive(Debug, Clone, Copy)]
pub struct Reaction {
    pub slave: u32,
    pub face: u32,
    pub w: [f64; 4],
    pub own: Option<[f64; 3]>,
}

/// One direction of one contact definition: slaves against a master surface.
#[derive(Debug, Clone)]
pub struct Side {
    pub contact_id: i64,
    pub row: usize,
    pub slaves: Vec<u32>,
    pub slave_t: Vec<f64>,
    pub(super) slave_m: Vec<f64>,
    /// Face nodes (unused entries 0), node count per face (2, 3 or 4).
    pub faces: Vec<[u32; 4]>,
    pub nf: usize,
    pub(super) face_t: Vec<[f64; 4]>,
    /// Nodal masses of each face [kg] (the penalty uses their interpolation at the
    /// contact point, continuous from face to face).
    pub(super) face_m: Vec<[f64; 4]>,
    pub face_id: Vec<i64>,
    /// The kind of the master part's elements, and each face's element (its index in the
    /// model's block of that kind, ascending).
    pub master_kind: ElementKind,
    pub(super) face_elem: Vec<u32>,
    /// A solid's (hexahedron part's) boundary as the master surface: the faces' contact
    /// thickness t_F, while `face_t` holds their box thickness 2R (see [`super::solid`]);
    /// None for membranes, trusses and beams.
    pub(super) solid: Option<f64>,
    /// Per face, whether its element is still in the model; an eroded face has an empty
    /// thickness box (no slave passes its box test) and leaves the grid at the next build.
    pub(super) face_alive: Vec<bool>,
    pub(super) dead_faces: usize,
    /// A solid's faces: the element across each (`u32::MAX`: the part's boundary); empty
    /// for other masters. With erosion, interior faces are in the surface, dormant
    /// (`face_alive` false) until the element across erodes.
    pub(super) face_other: Vec<u32>,
    /// The elements of an eroding solid that have eroded.
    pub(super) eroded_elems: std::collections::HashSet<u32>,
    /// Dormant faces uncovered at this step, alive from the next force evaluation (with
    /// a broad-phase build).
    pub(super) waking: Vec<u32>,
    pub(super) friction: Friction,
    pub(super) kappa: f64,
    /// Normal viscous damping as a fraction ζ of the pair's critical damping
    /// 2√(k m*) (0 in impact runs; `set_normal_damping` sets it for a relaxation).
    pub(super) damping: f64,
    /// Each face a slave penetrates is a pair of its own, its force the exact gradient
    /// of its ½ k_F g_F² (the per-face law, `narrow::Narrow::per_face_contact`), instead
    /// of the one contact shared over them: set once an element of the model has failed
    /// ([`super::SurfaceContact::erode`]). The shared normal and reaction are not the
    /// gradient of ½kg²: they work on a slave that slides over a kinked surface in
    /// proportion to k g |n̄ − n| v_t, nothing where a formed weave rests, but broken yarn
    /// ends recoil through the crossings at c ε_f (268 m/s at 3.6 %) and more: measured, a
    /// chain patch struck at 20 m/s gained 0.04 J (10 % of the impact energy) within 60 µs
    /// of its first failure. The deepest face alone (the law before this one) is a
    /// gradient too, of the kinked max_F ½kg_F², but a node squeezed between two plies
    /// sits in the kink and is pushed all one way, then all the other, step after step:
    /// measured on 8 plies of chains struck at 123 m/s, frictionless, the balance drifted
    /// by 0.085 J (0.56 % of the impact energy) after the first failure, against 0.0096 J
    /// (0.064 %) under this law (docs/theory.md, "Contact").
    pub(super) per_face: bool,
    /// Faces of elements that failed at this step, still in the surface until the
    /// contact at this step has measured what they held ([`super::SurfaceContact::forces`]).
    pub(super) pending: Vec<u32>,
    pub(super) on_initial: InitialPenetration,
    /// Contact distance of the thickest slave and face, t_s,max/2 + t_F,max/2 [m].
    pub(super) reach: f64,
    /// Largest slave thickness: the thickness boxes are inflated by half of it and the
    /// skin for the broad phase [m].
    pub(super) slave_t_max: f64,
    /// Round-off allowance η of the thickness-box tests [m] (see [`BOX_MARGIN`]).
    pub(super) box_margin: f64,
    /// Candidate lists from the last broad phase: per slave, (first, end) into `cand`,
    /// the lists of all slaves one after another, each slave's candidates ascending.
    pub(super) cand_at: Vec<[u32; 2]>,
    pub(super) cand: Vec<u32>,
    /// Per slave, from the last broad phase: its margin [m] (+∞ without candidates), so
    /// that the narrow phase can skip a slave that no candidate can reach yet.
    ///
    /// Let e_F be the Euclidean distance from x_s to the thickness box of a candidate F,
    /// and v_F = max over its two envelope directions m of m·x_s − h (the narrow phase's
    /// filter passes F only when e_F ≤ t_s/2 + η and v_F < t_s/2 + η). Between builds
    /// the directions are fixed, |m| ≤ 1, and for a pair that passes the box test every
    /// component d of the displacement since the build of a node a of F differs from the
    /// slave's by at most S_d, the spread of the displacements over the 3 × 3 × 3 cells
    /// around the slave's cell ([`staleness`](crate::solver::contact::staleness): F's nodes lie in them). The box's
    /// faces then move by at most S_d relative to the slave, so e_F ≥ e_F^b − |S|
    /// (b: at the build); and h = max_a (m·x_a + t_a/2) grows by at most m·u_s + |S|, so
    /// v_F ≥ v_F^b − |S|. With the margin min_F max(e_F^b, v_F^b) − t_s/2 − 2η, a slave
    /// whose margin exceeds |S| at a step passes no candidate, finds no penetration and
    /// opens (its stick spring released, a tracked initial penetration dropped): exactly
    /// what the full test gives; the second η covers the round-off of the margin, 10⁶
    /// times it as in the box test. Measured on the 60 × 60 woven quarter: 86 % of the
    /// slave-steps skipped to 10 µs, 43 % to 60 µs.
    pub(super) margin: Vec<f64>,
    /// Per slave, its cell of the staleness test at the last build (the narrow phase
    /// reads its spread |S| there).
    pub(super) slave_cell: Vec<u32>,
    pub state: Vec<SlaveState>,
    /// Per slave: whether its state differs from the default (a stick spring or a
    /// tracked initial penetration).
    pub(super) held: Vec<bool>,
    /// Per slave, its contact at the last step; valid only for the slaves in
    /// `chunk_active` (after the setup's narrow phase: for every slave).
    pub out: Vec<PairOut>,
    /// Per fixed chunk of slaves: the slaves in contact (indices), ...
    pub(super) chunk_active: Vec<Vec<u32>>,
    /// ... the shares of their reactions over the faces they penetrate, in slave order ...
    pub(super) chunk_reactions: Vec<Vec<Reaction>>,
    /// ... the chunk's energies and counts, summed in chunk order ...
    pub(super) chunk_sums: Vec<ChunkSums>,
    /// ... and, on more than one thread, its forces on the nodes by node block, for the
    /// parallel gather (`super::gather`).
    pub(super) chunk_contribs: Vec<ChunkContribs>,
    /// Its master surface's index in `SurfaceContact::masters`: the faces' boxes and
    /// envelope directions, shared with the other sides of that surface
    /// (`super::boxes::MasterBoxes`).
    pub(super) surface: usize,
}

/// What one chunk of slaves adds up in a narrow phase: the stored energy and the friction
/// work [J], the slaves skipped whole, the candidate faces whose box was tested, the faces
/// past the filters (whose closest point was computed), and the faces found penetrated.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct ChunkSums {
    pub(super) stored: f64,
    pub(super) dissipated: f64,
    pub(super) skipped: u64,
    pub(super) tested: u64,
    pub(super) evaluated: u64,
    pub(super) penetrated: u64,
}

/// Nodal contact thickness from a part's elements (None = all parts): membranes their
/// nodal thickness, trusses the diameter √(4A/π), beams the section height; the mean over
/// a node's elements.
fn nodal_thickness(m: &Model, part: Option<usize>) -> Vec<f64> {
    let nn = m.num_nodes();
    let (mut sum, mut cnt) = (vec![0.0; nn], vec![0u32; nn]);
    for (kind, b) in &m.elements {
        let npe = kind.nodes_per_element();
        for e in 0..b.len() {
            if part.is_some_and(|p| p != b.part[e]) {
                continue;
            }
            let p = &m.parts[b.part[e]].props;
            for a in 0..npe {
                let t = match kind {
                    ElementKind::Tri | ElementKind::Quad => {
                        if b.thickness.is_empty() {
                            p.thickness.unwrap_or(0.0)
                        } else {
                            b.thickness[npe * e + a]
                        }
                    }
                    ElementKind::Truss => {
                        (4.0 * b.truss_area(&m.parts, e) / std::f64::consts::PI).sqrt()
                    }
                    ElementKind::Beam => p.height.unwrap_or(0.0),
                    _ => continue,
                };
                let n = b.nodes[npe * e + a];
                sum[n] += t;
                cnt[n] += 1;
            }
        }
    }
    (0..nn)
        .map(|i| {
            if cnt[i] > 0 {
                sum[i] / cnt[i] as f64
            } else {
                0.0
            }
        })
        .collect()
}

/// The slave nodes of a part: its boundary nodes for a solid (see [`super::solid`]),
/// else the nodes of its elements; sorted.
fn slave_part_nodes(m: &Model, part: usize) -> Vec<u32> {
    if m.parts[part].kind == ElementKind::Hex {
        boundary_nodes(m, part)
    } else {
        part_nodes(m, part)
    }
}

/// The nodes of a part's elements, sorted.
pub(super) fn part_nodes(m: &Model, part: usize) -> Vec<u32> {
    let kind = m.parts[part].kind;
    let mut v: Vec<u32> = match m.elements.get(&kind) {
        Some(b) => {
            let npe = kind.nodes_per_element();
            (0..b.len())
                .filter(|&e| b.part[e] == part)
                .flat_map(|e| b.nodes[npe * e..npe * e + npe].iter().map(|&n| n as u32))
                .collect()
        }
        None => vec![],
    };
    v.sort_unstable();
    v.dedup();
    v
}

/// The slave nodes of a definition, sorted, each once.
fn slave_nodes(m: &Model, slave: &Slave) -> Vec<u32> {
    match slave {
        Slave::Part(p) => slave_part_nodes(m, *p),
        Slave::Set(s) => {
            let mut v: Vec<u32> = m.node_sets[s].iter().map(|&n| n as u32).collect();
            v.sort_unstable();
            v.dedup();
            v
        }
    }
}

/// The faces of a definition's master part, in element order: their nodes (unused
/// entries 0; `npe` per face), nodal contact thicknesses, nodal masses [kg] and element
/// ids; for a solid its boundary faces and their contact thickness (`solid`).
struct MasterFaces {
    faces: Vec<[u32; 4]>,
    npe: usize,
    face_t: Vec<[f64; 4]>,
    face_m: Vec<[f64; 4]>,
    face_id: Vec<i64>,
    face_elem: Vec<u32>,
    solid: Option<f64>,
    /// A solid's faces: the element across each (`u32::MAX`: on the boundary); empty
    /// otherwise. An eroding solid's interior faces are in `faces` too, dormant.
    face_other: Vec<u32>,
}

impl MasterFaces {
    /// The faces of part `master` of definition `d`, with the nodal masses `mass`: each
    /// node's thickness is the definition's `master_thickness`, else a membrane's own
    /// nodal thickness, else its nodal thickness from its elements.
    fn new(m: &Model, d: &ContactDef, master: usize, mass: &[f64]) -> MasterFaces {
        let kind = m.parts[master].kind;
        if kind == ElementKind::Hex {
            return MasterFaces::solid(m, d, master, mass);
        }
        let b = &m.elements[&kind];
        let npe = kind.nodes_per_element();
        let mt = nodal_thickness(m, Some(master));
        let mut mf = MasterFaces {
            faces: vec![],
            npe,
            face_t: vec![],
            face_m: vec![],
            face_id: vec![],
            face_elem: vec![],
            solid: None,
            face_other: vec![],
        };
        for e in 0..b.len() {
            if b.part[e] != master {
                continue;
            }
            let mut f = [0u32; 4];
            let mut t = [0.0; 4];
            let mut fm = [0.0; 4];
            for a in 0..npe {
                let n = b.nodes[npe * e + a];
                f[a] = n as u32;
                t[a] = d.master_thickness.unwrap_or(match kind {
                    ElementKind::Tri | ElementKind::Quad if !b.thickness.is_empty() => {
                        b.thickness[npe * e + a]
                    }
                    _ => mt[n],
                });
                fm[a] = mass[n];
            }
            mf.faces.push(f);
            mf.face_t.push(t);
            mf.face_m.push(fm);
            mf.face_id.push(b.id[e]);
            mf.face_elem.push(e as u32);
        }
        mf
    }

    /// The boundary faces of hexahedron part `master` of definition `d`: contact
    /// thickness t_F = `master_thickness` (0 when null), box thickness 2 max(t_F/2, D) at
    /// each node (D half the element's depth across the face; see [`super::solid`]).
    fn solid(m: &Model, d: &ContactDef, master: usize, mass: &[f64]) -> MasterFaces {
        let b = &m.elements[&ElementKind::Hex];
        let tf = d.master_thickness.unwrap_or(0.0);
        // A part whose cells erode keeps its interior faces, dormant until a neighbour's
        // erosion uncovers them (the eroding contact, `super::solid`).
        let eroding = m.parts[master].props.erosion_plastic_strain.is_some();
        let bf = solid_faces(m, master, eroding);
        MasterFaces {
            faces: bf.iter().map(|f| f.nodes).collect(),
            npe: 4,
            face_t: bf
                .iter()
                .map(|f| [2.0 * (0.5 * tf).max(f.depth); 4])
                .collect(),
            face_m: bf
                .iter()
                .map(|f| f.nodes.map(|n| mass[n as usize]))
                .collect(),
            face_id: bf.iter().map(|f| b.id[f.elem as usize]).collect(),
            face_elem: bf.iter().map(|f| f.elem).collect(),
            solid: Some(tf),
            face_other: bf.iter().map(|f| f.other).collect(),
        }
    }
}

impl Side {
    /// The live faces' nodes (a solid's boundary, not the dormant interior faces of an
    /// eroding one), each face's `nf` nodes in turn.
    pub fn for_live_faces(&self, mut f: impl FnMut(&[u32])) {
        for (i, face) in self.faces.iter().enumerate() {
            if self.face_alive.get(i).copied().unwrap_or(true) {
                f(&face[..self.nf]);
            }
        }
    }
    /// The side of definition `row` whose `slave` nodes meet the faces of part `master`,
    /// with the nodal masses `mass`.
    pub(super) fn new(m: &Model, row: usize, slave: &Slave, master: usize, mass: &[f64]) -> Side {
        let d = &m.contacts[row];
        let slaves = slave_nodes(m, slave);
        let st = nodal_thickness(
            m,
            match slave {
                Slave::Part(p) => Some(*p),
                Slave::Set(_) => None,
            },
        );
        let slave_t: Vec<f64> = slaves
            .iter()
            .map(|&s| d.slave_thickness.unwrap_or(st[s as usize]))
            .collect();
        let MasterFaces {
            faces,
            npe,
            face_t,
            face_m,
            face_id,
            face_elem,
            solid,
            face_other,
        } = MasterFaces::new(m, d, master, mass);
        // Dormant: an interior face of an eroding solid (its element's neighbour is still
        // there).
        let face_alive: Vec<bool> = if face_other.is_empty() {
            vec![true; face_elem.len()]
        } else {
            face_other.iter().map(|&o| o == u32::MAX).collect()
        };
        let dead_faces = face_alive.iter().filter(|&&a| !a).count();
        let ts_max = slave_t.iter().cloned().fold(0.0, f64::max);
        let tf_box = face_t.iter().flatten().cloned().fold(0.0, f64::max);
        // (A solid's contact thickness is t_F; its `face_t` the boxes' 2R.)
        let tf_max = solid.unwrap_or(tf_box);
        // The largest coordinate of the side's nodes, the scale of the round-off.
        let x_max = slaves
            .iter()
            .chain(faces.iter().flat_map(|f| f[..npe].iter()))
            .flat_map(|&n| m.coords[n as usize])
            .fold(0.0, |a: f64, c| a.max(c.abs()));
        Side {
            contact_id: d.id,
            row,
            slave_m: slaves.iter().map(|&s| mass[s as usize]).collect(),
            state: vec![SlaveState::default(); slaves.len()],
            held: vec![false; slaves.len()],
            out: vec![
                PairOut {
                    face: u32::MAX,
                    ..Default::default()
                };
                slaves.len()
            ],
            slaves,
            slave_t,
            faces,
            nf: npe,
            face_t,
            face_m,
            face_id,
            master_kind: m.parts[master].kind,
            face_alive,
            face_elem,
            face_other,
            eroded_elems: Default::default(),
            waking: vec![],
            solid,
            dead_faces,
            friction: Friction {
                mu_s: d.static_friction,
                mu_d: d.dynamic_friction,
                decay: d.friction_decay,
            },
            kappa: PENALTY_FACTOR * d.penalty_scale,
            damping: 0.0,
            per_face: false,
            pending: vec![],
            on_initial: d.initial_penetration,
            reach: 0.5 * (ts_max + tf_max),
            slave_t_max: ts_max,
            box_margin: BOX_MARGIN * (x_max + 0.5 * (ts_max + tf_box)),
            cand_at: vec![],
            cand: vec![],
            margin: vec![],
            slave_cell: vec![],
            chunk_active: vec![],
            chunk_reactions: vec![],
            chunk_sums: vec![],
            chunk_contribs: vec![],
            surface: 0,
        }
    }

    /// Mean of the largest extent of the faces [m].
    pub(super) fn mean_face_size(&self, x: &[[f64; 3]]) -> f64 {
        if self.faces.is_empty() {
            return 0.0;
        }
        let mut s = 0.0;
        for f in &self.faces {
            let (lo, hi) = bbox(f, self.nf, x);
            s += (0..3).map(|d| hi[d] - lo[d]).fold(0.0, f64::max);
        }
        s / self.faces.len() as f64
    }

    /// The faces of element `e` (of the master's kind) are to leave the surface (one, or
    /// a solid's boundary faces of it: `face_elem` is ascending): pending until
    /// [`Side::drop_pending`].
    pub(super) fn erode(&mut self, e: usize) {
        let faces_of = |face_elem: &[u32], e: u32| {
            face_elem.partition_point(|&x| x < e)..face_elem.partition_point(|&x| x <= e)
        };
        for f in faces_of(&self.face_elem, e as u32) {
            if self.face_alive[f] && !self.pending.contains(&(f as u32)) {
                self.pending.push(f as u32);
            }
        }
        if self.face_other.is_empty() {
            return;
        }
        // An eroding solid: the faces `e` shared with live neighbours are uncovered, each
        // the neighbour's copy (the one whose element across is `e`).
        self.eroded_elems.insert(e as u32);
        for f in faces_of(&self.face_elem, e as u32) {
            let o = self.face_other[f];
            if o == u32::MAX || self.eroded_elems.contains(&o) {
                continue;
            }
            for g in faces_of(&self.face_elem, o) {
                if self.face_other[g] == e as u32 && !self.face_alive[g] {
                    self.waking.push(g as u32);
                }
            }
        }
    }

    /// What the pairs of the last narrow phase hold at x^n and would do over the half step
    /// before it [J]: Σ (stored + dissipated) over its chunks, plus ½ Δt^{n−½} Σ v^{n−½}·f
    /// over the slaves in contact and their reactions' face nodes. The difference of two
    /// narrow phases at the same state, with and without some faces, is the energy those
    /// faces take when they leave (see `failure::taken_energy`, the same for an element).
    pub(super) fn pair_energy(&self, v: &[[f64; 3]], dt_prev: f64) -> f64 {
        let mut e = 0.0;
        let mut p = 0.0;
        for ((c, active), reactions) in self
            .chunk_sums
            .iter()
            .zip(&self.chunk_active)
            .zip(&self.chunk_reactions)
        {
            e += c.stored + c.dissipated;
            for &si in active {
                let f = &self.out[si as usize].f;
                p += dot(&v[self.slaves[si as usize] as usize], f);
            }
            for r in reactions {
                let f = &self.out[r.slave as usize].f;
                let face = &self.faces[r.face as usize];
                for a in 0..self.nf {
                    p -= r.w[a] * dot(&v[face[a] as usize], f);
                }
            }
        }
        e + 0.5 * dt_prev * p
    }
}

/// One contribution to the parallel gather (`super::gather`): a node and the force added
/// to it [N].
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Contrib {
    pub(super) node: u32,
    pub(super) f: [f64; 3],
}

/// One chunk's contributions sorted by node block, in the chunk's order within each
/// (filled by `super::gather`'s `ChunkContribs::fill`).
#[derive(Debug, Clone, Default)]
pub(super) struct ChunkContribs {
    /// Block b's contributions are `items[ptr[b]..ptr[b + 1]]`.
    pub(super) ptr: Vec<u32>,
    pub(super) items: Vec<Contrib>,
}
