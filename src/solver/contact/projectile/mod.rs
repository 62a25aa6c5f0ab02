//! Rigid projectile against nodes and membrane faces: penalty contact with Coulomb
//! friction. The projectile, its shapes and the penetration of a point are [`shape`]'s
//! (with the glossary: P the tip, a the axis, R the radius, g the penetration and n the
//! outward normal); this module is the contact during a run: the face sample points and
//! triangles the projectiles meet, the force and energy passes, and the projectiles'
//! motion.
//!
//! Force on the node f = k g n − friction, on the projectile the opposite (momentum is
//! exchanged exactly). Friction: f_t = −μ k g t̂ min(1, |v_t|/v_reg), t̂ along the
//! tangential relative velocity v_t; v_reg = 10⁻³ m/s regularises sticking. Penalty
//! k = κ_c m_i/Δt² per node (κ_c = 0.1: the contact spring alone has ω Δt ≈ 0.32, well
//! inside stability) unless the projectile gives `contact_stiffness`. Stored contact
//! energy ½ k g², friction work accumulated. Reference: Belytschko, Liu, Moran,
//! *Nonlinear Finite Elements*, §10.4 (penalty contact), Wriggers, *Computational
//! Contact Mechanics*, §5.2 (regularised Coulomb friction).

pub mod shape;

use rayon::prelude::*;

pub use super::closest::{closest_on_segment, closest_on_triangle};
use crate::model::{ElementKind, Model, ProjectileShape};
use crate::solver::vec3::{add, dot};
pub use shape::{friction, Projectile, V_REG};

/// Default κ_c of the penalty stiffness k = κ_c m/Δt².
pub const PENALTY_FACTOR: f64 = 0.1;
/// Penalty of a face sample point relative to the interpolated nodal penalty: with a
/// quarter, the node and face contacts together stay well inside stability.
pub const SEGMENT_FACTOR: f64 = 0.25;

/// A contact point on a membrane face: x = Σ w_a x_a over up to four nodes.
#[derive(Debug, Clone, Copy)]
pub struct SamplePoint {
    pub nodes: [u32; 4],
    pub w: [f64; 4],
    pub n: usize,
    /// Tributary mass for the penalty k = κ_c·SEGMENT_FACTOR·m/Δt² [kg].
    pub mass: f64,
}

/// Skin of the projectile's list of nearby face triangles, as a fraction of its radius:
/// the list holds every triangle that could come within the radius before the nose
/// centre and the nodes together have moved this far (a Verlet list).
const SKIN: f64 = 0.2;

/// A face triangle with its tributary mass (a quad gives four, along both diagonals).
#[derive(Debug, Clone, Copy)]
pub struct FaceTri {
    pub nodes: [u32; 3],
    pub mass: f64,
}

/// Contact of one sphere (centre c, radius r) with a face triangle: closest-point
/// weights, outward normal, penetration and penalty. The single geometry kernel of the
/// force and the energy passes.
#[inline]
fn sphere_face(
    p: &Projectile,
    c: &[f64; 3],
    t: &FaceTri,
    x: &[[f64; 3]],
    dt2: f64,
) -> Option<([f64; 3], [f64; 3], f64, f64)> {
    let xs = t.nodes.map(|n| x[n as usize]);
    // Cheap exact rejection: every point of the triangle is within e = max |x_a − x₀| of
    // x₀, so |c − x₀| ≥ R + e means no contact.
    let d0 = [xs[0][0] - c[0], xs[0][1] - c[1], xs[0][2] - c[2]];
    let r0 = dot(&d0, &d0);
    let (e1, e2) = (
        [
            xs[1][0] - xs[0][0],
            xs[1][1] - xs[0][1],
            xs[1][2] - xs[0][2],
        ],
        [
            xs[2][0] - xs[0][0],
            xs[2][1] - xs[0][1],
            xs[2][2] - xs[0][2],
        ],
    );
    let reach = p.radius + dot(&e1, &e1).max(dot(&e2, &e2)).sqrt();
    if r0 >= reach * reach {
        return None;
    }
    let w = closest_on_triangle(c, &xs[0], &xs[1], &xs[2]);
    let q: [f64; 3] = std::array::from_fn(|d| w[0] * xs[0][d] + w[1] * xs[1][d] + w[2] * xs[2][d]);
    let dq = [q[0] - c[0], q[1] - c[1], q[2] - c[2]];
    let dist = dot(&dq, &dq).sqrt();
    if dist >= p.radius || dist == 0.0 {
        return None;
    }
    // A round nose's hemisphere only: the cylinder behind it is left to node contact.
    if p.shape == ProjectileShape::Round && dot(&dq, &p.axis) < 0.0 {
        return None;
    }
    let n = [dq[0] / dist, dq[1] / dist, dq[2] / dist];
    let kp = p.stiffness.unwrap_or(PENALTY_FACTOR * t.mass / (3.0 * dt2));
    Some((w, n, p.radius - dist, kp))
}

