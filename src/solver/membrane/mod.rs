//! The membrane families: three-node triangles and four-node quadrilaterals
//! ([`MembraneGroup`]), their failure along the material directions and their collapse,
//! their stable-step rows and stiffening, their energies. The element itself (kinematics,
//! material, forces, hourglass control, stiffness) is in [`kernel`].

pub mod kernel;

pub use kernel::{
    energy, fibre_strains, forces, forces_with, green_strain, max_stiffness, stiffening, stress,
    tension_1, Material, Reference, NORMAL_RATIO,
};

use rayon::prelude::*;

use super::collapse::{limit as limit_step, CollapseRef};
use super::failure::{taken_energy, Criterion, Erosion, Failure, FailureLaw};
use super::family::{
    chunk_partials, for_chunks, for_chunks_of, Build, EnergyGroup, EnergyPartial, Family, ForceCtx,
    Per, StiffCtx, Stiffened, CHUNK,
};
use super::vec3::Vec3;
use crate::error::{Result, WeftError};
use crate::model::ElementKind;

/// A membrane element's failure laws: direction 1 and 2, and whether every direction
/// must fail before the element goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MembraneFailure {
    pub dir: [FailureLaw; 2],
    pub all_directions: bool,
}

/// The directions that fail now (bits), given those failed before.
#[inline(always)]
fn failing(lw: &MembraneFailure, eps: [f64; 2], rate: [f64; 2], before: u8) -> (u8, [f64; 2]) {
    let mut now = 0u8;
    let mut limit = [f64::INFINITY; 2];
    for i in 0..2 {
        if lw.dir[i].can_fail() && before & (1 << i) == 0 {
            limit[i] = lw.dir[i].threshold(rate[i]);
            if eps[i] >= limit[i] {
                now |= 1 << i;
            }
        }
    }
    (now, limit)
}

/// Membrane elements with `N` nodes (3: triangles, 4: quads), struct-of-arrays.
#[derive(Debug, Clone, Default)]
pub struct MembraneGroup<const N: usize> {
    pub id: Vec<i64>,
    pub nodes: Vec<[u32; N]>,
    pub reference: Vec<Reference<N>>,
    pub material: Vec<Material>,
    pub thickness: Vec<f64>,
    /// Hourglass stiffness k_hg [N/m] (quads).
    pub k_hg: Vec<f64>,
    /// Largest eigenvalue of the element stiffness [N/m] (stable step).
    pub k_max: Vec<f64>,
    /// Element mass ρ s A₀ [kg].
    pub mass: Vec<f64>,
    /// Failure laws and fates (empty when no element can fail), and per element its
    /// directions' laws (`erosion.law` holds direction 1's, to say who can fail).
    pub erosion: Erosion,
    pub failure: Vec<MembraneFailure>,
    /// Per element, what the collapse criterion keeps ([`super::collapse`]): empty until
    /// the explicit solver sets it ([`Family::step_was_set`]), and then
    /// only for a group whose elements can fail.
    pub collapse: Vec<CollapseRef>,
    partials: Vec<EnergyPartial>,
}

