//! Explicit central-difference solver with lumped masses.
//!
//! Glossary: n step index; t_n time; x^n positions; v^{n−½} half-step velocities;
//! Δt^{n+½} = t_{n+1} − t_n; a^n = M⁻¹(f_ext^n + f_int^n); α mass-proportional damping
//! [1/s]; u = x − X displacement.
//!
//! One step (Belytschko, Liu, Moran, *Nonlinear Finite Elements*, Box 6.1, with the
//! damping force −α m v^n evaluated at the full step):
//!   v^n     = (v^{n−½} + ½ Δt^{n−½} a^n) / (1 + ½ α Δt^{n−½})
//!   v^{n+½} = v^n (1 − ½ α Δt^{n+½}) + ½ Δt^{n+½} a^n
//!   x^{n+1} = x^n + Δt^{n+½} v^{n+½}
//! At n = 0, Δt^{−½} = 0, so v^0 is the initial velocity and the first step is the
//! usual half step.
//!
//! Phases of a step: loads (f_ext at t_n, external work) → element forces (per element,
//! in parallel chunks, into a per-element force buffer) → node update (each node gathers
//! its elements' forces in a fixed order through a node→slot index, then advances).
//! Every sum runs in an order that does not depend on the thread count, and reductions
//! use fixed chunks summed in chunk order, so results are bit-identical for any number of
//! threads. Buffers are allocated once at setup; the step allocates nothing.
//!
//! Stable step: a nodal Gershgorin bound. For elements joining nodes a, b with axial
//! stiffness k_e, Σ_e k_e (e·(u_a − u_b))² ≤ Σ_e k_e · 2(|u_a|² + |u_b|²), so the Rayleigh
//! quotient of M⁻¹K, hence ω_max², is bounded by max_i S_i/m_i with S_i = Σ_{e∋i} 2 k_e
//! (k_e alone when the other node is fully fixed). This is exact for a uniform chain of
//! trusses (Δt = L/c) and for a mass on a spring to ground (Δt = 2√(m/k)), and accounts
//! for point masses, links and mass scaling without special cases. With dashpots
//! (C_i = Σ 2 c_e, same rule) and mass damping, ξ_i = (C_i/m_i + α)/(2ω_i)
//! and Δt_i = (2/ω_i)(√(1+ξ_i²) − ξ_i) (Belytschko et al. eq. 6.2.23). The step is
//! safety × min_i Δt_i; the report names the node and its stiffest element.

pub mod beam;
pub mod contact;
pub mod link;
pub mod membrane;
pub mod output;
pub mod statics;
pub mod truss;

use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::error::{Result, WeftError};
use crate::model::{ElementKind, Load, Model};
use link::{LinkProps, LinkState};

/// Elements per parallel chunk. Fixed, so that chunked reductions do not depend on the
/// thread count; large enough (≈50 kB of element data) to amortise task overhead, small
/// enough that a 10⁴-element model splits evenly over two threads.
pub const CHUNK: usize = 1024;

/// The energy-balance stop applies from this step on. In the first steps every energy
/// is O(Δt⁴) and the trapezoidal external work lags the kinetic energy by a relative O(1)
/// (Belytschko et al. §6.2.3); an instability grows exponentially and is caught soon
/// after. NaN and infinity are caught from the first step.
pub const ENERGY_CHECK_AFTER: u64 = 100;

/// Trusses, struct-of-arrays.
#[derive(Debug, Clone, Default)]
pub struct TrussGroup {
    pub id: Vec<i64>,
    pub nodes: Vec<[u32; 2]>,
    /// Axial stiffness E·A/L₀ [N/m].
    pub k: Vec<f64>,
    /// Initial length L₀ [m].
    pub l0: Vec<f64>,
    pub tension_only: Vec<bool>,
    /// First slot of this group in the element-force buffer.
    pub slot0: usize,
}

/// Links, struct-of-arrays.
#[derive(Debug, Clone, Default)]
pub struct LinkGroup {
    pub id: Vec<i64>,
    pub nodes: Vec<[u32; 2]>,
    pub props: Vec<LinkProps>,
    /// Initial offset X₂ − X₁ [m].
    pub d0: Vec<[f64; 3]>,
    pub state: Vec<LinkState>,
    pub slot0: usize,
}

/// Membrane elements with `N` nodes (3: triangles, 4: quads), struct-of-arrays.
#[derive(Debug, Clone, Default)]
pub struct MembraneGroup<const N: usize> {
    pub id: Vec<i64>,
    pub nodes: Vec<[u32; N]>,
    pub reference: Vec<membrane::Reference<N>>,
    pub material: Vec<membrane::Material>,
    pub thickness: Vec<f64>,
    /// Hourglass stiffness k_hg [N/m] (quads).
    pub k_hg: Vec<f64>,
    /// Largest eigenvalue of the element stiffness [N/m] (stable step).
    pub k_max: Vec<f64>,
    /// Element mass ρ s A₀ [kg].
    pub mass: Vec<f64>,
    pub slot0: usize,
}