/// A face triangle the nose penetrates: its index in `face_tris`, the closest point's
/// weights, the outward normal, the penetration and the penalty ([`sphere_face`]).
type TriangleHit = (u32, [f64; 3], [f64; 3], f64, f64);

/// Penalty of a face sample point.
#[inline]
fn sample_penalty(p: &Projectile, sp: &SamplePoint, dt2: f64) -> f64 {
    SEGMENT_FACTOR * p.stiffness.unwrap_or(PENALTY_FACTOR * sp.mass / dt2)
}

/// A dissipative contact force of one force pass (the dashpot's and the friction's), on a
/// point of the fabric (a node, or a face point with its nodes' weights) against one
/// projectile.
///
/// The work a force f^n does over its step of the central difference is f^n·Δx, the point
/// moving from t^{n−½} to t^{n+½} by (Δt^{n−½} v^{n−½} + Δt^{n+½} v^{n+½})/2 relative to
/// the projectile: the midpoint rule, the one under which the ledger's kinetic energy
/// ½ M v^{n−½}·v^{n+½} balances exactly. The first half is booked with the force, the
/// second at the next pass, when v^{n+½} is known. Booking the whole step with v^{n−½}
/// alone over-counts what a stiff dashpot or a chattering friction force dissipates (the
/// dashpot changes the node's approach speed by 2ζ√κ ≈ 32 % a step at ζ = 0.5; a Coulomb
/// force that reverses the slip each step does almost no work while v^{n−½}·f books its
/// full |f||v|): measured on a slow perforation of a patch in a membrane, 8.1 % of the
/// impact energy by 2.4 ms, against 1.1 % with the projectile's friction and damping off.
#[derive(Debug, Clone, Copy)]
struct Pending {
    projectile: u32,
    /// How many of `nodes` and `w` count.
    n: u8,
    nodes: [u32; 4],
    w: [f64; 4],
    damping: [f64; 3],
    friction: [f64; 3],
}

impl Pending {
    fn at_node(projectile: usize, node: usize, damping: [f64; 3], friction: [f64; 3]) -> Self {
        Pending {
            projectile: projectile as u32,
            n: 1,
            nodes: [node as u32, 0, 0, 0],
            w: [1.0, 0.0, 0.0, 0.0],
            damping,
            friction,
        }
    }

    /// A face point's friction force `ft` (nodes and weights, at most four).
    fn at_point(projectile: usize, nodes: &[u32], w: &[f64], ft: [f64; 3]) -> Self {
        Pending {
            projectile: projectile as u32,
            n: nodes.len() as u8,
            nodes: std::array::from_fn(|a| nodes.get(a).copied().unwrap_or(0)),
            w: std::array::from_fn(|a| w.get(a).copied().unwrap_or(0.0)),
            damping: [0.0; 3],
            friction: ft,
        }
    }

    /// Shares the work `work` of the first half step among the point's nodes (when the
    /// per-node account is kept) and returns it.
    fn book_first_half(&self, node_friction: &mut Option<Vec<f64>>, work: f64) -> f64 {
        if let Some(nf) = node_friction.as_mut() {
            for a in 0..self.n as usize {
                nf[self.nodes[a] as usize] += self.w[a] * work;
            }
        }
        work
    }