impl<const N: usize> Family for MembraneGroup<N> {
    const KIND: ElementKind = if N == 3 {
        ElementKind::Tri
    } else {
        ElementKind::Quad
    };
    const SLOTS: usize = N;
    const GROUP: EnergyGroup = EnergyGroup::Membrane;
    const BY_LAYER: bool = true;
    /// Adds each element's stiffening (see [`stiffening`]) to its nodes' stiffness rows
    /// of the stable step, (ratio − 1) × its largest eigenvalue k_max, and keeps, per
    /// node, the element that adds most: `(added, kind, element id, Green strain)`.
    fn add_stiffening(&self, x: &[Vec3], extra: &mut [f64], most: &mut [Option<Stiffened>]) {
        // The elements' ratios in parallel, added to their nodes in element order (the
        // same sums whatever the threads).
        let ratios: Vec<(f64, [f64; 3])> = (0..self.nodes.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|e| {
                let ns = &self.nodes[e];
                let xe: [[f64; 3]; N] = std::array::from_fn(|a| x[ns[a] as usize]);
                stiffening(&xe, &self.reference[e], &self.material[e])
            })
            .collect();
        for (e, (ns, &(r, strain))) in self.nodes.iter().zip(&ratios).enumerate() {
            if r <= 1.0 || !self.erosion.alive(e) {
                continue;
            }
            let add = (r - 1.0) * self.k_max[e];
            for &n in ns {
                let n = n as usize;
                extra[n] += add;
                if most[n].is_none_or(|m| add > m.added) {
                    most[n] = Some(Stiffened {
                        added: add,
                        id: self.id[e],
                        q: strain,
                        describe: Self::describe_stiffening,
                    });
                }
            }
        }
    }
    /// Sets up the collapse criterion ([`super::collapse`]) of a group whose elements can
    /// fail, from the reference positions `x_ref` and the run's nodal masses (with what
    /// ties and mass scaling added); a node fully fixed (`fixed` = 0b111) does not count.
    /// An element that cannot fail is never removed by it.
    fn step_was_set(&mut self, x_ref: &[Vec3], mass: &[f64], fixed: &[u8]) {
        if !self.erosion.active() {
            return;
        }
        self.collapse = (0..self.nodes.len())
            .map(|e| {
                let ns = &self.nodes[e];
                let xe: [[f64; 3]; N] = std::array::from_fn(|a| x_ref[ns[a] as usize]);
                let can_fail = self.failure[e].dir.iter().any(FailureLaw::can_fail);
                let k = if can_fail { self.k_max[e] } else { 0.0 };
                let free = ns
                    .iter()
                    .map(|&n| n as usize)
                    .filter(|&n| fixed[n] != 0b111);
                CollapseRef::new(&xe, k, free.map(|n| mass[n]))
            })
            .collect();
    }
    fn contact_faces<'a>(&'a self, out: &mut Vec<(&'a [u32], f64)>) {
        out.extend(
            self.nodes
                .iter()
                .map(|f| &f[..])
                .zip(self.mass.iter().copied()),
        );
    }

