//! Corotational two-node truss (rod) kernel.
//!
//! Glossary: x₁, x₂ current node positions [m]; d = x₂ − x₁; L = |d|; L₀ initial length;
//! k = E·A/L₀ axial stiffness [N/m]; N = k (L − L₀) axial force [N] (tension > 0),
//! N = max(N, 0) when tension-only; e = d/L the current axis.
//!
//! Internal force on node 2: f₂ = −N e, on node 1: f₁ = +N e (these are the forces the
//! element exerts, so they enter the nodal balance with a plus sign). Strain energy
//! W = ½ k (L − L₀)² (tension-only: zero when L < L₀); f = −∂W/∂x exactly, and the force
//! depends on x only through L and e, so a rigid rotation produces no force (the
//! corotational property). Small strain, large displacement and rotation: the
//! engineering strain (L − L₀)/L₀ with a constant cross-section (no Poisson thinning).
//!
//! Reference: Belytschko, Liu, Moran, *Nonlinear Finite Elements for Continua and
//! Structures*, 2nd ed., §2.8 (rod element, corotational form).

/// Force exerted by the truss on node 2 (node 1 gets the opposite).
///
/// ```
/// // A 1 m truss of k = 1000 N/m stretched by 1 mm pulls node 2 back with 1 N.
/// let f2 = weft::solver::truss::force(&[0.0; 3], &[1.001, 0.0, 0.0], 1000.0, 1.0, false);
/// assert!((f2[0] + 1.0).abs() < 1e-9 && f2[1] == 0.0);
/// ```
#[inline(always)]
pub fn force(x1: &[f64; 3], x2: &[f64; 3], k: f64, l0: f64, tension_only: bool) -> [f64; 3] {
    let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let mut n = k * (l - l0);
    if tension_only && n < 0.0 {
        n = 0.0;
    }
    let s = -n / l;
    [s * d[0], s * d[1], s * d[2]]
}

/// Strain energy ½ k (L − L₀)² [J] (zero in compression when tension-only).
#[inline(always)]
pub fn energy(x1: &[f64; 3], x2: &[f64; 3], k: f64, l0: f64, tension_only: bool) -> f64 {
    let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let e = l - l0;
    if tension_only && e < 0.0 {
        0.0
    } else {
        0.5 * k * e * e
    }
}

/// Axial force N [N] (tension positive).
#[inline(always)]
pub fn axial_force(x1: &[f64; 3], x2: &[f64; 3], k: f64, l0: f64, tension_only: bool) -> f64 {
    let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let n = k * (l - l0);
    if tension_only && n < 0.0 {
        0.0
    } else {
        n
    }
}

// ---------------------------------------------------------------------------------------
// The truss family.

/// The engineering axial strain (L − L_ref)/L_ref and its rate ε̇ = e·(v₂ − v₁)/L_ref.
#[inline(always)]
pub fn strain_and_rate(
    x1: &[f64; 3],
    x2: &[f64; 3],
    v1: &[f64; 3],
    v2: &[f64; 3],
    l0: f64,
) -> (f64, f64) {
    let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let dv = [v2[0] - v1[0], v2[1] - v1[1], v2[2] - v1[2]];
    let rate = if l > 0.0 {
        (d[0] * dv[0] + d[1] * dv[1] + d[2] * dv[2]) / (l * l0)
    } else {
        0.0
    };
    ((l - l0) / l0, rate)
}

use super::chain_strain::Windows;
use super::failure::{taken_energy, Criterion, Erosion, Failure, FailureLaw};
use super::family::{
    chunk_partials, for_chunks, for_chunks_of, Build, EnergyGroup, EnergyPartial, Family, ForceCtx,
    Per, StiffCtx, CHUNK,
};
use super::vec3::dot;
use crate::error::Result;
use crate::model::ElementKind;

/// Trusses, struct-of-arrays.
#[derive(Debug, Clone, Default)]
pub struct TrussGroup {
    pub id: Vec<i64>,
    pub nodes: Vec<[u32; 2]>,
    /// Axial stiffness E·A/L_ref [N/m].
    pub k: Vec<f64>,
    /// Unstressed length L_ref = L₀/(1 + ε₀) [m].
    pub l0: Vec<f64>,
    pub tension_only: Vec<bool>,
    /// Failure laws and fates (empty when no truss can fail).
    pub erosion: Erosion,
    /// The windows over which a chain's strain is averaged for its failure (empty when
    /// no part has a `failure_length`; see [`super::chain_strain`]).
    pub windows: Windows,
    partials: Vec<EnergyPartial>,
}