impl<const N: usize> MembraneGroup<N> {
    fn build(m: &Model, kind: ElementKind, mass: &mut [f64]) -> Result<Self> {
        let mut g = MembraneGroup::<N> {
            id: vec![],
            nodes: vec![],
            reference: vec![],
            material: vec![],
            thickness: vec![],
            k_hg: vec![],
            k_max: vec![],
            mass: vec![],
            slot0: 0,
        };
        let Some(b) = m.block(kind) else { return Ok(g) };
        for e in 0..b.len() {
            let part = &m.parts[b.part[e]];
            let p = &part.props;
            let ns: [usize; N] = std::array::from_fn(|a| b.nodes[N * e + a]);
            let x: [[f64; 3]; N] = std::array::from_fn(|a| m.coords[ns[a]]);
            let r = membrane::Reference::<N>::new(&x, p.material_angle.unwrap_or(0.0)).ok_or_else(
                || {
                    WeftError::input(format!(
                        "{} `{}` is degenerate: zero area, inverted or (quad) not convex; nodes {}",
                        kind.name(),
                        b.id[e],
                        ns.iter()
                            .map(|&n| format!("`{}`", m.node_id[n]))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
                    .in_file(format!("elements_{}.parquet", kind.name()))
                    .at_row(e)
                    .expected(
                        "nodes in counter-clockwise order around a convex element of positive area",
                    )
                },
            )?;
            let mat = membrane::Material::orthotropic(
                p.youngs_modulus_1.unwrap(),
                p.youngs_modulus_2.unwrap(),
                p.poisson_ratio_12.unwrap_or(0.0),
                p.shear_modulus_12.unwrap(),
                p.no_compression.unwrap_or(false),
            )
            .map_err(|err| err.in_file("parts.parquet").in_column("poisson_ratio_12"))?;
            let s = p.thickness.unwrap();
            let k_hg = if N == 4 {
                p.hourglass_coefficient() * mat.e_max() * s * r.area * r.grad2()
            } else {
                0.0
            };
            let me = p.density.unwrap() * s * r.area;
            for &n in &ns {
                mass[n] += me / N as f64;
            }
            g.k_max.push(membrane::max_stiffness(&r, &mat, s, k_hg));
            g.mass.push(me);
            g.id.push(b.id[e]);
            g.nodes.push(std::array::from_fn(|a| ns[a] as u32));
            g.reference.push(r);
            g.material.push(mat);
            g.thickness.push(s);
            g.k_hg.push(k_hg);
        }
        Ok(g)
    }

    fn forces(&self, x: &[[f64; 3]], fe: &mut [[f64; 3]]) {
        let body = |(ci, out): (usize, &mut [[f64; 3]])| {
            let e0 = ci * CHUNK;
            for (j, el) in out.chunks_exact_mut(N).enumerate() {
                let e = e0 + j;
                let nodes = &self.nodes[e];
                let xe: [[f64; 3]; N] = std::array::from_fn(|a| x[nodes[a] as usize]);
                let f = membrane::forces(
                    &xe,
                    &self.reference[e],
                    &self.material[e],
                    self.thickness[e],
                    self.k_hg[e],
                );
                el.copy_from_slice(&f);
            }
        };
        if self.id.len() <= CHUNK {
            fe.chunks_mut(N * CHUNK).enumerate().for_each(body);
        } else {
            fe.par_chunks_mut(N * CHUNK).enumerate().for_each(body);
        }
    }

    /// Per-chunk (membrane, hourglass) energies into `out`.
    fn energies(&self, x: &[[f64; 3]], out: &mut [[f64; 3]]) {
        out.par_iter_mut()
            .enumerate()
            .with_min_len(4)
            .for_each(|(ci, o)| {
                let mut acc = [0.0; 3];
                for e in ci * CHUNK..((ci + 1) * CHUNK).min(self.id.len()) {
                    let nodes = &self.nodes[e];
                    let xe: [[f64; 3]; N] = std::array::from_fn(|a| x[nodes[a] as usize]);
                    let (w, h) = membrane::energy(
                        &xe,
                        &self.reference[e],
                        &self.material[e],
                        self.thickness[e],
                        self.k_hg[e],
                    );
                    acc[0] += w;
                    acc[1] += h;
                }
                *o = acc;
            });
    }
}

/// Beams, struct-of-arrays; their nodes carry rotations.
#[derive(Debug, Clone, Default)]
pub struct BeamGroup {
    pub id: Vec<i64>,
    pub nodes: Vec<[u32; 2]>,
    /// Rotation indices of the two nodes.
    pub rot: Vec<[u32; 2]>,
    pub props: Vec<beam::BeamProps>,
    pub slot0: usize,
}

/// Rotational state of the nodes that carry beams.
#[derive(Debug, Clone, Default)]
pub struct Rotations {
    /// Node index of each rotational node.
    pub node: Vec<usize>,
    /// Orientation R (global).
    pub r: Vec<beam::Mat3>,
    /// Half-step angular velocity ω^{n−½} (global) [rad/s].
    pub omega: Vec<[f64; 3]>,
    /// Lumped rotational inertia J [kg·m²].
    pub j: Vec<f64>,
    /// Bit d set when the rotation about axis d is fixed.
    pub fixed: Vec<u8>,
    /// Moment slots per rotational node (CSR).
    ptr: Vec<u32>,
    slots: Vec<u32>,
    /// Per-beam end moments, two slots per beam.
    me: Vec<[f64; 3]>,
}

/// The stable time step and what controls it.
#[derive(Debug, Clone)]
pub struct StableStep {
    /// The step used [s].
    pub dt: f64,
    /// The stable step estimate without the safety factor [s].
    pub dt_stable: f64,
    /// Node that controls the step (index).
    pub node: usize,
    /// Its stiffest element.
    pub element: Option<(ElementKind, i64)>,
}

/// Mass added by mass scaling.
#[derive(Debug, Clone, Default)]
pub struct MassScaling {
    /// Stable step before scaling [s] (without safety factor).
    pub dt_stable_unscaled: f64,
    pub added_mass: f64,
    /// Added mass over the model's physical mass.
    pub added_fraction: f64,
    pub nodes_scaled: usize,
    /// Largest nodal mass ratio m_scaled / m.
    pub max_ratio: f64,
}

/// Energies at one time [J].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energies {
    pub kinetic: f64,
    /// Stored elastic energy of all elements.
    pub internal: f64,
    /// Dissipated by dashpots and mass-proportional damping.
    pub damping: f64,
    /// Dissipated by friction sliders.
    pub friction: f64,
    /// Hourglass energy (membrane elements; 0 until they exist).
    pub hourglass: f64,
    /// Contact energy (projectile contact; 0 until it exists).
    pub contact: f64,
    pub external_work: f64,
    /// kinetic + internal + damping + friction + hourglass + contact − initial − external work.
    pub balance_error: f64,
    /// |balance_error| over the reference energy max(initial, |external work|,
    /// kinetic + internal).
    pub balance_error_relative: f64,
}

impl Energies {
    fn lerp(&self, o: &Energies, w: f64) -> Energies {
        let l = |a: f64, b: f64| a + w * (b - a);
        Energies {
            kinetic: l(self.kinetic, o.kinetic),
            internal: l(self.internal, o.internal),
            damping: l(self.damping, o.damping),
            friction: l(self.friction, o.friction),
            hourglass: l(self.hourglass, o.hourglass),
            contact: l(self.contact, o.contact),
            external_work: l(self.external_work, o.external_work),
            balance_error: l(self.balance_error, o.balance_error),
            balance_error_relative: l(self.balance_error_relative, o.balance_error_relative),
        }
    }
}

/// Receives the output samples on the output time grid.
pub trait Sink {
    /// Displacements and velocities of the output nodes at time t.
    fn history(&mut self, t: f64, nodes: &[usize], u: &[[f64; 3]], v: &[[f64; 3]]) -> Result<()>;
    fn energy(&mut self, t: f64, e: &Energies) -> Result<()>;
    /// A projectile at time t: tip position, velocity, contact force on it.
    fn projectile(&mut self, _t: f64, _id: i64, _state: &[f64; 9]) -> Result<()> {
        Ok(())
    }
}

/// Wall time per phase.
#[derive(Debug, Clone, Default)]
pub struct PhaseTimes {
    pub setup: Duration,
    pub loads: Duration,
    pub forces: Duration,
    pub update: Duration,
    pub output: Duration,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct RunStats {
    pub steps: u64,
    pub end_time: f64,
    pub times: PhaseTimes,
    pub threads: usize,
    pub max_balance_error_relative: f64,
    pub final_energies: Energies,
    pub elements: usize,
    pub nodes: usize,
}

impl RunStats {
    /// Element updates per second over the force and node-update phases.
    pub fn element_updates_per_second(&self) -> f64 {
        let s = (self.times.forces + self.times.update + self.times.loads).as_secs_f64();
        if s > 0.0 {
            self.steps as f64 * self.elements as f64 / s
        } else {
            0.0
        }
    }
}

#[derive(Debug, Clone, Copy, Default)]
struct NodePartial {
    ke: f64,
    damp_power: f64,
    bad: usize,
}

/// One snapshot of the output nodes at a step.
#[derive(Debug, Clone, Default)]
struct Snapshot {
    t: f64,
    u: Vec<[f64; 3]>,
    v: Vec<[f64; 3]>,
    e: Energies,
    /// Per projectile: tip x, y, z, velocity, contact force.
    proj: Vec<[f64; 9]>,
}

/// The explicit solver: owns the state and scratch buffers of one model.
pub struct Solver {
    pub node_id: Vec<i64>,
    pub x0: Vec<[f64; 3]>,
    /// Positions x^n.
    pub x: Vec<[f64; 3]>,
    /// Half-step velocities v^{n−½}.
    pub v: Vec<[f64; 3]>,
    /// Lumped nodal masses (with mass scaling) [kg].
    pub mass: Vec<f64>,
    /// Physical model mass (without scaling) [kg].
    pub physical_mass: f64,
    inv_m: Vec<f64>,
    /// Bit d set when direction d is fixed.
    fixed: Vec<u8>,
    fext: Vec<[f64; 3]>,
    slot_ptr: Vec<u32>,
    slots: Vec<u32>,
    /// Per-element nodal forces, one slot per element node.
    fe: Vec<[f64; 3]>,
    pub truss: TrussGroup,
    pub link: LinkGroup,
    pub tri: MembraneGroup<3>,
    pub quad: MembraneGroup<4>,
    pub beam: BeamGroup,
    pub rot: Rotations,
    /// Rotational node of each node (u32::MAX: none).
    pub rot_of: Vec<u32>,
    /// Rigid projectiles.
    pub projectiles: Vec<contact::Projectile>,
    /// Contact sample points on the membrane faces (centroids, edge midpoints), for
    /// flat noses.
    samples: Vec<contact::SamplePoint>,
    /// Face triangles (quads split along both diagonals) with their masses, for
    /// spherical noses.
    face_tris: Vec<([u32; 3], f64)>,
    /// Contact forces on nodes, and the nodes that carry one.
    fcon: Vec<[f64; 3]>,
    con_nodes: Vec<usize>,
    /// Default penalty stiffness per node κ_c m/Δt² [N/m].
    k_contact: Vec<f64>,
    /// Friction work dissipated in contact [J].
    e_contact_friction: f64,
    /// Work done by projectiles with prescribed velocity [J].
    w_prescribed: f64,
    /// Directions normal to the symmetry planes: projectiles cannot move along them.
    proj_fixed: [bool; 3],
    /// Tied slave nodes: (slave, masters, weights).
    pub ties: Vec<(usize, Vec<usize>, Vec<f64>)>,
    loads: Vec<Load>,
    loaded_nodes: Vec<usize>,
    fext_prev: Vec<[f64; 3]>,
    /// Output nodes (indices).
    pub output_nodes: Vec<usize>,
    xn: Vec<[f64; 3]>,
    vn: Vec<[f64; 3]>,
    partials: Vec<NodePartial>,
    /// Per-chunk energy sums: truss chunks, then link chunks.
    energy_partials: Vec<[f64; 3]>,
    /// Per-chunk (membrane, hourglass) sums: triangle chunks, then quad chunks.
    membrane_partials: Vec<[f64; 3]>,
    alpha: f64,
    pub t: f64,
    pub step: u64,
    dt_prev: f64,
    w_ext: f64,
    e_mass_damp: f64,
    pub stable: StableStep,
    pub scaling: Option<MassScaling>,
    pub analysis: crate::model::Analysis,
}

fn add(a: &mut [f64; 3], b: &[f64; 3]) {
    a[0] += b[0];
    a[1] += b[1];
    a[2] += b[2];
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Weights of a point on a master edge (2 nodes: projection), triangle (barycentric) or
/// quad (inverse bilinear map), and the distance of the point from the master entity.
pub fn tie_weights(p: &[f64; 3], m: &[[f64; 3]]) -> (Vec<f64>, f64) {
    let sub = |a: &[f64; 3], b: &[f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let lerp_err = |w: &[f64]| {
        let q: [f64; 3] = std::array::from_fn(|d| (0..m.len()).map(|a| w[a] * m[a][d]).sum());
        let e = sub(p, &q);
        dot(&e, &e).sqrt()
    };
    match m.len() {
        2 => {
            let e = sub(&m[1], &m[0]);
            let t = dot(&sub(p, &m[0]), &e) / dot(&e, &e);
            let w = vec![1.0 - t, t];
            let d = lerp_err(&w);
            (w, d)
        }
        3 => {
            let (e1, e2, r) = (sub(&m[1], &m[0]), sub(&m[2], &m[0]), sub(p, &m[0]));
            let (a, b, c) = (dot(&e1, &e1), dot(&e1, &e2), dot(&e2, &e2));
            let (d1, d2) = (dot(&r, &e1), dot(&r, &e2));
            let det = a * c - b * b;
            let (u, v) = ((c * d1 - b * d2) / det, (a * d2 - b * d1) / det);
            let w = vec![1.0 - u - v, u, v];
            let d = lerp_err(&w);
            (w, d)
        }
        _ => {
            // Newton on the bilinear map x(ξ, η) = Σ N_a x_a, least squares in 3-D.
            let (mut xi, mut eta) = (0.0f64, 0.0f64);
            let sh = |xi: f64, eta: f64| {
                [
                    0.25 * (1.0 - xi) * (1.0 - eta),
                    0.25 * (1.0 + xi) * (1.0 - eta),
                    0.25 * (1.0 + xi) * (1.0 + eta),
                    0.25 * (1.0 - xi) * (1.0 + eta),
                ]
            };
            for _ in 0..30 {
                let n = sh(xi, eta);
                let x: [f64; 3] = std::array::from_fn(|d| (0..4).map(|a| n[a] * m[a][d]).sum());
                let dxi: [f64; 3] = std::array::from_fn(|d| {
                    0.25 * (-(1.0 - eta) * m[0][d] + (1.0 - eta) * m[1][d] + (1.0 + eta) * m[2][d]
                        - (1.0 + eta) * m[3][d])
                });
                let deta: [f64; 3] = std::array::from_fn(|d| {
                    0.25 * (-(1.0 - xi) * m[0][d] - (1.0 + xi) * m[1][d]
                        + (1.0 + xi) * m[2][d]
                        + (1.0 - xi) * m[3][d])
                });
                let r = sub(p, &x);
                let (a, b, c) = (dot(&dxi, &dxi), dot(&dxi, &deta), dot(&deta, &deta));
                let (g1, g2) = (dot(&r, &dxi), dot(&r, &deta));
                let det = a * c - b * b;
                if det.abs() < f64::MIN_POSITIVE {
                    break;
                }
                xi += (c * g1 - b * g2) / det;
                eta += (a * g2 - b * g1) / det;
            }
            let w = sh(xi, eta).to_vec();
            let d = lerp_err(&w);
            (w, d)
        }
    }
}

/// Stable step of one node: Δt = (2/ω)(√(1+ξ²) − ξ), ω² = S/m, 2ξω = C/m + α.
fn nodal_dt(s: f64, c: f64, m: f64, alpha: f64) -> f64 {
    let damp = c / m + alpha;
    if s <= 0.0 {
        return if damp > 0.0 {
            2.0 / damp
        } else {
            f64::INFINITY
        };
    }
    let w = (s / m).sqrt();
    let xi = damp / (2.0 * w);
    (2.0 / w) * ((1.0 + xi * xi).sqrt() - xi)
}

impl Solver {
    /// Set up a solver for a validated model: masses, element groups, the gather index,
    /// the stable step and (when asked) mass scaling.
    pub fn new(m: &Model) -> Result<Solver> {
        m.validate()?;
        let nn = m.num_nodes();
        if nn >= u32::MAX as usize {
            return Err(WeftError::input(format!(
                "{nn} nodes exceed the solver's limit of 2³²−1"
            )));
        }
        let mut mass = vec![0.0; nn];
        let mut truss = TrussGroup::default();
        let mut linkg = LinkGroup::default();
        if let Some(b) = m.block(ElementKind::Truss) {
            for e in 0..b.len() {
                let p = &m.parts[b.part[e]].props;
                let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
                let d = [
                    m.coords[c][0] - m.coords[a][0],
                    m.coords[c][1] - m.coords[a][1],
                    m.coords[c][2] - m.coords[a][2],
                ];
                let l0 = dot(&d, &d).sqrt();
                let (e_mod, rho, area) = (
                    p.youngs_modulus.unwrap(),
                    p.density.unwrap(),
                    p.area.unwrap(),
                );
                let me = rho * area * l0;
                mass[a] += 0.5 * me;
                mass[c] += 0.5 * me;
                truss.id.push(b.id[e]);
                truss.nodes.push([a as u32, c as u32]);
                // Pretension: the unstressed length is shorter than the geometric one.
                let lref = l0 / (1.0 + p.prestrain.unwrap_or(0.0));
                truss.k.push(e_mod * area / lref);
                truss.l0.push(lref);
                truss.tension_only.push(p.tension_only.unwrap_or(false));
            }
        }
        if let Some(b) = m.block(ElementKind::Link) {
            for e in 0..b.len() {
                let p = &m.parts[b.part[e]].props;
                let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
                let z = |v: Option<f64>| v.unwrap_or(0.0);
                linkg.id.push(b.id[e]);
                linkg.nodes.push([a as u32, c as u32]);
                linkg.props.push(LinkProps {
                    k: [z(p.kx), z(p.ky), z(p.kz)],
                    c: [z(p.cx), z(p.cy), z(p.cz)],
                    slip_force: p.slip_force.unwrap_or(f64::INFINITY),
                });
                linkg.d0.push([
                    m.coords[c][0] - m.coords[a][0],
                    m.coords[c][1] - m.coords[a][1],
                    m.coords[c][2] - m.coords[a][2],
                ]);
                linkg.state.push(LinkState::default());
            }
        }
        if let Some(b) = m.block(ElementKind::PointMass) {
            for e in 0..b.len() {
                mass[b.nodes[e]] += m.parts[b.part[e]].props.mass.unwrap();
            }
        }
        let mut tri = MembraneGroup::<3>::build(m, ElementKind::Tri, &mut mass)?;
        let mut quad = MembraneGroup::<4>::build(m, ElementKind::Quad, &mut mass)?;
        // Contact sample points on the faces, each with a tributary mass for its penalty:
        // half the face's mass at its centroid, the other half shared among its edges (an
        // edge collects from every face it bounds), so the penalty of a face does not
        // depend on what lies beyond it (a symmetry plane, a free edge).
        let samples = {
            let mut v = Vec::new();
            let mut edge_at: std::collections::BTreeMap<(u32, u32), usize> = Default::default();
            let faces = tri
                .nodes
                .iter()
                .map(|f| f.to_vec())
                .zip(tri.mass.iter())
                .chain(quad.nodes.iter().map(|f| f.to_vec()).zip(quad.mass.iter()));
            for (f, &mf) in faces {
                let n = f.len();
                let mut nodes = [0u32; 4];
                nodes[..n].copy_from_slice(&f);
                let mut w = [0.0; 4];
                for x in w.iter_mut().take(n) {
                    *x = 1.0 / n as f64;
                }
                v.push(contact::SamplePoint {
                    nodes,
                    w,
                    n,
                    mass: 0.5 * mf,
                });
                for a in 0..n {
                    let (p, q) = (f[a], f[(a + 1) % n]);
                    let k = *edge_at.entry((p.min(q), p.max(q))).or_insert_with(|| {
                        v.push(contact::SamplePoint {
                            nodes: [p, q, 0, 0],
                            w: [0.5, 0.5, 0.0, 0.0],
                            n: 2,
                            mass: 0.0,
                        });
                        v.len() - 1
                    });
                    v[k].mass += 0.5 * mf / n as f64;
                }
            }
            v
        };
        let face_tris: Vec<([u32; 3], f64)> = tri
            .nodes
            .iter()
            .zip(&tri.mass)
            .map(|(f, &m)| (*f, m))
            .chain(quad.nodes.iter().zip(&quad.mass).flat_map(|(f, &m)| {
                // Both diagonals, so that the split has no handedness (a mirrored mesh,
                // e.g. across a symmetry plane, gets the mirrored contact).
                [
                    ([f[0], f[1], f[2]], 0.25 * m),
                    ([f[0], f[2], f[3]], 0.25 * m),
                    ([f[1], f[2], f[3]], 0.25 * m),
                    ([f[1], f[3], f[0]], 0.25 * m),
                ]
            }))
            .collect();
        let mut beams = BeamGroup::default();
        let mut rot = Rotations::default();
        let mut rot_of = vec![u32::MAX; nn];
        if let Some(b) = m.block(ElementKind::Beam) {
            for e in 0..b.len() {
                let p = &m.parts[b.part[e]].props;
                let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
                let e0 = beam::reference_frame(&m.coords[a], &m.coords[c]).ok_or_else(|| {
                    WeftError::input(format!("beam `{}` has zero length", b.id[e]))
                        .in_file("elements_beam.parquet")
                        .at_row(e)
                        .expected("two nodes at distinct positions")
                })?;
                let d = [
                    m.coords[c][0] - m.coords[a][0],
                    m.coords[c][1] - m.coords[a][1],
                    m.coords[c][2] - m.coords[a][2],
                ];
                let l0 = dot(&d, &d).sqrt();
                let (em, rho, bw, hh) = (
                    p.youngs_modulus.unwrap(),
                    p.density.unwrap(),
                    p.width.unwrap(),
                    p.height.unwrap(),
                );
                let g = em / (2.0 * (1.0 + p.poisson_ratio.unwrap_or(0.3)));
                let area = bw * hh;
                let me = rho * area * l0;
                // Lumped rotary inertia: each half of the beam as a rigid bar about its end
                // node's centre of mass, isotropic (J = ½ m (L² + b² + h²)/12).
                let jn = 0.5 * me * (l0 * l0 + bw * bw + hh * hh) / 12.0;
                let mut rids = [0u32; 2];
                for (k, &n) in [a, c].iter().enumerate() {
                    mass[n] += 0.5 * me;
                    if rot_of[n] == u32::MAX {
                        rot_of[n] = rot.node.len() as u32;
                        rot.node.push(n);
                        rot.r
                            .push([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
                        rot.omega.push([0.0; 3]);
                        rot.j.push(0.0);
                        rot.fixed.push(0);
                    }
                    rids[k] = rot_of[n];
                    rot.j[rot_of[n] as usize] += jn;
                }
                beams.id.push(b.id[e]);
                beams.nodes.push([a as u32, c as u32]);
                beams.rot.push(rids);
                beams.props.push(beam::BeamProps {
                    l0,
                    ea: em * area,
                    gj: g * beam::torsion_constant(bw, hh),
                    eiy: em * bw * hh.powi(3) / 12.0,
                    eiz: em * hh * bw.powi(3) / 12.0,
                    e0,
                });
            }
        }
        for (n, f) in &m.rot_constraints {
            if rot_of[*n] != u32::MAX {
                for d in 0..3 {
                    if f[d] {
                        rot.fixed[rot_of[*n] as usize] |= 1 << d;
                    }
                }
            }
        }
        // On a symmetry plane with normal d the rotations about the other two axes vanish.
        for sp in &m.symmetry {
            for (k, &n) in rot.node.iter().enumerate() {
                if (m.coords[n][sp.normal] - sp.position).abs() <= sp.tolerance {
                    for d in 0..3 {
                        if d != sp.normal {
                            rot.fixed[k] |= 1 << d;
                        }
                    }
                }
            }
        }
        // Moment slots: two per beam, gathered per rotational node in slot order.
        let nr = rot.node.len();
        let mut cnt = vec![0u32; nr + 1];
        for r in beams.rot.iter().flatten() {
            cnt[*r as usize + 1] += 1;
        }
        for i in 0..nr {
            cnt[i + 1] += cnt[i];
        }
        rot.ptr = cnt.clone();
        rot.slots = vec![0; 2 * beams.id.len()];
        for (sl, r) in beams.rot.iter().flatten().enumerate() {
            rot.slots[cnt[*r as usize] as usize] = sl as u32;
            cnt[*r as usize] += 1;
        }
        rot.me = vec![[0.0; 3]; 2 * beams.id.len()];
        truss.slot0 = 0;
        linkg.slot0 = 2 * truss.id.len();
        tri.slot0 = linkg.slot0 + 2 * linkg.id.len();
        quad.slot0 = tri.slot0 + 3 * tri.id.len();
        beams.slot0 = quad.slot0 + 4 * quad.id.len();
        let nslots = beams.slot0 + 2 * beams.id.len();

        let mut fixed = vec![0u8; nn];
        for (n, f) in &m.constraints {
            for d in 0..3 {
                if f[d] {
                    fixed[*n] |= 1 << d;
                }
            }
        }

        for sp in &m.symmetry {
            for i in 0..nn {
                if (m.coords[i][sp.normal] - sp.position).abs() <= sp.tolerance {
                    fixed[i] |= 1 << sp.normal;
                }
            }
        }

        // Gather index: node → its element slots in ascending slot order.
        let mut count = vec![0u32; nn + 1];
        let slot_nodes: Vec<u32> = truss
            .nodes
            .iter()
            .chain(linkg.nodes.iter())
            .flat_map(|p| [p[0], p[1]])
            .chain(tri.nodes.iter().flatten().copied())
            .chain(quad.nodes.iter().flatten().copied())
            .chain(beams.nodes.iter().flatten().copied())
            .collect();
        for &n in &slot_nodes {
            count[n as usize + 1] += 1;
        }
        for i in 0..nn {
            count[i + 1] += count[i];
        }
        let slot_ptr = count.clone();
        let mut fill = count;
        let mut slots = vec![0u32; nslots];
        for (s, &n) in slot_nodes.iter().enumerate() {
            slots[fill[n as usize] as usize] = s as u32;
            fill[n as usize] += 1;
        }

        // Ties: weights from the reference geometry; the slave's mass goes to its masters.
        let mut ties = Vec::with_capacity(m.ties.len());
        let mut is_slave = vec![false; nn];
        for (row, t) in m.ties.iter().enumerate() {
            let mx: Vec<[f64; 3]> = t.masters.iter().map(|&a| m.coords[a]).collect();
            let (w, dist) = tie_weights(&m.coords[t.slave], &mx);
            let size = (1..mx.len())
                .map(|a| {
                    let d = [
                        mx[a][0] - mx[0][0],
                        mx[a][1] - mx[0][1],
                        mx[a][2] - mx[0][2],
                    ];
                    dot(&d, &d).sqrt()
                })
                .fold(0.0, f64::max);
            let tol = 1e-6 * size;
            if !(dist <= tol && w.iter().all(|&x| x >= -1e-9 && x <= 1.0 + 1e-9)) {
                return Err(WeftError::input(format!(
                    "tied node `{}` is not on its master {} (distance {dist:.3e} m, weights {w:?})",
                    m.node_id[t.slave],
                    if mx.len() == 2 { "edge" } else { "face" }
                ))
                .in_file("ties.parquet")
                .at_row(row)
                .expected(format!(
                    "the slave on the edge or face of its masters, within {tol:.1e} m"
                ))
                .hint(
                    "order the masters around the face, or tie the node to the entity it lies on",
                ));
            }
            let w: Vec<f64> = w.iter().map(|x| x.clamp(0.0, 1.0)).collect();
            let sum: f64 = w.iter().sum();
            let w: Vec<f64> = w.iter().map(|x| x / sum).collect();
            for (a, &mn) in t.masters.iter().enumerate() {
                mass[mn] += w[a] * mass[t.slave];
            }
            mass[t.slave] = 0.0;
            is_slave[t.slave] = true;
            ties.push((t.slave, t.masters.clone(), w));
        }

        // Nodes that can move must have mass.
        let mut loaded = vec![false; nn];
        for l in &m.loads {
            loaded[l.node] = true;
        }
        for i in 0..nn {
            let attached = slot_ptr[i + 1] > slot_ptr[i];
            if mass[i] <= 0.0 && fixed[i] != 0b111 && (attached || loaded[i]) && !is_slave[i] {
                return Err(WeftError::input(format!(
                    "node `{}` has no mass but can move and {}",
                    m.node_id[i],
                    if attached {
                        "has elements attached"
                    } else {
                        "carries a load"
                    }
                ))
                .in_file("nodes.parquet")
                .expected("mass > 0 at every free node that elements or loads act on")
                .hint(
                    "links carry no mass: attach a truss or a point_mass to the node, or fix it",
                ));
            }
        }
        let physical_mass: f64 = mass.iter().sum();

        let x = m.coords.clone();
        let mut v = vec![[0.0; 3]; nn];
        for (n, vel) in &m.initial_velocities {
            v[*n] = *vel;
        }
        let output_nodes: Vec<usize> = if m.analysis.history_sets.is_empty() {
            (0..nn).collect()
        } else {
            let mut sel = vec![false; nn];
            for s in &m.analysis.history_sets {
                let set = m.node_sets.get(s).ok_or_else(|| {
                    WeftError::input(format!("history node set `{s}` does not exist"))
                        .in_file("analysis.parquet")
                        .in_column("history_sets")
                        .expected(format!(
                            "one of the model's node sets: {}",
                            m.node_sets
                                .keys()
                                .map(|k| format!("`{k}`"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        ))
                })?;
                for &i in set {
                    sel[i] = true;
                }
            }
            (0..nn).filter(|&i| sel[i]).collect()
        };
        let mut loaded_nodes: Vec<usize> = m.loads.iter().map(|l| l.node).collect();
        loaded_nodes.sort_unstable();
        loaded_nodes.dedup();
        let nchunks = nn.div_ceil(CHUNK);
        let (truss_chunks, link_chunks) = (
            truss.id.len().div_ceil(CHUNK),
            linkg.id.len().div_ceil(CHUNK),
        );
        let mut s = Solver {
            node_id: m.node_id.clone(),
            x0: m.coords.clone(),
            x,
            v,
            inv_m: vec![0.0; nn],
            mass,
            physical_mass,
            fixed,
            fext: vec![[0.0; 3]; nn],
            slot_ptr,
            slots,
            fe: vec![[0.0; 3]; nslots],
            truss,
            link: linkg,
            membrane_partials: vec![
                [0.0; 3];
                tri.id.len().div_ceil(CHUNK) + quad.id.len().div_ceil(CHUNK)
            ],
            tri,
            quad,
            beam: beams,
            rot,
            rot_of,
            projectiles: m.projectiles.iter().map(contact::Projectile::new).collect(),
            samples,
            face_tris,
            fcon: vec![[0.0; 3]; nn],
            con_nodes: Vec::with_capacity(nn),
            k_contact: vec![0.0; nn],
            e_contact_friction: 0.0,
            w_prescribed: 0.0,
            proj_fixed: std::array::from_fn(|d| m.symmetry.iter().any(|sp| sp.normal == d)),
            ties,
            loads: m.loads.clone(),
            fext_prev: vec![[0.0; 3]; loaded_nodes.len()],
            loaded_nodes,
            output_nodes,
            xn: vec![[0.0; 3]; nn],
            vn: vec![[0.0; 3]; nn],
            partials: vec![NodePartial::default(); nchunks],
            energy_partials: vec![[0.0; 3]; truss_chunks + link_chunks],
            alpha: m.analysis.mass_damping,
            t: 0.0,
            step: 0,
            dt_prev: 0.0,
            w_ext: 0.0,
            e_mass_damp: 0.0,
            stable: StableStep {
                dt: 0.0,
                dt_stable: 0.0,
                node: 0,
                element: None,
            },
            scaling: None,
            analysis: m.analysis.clone(),
        };
        let a = &m.analysis;
        if a.time_step.is_some() && a.target_time_step.is_some() {
            return Err(
                WeftError::input("both time_step and target_time_step are set")
                    .in_file("analysis.parquet")
                    .expected(
                        "at most one: a fixed step, or a target step reached by mass scaling",
                    ),
            );
        }
        if let Some(target) = a.target_time_step {
            s.scale_mass(target, a.dt_safety);
        }
        s.update_inv_mass();
        let (dt_stable, node) = s.stable_step();
        if !dt_stable.is_finite() {
            return Err(WeftError::input(
                "no element limits the time step (the model has no stiffness)",
            )
            .expected("at least one truss, or a link with stiffness or damping")
            .hint("set `time_step` in analysis.parquet for a model of free masses"));
        }
        let dt = match (a.time_step, a.target_time_step) {
            (Some(dt), _) => {
                if dt > dt_stable {
                    let (k, id) = s
                        .controlling_element(node)
                        .unwrap_or((ElementKind::PointMass, -1));
                    return Err(WeftError::input(format!(
                        "time_step {dt:.4e} s exceeds the stable step {dt_stable:.4e} s set by node `{}` ({} `{id}`)",
                        s.node_id[node],
                        k.name()
                    ))
                    .in_file("analysis.parquet")
                    .in_column("time_step")
                    .expected(format!("a step ≤ {dt_stable:.4e} s"))
                    .hint("leave time_step empty to use the stable step, or use target_time_step for mass scaling"));
                }
                dt
            }
            (None, Some(target)) => target.min(a.dt_safety * dt_stable),
            (None, None) => a.dt_safety * dt_stable,
        };
        s.stable = StableStep {
            dt,
            dt_stable,
            node,
            element: s.controlling_element(node),
        };
        for i in 0..nn {
            s.k_contact[i] = contact::PENALTY_FACTOR * s.mass[i] / (dt * dt);
        }
        s.update_slaves(false);
        for (n, v) in &m.initial_velocities {
            if let Some((_, ms, _)) = s.ties.iter().find(|t| t.0 == *n) {
                let vs = s.v[*n];
                if (0..3).any(|d| (vs[d] - v[d]).abs() > 1e-9 * (1.0 + v[d].abs())) {
                    return Err(WeftError::input(format!(
                        "tied node `{}` is given the initial velocity {v:?}, but its masters move with {vs:?}",
                        m.node_id[*n]
                    ))
                    .in_file("initial_velocities.parquet")
                    .expected(format!("no initial velocity on a slave, or the masters' ({} nodes)", ms.len()))
                    .hint("give the initial velocity to the master nodes"));
                }
            }
        }
        Ok(s)
    }

    fn update_inv_mass(&mut self) {
        for (im, m) in self.inv_m.iter_mut().zip(&self.mass) {
            *im = if *m > 0.0 { 1.0 / m } else { 0.0 };
        }
    }

    /// Per-node stiffness and damping sums S_i = Σ 2k_e, C_i = Σ 2c_e.
    fn nodal_sums(&self) -> (Vec<f64>, Vec<f64>) {
        let nn = self.x.len();
        let (mut s, mut c) = (vec![0.0; nn], vec![0.0; nn]);
        // Row sum of |K| for node i: k_e on the diagonal, plus k_e off the diagonal when
        // the other node can move (a fully fixed node's degrees of freedom are eliminated).
        let w = |other: u32| {
            if self.fixed[other as usize] == 0b111 {
                1.0
            } else {
                2.0
            }
        };
        for (e, p) in self.truss.nodes.iter().enumerate() {
            s[p[0] as usize] += w(p[1]) * self.truss.k[e];
            s[p[1] as usize] += w(p[0]) * self.truss.k[e];
        }
        for (e, p) in self.link.nodes.iter().enumerate() {
            let pr = &self.link.props[e];
            let kmax = pr.k.iter().cloned().fold(0.0, f64::max);
            let cmax = pr.c.iter().cloned().fold(0.0, f64::max);
            for (n, o) in [(p[0], p[1]), (p[1], p[0])] {
                s[n as usize] += w(o) * kmax;
                c[n as usize] += w(o) * cmax;
            }
        }
        // Membranes: uₑᵀKₑuₑ ≤ λ_max(Kₑ) Σ_{a∈e} |u_a|², so each node of e gets λ_max(Kₑ).
        for (p, k) in self.tri.nodes.iter().zip(&self.tri.k_max) {
            for &n in p {
                s[n as usize] += k;
            }
        }
        for (p, k) in self.quad.nodes.iter().zip(&self.quad.k_max) {
            for &n in p {
                s[n as usize] += k;
            }
        }
        // Beams: row sums of M^{-1/2} K M^{-1/2}. A translational row carries the axial and
        // bending-shear terms and the coupling 12EI/L² to the rotations (scaled by
        // √(m/J) so that it adds to S/m); a rotational row carries 12EI/(L²√(mJ)) +
        // (4 + 2)EI/(L J) + 2GJ/(L J). A node's bound is the larger of the two rows.
        let mut rrow = vec![0.0; self.x.len()];
        for (e, p) in self.beam.props.iter().enumerate() {
            let [a, b] = self.beam.nodes[e];
            let ei = p.eiy.max(p.eiz);
            let l = p.l0;
            for (n, o, rk) in [(a, b, self.beam.rot[e][0]), (b, a, self.beam.rot[e][1])] {
                let (n, o) = (n as usize, o as usize);
                let (mn, jn) = (self.mass[n].max(f64::MIN_POSITIVE), self.rot.j[rk as usize]);
                let wo = if self.fixed[o] == 0b111 { 1.0 } else { 2.0 };
                s[n] +=
                    wo * p.ea / l + 24.0 * ei / l.powi(3) + 12.0 * ei / (l * l) * (mn / jn).sqrt();
                rrow[n] += 12.0 * ei / (l * l * (mn * jn).sqrt())
                    + 6.0 * ei / (l * jn)
                    + 2.0 * p.gj / (l * jn);
            }
        }
        for n in 0..self.x.len() {
            s[n] = s[n].max(rrow[n] * self.mass[n]);
        }
        // A slave's stiffness acts on its masters: |u_s|² ≤ Σ w_a |u_a|² (Jensen, w ≥ 0).
        for (sl, ms, w) in &self.ties {
            for (a, &mn) in ms.iter().enumerate() {
                s[mn] += w[a] * s[*sl];
                c[mn] += w[a] * c[*sl];
            }
        }
        (s, c)
    }

    /// The stable step (without safety factor) and its controlling node.
    pub fn stable_step(&self) -> (f64, usize) {
        let (s, c) = self.nodal_sums();
        let mut best = (f64::INFINITY, 0);
        for i in 0..self.x.len() {
            if self.fixed[i] == 0b111 || self.mass[i] <= 0.0 {
                continue;
            }
            let dt = nodal_dt(s[i], c[i], self.mass[i], self.alpha);
            if dt < best.0 {
                best = (dt, i);
            }
        }
        best
    }

    /// The stiffest element attached to a node.
    pub fn controlling_element(&self, node: usize) -> Option<(ElementKind, i64)> {
        let mut best: Option<(f64, ElementKind, i64)> = None;
        for &slot in &self.slots[self.slot_ptr[node] as usize..self.slot_ptr[node + 1] as usize] {
            let (kind, id, k) = self.slot_element(slot as usize);
            if best.map_or(true, |b| k > b.0) {
                best = Some((k, kind, id));
            }
        }
        best.map(|b| (b.1, b.2))
    }

    /// Element of a force slot: kind, id, stiffness.
    fn slot_element(&self, slot: usize) -> (ElementKind, i64, f64) {
        if slot < self.link.slot0 {
            let e = slot / 2;
            (ElementKind::Truss, self.truss.id[e], self.truss.k[e])
        } else if slot < self.tri.slot0 {
            let e = (slot - self.link.slot0) / 2;
            let p = &self.link.props[e];
            let k = p.k.iter().chain(p.c.iter()).cloned().fold(0.0, f64::max);
            (ElementKind::Link, self.link.id[e], k)
        } else if slot < self.quad.slot0 {
            let e = (slot - self.tri.slot0) / 3;
            (ElementKind::Tri, self.tri.id[e], self.tri.k_max[e])
        } else if slot < self.beam.slot0 {
            let e = (slot - self.quad.slot0) / 4;
            (ElementKind::Quad, self.quad.id[e], self.quad.k_max[e])
        } else {
            let e = (slot - self.beam.slot0) / 2;
            (
                ElementKind::Beam,
                self.beam.id[e],
                self.beam.props[e].ea / self.beam.props[e].l0,
            )
        }
    }

    /// Conventional mass scaling applied selectively: only nodes whose stable step is
    /// below the target get mass, just enough to reach it (with the safety factor).
    fn scale_mass(&mut self, target: f64, safety: f64) {
        let (s, c) = self.nodal_sums();
        let dt_before = {
            let mut best = f64::INFINITY;
            for i in 0..self.x.len() {
                if self.fixed[i] != 0b111 && self.mass[i] > 0.0 {
                    best = best.min(nodal_dt(s[i], c[i], self.mass[i], self.alpha));
                }
            }
            best
        };
        let mut rep = MassScaling {
            dt_stable_unscaled: dt_before,
            max_ratio: 1.0,
            ..Default::default()
        };
        for i in 0..self.x.len() {
            if self.fixed[i] == 0b111 || self.mass[i] <= 0.0 {
                continue;
            }
            let m0 = self.mass[i];
            let mut m = m0;
            // Δt grows like √m (faster with damping): a few multiplicative passes converge.
            for _ in 0..60 {
                let dt = safety * nodal_dt(s[i], c[i], m, self.alpha);
                if dt >= target {
                    break;
                }
                m *= (target / dt).powi(2) * (1.0 + 1e-12);
            }
            if m > m0 {
                rep.added_mass += m - m0;
                rep.nodes_scaled += 1;
                rep.max_ratio = rep.max_ratio.max(m / m0);
                self.mass[i] = m;
            }
        }
        rep.added_fraction = rep.added_mass / self.physical_mass.max(f64::MIN_POSITIVE);
        self.scaling = Some(rep);
    }

    fn apply_loads(&mut self) {
        let t = self.t;
        for &n in &self.loaded_nodes {
            self.fext[n] = [0.0; 3];
        }
        for l in &self.loads {
            let g = l.law.eval(t);
            let f = &mut self.fext[l.node];
            f[0] += l.force[0] * g;
            f[1] += l.force[1] * g;
            f[2] += l.force[2] * g;
        }
        // External work, trapezoidal: W += ½ Δu^n · (f^{n−1} + f^n), Δu^n = Δt^{n−½} v^{n−½}.
        let mut w = 0.0;
        for (j, &n) in self.loaded_nodes.iter().enumerate() {
            let f = self.fext[n];
            let fp = self.fext_prev[j];
            let vv = self.v[n];
            w += 0.5 * self.dt_prev * dot(&vv, &[f[0] + fp[0], f[1] + fp[1], f[2] + fp[2]]);
            self.fext_prev[j] = f;
        }
        self.w_ext += w;
    }

    fn element_forces(&mut self) {
        let x = &self.x;
        let v = &self.v;
        let (fe_all, fe_beam) = self.fe.split_at_mut(self.beam.slot0);
        {
            let bg = &self.beam;
            let rr = &self.rot.r;
            let body = |(ci, (out, mo)): (usize, (&mut [[f64; 3]], &mut [[f64; 3]]))| {
                let e0 = ci * CHUNK;
                for (j, (f, m)) in out
                    .chunks_exact_mut(2)
                    .zip(mo.chunks_exact_mut(2))
                    .enumerate()
                {
                    let e = e0 + j;
                    let [a, b] = bg.nodes[e];
                    let [ra, rb] = bg.rot[e];
                    let r = beam::forces(
                        &x[a as usize],
                        &x[b as usize],
                        &rr[ra as usize],
                        &rr[rb as usize],
                        &bg.props[e],
                    );
                    f[0] = r[0];
                    f[1] = r[1];
                    m[0] = r[2];
                    m[1] = r[3];
                }
            };
            if bg.id.len() <= CHUNK {
                fe_beam
                    .chunks_mut(2 * CHUNK)
                    .zip(self.rot.me.chunks_mut(2 * CHUNK))
                    .enumerate()
                    .for_each(body);
            } else {
                fe_beam
                    .par_chunks_mut(2 * CHUNK)
                    .zip(self.rot.me.par_chunks_mut(2 * CHUNK))
                    .enumerate()
                    .for_each(body);
            }
        }
        let (fe_rest, fe_quad) = fe_all.split_at_mut(self.quad.slot0);
        let (fe_rest, fe_tri) = fe_rest.split_at_mut(self.tri.slot0);
        self.tri.forces(x, fe_tri);
        self.quad.forces(x, fe_quad);
        let (fe_truss, fe_link) = fe_rest.split_at_mut(self.link.slot0);
        let g = &self.truss;
        let truss_chunk = |(ci, out): (usize, &mut [[f64; 3]])| {
            let e0 = ci * CHUNK;
            let n = out.len() / 2;
            for (((pair, nodes), k), (l0, to)) in out
                .chunks_exact_mut(2)
                .zip(&g.nodes[e0..e0 + n])
                .zip(&g.k[e0..e0 + n])
                .zip(g.l0[e0..e0 + n].iter().zip(&g.tension_only[e0..e0 + n]))
            {
                let f2 = truss::force(&x[nodes[0] as usize], &x[nodes[1] as usize], *k, *l0, *to);
                pair[0] = [-f2[0], -f2[1], -f2[2]];
                pair[1] = f2;
            }
        };
        if g.id.len() <= CHUNK {
            fe_truss
                .chunks_mut(2 * CHUNK)
                .enumerate()
                .for_each(truss_chunk);
        } else {
            fe_truss
                .par_chunks_mut(2 * CHUNK)
                .enumerate()
                .for_each(truss_chunk);
        }
        let lg = &mut self.link;
        let dt_prev = self.dt_prev;
        let (nodes, props, d0) = (&lg.nodes, &lg.props, &lg.d0);
        let link_chunk = |(ci, (out, st)): (usize, (&mut [[f64; 3]], &mut [LinkState]))| {
            let e0 = ci * CHUNK;
            for (j, (pair, s)) in out.chunks_exact_mut(2).zip(st.iter_mut()).enumerate() {
                let e = e0 + j;
                let [a, b] = nodes[e];
                let (a, b) = (a as usize, b as usize);
                let d = link::rel_disp(&x[a], &x[b], &d0[e]);
                let dd = [v[b][0] - v[a][0], v[b][1] - v[a][1], v[b][2] - v[a][2]];
                let f2 = link::force_update(&d, &dd, &props[e], s, dt_prev);
                pair[0] = [-f2[0], -f2[1], -f2[2]];
                pair[1] = f2;
            }
        };
        if lg.id.len() <= CHUNK {
            fe_link
                .chunks_mut(2 * CHUNK)
                .zip(lg.state.chunks_mut(CHUNK))
                .enumerate()
                .for_each(link_chunk);
        } else {
            fe_link
                .par_chunks_mut(2 * CHUNK)
                .zip(lg.state.par_chunks_mut(CHUNK))
                .enumerate()
                .for_each(link_chunk);
        }
    }

    /// Penalty contact of every projectile against every node with mass, at x^n.
    /// Forces beside the elements' and the loads': contact, then the tie transfer of the
    /// slaves' forces to their masters (so that contact on a slave reaches its masters).
    fn extra_forces(&mut self) {
        for &i in &self.con_nodes {
            self.fcon[i] = [0.0; 3];
        }
        self.con_nodes.clear();
        if !self.projectiles.is_empty() {
            self.contact_forces();
        }
        for (sl, ms, w) in &self.ties {
            let mut f = self.fext[*sl];
            add(&mut f, &self.fcon[*sl]);
            for &slot in &self.slots[self.slot_ptr[*sl] as usize..self.slot_ptr[*sl + 1] as usize] {
                add(&mut f, &self.fe[slot as usize]);
            }
            for (a, &mn) in ms.iter().enumerate() {
                add(&mut self.fcon[mn], &[w[a] * f[0], w[a] * f[1], w[a] * f[2]]);
                self.con_nodes.push(mn);
            }
        }
    }

    /// Slaves follow their masters: x_s = Σ w_a x_a, v_s = Σ w_a v_a (and v^n when `snap`).
    fn update_slaves(&mut self, snap: bool) {
        for (sl, ms, w) in &self.ties {
            let mut x = [0.0; 3];
            let mut v = [0.0; 3];
            let mut vn = [0.0; 3];
            for (a, &mn) in ms.iter().enumerate() {
                for d in 0..3 {
                    x[d] += w[a] * self.x[mn][d];
                    v[d] += w[a] * self.v[mn][d];
                    vn[d] += w[a] * self.vn[mn][d];
                }
            }
            self.x[*sl] = x;
            self.v[*sl] = v;
            if snap {
                self.vn[*sl] = vn;
            }
        }
    }

    fn contact_forces(&mut self) {
        let (x, v, mass, kc) = (&self.x, &self.v, &self.mass, &self.k_contact);
        let dt_prev = self.dt_prev;
        let dt2 = self.stable.dt * self.stable.dt;
        for p in self.projectiles.iter_mut() {
            let mut ftot = [0.0; 3];
            for i in 0..x.len() {
                if mass[i] <= 0.0 {
                    continue;
                }
                let Some((g, n)) = p.penetration(&x[i]) else {
                    continue;
                };
                let fnorm = p.stiffness.unwrap_or(kc[i]) * g;
                let mut f = [n[0] * fnorm, n[1] * fnorm, n[2] * fnorm];
                if p.friction > 0.0 {
                    let vr = [v[i][0] - p.v[0], v[i][1] - p.v[1], v[i][2] - p.v[2]];
                    let (ft, power) = contact::friction(&n, fnorm, &vr, p.friction);
                    f = [f[0] + ft[0], f[1] + ft[1], f[2] + ft[2]];
                    self.e_contact_friction += power * dt_prev;
                }
                add(&mut self.fcon[i], &f);
                ftot = [ftot[0] - f[0], ftot[1] - f[1], ftot[2] - f[2]];
                self.con_nodes.push(i);
            }
            if p.segments && p.nose_centre().is_some() {
                // Exact: the sphere against the closest point of every face triangle.
                let c = p.nose_centre().expect("spherical nose");
                for (tri_n, mt) in &self.face_tris {
                    let xs = tri_n.map(|n| x[n as usize]);
                    let w = contact::closest_on_triangle(&c, &xs[0], &xs[1], &xs[2]);
                    let q: [f64; 3] = std::array::from_fn(|d| {
                        w[0] * xs[0][d] + w[1] * xs[1][d] + w[2] * xs[2][d]
                    });
                    let dq = [q[0] - c[0], q[1] - c[1], q[2] - c[2]];
                    let dist = dot(&dq, &dq).sqrt();
                    if dist >= p.radius || dist == 0.0 {
                        continue;
                    }
                    // A round nose's hemisphere only: the cylinder behind it is left to node contact.
                    if p.shape == crate::model::ProjectileShape::Round && dot(&dq, &p.axis) < 0.0 {
                        continue;
                    }
                    let n = [dq[0] / dist, dq[1] / dist, dq[2] / dist];
                    let kp = p
                        .stiffness
                        .unwrap_or(contact::PENALTY_FACTOR * mt / (3.0 * dt2));
                    let fnorm = kp * (p.radius - dist);
                    let mut f = [n[0] * fnorm, n[1] * fnorm, n[2] * fnorm];
                    if p.friction > 0.0 {
                        let vq: [f64; 3] = std::array::from_fn(|d| {
                            (0..3).map(|a| w[a] * v[tri_n[a] as usize][d]).sum()
                        });
                        let vr = [vq[0] - p.v[0], vq[1] - p.v[1], vq[2] - p.v[2]];
                        let (ft, power) = contact::friction(&n, fnorm, &vr, p.friction);
                        f = [f[0] + ft[0], f[1] + ft[1], f[2] + ft[2]];
                        self.e_contact_friction += power * dt_prev;
                    }
                    for a in 0..3 {
                        let i = tri_n[a] as usize;
                        add(&mut self.fcon[i], &[w[a] * f[0], w[a] * f[1], w[a] * f[2]]);
                        self.con_nodes.push(i);
                    }
                    ftot = [ftot[0] - f[0], ftot[1] - f[1], ftot[2] - f[2]];
                }
            } else if p.segments {
                for sp in &self.samples {
                    let nodes = &sp.nodes[..sp.n];
                    let pos: [f64; 3] = std::array::from_fn(|d| {
                        (0..sp.n).map(|a| sp.w[a] * x[nodes[a] as usize][d]).sum()
                    });
                    let Some((g, n)) = p.penetration(&pos) else {
                        continue;
                    };
                    let kp = contact::SEGMENT_FACTOR
                        * p.stiffness
                            .unwrap_or(contact::PENALTY_FACTOR * sp.mass / dt2);
                    let fnorm = kp * g;
                    let mut f = [n[0] * fnorm, n[1] * fnorm, n[2] * fnorm];
                    if p.friction > 0.0 {
                        let vp: [f64; 3] = std::array::from_fn(|d| {
                            (0..sp.n).map(|a| sp.w[a] * v[nodes[a] as usize][d]).sum()
                        });
                        let vr = [vp[0] - p.v[0], vp[1] - p.v[1], vp[2] - p.v[2]];
                        let (ft, power) = contact::friction(&n, fnorm, &vr, p.friction);
                        f = [f[0] + ft[0], f[1] + ft[1], f[2] + ft[2]];
                        self.e_contact_friction += power * dt_prev;
                    }
                    for a in 0..sp.n {
                        let i = nodes[a] as usize;
                        add(
                            &mut self.fcon[i],
                            &[sp.w[a] * f[0], sp.w[a] * f[1], sp.w[a] * f[2]],
                        );
                        self.con_nodes.push(i);
                    }
                    ftot = [ftot[0] - f[0], ftot[1] - f[1], ftot[2] - f[2]];
                }
            }
            p.force = ftot;
        }
    }

    /// Advance the projectiles (central difference, like the nodes); returns their
    /// kinetic energy at t_n (free ones) and keeps their velocity at t_n in `v_full`.
    fn advance_projectiles(&mut self, dt_next: f64) -> f64 {
        let mut ke = 0.0;
        for p in self.projectiles.iter_mut() {
            if p.prescribed {
                // The work the imposed motion does on the system.
                self.w_prescribed -= dt_next * dot(&p.force, &p.v);
                p.v_full = p.v;
            } else {
                // In a symmetric model the projectile stays on the symmetry planes.
                let a: [f64; 3] = std::array::from_fn(|d| {
                    if self.proj_fixed[d] {
                        0.0
                    } else {
                        p.force[d] / p.mass
                    }
                });
                let vn: [f64; 3] = std::array::from_fn(|d| p.v[d] + 0.5 * self.dt_prev * a[d]);
                ke += 0.5 * p.mass * dot(&vn, &vn);
                p.v = std::array::from_fn(|d| vn[d] + 0.5 * dt_next * a[d]);
                p.v_full = vn;
            }
            for d in 0..3 {
                p.tip[d] += dt_next * p.v[d];
            }
        }
        ke
    }

    /// Advance the rotations of the beam nodes; returns (rotational kinetic energy at t_n,
    /// mass-damping power α Σ J |ω^n|²). Same scheme as the translations.
    fn update_rotations(&mut self, dt_next: f64) -> Result<(f64, f64)> {
        let (alpha, dt_prev) = (self.alpha, self.dt_prev);
        let c1 = 1.0 / (1.0 + 0.5 * alpha * dt_prev);
        let c2 = 1.0 - 0.5 * alpha * dt_next;
        let (mut ke, mut dp) = (0.0, 0.0);
        let rot = &mut self.rot;
        for k in 0..rot.node.len() {
            let mut mom = [0.0; 3];
            for &sl in &rot.slots[rot.ptr[k] as usize..rot.ptr[k + 1] as usize] {
                add(&mut mom, &rot.me[sl as usize]);
            }
            let ij = 1.0 / rot.j[k];
            let a: [f64; 3] = std::array::from_fn(|d| {
                if rot.fixed[k] & (1 << d) != 0 {
                    0.0
                } else {
                    mom[d] * ij
                }
            });
            let w = rot.omega[k];
            let wn: [f64; 3] = std::array::from_fn(|d| (w[d] + 0.5 * dt_prev * a[d]) * c1);
            let wnew: [f64; 3] = std::array::from_fn(|d| wn[d] * c2 + 0.5 * dt_next * a[d]);
            let w2 = dot(&wn, &wn);
            ke += 0.5 * rot.j[k] * w2;
            dp += alpha * rot.j[k] * w2;
            if !(wnew[0] + wnew[1] + wnew[2]).is_finite() {
                return Err(WeftError::Numerical {
                    what: format!(
                        "the rotation of node `{}` became NaN or infinite",
                        self.node_id[rot.node[k]]
                    ),
                    step: self.step,
                    time: self.t,
                    hint: Some("check the beam properties near this node".into()),
                });
            }
            rot.omega[k] = wnew;
            rot.r[k] = beam::rotate(
                &rot.r[k],
                &[dt_next * wnew[0], dt_next * wnew[1], dt_next * wnew[2]],
            );
        }
        Ok((ke, dp))
    }

    /// Strain energy of the beams at the current positions and rotations.
    fn beam_energy(&self) -> f64 {
        let (bg, rr, x) = (&self.beam, &self.rot.r, &self.x);
        (0..bg.id.len())
            .map(|e| {
                let [a, b] = bg.nodes[e];
                let [ra, rb] = bg.rot[e];
                beam::energy(
                    &x[a as usize],
                    &x[b as usize],
                    &rr[ra as usize],
                    &rr[rb as usize],
                    &bg.props[e],
                )
            })
            .sum()
    }

    /// Stored penalty energy ½ Σ k g² at the current positions.
    fn contact_energy(&self) -> f64 {
        let mut e = 0.0;
        for p in self.projectiles.iter().filter(|p| p.segments) {
            if let Some(c) = p.nose_centre() {
                let dt2 = self.stable.dt * self.stable.dt;
                for (tri_n, mt) in &self.face_tris {
                    let xs = tri_n.map(|n| self.x[n as usize]);
                    let w = contact::closest_on_triangle(&c, &xs[0], &xs[1], &xs[2]);
                    let dq: [f64; 3] = std::array::from_fn(|d| {
                        w[0] * xs[0][d] + w[1] * xs[1][d] + w[2] * xs[2][d] - c[d]
                    });
                    let dist = dot(&dq, &dq).sqrt();
                    if dist >= p.radius || dist == 0.0 {
                        continue;
                    }
                    if p.shape == crate::model::ProjectileShape::Round && dot(&dq, &p.axis) < 0.0 {
                        continue;
                    }
                    let kp = p
                        .stiffness
                        .unwrap_or(contact::PENALTY_FACTOR * mt / (3.0 * dt2));
                    e += 0.5 * kp * (p.radius - dist).powi(2);
                }
                continue;
            }
            for sp in &self.samples {
                let nodes = &sp.nodes[..sp.n];
                let pos: [f64; 3] = std::array::from_fn(|d| {
                    (0..sp.n)
                        .map(|a| sp.w[a] * self.x[nodes[a] as usize][d])
                        .sum()
                });
                if let Some((g, _)) = p.penetration(&pos) {
                    let dt2 = self.stable.dt * self.stable.dt;
                    let kp = contact::SEGMENT_FACTOR
                        * p.stiffness
                            .unwrap_or(contact::PENALTY_FACTOR * sp.mass / dt2);
                    e += 0.5 * kp * g * g;
                }
            }
        }
        for p in &self.projectiles {
            for i in 0..self.x.len() {
                if self.mass[i] <= 0.0 {
                    continue;
                }
                if let Some((g, _)) = p.penetration(&self.x[i]) {
                    e += 0.5 * p.stiffness.unwrap_or(self.k_contact[i]) * g * g;
                }
            }
        }
        e
    }

    /// Gather forces and advance every node; returns (kinetic energy at t_n when
    /// `SNAP`, mass-damping power α Σ m |v^n|²).
    fn update_nodes<const SNAP: bool>(&mut self, dt_next: f64) -> Result<(f64, f64)> {
        let (alpha, dt_prev) = (self.alpha, self.dt_prev);
        let c1 = 1.0 / (1.0 + 0.5 * alpha * dt_prev);
        let c2 = 1.0 - 0.5 * alpha * dt_next;
        let (h_prev, h_next) = (0.5 * dt_prev, 0.5 * dt_next);
        let (fe, slots, ptr) = (&self.fe, &self.slots, &self.slot_ptr);
        let (fext, inv_m, mass, fixed) = (&self.fext, &self.inv_m, &self.mass, &self.fixed);
        let fcon = (!self.projectiles.is_empty() || !self.ties.is_empty()).then_some(&self.fcon);
        let body = |(ci, ((((x, v), xn), vn), part)): (
            usize,
            (
                (
                    ((&mut [[f64; 3]], &mut [[f64; 3]]), &mut [[f64; 3]]),
                    &mut [[f64; 3]],
                ),
                &mut NodePartial,
            ),
        )| {
            let i0 = ci * CHUNK;
            let (mut ke, mut dp, mut bad) = (0.0, 0.0, usize::MAX);
            for j in 0..x.len() {
                let i = i0 + j;
                let mut f = fext[i];
                if let Some(fc) = fcon {
                    add(&mut f, &fc[i]);
                }
                for &s in &slots[ptr[i] as usize..ptr[i + 1] as usize] {
                    add(&mut f, &fe[s as usize]);
                }
                let im = inv_m[i];
                let mut a = [f[0] * im, f[1] * im, f[2] * im];
                let fx = fixed[i];
                if fx != 0 {
                    for (d, ad) in a.iter_mut().enumerate() {
                        if fx & (1 << d) != 0 {
                            *ad = 0.0;
                        }
                    }
                }
                let vo = v[j];
                let vh = [
                    (vo[0] + h_prev * a[0]) * c1,
                    (vo[1] + h_prev * a[1]) * c1,
                    (vo[2] + h_prev * a[2]) * c1,
                ];
                let vnew = [
                    vh[0] * c2 + h_next * a[0],
                    vh[1] * c2 + h_next * a[1],
                    vh[2] * c2 + h_next * a[2],
                ];
                let v2 = dot(&vh, &vh);
                if SNAP {
                    xn[j] = x[j];
                    vn[j] = vh;
                    ke += 0.5 * mass[i] * v2;
                }
                dp += mass[i] * v2;
                let xo = x[j];
                let xnew = [
                    xo[0] + dt_next * vnew[0],
                    xo[1] + dt_next * vnew[1],
                    xo[2] + dt_next * vnew[2],
                ];
                if !(vnew[0] + vnew[1] + vnew[2] + xnew[0] + xnew[1] + xnew[2]).is_finite()
                    && bad == usize::MAX
                {
                    bad = i;
                }
                v[j] = vnew;
                x[j] = xnew;
            }
            *part = NodePartial {
                ke,
                damp_power: alpha * dp,
                bad,
            };
        };
        let it_len = self.x.len();
        if it_len <= CHUNK {
            self.x
                .chunks_mut(CHUNK)
                .zip(self.v.chunks_mut(CHUNK))
                .zip(self.xn.chunks_mut(CHUNK))
                .zip(self.vn.chunks_mut(CHUNK))
                .zip(self.partials.iter_mut())
                .enumerate()
                .for_each(body);
        } else {
            self.x
                .par_chunks_mut(CHUNK)
                .zip(self.v.par_chunks_mut(CHUNK))
                .zip(self.xn.par_chunks_mut(CHUNK))
                .zip(self.vn.par_chunks_mut(CHUNK))
                .zip(self.partials.par_iter_mut())
                .enumerate()
                .for_each(body);
        }
        let (mut ke, mut dp) = (0.0, 0.0);
        for p in &self.partials {
            if p.bad != usize::MAX {
                return Err(self.nan_error(p.bad));
            }
            ke += p.ke;
            dp += p.damp_power;
        }
        Ok((ke, dp))
    }

    fn nan_error(&self, node: usize) -> WeftError {
        let mut culprit = String::new();
        for &slot in &self.slots[self.slot_ptr[node] as usize..self.slot_ptr[node + 1] as usize] {
            let f = self.fe[slot as usize];
            if !(f[0] + f[1] + f[2]).is_finite() {
                let (k, id, _) = self.slot_element(slot as usize);
                culprit = format!("; the force of {} `{id}` is not finite", k.name());
                break;
            }
        }
        if culprit.is_empty()
            && !(self.fext[node][0] + self.fext[node][1] + self.fext[node][2]).is_finite()
        {
            culprit = "; its external load is not finite".into();
        }
        WeftError::Numerical {
            what: format!(
                "velocity or position of node `{}` became NaN or infinite{culprit}",
                self.node_id[node]
            ),
            step: self.step,
            time: self.t,
            hint: Some(format!(
                "the step is {:.4e} s against a stable estimate of {:.4e} s; check for extreme properties or loads near this node",
                self.stable.dt, self.stable.dt_stable
            )),
        }
    }

    /// Stored elastic energy of all elements at the current positions, the energy
    /// dissipated so far by dashpots and sliders, and the hourglass energy:
    /// (internal, damping, friction, hourglass). Sums
    /// run over fixed chunks into preallocated partials, summed in chunk order.
    pub fn internal_energy(&mut self) -> (f64, f64, f64, f64) {
        let x = &self.x;
        let g = &self.truss;
        let (tp, lp) = self
            .energy_partials
            .split_at_mut(g.id.len().div_ceil(CHUNK));
        let truss_chunk = |(ci, out): (usize, &mut [f64; 3])| {
            let r = ci * CHUNK..((ci + 1) * CHUNK).min(g.id.len());
            let mut e = 0.0;
            for k in r {
                let [a, b] = g.nodes[k];
                e += truss::energy(
                    &x[a as usize],
                    &x[b as usize],
                    g.k[k],
                    g.l0[k],
                    g.tension_only[k],
                );
            }
            *out = [e, 0.0, 0.0];
        };
        let lg = &self.link;
        let link_chunk = |(ci, out): (usize, &mut [f64; 3])| {
            let r = ci * CHUNK..((ci + 1) * CHUNK).min(lg.id.len());
            let mut acc = [0.0; 3];
            for k in r {
                let [a, b] = lg.nodes[k];
                let d = link::rel_disp(&x[a as usize], &x[b as usize], &lg.d0[k]);
                acc[0] += link::energy(&d, &lg.props[k], &lg.state[k].slip);
                acc[1] += lg.state[k].damping_energy;
                acc[2] += lg.state[k].friction_energy;
            }
            *out = acc;
        };
        tp.par_iter_mut()
            .enumerate()
            .with_min_len(4)
            .for_each(truss_chunk);
        lp.par_iter_mut()
            .enumerate()
            .with_min_len(4)
            .for_each(link_chunk);
        let (mt, mq) = self
            .membrane_partials
            .split_at_mut(self.tri.id.len().div_ceil(CHUNK));
        self.tri.energies(x, mt);
        self.quad.energies(x, mq);
        let mut sum = [0.0; 3];
        for p in self.energy_partials.iter() {
            for d in 0..3 {
                sum[d] += p[d];
            }
        }
        let (mut mem, mut hg) = (0.0, 0.0);
        for p in self.membrane_partials.iter() {
            mem += p[0];
            hg += p[1];
        }
        (sum[0] + mem, sum[1], sum[2], hg)
    }

    /// Current force of every link on its node 2 at the current positions: spring and
    /// slider (the slider return-mapped on a copy of its state), without the dashpot.
    pub fn link_forces(&self) -> Vec<[f64; 3]> {
        let lg = &self.link;
        (0..lg.id.len())
            .map(|e| {
                let [a, b] = lg.nodes[e];
                let d = link::rel_disp(&self.x[a as usize], &self.x[b as usize], &lg.d0[e]);
                let mut st = lg.state[e];
                link::force_update(&d, &[0.0; 3], &lg.props[e], &mut st, 0.0)
            })
            .collect()
    }

    /// Run to the end time, sending samples on the output grid to `sink`. `progress` is
    /// called now and then with the fraction of simulated time done.
    pub fn run(
        &mut self,
        sink: &mut (dyn Sink + Send),
        progress: &mut (dyn FnMut(f64) + Send),
    ) -> Result<RunStats> {
        let a = self.analysis.clone();
        let n_out = (a.end_time / a.output_interval).round() as u64;
        let t_out = |k: u64| k as f64 * a.output_interval;
        let dt = self.stable.dt;
        let mut times = PhaseTimes::default();
        let nout = self.output_nodes.len();
        let mut prev = Snapshot {
            u: vec![[0.0; 3]; nout],
            v: vec![[0.0; 3]; nout],
            ..Default::default()
        };
        let mut cur = prev.clone();
        let mut have_prev = false;
        let mut k = 0u64;
        let mut e0: Option<f64> = None;
        let mut ref_energy: f64 = 0.0;
        let mut max_rel: f64 = 0.0;
        // A run shorter than ENERGY_CHECK_AFTER steps reports its final balance.
        let mut last_rel = 0.0f64;
        let mut interp_u = vec![[0.0; 3]; nout];
        let mut interp_v = vec![[0.0; 3]; nout];
        let progress_every = ((n_out / 200).max(1)) as u64;
        let mut last_e = Energies::default();
        while k <= n_out {
            let t0 = Instant::now();
            self.apply_loads();
            let t1 = Instant::now();
            self.element_forces();
            if !self.projectiles.is_empty() || !self.ties.is_empty() {
                self.extra_forces();
            }
            let t2 = Instant::now();
            times.loads += t1 - t0;
            times.forces += t2 - t1;
            let dt_next = dt;
            let snap = t_out(k) <= self.t + dt_next;
            let (ke, dp) = if snap {
                self.update_nodes::<true>(dt_next)?
            } else {
                self.update_nodes::<false>(dt_next)?
            };
            // Beam strain energy at t_n needs the rotations at t_n: before they advance.
            let mut beam_e = 0.0;
            if snap && !self.beam.id.is_empty() {
                std::mem::swap(&mut self.x, &mut self.xn);
                beam_e = self.beam_energy();
                std::mem::swap(&mut self.x, &mut self.xn);
            }
            let (ke_rot, dp_rot) = if self.rot.node.is_empty() {
                (0.0, 0.0)
            } else {
                self.update_rotations(dt_next)?
            };
            let (ke, dp) = (ke + ke_rot, dp + dp_rot);
            self.e_mass_damp += 0.5 * self.dt_prev * dp;
            if !self.ties.is_empty() {
                self.update_slaves(snap);
            }
            let mut contact_e = 0.0;
            if snap {
                // Projectile states at t_n: tip and contact force before their update.
                cur.proj.clear();
                for p in &self.projectiles {
                    cur.proj.push([
                        p.tip[0], p.tip[1], p.tip[2], 0.0, 0.0, 0.0, p.force[0], p.force[1],
                        p.force[2],
                    ]);
                }
                if !self.projectiles.is_empty() {
                    std::mem::swap(&mut self.x, &mut self.xn);
                    contact_e = self.contact_energy();
                    std::mem::swap(&mut self.x, &mut self.xn);
                }
            }
            let ke_proj = if self.projectiles.is_empty() {
                0.0
            } else {
                self.advance_projectiles(dt_next)
            };
            let ke = ke + ke_proj;
            let t3 = Instant::now();
            times.update += t3 - t2;
            if snap {
                for (row, p) in cur.proj.iter_mut().zip(&self.projectiles) {
                    row[3..6].copy_from_slice(&p.v_full);
                }
                // Energies at t_n (positions x^n are in xn; internal energy from them).
                std::mem::swap(&mut self.x, &mut self.xn);
                let (ie, damp, fric, hg) = self.internal_energy();
                let ie = ie + beam_e;
                std::mem::swap(&mut self.x, &mut self.xn);
                let contact = contact_e + self.e_contact_friction;
                let w_ext = self.w_ext + self.w_prescribed;
                let total = ke + ie + damp + self.e_mass_damp + fric + hg + contact;
                let e_init = *e0.get_or_insert(total);
                let err = total - e_init - w_ext;
                ref_energy = ref_energy.max(e_init.abs()).max(w_ext.abs()).max(ke + ie);
                let rel = if ref_energy > 0.0 {
                    err.abs() / ref_energy
                } else {
                    0.0
                };
                cur.t = self.t;
                cur.e = Energies {
                    kinetic: ke,
                    internal: ie,
                    damping: damp + self.e_mass_damp,
                    friction: fric,
                    hourglass: hg,
                    contact,
                    external_work: w_ext,
                    balance_error: err,
                    balance_error_relative: rel,
                };
                last_e = cur.e;
                if self.step >= ENERGY_CHECK_AFTER {
                    max_rel = max_rel.max(rel);
                }
                last_rel = rel;
                if rel > a.max_energy_error && self.step >= ENERGY_CHECK_AFTER {
                    return Err(WeftError::Numerical {
                        what: format!(
                            "energy balance error {:.3e} J is {:.1} % of the reference energy {:.3e} J (limit {:.1} %): the run is unstable or a force is not conservative",
                            err, 100.0 * rel, ref_energy, 100.0 * a.max_energy_error
                        ),
                        step: self.step,
                        time: self.t,
                        hint: Some(format!(
                            "the step is {:.4e} s (stable estimate {:.4e} s); lower dt_safety, or raise max_energy_error if the loss is physical",
                            self.stable.dt, self.stable.dt_stable
                        )),
                    });
                }
                for (j, &i) in self.output_nodes.iter().enumerate() {
                    let (x, x0) = (self.xn[i], self.x0[i]);
                    cur.u[j] = [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]];
                    cur.v[j] = self.vn[i];
                }
                while k <= n_out && t_out(k) <= self.t {
                    let tk = t_out(k);
                    let w = if have_prev && prev.t < tk {
                        (tk - prev.t) / (self.t - prev.t)
                    } else {
                        1.0
                    };
                    for (j, p) in self.projectiles.iter().enumerate() {
                        let row: [f64; 9] = if w >= 1.0 {
                            cur.proj[j]
                        } else {
                            std::array::from_fn(|c| {
                                prev.proj[j][c] + w * (cur.proj[j][c] - prev.proj[j][c])
                            })
                        };
                        sink.projectile(tk, p.id, &row)?;
                    }
                    let (src_u, src_v, e) = if w >= 1.0 {
                        (&cur.u, &cur.v, cur.e)
                    } else {
                        for j in 0..nout {
                            for d in 0..3 {
                                interp_u[j][d] = prev.u[j][d] + w * (cur.u[j][d] - prev.u[j][d]);
                                interp_v[j][d] = prev.v[j][d] + w * (cur.v[j][d] - prev.v[j][d]);
                            }
                        }
                        (&interp_u, &interp_v, prev.e.lerp(&cur.e, w))
                    };
                    sink.history(tk, &self.output_nodes, src_u, src_v)?;
                    sink.energy(tk, &e)?;
                    if k % progress_every == 0 {
                        progress(tk / a.end_time);
                    }
                    k += 1;
                }
                std::mem::swap(&mut prev, &mut cur);
                have_prev = true;
                times.output += t3.elapsed();
            }
            self.e_mass_damp += 0.5 * dt_next * dp;
            self.t += dt_next;
            self.dt_prev = dt_next;
            self.step += 1;
        }
        progress(1.0);
        Ok(RunStats {
            steps: self.step,
            end_time: a.end_time,
            times,
            threads: rayon::current_num_threads(),
            max_balance_error_relative: if self.step >= ENERGY_CHECK_AFTER {
                max_rel
            } else {
                last_rel
            },
            final_energies: last_e,
            elements: self.truss.id.len()
                + self.link.id.len()
                + self.tri.id.len()
                + self.quad.id.len()
                + self.beam.id.len(),
            nodes: self.x.len(),
        })
    }
}

/// Set up and run a model in the current thread pool, keeping every output sample in
/// memory (tests, and stages that run the solver in-process).
pub fn run_in_memory(m: &Model) -> Result<(Solver, output::MemorySink, RunStats)> {
    let mut s = Solver::new(m)?;
    let mut sink = output::MemorySink::default();
    let stats = s.run(&mut sink, &mut |_| {})?;
    Ok((s, sink, stats))
}

impl Solver {
    /// Internal nodal forces at the current positions (the forces the elements exert;
    /// the dashpots see the current half-step velocities and the sliders do not advance).
    pub fn internal_forces(&mut self) -> Vec<[f64; 3]> {
        let saved = self.link.state.clone();
        self.element_forces();
        self.link.state = saved;
        (0..self.x.len())
            .map(|i| {
                let mut f = [0.0; 3];
                for &sl in &self.slots[self.slot_ptr[i] as usize..self.slot_ptr[i + 1] as usize] {
                    add(&mut f, &self.fe[sl as usize]);
                }
                f
            })
            .collect()
    }
}