    /// The point's velocity relative to the projectile's `vp`.
    fn relative_velocity(&self, v: &[[f64; 3]], vp: &[f64; 3]) -> [f64; 3] {
        std::array::from_fn(|d| {
            (0..self.n as usize)
                .map(|a| self.w[a] * v[self.nodes[a] as usize][d])
                .sum::<f64>()
                - vp[d]
        })
    }
}

/// What one force pass reads: the positions x^n and velocities v^{n−½}, Δt² of the
/// penalty and half the last step (the first half of the dissipative work, [`Pending`]).
struct Pass<'a> {
    x: &'a [[f64; 3]],
    v: &'a [[f64; 3]],
    dt2: f64,
    half: f64,
}

/// What one force pass writes: the forces on the nodes, the nodes touched, and the force
/// on the current projectile.
struct PassOut<'a> {
    fcon: &'a mut [[f64; 3]],
    touched: &'a mut Vec<usize>,
    ftot: [f64; 3],
}

impl PassOut<'_> {
    /// A contact force `f` on node `i`, the opposite on the projectile.
    fn push_node(&mut self, i: usize, f: &[f64; 3]) {
        add(&mut self.fcon[i], f);
        self.touched.push(i);
        self.take(f);
    }

    /// A contact force `f` on a face point of weights `w` over `nodes`: each node gets
    /// w_a f, the projectile −f.
    fn push_point(&mut self, nodes: &[u32], w: &[f64], f: &[f64; 3]) {
        for (&i, &wa) in nodes.iter().zip(w) {
            let i = i as usize;
            add(&mut self.fcon[i], &[wa * f[0], wa * f[1], wa * f[2]]);
            self.touched.push(i);
        }
        self.take(f);
    }

    /// −`f` onto the projectile's force.
    fn take(&mut self, f: &[f64; 3]) {
        self.ftot = [
            self.ftot[0] - f[0],
            self.ftot[1] - f[1],
            self.ftot[2] - f[2],
        ];
    }
}

/// Every projectile of a model and what it can touch.
#[derive(Debug, Clone, Default)]
pub struct ProjectileContact {
    pub projectiles: Vec<Projectile>,
    /// Contact sample points on the membrane faces (centroids, edge midpoints), for
    /// flat noses.
    samples: Vec<SamplePoint>,
    /// Face triangles (quads split along both diagonals), for spherical noses.
    face_tris: Vec<FaceTri>,
    /// Erosion: per face (the triangles' elements, then the quads'), its triangles
    /// (first, end) in `face_tris` and its samples (centroid, then its edges') with its
    /// mass; per triangle whether it is live, per sample how many live faces it samples.
    n_tri_faces: usize,
    face_tri_range: Vec<(u32, u32)>,
    face_samples: Vec<([u32; 5], f64)>,
    tri_alive: Vec<bool>,
    sample_faces: Vec<u16>,
    /// Default penalty stiffness per node κ_c m/Δt² [N/m].
    k_node: Vec<f64>,
    /// Friction work dissipated in contact [J].
    pub friction_work: f64,
    /// Work dissipated by the contact springs' dashpots [J].
    pub damping_work: f64,
    /// The dissipative forces of the last force pass, whose work over the second half of
    /// their step is booked at the next pass, once v^{n+½} is known ([`Pending`]).
    pending: Vec<Pending>,
    /// When asked, the friction and dashpot work so far by node [J] (a face contact's
    /// shared by the face's nodes with the contact point's weights), for the energy
    /// absorbed per layer.
    pub node_friction: Option<Vec<f64>>,
    /// Work done by projectiles with prescribed velocity [J].
    pub prescribed_work: f64,
    /// Per projectile, the directions normal to the symmetry planes through its tip: it
    /// cannot move along them (a plane elsewhere, a clay box's wall or floor, leaves it
    /// free).
    fixed: Vec<[bool; 3]>,
    /// Per projectile, the face triangles (indices into `face_tris`) that may touch its
    /// spherical nose, with the node positions and nose centres they were listed at.
    near: Vec<Vec<u32>>,
    near_x: Vec<[f64; 3]>,
    near_c: Vec<[f64; 3]>,
}