    fn build(bd: &mut Build) -> Result<Self> {
        let (m, kind) = (bd.model, Self::KIND);
        let mut g = MembraneGroup::<N> {
            id: vec![],
            nodes: vec![],
            reference: vec![],
            material: vec![],
            thickness: vec![],
            k_hg: vec![],
            k_max: vec![],
            mass: vec![],
            erosion: Erosion::default(),
            failure: vec![],
            collapse: vec![],
            partials: vec![],
        };
        let Some(b) = m.block(kind) else { return Ok(g) };
        for e in 0..b.len() {
            let part = &m.parts[b.part[e]];
            let p = &part.props;
            let ns: [usize; N] = std::array::from_fn(|a| b.nodes[N * e + a]);
            let x: [[f64; 3]; N] = std::array::from_fn(|a| m.coords[ns[a]]);
            let r = Reference::<N>::new(&x, p.material_angle.unwrap_or(0.0))
                .ok_or_else(|| degenerate(kind, m, b.id[e], e, &ns))?;
            let mat = Material::orthotropic(
                p.youngs_modulus_1.unwrap(),
                p.youngs_modulus_2.unwrap(),
                p.poisson_ratio_12.unwrap_or(0.0),
                p.shear_modulus_12.unwrap(),
                p.no_compression.unwrap_or(false),
            )
            .map_err(|err| err.in_file("parts.parquet").in_column("poisson_ratio_12"))?;
            let mut mat = mat;
            if !b.stress0.is_empty() {
                mat.s0 = b.stress0[e];
            }
            let s = thickness::<N>(kind, b, e, p)?;
            let k_hg = if N == 4 {
                p.hourglass_coefficient() * mat.e_max() * s * r.area * r.grad2()
            } else {
                0.0
            };
            let me = p.density.unwrap() * s * r.area;
            for &n in &ns {
                bd.mass[n] += me / N as f64;
            }
            g.k_max.push(max_stiffness(&r, &mat, s, k_hg));
            g.mass.push(me);
            g.id.push(b.id[e]);
            g.nodes.push(std::array::from_fn(|a| ns[a] as u32));
            g.reference.push(r);
            g.material.push(mat);
            g.thickness.push(s);
            g.k_hg.push(k_hg);
            g.failure.push(failure_laws(p, b.failure_factor(e)));
        }
        g.watch_failures();
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
        self.k_max[e]
    }
    fn forces(&mut self, ctx: &ForceCtx, fe: &mut [[f64; 3]]) {
        if self.erosion.active() {
            return self.forces_with_failure(ctx, fe);
        }
        let (g, x) = (&*self, ctx.x);
        for_chunks(fe, N, g.id.len(), |ci, out| {
            let e0 = ci * CHUNK;
            for (j, el) in out.chunks_exact_mut(N).enumerate() {
                let e = e0 + j;
                let nodes = &g.nodes[e];
                let xe: [[f64; 3]; N] = std::array::from_fn(|a| x[nodes[a] as usize]);
                let f = forces(
                    &xe,
                    &g.reference[e],
                    &g.material[e],
                    g.thickness[e],
                    g.k_hg[e],
                );
                el.copy_from_slice(&f);
            }
        });
    }
    fn stiffness_sums(&self, _: &StiffCtx, s: &mut [f64], _c: &mut [f64], _r: &mut [f64]) {
        // uₑᵀKₑuₑ ≤ λ_max(Kₑ) Σ_{a∈e} |u_a|², so each node of e gets λ_max(Kₑ).
        for (p, k) in self.nodes.iter().zip(&self.k_max) {
            for &n in p {
                s[n as usize] += k;
            }
        }
    }
    fn energies(&mut self, ctx: &ForceCtx) -> &[EnergyPartial] {
        let x = ctx.x;
        let (nodes, reference, material, thickness, k_hg) = (
            &self.nodes,
            &self.reference,
            &self.material,
            &self.thickness,
            &self.k_hg,
        );
        let er = &self.erosion;
        chunk_partials(&mut self.partials, nodes.len(), |r| {
            let mut acc = [0.0; 4];
            for e in r {
                if !er.alive(e) {
                    continue;
                }
                let ns = &nodes[e];
                let xe: [[f64; 3]; N] = std::array::from_fn(|a| x[ns[a] as usize]);
                let dirs = er.fate.get(e).map_or(0, |f| f.dirs);
                let mat = if dirs == 0 {
                    material[e]
                } else {
                    material[e].with_failed(dirs)
                };
                let (w, h) = energy(&xe, &reference[e], &mat, thickness[e], k_hg[e]);
                acc[0] += w;
                acc[3] += h;
            }
            acc
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
        let ns = &self.nodes[e];
        let xe: [[f64; 3]; N] = std::array::from_fn(|a| x[ns[a] as usize]);
        let dirs = self.erosion.fate.get(e).map_or(0, |f| f.dirs);
        let mat = if dirs == 0 {
            self.material[e]
        } else {
            self.material[e].with_failed(dirs)
        };
        let (w, h) = energy(
            &xe,
            &self.reference[e],
            &mat,
            self.thickness[e],
            self.k_hg[e],
        );
        w + h
    }
    fn element_eroded(&self, e: usize) -> f64 {
        self.erosion.fate.get(e).map_or(0.0, |f| f.energy)
    }
}

/// One membrane element's constants: reference geometry, undamaged material, thickness,
/// hourglass stiffness.
struct Element<'a, const N: usize> {
    r: &'a Reference<N>,
    mat: &'a Material,
    s: f64,
    k_hg: f64,
}

impl<const N: usize> Element<'_, N> {
    /// Its material with the directions `dirs` failed (bits; 0: undamaged).
    fn with_failed(&self, dirs: u8) -> Material {
        if dirs == 0 {
            *self.mat
        } else {
            self.mat.with_failed(dirs)
        }
    }