/// A truss's failure law: its part's `failure_strain` × its factor, with the rate law.
fn failure_law(p: &crate::model::PartProps, factor: f64) -> FailureLaw {
    match p.failure_strain {
        Some(eps) => FailureLaw {
            strain: eps * factor,
            rate_coefficient: p.failure_rate_coefficient.unwrap_or(0.0),
            reference_rate: p.failure_reference_rate.unwrap_or(1.0),
            delay: p.failure_delay.unwrap_or(0.0),
        },
        None => FailureLaw::NONE,
    }
}

impl TrussGroup {
    /// The force pass of a group whose trusses can fail: a live truss whose strain has
    /// reached its limit fails (no force from this step on; its strain energy is kept
    /// in its fate), the others as [`force`].
    fn forces_with_failure(&mut self, ctx: &ForceCtx, fe: &mut [[f64; 3]]) {
        let (x, v) = (ctx.x, ctx.v);
        let TrussGroup {
            nodes,
            k,
            l0,
            tension_only,
            erosion,
            windows,
            ..
        } = self;
        if !windows.is_empty() {
            // Every truss's own strain first (in element order: the same bits on any
            // thread count), then each compares its window's mean.
            for (e, own) in windows.own.iter_mut().enumerate() {
                let [a, b] = nodes[e];
                *own = if erosion.fate[e].eroded {
                    f64::NAN
                } else {
                    strain_and_rate(
                        &x[a as usize],
                        &x[b as usize],
                        &v[a as usize],
                        &v[b as usize],
                        l0[e],
                    )
                    .0
                };
            }
        }
        let windows = &*windows;
        let Erosion { law, fate, any, .. } = erosion;
        let (nodes, k, l0, tension_only, law, any) =
            (&*nodes, &*k, &*l0, &*tension_only, &*law, &*any);
        for_chunks_of(
            nodes.len(),
            (Per(fe, 2), Per(&mut fate[..], 1)),
            |ci, (out, fates)| {
                let e0 = ci * CHUNK;
                for (j, (pair, fate)) in out.chunks_exact_mut(2).zip(fates.iter_mut()).enumerate() {
                    let e = e0 + j;
                    if fate.eroded {
                        pair[0] = [0.0; 3];
                        pair[1] = [0.0; 3];
                        continue;
                    }
                    let [a, b] = nodes[e];
                    let (a, b) = (a as usize, b as usize);
                    let lw = &law[e];
                    if lw.can_fail() {
                        let (mut eps, rate) = strain_and_rate(&x[a], &x[b], &v[a], &v[b], l0[e]);
                        if !windows.is_empty() {
                            eps = windows.mean(e);
                        }
                        let eps = lw.filter(eps, ctx.dt_prev, &mut fate.filtered[0]);
                        let limit = lw.threshold(rate);
                        if eps >= limit {
                            // Its strain energy, and the half step of work its force would
                            // have done (the central difference's trapezoid): what the
                            // failure takes (see `failure::taken_energy`).
                            let f2 = force(&x[a], &x[b], k[e], l0[e], tension_only[e]);
                            let w = taken_energy(
                                energy(&x[a], &x[b], k[e], l0[e], tension_only[e]),
                                ctx.dt_prev,
                                &[v[a], v[b]],
                                &[[-f2[0], -f2[1], -f2[2]], f2],
                            );
                            let failure = Failure {
                                kind: ElementKind::Truss,
                                element: e,
                                criterion: Criterion::Axial,
                                value: eps,
                                limit,
                                eroded: true,
                                energy: w,
                            };
                            fate.fail(failure, any);
                            pair[0] = [0.0; 3];
                            pair[1] = [0.0; 3];
                            continue;
                        }
                    }
                    let f2 = force(&x[a], &x[b], k[e], l0[e], tension_only[e]);
                    pair[0] = [-f2[0], -f2[1], -f2[2]];
                    pair[1] = f2;
                }
            },
        );
    }
}

impl Family for TrussGroup {
    const KIND: ElementKind = ElementKind::Truss;
    const SLOTS: usize = 2;
    const GROUP: EnergyGroup = EnergyGroup::Line;
    const BY_LAYER: bool = true;