impl ProjectileContact {
    /// `faces`: every membrane face (its nodes, 3 or 4) with its mass.
    pub fn new(m: &Model, faces: &[(&[u32], f64)]) -> ProjectileContact {
        // Contact sample points on the faces, each with a tributary mass for its penalty:
        // half the face's mass at its centroid, the other half shared among its edges (an
        // edge collects from every face it bounds), so the penalty of a face does not
        // depend on what lies beyond it (a symmetry plane, a free edge).
        let mut samples = Vec::new();
        let mut edge_at: std::collections::BTreeMap<(u32, u32), usize> = Default::default();
        let mut face_samples = Vec::with_capacity(faces.len());
        let mut sample_faces: Vec<u16> = Vec::new();
        for &(f, mf) in faces {
            let n = f.len();
            let mut own = [u32::MAX; 5];
            own[0] = samples.len() as u32;
            let mut nodes = [0u32; 4];
            nodes[..n].copy_from_slice(f);
            let mut w = [0.0; 4];
            for x in w.iter_mut().take(n) {
                *x = 1.0 / n as f64;
            }
            samples.push(SamplePoint {
                nodes,
                w,
                n,
                mass: 0.5 * mf,
            });
            for a in 0..n {
                let (p, q) = (f[a], f[(a + 1) % n]);
                let k = *edge_at.entry((p.min(q), p.max(q))).or_insert_with(|| {
                    samples.push(SamplePoint {
                        nodes: [p, q, 0, 0],
                        w: [0.5, 0.5, 0.0, 0.0],
                        n: 2,
                        mass: 0.0,
                    });
                    samples.len() - 1
                });
                samples[k].mass += 0.5 * mf / n as f64;
                own[1 + a] = k as u32;
            }
            face_samples.push((own, mf));
            sample_faces.resize(samples.len(), 0);
            for &k in own.iter().filter(|&&k| k != u32::MAX) {
                sample_faces[k as usize] += 1;
            }
        }
        let mut face_tris = Vec::new();
        let mut face_tri_range = Vec::with_capacity(faces.len());
        for &(f, m) in faces {
            let first = face_tris.len() as u32;
            if f.len() == 3 {
                face_tris.push(FaceTri {
                    nodes: [f[0], f[1], f[2]],
                    mass: m,
                });
            } else {
                // Both diagonals, so that the split has no handedness (a mirrored mesh,
                // e.g. across a symmetry plane, gets the mirrored contact).
                for t in [
                    [f[0], f[1], f[2]],
                    [f[0], f[2], f[3]],
                    [f[1], f[2], f[3]],
                    [f[1], f[3], f[0]],
                ] {
                    face_tris.push(FaceTri {
                        nodes: t,
                        mass: 0.25 * m,
                    });
                }
            }
            face_tri_range.push((first, face_tris.len() as u32));
        }
        let n_tri_faces = faces.iter().take_while(|f| f.0.len() == 3).count();
        ProjectileContact {
            n_tri_faces,
            face_tri_range,
            face_samples,
            tri_alive: vec![true; face_tris.len()],
            sample_faces,
            projectiles: m.projectiles.iter().map(Projectile::new).collect(),
            samples,
            face_tris,
            k_node: vec![],
            friction_work: 0.0,
            damping_work: 0.0,
            pending: vec![],
            node_friction: None,
            prescribed_work: 0.0,
            fixed: m
                .projectiles
                .iter()
                .map(|p| {
                    std::array::from_fn(|d| {
                        m.symmetry.iter().any(|sp| {
                            sp.normal == d && (sp.position - p.tip[d]).abs() <= sp.tolerance
                        })
                    })
                })
                .collect(),
            near: vec![],
            near_x: vec![],
            near_c: vec![],
        }
    }