    /// What a failure at positions `xe` (velocities `vn`) takes, from the element with
    /// the directions `before` failed: everything it holds when it is eroded (`to` =
    /// None), else what the newly failed directions carried, the element left with the
    /// directions `to` failed: energy and forces (see `failure::taken_energy`).
    fn taken(
        &self,
        xe: &[Vec3; N],
        vn: &[Vec3; N],
        before: u8,
        to: Option<u8>,
        dt_prev: f64,
    ) -> f64 {
        let mat_before = self.with_failed(before);
        let (w0, h0) = energy(xe, self.r, &mat_before, self.s, self.k_hg);
        let f0 = forces(xe, self.r, &mat_before, self.s, self.k_hg);
        let Some(dirs) = to else {
            return taken_energy(w0 + h0, dt_prev, vn, &f0);
        };
        let mat1 = self.mat.with_failed(dirs);
        let (w1, _) = energy(xe, self.r, &mat1, self.s, self.k_hg);
        let f1 = forces(xe, self.r, &mat1, self.s, self.k_hg);
        let df: [Vec3; N] = std::array::from_fn(|a| std::array::from_fn(|c| f0[a][c] - f1[a][c]));
        taken_energy(w0 - w1, dt_prev, vn, &df)
    }
}

/// The error for a degenerate element of kind `kind`: id, row `e`, nodes `ns`.
fn degenerate(
    kind: ElementKind,
    m: &crate::model::Model,
    id: i64,
    e: usize,
    ns: &[usize],
) -> WeftError {
    WeftError::input(format!(
        "{} `{id}` is degenerate: zero area, inverted or (quad) not convex; nodes {}",
        kind.name(),
        ns.iter()
            .map(|&n| format!("`{}`", m.node_id[n]))
            .collect::<Vec<_>>()
            .join(", ")
    ))
    .in_file(format!("elements_{}.parquet", kind.name()))
    .at_row(e)
    .expected("nodes in counter-clockwise order around a convex element of positive area")
}

/// The thickness of element `e` of block `b` [m]: the part's, or (one-point element)
/// the mean of its nodal thicknesses when the block gives them; refused unless > 0.
fn thickness<const N: usize>(
    kind: ElementKind,
    b: &crate::model::ElementBlock,
    e: usize,
    p: &crate::model::PartProps,
) -> Result<f64> {
    let s = if b.thickness.is_empty() {
        p.thickness.unwrap()
    } else {
        b.thickness[N * e..N * e + N].iter().sum::<f64>() / N as f64
    };
    if !(s > 0.0) {
        return Err(WeftError::input(format!(
            "{} `{}` has a mean nodal thickness of {s:e} m",
            kind.name(),
            b.id[e]
        ))
        .in_file(format!("elements_{}.parquet", kind.name()))
        .at_row(e)
        .expected("a positive mean thickness (t1…)"));
    }
    Ok(s)
}

/// A membrane's failure laws from its part: `failure_strain` along direction 1,
/// `failure_strain_2` along 2, each × the element's factor, with the rate law.
fn failure_laws(p: &crate::model::PartProps, factor: f64) -> MembraneFailure {
    let law = |eps: Option<f64>| match eps {
        Some(e) => FailureLaw {
            strain: e * factor,
            rate_coefficient: p.failure_rate_coefficient.unwrap_or(0.0),
            reference_rate: p.failure_reference_rate.unwrap_or(1.0),
            delay: p.failure_delay.unwrap_or(0.0),
        },
        None => FailureLaw::NONE,
    };
    MembraneFailure {
        dir: [law(p.failure_strain), law(p.failure_strain_2)],
        all_directions: p.failure_all_directions.unwrap_or(false),
    }
}

impl<const N: usize> MembraneGroup<N> {
    /// After the build: the erosion watches the elements when any direction of any
    /// element can fail (its law the first direction that can), else the group keeps no
    /// failure laws at all.
    fn watch_failures(&mut self) {
        if !self
            .failure
            .iter()
            .any(|f| f.dir.iter().any(FailureLaw::can_fail))
        {
            self.failure.clear();
            return;
        }
        self.erosion = Erosion::new(
            self.failure
                .iter()
                .map(|f| {
                    if f.dir[0].can_fail() {
                        f.dir[0]
                    } else {
                        f.dir[1]
                    }
                })
                .collect(),
        );
    }