    fn build(bd: &mut Build) -> Result<Self> {
        let (m, mass) = (bd.model, &mut *bd.mass);
        let mut g = TrussGroup::default();
        let Some(b) = m.block(ElementKind::Truss) else {
            return Ok(g);
        };
        let mut laws = Vec::with_capacity(b.len());
        let length: Vec<f64> = m
            .parts
            .iter()
            .map(|p| p.props.failure_length.unwrap_or(0.0))
            .collect();
        for e in 0..b.len() {
            let p = &m.parts[b.part[e]].props;
            let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
            let d = super::vec3::sub(&m.coords[c], &m.coords[a]);
            let l0 = dot(&d, &d).sqrt();
            let (e_mod, rho, area) = (
                p.youngs_modulus.unwrap(),
                p.density.unwrap(),
                b.truss_area(&m.parts, e),
            );
            let me = rho * area * l0;
            mass[a] += 0.5 * me;
            mass[c] += 0.5 * me;
            g.id.push(b.id[e]);
            g.nodes.push([a as u32, c as u32]);
            // Pretension: the unstressed length is shorter than the geometric one.
            let lref = l0 / (1.0 + p.prestrain.unwrap_or(0.0));
            g.k.push(e_mod * area / lref);
            g.l0.push(lref);
            g.tension_only.push(p.tension_only.unwrap_or(false));
            laws.push(failure_law(p, b.failure_factor(e)));
        }
        g.erosion = Erosion::new(laws);
        if g.erosion.active() {
            g.windows = Windows::new(&g.nodes, &g.l0, &b.part, &length);
        }
        Ok(g)
    }
    fn len(&self) -> usize {
        self.id.len()
    }
    fn id(&self, e: usize) -> i64 {
        self.id[e]
    }
    fn slot_nodes(&self, e: usize) -> &[u32] {
        &self.nodes[e]
    }
    fn stiffness(&self, e: usize) -> f64 {
        self.k[e]
    }
    fn forces(&mut self, ctx: &ForceCtx, fe: &mut [[f64; 3]]) {
        if self.erosion.active() {
            return self.forces_with_failure(ctx, fe);
        }
        let (g, x) = (&*self, ctx.x);
        for_chunks(fe, 2, g.id.len(), |ci, out| {
            let e0 = ci * CHUNK;
            let n = out.len() / 2;
            for (((pair, nodes), k), (l0, to)) in out
                .chunks_exact_mut(2)
                .zip(&g.nodes[e0..e0 + n])
                .zip(&g.k[e0..e0 + n])
                .zip(g.l0[e0..e0 + n].iter().zip(&g.tension_only[e0..e0 + n]))
            {
                let f2 = force(&x[nodes[0] as usize], &x[nodes[1] as usize], *k, *l0, *to);
                pair[0] = [-f2[0], -f2[1], -f2[2]];
                pair[1] = f2;
            }
        });
    }
    fn stiffness_sums(&self, ctx: &StiffCtx, s: &mut [f64], _c: &mut [f64], _r: &mut [f64]) {
        // Row sum of |K| for node i: k_e on the diagonal, plus k_e off the diagonal when
        // the other node can move (a fully fixed node's degrees of freedom are eliminated).
        let w = |other: u32| {
            if ctx.fixed[other as usize] == 0b111 {
                1.0
            } else {
                2.0
            }
        };
        for (e, p) in self.nodes.iter().enumerate() {
            s[p[0] as usize] += w(p[1]) * self.k[e];
            s[p[1] as usize] += w(p[0]) * self.k[e];
        }
    }
    fn energies(&mut self, ctx: &ForceCtx) -> &[EnergyPartial] {
        let (x, nodes, k, l0, to) = (ctx.x, &self.nodes, &self.k, &self.l0, &self.tension_only);
        let er = &self.erosion;
        chunk_partials(&mut self.partials, nodes.len(), |r| {
            let mut e = 0.0;
            for i in r {
                if !er.alive(i) {
                    continue;
                }
                let [a, b] = nodes[i];
                e += energy(&x[a as usize], &x[b as usize], k[i], l0[i], to[i]);
            }
            [e, 0.0, 0.0, 0.0]
        });
        &self.partials
    }
    fn erosion(&self) -> Option<&Erosion> {
        Some(&self.erosion)
    }
    fn erosion_mut(&mut self) -> Option<&mut Erosion> {
        Some(&mut self.erosion)
    }
    fn element_energy(&self, x: &[[f64; 3]], e: usize) -> f64 {
        if !self.erosion.alive(e) {
            return 0.0;
        }
        let [a, b] = self.nodes[e];
        energy(
            &x[a as usize],
            &x[b as usize],
            self.k[e],
            self.l0[e],
            self.tension_only[e],
        )
    }
    fn element_eroded(&self, e: usize) -> f64 {
        self.erosion.fate.get(e).map_or(0.0, |f| f.energy)
    }
}