    pub fn is_empty(&self) -> bool {
        self.projectiles.is_empty()
    }

    /// Membrane element `e` of kind `kind` has failed: its face triangles and centroid
    /// leave the projectiles' targets, its edges keep the mass of the faces still on them
    /// and leave with the last.
    pub fn erode(&mut self, kind: ElementKind, e: usize) {
        let f = match kind {
            ElementKind::Tri => e,
            ElementKind::Quad => self.n_tri_faces + e,
            _ => return,
        };
        let Some(&(first, end)) = self.face_tri_range.get(f) else {
            return;
        };
        if !self.tri_alive[first as usize] {
            return;
        }
        for t in first..end {
            self.tri_alive[t as usize] = false;
        }
        let (own, mf) = self.face_samples[f];
        let n = own[1..].iter().filter(|&&k| k != u32::MAX).count();
        for (j, &k) in own.iter().enumerate().filter(|(_, &k)| k != u32::MAX) {
            let k = k as usize;
            self.sample_faces[k] -= 1;
            if j > 0 {
                self.samples[k].mass -= 0.5 * mf / n as f64;
            }
        }
    }

    /// Node penalties κ_c m_i/Δt², once the step is known.
    pub fn set_step(&mut self, mass: &[f64], dt: f64) {
        self.k_node = mass
            .iter()
            .map(|m| PENALTY_FACTOR * m / (dt * dt))
            .collect();
    }

    /// Penalty contact of every projectile against every node with mass and (when
    /// asked) the faces, at x^n: forces on the nodes into `fcon` (the nodes touched are
    /// pushed on `touched`), the opposite force on each projectile. Per projectile, in
    /// this order (the sums' order): its nodes ([`ProjectileContact::node_forces`]), then
    /// with `segments` its face triangles for a spherical nose
    /// ([`ProjectileContact::triangle_forces`]) or its face sample points for a flat one
    /// ([`ProjectileContact::sample_forces`]).
    #[allow(clippy::too_many_arguments)]
    pub fn forces(
        &mut self,
        x: &[[f64; 3]],
        v: &[[f64; 3]],
        mass: &[f64],
        dt: f64,
        dt_prev: f64,
        fcon: &mut [[f64; 3]],
        touched: &mut Vec<usize>,
    ) {
        self.update_near(x);
        self.book_pending(v, dt_prev);
        let mut out = PassOut {
            fcon,
            touched,
            ftot: [0.0; 3],
        };
        let step = Pass {
            x,
            v,
            dt2: dt * dt,
            half: 0.5 * dt_prev,
        };
        for k in 0..self.projectiles.len() {
            out.ftot = [0.0; 3];
            self.node_forces(k, &step, mass, &mut out);
            let p = &self.projectiles[k];
            if p.segments && p.nose_centre().is_some() {
                self.triangle_forces(k, &step, &mut out);
            } else if p.segments {
                self.sample_forces(k, &step, &mut out);
            }
            self.projectiles[k].force = out.ftot;
        }
    }