    /// The force pass of a group whose elements can fail. Per live element: the fibre
    /// strains; a direction that reaches its limit fails. Without
    /// `failure_all_directions` the element then leaves the model (no force from this
    /// step on); with it, the direction stops carrying normal stress
    /// ([`Material::with_failed`]) and the element leaves once every direction that can
    /// fail has. The strain energy a failure takes (the element's, or what the failed
    /// direction held) is kept in its fate.
    fn forces_with_failure(&mut self, ctx: &ForceCtx, fe: &mut [[f64; 3]]) {
        let (x, v) = (ctx.x, ctx.v);
        let MembraneGroup {
            nodes,
            reference,
            material,
            thickness,
            k_hg,
            erosion,
            failure,
            collapse,
            ..
        } = self;
        let Erosion { fate, any, .. } = erosion;
        let (nodes, reference, material, thickness, k_hg, failure, collapse, any) = (
            &*nodes,
            &*reference,
            &*material,
            &*thickness,
            &*k_hg,
            &*failure,
            &*collapse,
            &*any,
        );
        for_chunks_of(
            nodes.len(),
            (Per(fe, N), Per(&mut fate[..], 1)),
            |ci, (out, fates)| {
                let e0 = ci * CHUNK;
                for (j, (el, fate)) in out.chunks_exact_mut(N).zip(fates.iter_mut()).enumerate() {
                    let e = e0 + j;
                    if fate.eroded {
                        el.fill([0.0; 3]);
                        continue;
                    }
                    let ns = &nodes[e];
                    let xe: [[f64; 3]; N] = std::array::from_fn(|a| x[ns[a] as usize]);
                    let lw = &failure[e];
                    let with_rate = lw.dir.iter().any(|d| d.rate_coefficient != 0.0);
                    let ve: [[f64; 3]; N] = if with_rate {
                        std::array::from_fn(|a| v[ns[a] as usize])
                    } else {
                        [[0.0; 3]; N]
                    };
                    let (eps, rate) = fibre_strains(&xe, &ve, &reference[e], with_rate);
                    let eps: [f64; 2] = std::array::from_fn(|i| {
                        lw.dir[i].filter(eps[i], ctx.dt_prev, &mut fate.filtered[i])
                    });
                    let (now, limit) = failing(lw, eps, rate, fate.dirs);
                    // Collapsed: its own stable step below half the run's
                    // ([`super::collapse`]).
                    let collapsed = collapse.get(e).and_then(|c| c.below(&xe, ctx.dt_prev));
                    let before = fate.dirs;
                    let elem = Element {
                        r: &reference[e],
                        mat: &material[e],
                        s: thickness[e],
                        k_hg: k_hg[e],
                    };
                    if now != 0 || collapsed.is_some() {
                        let dirs = before | now;
                        let can =
                            (lw.dir[0].can_fail() as u8) | ((lw.dir[1].can_fail() as u8) << 1);
                        let eroded = collapsed.is_some() || !lw.all_directions || dirs & can == can;
                        let vn: [[f64; 3]; N] = std::array::from_fn(|a| v[ns[a] as usize]);
                        let to = if eroded { None } else { Some(dirs) };
                        let taken = elem.taken(&xe, &vn, before, to, ctx.dt_prev);
                        // The first direction that failed now names the criterion, else the
                        // collapse: the element's step against the run's.
                        let (criterion, value, limit) = match (now, collapsed) {
                            (0, Some(step)) => (Criterion::TimeStep, step, limit_step(ctx.dt_prev)),
                            _ if now & 1 != 0 => (Criterion::Direction1, eps[0], limit[0]),
                            _ => (Criterion::Direction2, eps[1], limit[1]),
                        };
                        fate.dirs = dirs;
                        let failure = Failure {
                            kind: Self::KIND,
                            element: e,
                            criterion,
                            value,
                            limit,
                            eroded,
                            energy: taken,
                        };
                        fate.fail(failure, any);
                        if eroded {
                            el.fill([0.0; 3]);
                            continue;
                        }
                    }
                    let mat = elem.with_failed(fate.dirs);
                    let f = forces(&xe, elem.r, &mat, elem.s, elem.k_hg);
                    el.copy_from_slice(&f);
                }
            },
        );
    }
}