    /// Projectile `k` against every node with mass inside it: the penalty, with the
    /// dashpot and the friction when it has them (their work booked by the midpoint
    /// rule, [`Pending`]).
    fn node_forces(&mut self, k: usize, step: &Pass, mass: &[f64], out: &mut PassOut) {
        let (x, v, half) = (step.x, step.v, step.half);
        let p = &self.projectiles[k];
        // The nodes inside, found in parallel and applied in node order (the same sums
        // whatever the threads).
        let inside: Vec<(usize, f64, [f64; 3])> = (0..x.len())
            .into_par_iter()
            .with_min_len(4096)
            .filter_map(|i| {
                if mass[i] <= 0.0 {
                    return None;
                }
                p.penetration(&x[i]).map(|(g, n)| (i, g, n))
            })
            .collect();
        for (i, g, n) in inside {
            let kn = p.stiffness.unwrap_or(self.k_node[i]);
            let mut fnorm = kn * g;
            let vr = [v[i][0] - p.v[0], v[i][1] - p.v[1], v[i][2] - p.v[2]];
            // (fdamp, its work over this half step), (ffric, its work): booked by the
            // midpoint rule, this half step now, the next with the next pass (`Pending`).
            let (mut fdamp, mut wd, mut ffric, mut wf) = ([0.0; 3], 0.0, [0.0; 3], 0.0);
            if p.damping > 0.0 {
                // A dashpot on the approach speed, never pulling the node back
                // (LS-DYNA's VDC); its work on the node is dissipated.
                let vn = vr[0] * n[0] + vr[1] * n[1] + vr[2] * n[2];
                let fd = (-2.0 * p.damping * (kn * mass[i]).sqrt() * vn).max(-fnorm);
                fnorm += fd;
                (fdamp, wd) = ([n[0] * fd, n[1] * fd, n[2] * fd], -fd * vn * half);
            }
            let mut f = [n[0] * fnorm, n[1] * fnorm, n[2] * fnorm];
            if p.friction > 0.0 {
                let (ft, power) = friction(&n, fnorm, &vr, p.friction);
                f = [f[0] + ft[0], f[1] + ft[1], f[2] + ft[2]];
                (ffric, wf) = (ft, power * half);
            }
            if p.damping > 0.0 || p.friction > 0.0 {
                let q = Pending::at_node(k, i, fdamp, ffric);
                self.damping_work += q.book_first_half(&mut self.node_friction, wd);
                self.friction_work += q.book_first_half(&mut self.node_friction, wf);
                self.pending.push(q);
            }
            out.push_node(i, &f);
        }
    }

    /// Projectile `k`'s spherical nose against the face triangles of its list (exact:
    /// the sphere against each triangle's closest point), with friction.
    fn triangle_forces(&mut self, k: usize, step: &Pass, out: &mut PassOut) {
        let (x, v) = (step.x, step.v);
        let p = &self.projectiles[k];
        let c = p.nose_centre().expect("spherical nose");
        // Only the listed triangles: the others are farther than the radius. The
        // contacts are found in parallel and applied in list order (the same sums
        // whatever the threads; measured, this loop alone was ~3 % of a woven impact's
        // CPU time and ran on one thread).
        let (tris, tri_alive) = (&self.face_tris, &self.tri_alive);
        let hits: Vec<TriangleHit> = self.near[k]
            .par_iter()
            .with_min_len(256)
            .filter_map(|&ti| {
                if !tri_alive[ti as usize] {
                    return None;
                }
                sphere_face(p, &c, &tris[ti as usize], x, step.dt2)
                    .map(|(w, n, g, kp)| (ti, w, n, g, kp))
            })
            .collect();
        for (ti, w, n, g, kp) in hits {
            let t = &self.face_tris[ti as usize];
            let fnorm = kp * g;
            let mut f = [n[0] * fnorm, n[1] * fnorm, n[2] * fnorm];
            if p.friction > 0.0 {
                let vq: [f64; 3] =
                    std::array::from_fn(|d| (0..3).map(|a| w[a] * v[t.nodes[a] as usize][d]).sum());
                let vr = [vq[0] - p.v[0], vq[1] - p.v[1], vq[2] - p.v[2]];
                let (ft, power) = friction(&n, fnorm, &vr, p.friction);
                f = [f[0] + ft[0], f[1] + ft[1], f[2] + ft[2]];
                let q = Pending::at_point(k, &t.nodes, &w, ft);
                self.friction_work += q.book_first_half(&mut self.node_friction, power * step.half);
                self.pending.push(q);
            }
            out.push_point(&t.nodes, &w, &f);
        }
    }

    /// Projectile `k`'s flat nose against the face sample points still on a face, with
    /// friction.
    fn sample_forces(&mut self, k: usize, step: &Pass, out: &mut PassOut) {
        let (x, v) = (step.x, step.v);
        let p = &self.projectiles[k];
        for (sp, &live) in self.samples.iter().zip(&self.sample_faces) {
            if live == 0 {
                continue;
            }
            let nodes = &sp.nodes[..sp.n];
            let pos: [f64; 3] =
                std::array::from_fn(|d| (0..sp.n).map(|a| sp.w[a] * x[nodes[a] as usize][d]).sum());
            let Some((g, n)) = p.penetration(&pos) else {
                continue;
            };
            let fnorm = sample_penalty(p, sp, step.dt2) * g;
            let mut f = [n[0] * fnorm, n[1] * fnorm, n[2] * fnorm];
            if p.friction > 0.0 {
                let vp: [f64; 3] = std::array::from_fn(|d| {
                    (0..sp.n).map(|a| sp.w[a] * v[nodes[a] as usize][d]).sum()
                });
                let vr = [vp[0] - p.v[0], vp[1] - p.v[1], vp[2] - p.v[2]];
                let (ft, power) = friction(&n, fnorm, &vr, p.friction);
                f = [f[0] + ft[0], f[1] + ft[1], f[2] + ft[2]];
                let q = Pending::at_point(k, nodes, &sp.w[..sp.n], ft);
                self.friction_work += q.book_first_half(&mut self.node_friction, power * step.half);
                self.pending.push(q);
            }
            out.push_point(nodes, &sp.w[..sp.n], &f);
        }
    }

    /// The second half of the last pass's dissipative work ([`Pending`]): its forces
    /// against the velocities v^{n+½} of this pass over the step just taken, `dt_prev`.
    fn book_pending(&mut self, v: &[[f64; 3]], dt_prev: f64) {
        let half = 0.5 * dt_prev;
        for q in self.pending.drain(..) {
            let vp = &self.projectiles[q.projectile as usize].v;
            let vr = q.relative_velocity(v, vp);
            let wd = -dot(&q.damping, &vr) * half;
            let w = -dot(&q.friction, &vr) * half;
            self.damping_work += wd;
            self.friction_work += w;
            if let Some(nf) = self.node_friction.as_mut() {
                for a in 0..q.n as usize {
                    nf[q.nodes[a] as usize] += q.w[a] * (w + wd);
                }
            }
        }
    }

    /// Keep each spherical nose's list of nearby face triangles valid: a triangle left
    /// out was at least R + skin from the nose centre when listed, and the distance from
    /// a point to a triangle changes by at most the point's move plus the largest move of
    /// the triangle's nodes; so the list stands while the nose centre's move plus the
    /// largest node move stay within the skin, and is rebuilt when they do not.
    fn update_near(&mut self, x: &[[f64; 3]]) {
        let spheres: Vec<Option<([f64; 3], f64)>> = self
            .projectiles
            .iter()
            .map(|p| {
                p.nose_centre()
                    .filter(|_| p.segments)
                    .map(|c| (c, SKIN * p.radius))
            })
            .collect();
        if spheres.iter().all(|s| s.is_none()) {
            return;
        }
        let fresh = self.near_x.len() == x.len() && self.near.len() == spheres.len() && {
            let moved = x
                .par_iter()
                .zip(self.near_x.par_iter())
                .map(|(a, b)| {
                    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
                    dot(&d, &d)
                })
                .reduce(|| 0.0, f64::max)
                .sqrt();
            spheres.iter().zip(&self.near_c).all(|(s, cb)| match s {
                Some((c, skin)) => {
                    let d = [c[0] - cb[0], c[1] - cb[1], c[2] - cb[2]];
                    moved + dot(&d, &d).sqrt() <= *skin
                }
                None => true,
            })
        };
        if fresh {
            return;
        }
        self.near_x = x.to_vec();
        self.near_c = spheres
            .iter()
            .map(|s| s.map_or([0.0; 3], |s| s.0))
            .collect();
        let tris = &self.face_tris;
        self.near = spheres
            .iter()
            .zip(&self.projectiles)
            .map(|(s, p)| {
                let Some((c, skin)) = s else {
                    return vec![];
                };
                let reach = p.radius + skin;
                tris.par_iter()
                    .enumerate()
                    .filter(|(_, t)| {
                        let xs = t.nodes.map(|n| x[n as usize]);
                        let d0 = [xs[0][0] - c[0], xs[0][1] - c[1], xs[0][2] - c[2]];
                        let e = (1..3)
                            .map(|a| {
                                let d = [
                                    xs[a][0] - xs[0][0],
                                    xs[a][1] - xs[0][1],
                                    xs[a][2] - xs[0][2],
                                ];
                                dot(&d, &d)
                            })
                            .fold(0.0, f64::max)
                            .sqrt();
                        dot(&d0, &d0).sqrt() < reach + e
                    })
                    .map(|(i, _)| i as u32)
                    .collect()
            })
            .collect();
    }

    /// Stored penalty energy ½ Σ k g² at the positions `x`. The terms are found in
    /// parallel and summed in triangle and node order (the same sum whatever the threads;
    /// measured, the serial loops over every face triangle were ~1 % of a woven impact's
    /// CPU time, on one thread while the other waited).
    pub fn energy(&self, x: &[[f64; 3]], mass: &[f64], dt: f64) -> f64 {
        let dt2 = dt * dt;
        let mut e = 0.0;
        for p in self.projectiles.iter().filter(|p| p.segments) {
            if let Some(c) = p.nose_centre() {
                let terms: Vec<f64> = self
                    .face_tris
                    .par_iter()
                    .zip(self.tri_alive.par_iter())
                    .with_min_len(4096)
                    .filter_map(|(t, &live)| {
                        if !live {
                            return None;
                        }
                        sphere_face(p, &c, t, x, dt2).map(|(_, _, g, kp)| 0.5 * kp * g.powi(2))
                    })
                    .collect();
                for t in terms {
                    e += t;
                }
                continue;
            }
            for (sp, &live) in self.samples.iter().zip(&self.sample_faces) {
                if live == 0 {
                    continue;
                }
                let nodes = &sp.nodes[..sp.n];
                let pos: [f64; 3] = std::array::from_fn(|d| {
                    (0..sp.n).map(|a| sp.w[a] * x[nodes[a] as usize][d]).sum()
                });
                if let Some((g, _)) = p.penetration(&pos) {
                    e += 0.5 * sample_penalty(p, sp, dt2) * g * g;
                }
            }
        }
        for p in &self.projectiles {
            let terms: Vec<f64> = (0..x.len())
                .into_par_iter()
                .with_min_len(4096)
                .filter_map(|i| {
                    if mass[i] <= 0.0 {
                        return None;
                    }
                    p.penetration(&x[i])
                        .map(|(g, _)| 0.5 * p.stiffness.unwrap_or(self.k_node[i]) * g * g)
                })
                .collect();
            for t in terms {
                e += t;
            }
        }
        e
    }

    /// Advance the projectiles (central difference, like the nodes); returns their
    /// kinetic energy at t_n (free ones) and keeps their velocity at t_n in `v_full`.
    pub fn advance(&mut self, dt_prev: f64, dt_next: f64) -> f64 {
        let mut ke = 0.0;
        for (p, fixed) in self.projectiles.iter_mut().zip(&self.fixed) {
            if p.prescribed {
                // The work the imposed motion does on the system.
                self.prescribed_work -= dt_next * dot(&p.force, &p.v);
                p.v_full = p.v;
            } else {
                // In a symmetric model the projectile stays on the symmetry planes.
                let a: [f64; 3] =
                    std::array::from_fn(|d| if fixed[d] { 0.0 } else { p.force[d] / p.mass });
                let vn: [f64; 3] = std::array::from_fn(|d| p.v[d] + 0.5 * dt_prev * a[d]);
                let v_new: [f64; 3] = std::array::from_fn(|d| vn[d] + 0.5 * dt_next * a[d]);
                // ½ M v^{n−½}·v^{n+½}, as the nodes' (`integrator::advance_nodes`).
                ke += 0.5 * p.mass * dot(&p.v, &v_new);
                p.v = v_new;
                p.v_full = vn;
            }
            for d in 0..3 {
                p.tip[d] += dt_next * p.v[d];
            }
        }
        ke
    }
}
