//! The link families: links in global axes ([`LinkGroup`], two force slots) and links in
//! a local frame ([`FramedLinkGroup`], six: node 1, node 2 and the frame nodes f1…f4,
//! which take the reaction of the turning frame), one group [`Links`] over the axes
//! ([`Axes`]: how a link reaches its nodes, measures its relative displacement and
//! advances). The link itself (its law, the frame's kinematics and forces) is in
//! [`kernel`]; the links that slide along their yarns are [`super::sliding_link`].

pub mod kernel;

pub(crate) use kernel::{
    bound_stiffness, frame_kin, framed_node_forces, law_of, link_props, normal_spring, FrameKin,
    DEFAULT_LAW,
};
pub use kernel::{
    elastic_force, elastic_force_law, energy, energy_law, force_update, force_update_law,
    force_update_parts, framed_elastic_forces, framed_force_update, framed_rel_disp, local_frame,
    rel_disp, to_global, FramedX, LinkLaw, LinkProps, LinkState,
};

use std::marker::PhantomData;

use super::failure::{taken_energy, Criterion, Erosion, Failure, FailureLaw};
use super::family::{
    chunk_partials, for_chunks_of, Build, EnergyGroup, EnergyPartial, Family, ForceCtx, Per,
    StiffCtx, CHUNK,
};
use super::vec3::{mv, norm, sub, Vec3};
use crate::error::Result;
use crate::model::{ElementBlock, ElementKind, Model, PartProps};

/// How a link reaches its nodes: in global axes ([`Global`]) or in a local frame given by
/// four frame nodes ([`Framed`]).
pub trait Axes: Sized + Default + Clone + std::fmt::Debug + Send + Sync {
    /// The link's nodes, one per force slot.
    type Nodes: Copy + std::fmt::Debug + Send + Sync + AsRef<[u32]>;
    const SLOTS: usize;
    /// Whether the group takes the links of parts with `local_frame`.
    const FRAMED: bool;
    /// Row `e` of the model's link block: its nodes, its initial offset d₀ in its axes
    /// and the frame's chords |X_f2 − X_f1|, |X_f4 − X_f3| (none in global axes).
    fn setup(m: &Model, b: &ElementBlock, e: usize) -> (Self::Nodes, Vec3, Option<[f64; 2]>);
    /// The relative displacement d in the link's axes at positions `x`; `None` where the
    /// frame degenerates.
    fn rel_disp(x: &[Vec3], nodes: &Self::Nodes, d0: &Vec3) -> Option<Vec3>;
    /// The force pass over the group (advances the sliders, books failures).
    fn forces(g: &mut Links<Self>, ctx: &ForceCtx, fe: &mut [Vec3]);
    /// What the stable-step bound adds beyond the link's two nodes (a frame's nodes).
    fn extra_rows(_g: &Links<Self>, _e: usize, _kmax: f64, _s: &mut [f64]) {}
}

/// Links of one kind of axes, struct-of-arrays.
#[derive(Debug, Clone)]
pub struct Links<A: Axes> {
    pub id: Vec<i64>,
    pub nodes: Vec<A::Nodes>,
    pub props: Vec<LinkProps>,
    /// The law of each link; empty when every link has the default law (so that plain
    /// links read no more memory per step than before).
    pub law: Vec<LinkLaw>,
    /// Initial offset in the link's axes: X₂ − X₁, or R₀ (X₂ − X₁) in a frame [m].
    pub d0: Vec<Vec3>,
    /// A framed link's |X_f2 − X_f1|, |X_f4 − X_f3| at the reference [m] (the stable-step
    /// bound); empty in global axes.
    pub chords: Vec<[f64; 2]>,
    pub state: Vec<LinkState>,
    /// Failure (links in global axes): per link its breaking force
    /// (`erosion.law[e].strain`, N) and opening (`break_opening`, m), each `f64::INFINITY`
    /// when not given; empty when no link can break.
    pub erosion: Erosion,
    pub break_opening: Vec<f64>,
    partials: Vec<EnergyPartial>,
    axes: PhantomData<A>,
}

impl<A: Axes> Default for Links<A> {
    fn default() -> Self {
        Links {
            id: vec![],
            nodes: vec![],
            props: vec![],
            law: vec![],
            d0: vec![],
            chords: vec![],
            state: vec![],
            erosion: Erosion::default(),
            break_opening: vec![],
            partials: vec![],
            axes: PhantomData,
        }
    }
}

/// Links in global axes.
#[derive(Debug, Clone, Copy, Default)]
pub struct Global;
/// Links in a local frame (`local_frame`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Framed;

/// Links in global axes: two force slots each.
pub type LinkGroup = Links<Global>;
/// Links in a local frame: six force slots each, node 1, node 2 and the frame nodes
/// f1…f4 (see [`framed_force_update`]).
pub type FramedLinkGroup = Links<Framed>;

/// Whether link `e` of the model's link block acts in a local frame given by frame nodes.
fn is_framed(m: &Model, e: usize) -> bool {
    m.block(ElementKind::Link)
        .is_some_and(|b| m.parts[b.part[e]].props.local_frame == Some(true))
}

/// Whether link `e` of the model's link block slides along its yarns
/// ([`super::sliding_link`]).
pub(super) fn is_sliding(m: &Model, e: usize) -> bool {
    m.block(ElementKind::Link)
        .is_some_and(|b| m.parts[b.part[e]].props.sliding == Some(true))
}

/// A link's breaking force and opening from its part, × its factor (∞: not given).
fn break_limits(p: &PartProps, factor: f64) -> (f64, f64) {
    (
        p.failure_force.map_or(f64::INFINITY, |f| f * factor),
        p.failure_opening.map_or(f64::INFINITY, |o| o * factor),
    )
}

/// The positions of a framed link's nodes.
#[inline(always)]
fn gather(x: &[Vec3], nodes: &[u32; 6]) -> FramedX {
    std::array::from_fn(|k| x[nodes[k] as usize])
}

impl Axes for Global {
    type Nodes = [u32; 2];
    const SLOTS: usize = 2;
    const FRAMED: bool = false;
    fn setup(m: &Model, b: &ElementBlock, e: usize) -> ([u32; 2], Vec3, Option<[f64; 2]>) {
        let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
        ([a as u32, c as u32], sub(&m.coords[c], &m.coords[a]), None)
    }
    #[inline(always)]
    fn rel_disp(x: &[Vec3], nodes: &[u32; 2], d0: &Vec3) -> Option<Vec3> {
        Some(rel_disp(&x[nodes[0] as usize], &x[nodes[1] as usize], d0))
    }
    fn forces(g: &mut LinkGroup, ctx: &ForceCtx, fe: &mut [[f64; 3]]) {
        if g.erosion.active() {
            return Self::forces_with_failure(g, ctx, fe);
        }
        let (x, v, dt_prev) = (ctx.x, ctx.v, ctx.dt_prev);
        let (nodes, props, law, d0) = (&g.nodes, &g.props, &g.law, &g.d0);
        // Plain links (the default law: the group stores none) take the kernel without
        // the per-link law look-up, as before the laws existed (with the look-ups the
        // link benchmark ran 15–25 % slower on a shared 2-core machine; with this path,
        // best of 6: 5.8·10⁷ against 6.2·10⁷ updates/s before, within that machine's
        // noise).
        let plain = law.is_empty();
        for_chunks_of(
            g.id.len(),
            (Per(fe, 2), Per(&mut g.state[..], 1)),
            |ci, (out, st)| {
                let e0 = ci * CHUNK;
                for (j, (pair, s)) in out.chunks_exact_mut(2).zip(st.iter_mut()).enumerate() {
                    let e = e0 + j;
                    let [a, b] = nodes[e];
                    let (a, b) = (a as usize, b as usize);
                    let d = rel_disp(&x[a], &x[b], &d0[e]);
                    let dd = [v[b][0] - v[a][0], v[b][1] - v[a][1], v[b][2] - v[a][2]];
                    let f2 = if plain {
                        force_update(&d, &dd, &props[e], s, dt_prev)
                    } else {
                        force_update_law(&d, &dd, &props[e], &law[e], s, dt_prev)
                    };
                    pair[0] = [-f2[0], -f2[1], -f2[2]];
                    pair[1] = f2;
                }
            },
        );
    }
}

impl Global {
    /// The force pass of a group whose links can break: a live link breaks when its
    /// opening |d| reaches its breaking opening, or the length of its spring force (after
    /// the slider's update) its breaking force; a broken link exerts no force from that
    /// step on, and the stored energy it held is kept in its fate.
    fn forces_with_failure(g: &mut LinkGroup, ctx: &ForceCtx, fe: &mut [[f64; 3]]) {
        let (x, v, dt_prev) = (ctx.x, ctx.v, ctx.dt_prev);
        let Links {
            nodes,
            props,
            law,
            d0,
            state,
            erosion,
            break_opening,
            ..
        } = g;
        let Erosion {
            law: force_limit,
            fate,
            any,
            ..
        } = erosion;
        let (nodes, props, law, d0, force_limit, break_opening, any) = (
            &*nodes,
            &*props,
            &*law,
            &*d0,
            &*force_limit,
            &*break_opening,
            &*any,
        );
        let n = nodes.len();
        for_chunks_of(
            n,
            ((Per(fe, 2), Per(&mut state[..], 1)), Per(&mut fate[..], 1)),
            |ci, ((out, st), fates)| {
                let e0 = ci * CHUNK;
                for (j, ((pair, s), fate)) in out
                    .chunks_exact_mut(2)
                    .zip(st.iter_mut())
                    .zip(fates.iter_mut())
                    .enumerate()
                {
                    let e = e0 + j;
                    if fate.eroded {
                        pair[0] = [0.0; 3];
                        pair[1] = [0.0; 3];
                        continue;
                    }
                    let [a, b] = nodes[e];
                    let (a, b) = (a as usize, b as usize);
                    let d = rel_disp(&x[a], &x[b], &d0[e]);
                    let lw = law_of(law, e);
                    let opening = norm(&d);
                    let broken = if opening >= break_opening[e] {
                        Some((Criterion::Opening, opening, break_opening[e]))
                    } else {
                        None
                    };
                    let dd = [v[b][0] - v[a][0], v[b][1] - v[a][1], v[b][2] - v[a][2]];
                    let broken = broken.or_else(|| {
                        let mut trial = *s;
                        let (fs, _) =
                            force_update_parts(&d, &dd, &props[e], lw, &mut trial, dt_prev);
                        let f = norm(&fs);
                        (f >= force_limit[e].strain).then_some((
                            Criterion::Force,
                            f,
                            force_limit[e].strain,
                        ))
                    });
                    if let Some((criterion, value, limit)) = broken {
                        // Its stored energy, with the half step of its spring's work (see
                        // `failure::taken_energy`).
                        let f2 = elastic_force_law(&d, &props[e], lw, &s.slip);
                        let w = taken_energy(
                            energy_law(&d, &props[e], lw, &s.slip),
                            dt_prev,
                            &[v[a], v[b]],
                            &[[-f2[0], -f2[1], -f2[2]], f2],
                        );
                        let failure = Failure {
                            kind: ElementKind::Link,
                            element: e,
                            criterion,
                            value,
                            limit,
                            eroded: true,
                            energy: w,
                        };
                        fate.fail(failure, any);
                        pair[0] = [0.0; 3];
                        pair[1] = [0.0; 3];
                        continue;
                    }
                    let f2 = force_update_law(&d, &dd, &props[e], lw, s, dt_prev);
                    pair[0] = [-f2[0], -f2[1], -f2[2]];
                    pair[1] = f2;
                }
            },
        );
    }
}

impl Axes for Framed {
    type Nodes = [u32; 6];
    const SLOTS: usize = 6;
    const FRAMED: bool = true;
    fn setup(m: &Model, b: &ElementBlock, e: usize) -> ([u32; 6], Vec3, Option<[f64; 2]>) {
        let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
        // `Model::validate` checked that the frame nodes span a plane.
        let f = b.frame[e];
        let nodes = [a, c, f[0], f[1], f[2], f[3]].map(|n| n as u32);
        let xe = gather(&m.coords, &nodes);
        let r0 =
            local_frame(&sub(&xe[3], &xe[2]), &sub(&xe[5], &xe[4])).expect("validated frame nodes");
        let chords = [norm(&sub(&xe[3], &xe[2])), norm(&sub(&xe[5], &xe[4]))];
        (nodes, mv(&r0, &sub(&xe[1], &xe[0])), Some(chords))
    }
    #[inline(always)]
    fn rel_disp(x: &[Vec3], nodes: &[u32; 6], d0: &Vec3) -> Option<Vec3> {
        framed_rel_disp(&gather(x, nodes), d0)
    }
    fn forces(g: &mut FramedLinkGroup, ctx: &ForceCtx, fe: &mut [[f64; 3]]) {
        let (x, v, dt_prev) = (ctx.x, ctx.v, ctx.dt_prev);
        let (nodes, props, law, d0) = (&g.nodes, &g.props, &g.law, &g.d0);
        let state = &mut g.state;
        let n = nodes.len();
        // The state is advanced per link: split it by chunks alongside the slots.
        for_chunks_of(n, (Per(fe, 6), Per(&mut state[..], 1)), |ci, (out, st)| {
            let e0 = ci * CHUNK;
            for (j, (six, s)) in out.chunks_exact_mut(6).zip(st.iter_mut()).enumerate() {
                let e = e0 + j;
                let nd = &nodes[e];
                let xe = gather(x, nd);
                let ve = [v[nd[0] as usize], v[nd[1] as usize]];
                let f =
                    framed_force_update(&xe, &ve, &d0[e], &props[e], law_of(law, e), s, dt_prev);
                six.copy_from_slice(&f);
            }
        });
    }
    /// The frame nodes feel the link through the frame's turn: a turn δθ = δx/|u| of the
    /// frame moves the link's anchor, at a lever |r| from node 1 (r the offset of the
    /// link nodes, the accumulated slip included), by |r| δθ, so their stiffness rows
    /// hold terms k ρ and k ρ², ρ = |r|/|u|. Bounded for link nodes up to |d₀| + half a
    /// chord apart (a slide to the midpoint of the next crossing, where a crossing's link
    /// has lost its meaning): with a slider and no normal force the yarns slid 1.2 mm
    /// past each other at a 1 mm spacing in the reduced model's impact, and a bound made
    /// for 5 % of a chord let that run go unstable (measured).
    fn extra_rows(g: &FramedLinkGroup, e: usize, kmax: f64, s: &mut [f64]) {
        let nd = &g.nodes[e];
        let d0 = norm(&g.d0[e]);
        for (k, chord) in [(2, g.chords[e][0]), (4, g.chords[e][1])] {
            let rho = (d0 + 0.5 * chord) / chord;
            for f in [nd[k], nd[k + 1]] {
                s[f as usize] += 4.0 * (rho + rho * rho) * kmax;
            }
        }
    }
}

impl<A: Axes> Links<A> {
    /// Link `e`'s largest bound stiffness ([`bound_stiffness`]) and dashpot.
    fn bound(&self, e: usize) -> (f64, f64) {
        let pr = &self.props[e];
        let kmax = bound_stiffness(pr, law_of(&self.law, e))
            .iter()
            .cloned()
            .fold(0.0, f64::max);
        (kmax, pr.c.iter().cloned().fold(0.0, f64::max))
    }

    /// The normal spring's force −k_z d_z of link `e` at positions `x`, as a two-way
    /// spring (> 0: the link presses its nodes apart, the yarns are in contact; 0 where a
    /// frame degenerates).
    pub fn normal_spring_force(&self, e: usize, x: &[Vec3]) -> f64 {
        A::rel_disp(x, &self.nodes[e], &self.d0[e]).map_or(0.0, |d| -self.props[e].k[2] * d[2])
    }

    /// The links of the model's link block that these axes take, and (links in global
    /// axes) their breaking limits.
    fn build_from(m: &Model, b: &ElementBlock) -> (Self, Vec<(f64, f64)>) {
        let mut g = Self::default();
        let mut limits = Vec::new();
        for e in (0..b.len()).filter(|&e| is_framed(m, e) == A::FRAMED && !is_sliding(m, e)) {
            let (nodes, d0, chords) = A::setup(m, b, e);
            let part = &m.parts[b.part[e]].props;
            let (props, law) = link_props(part);
            if !A::FRAMED {
                limits.push(break_limits(part, b.failure_factor(e)));
            }
            g.id.push(b.id[e]);
            g.nodes.push(nodes);
            g.props.push(props);
            g.law.push(law);
            g.d0.push(d0);
            g.chords.extend(chords);
            g.state.push(LinkState::default());
        }
        if g.law.iter().all(|l| *l == DEFAULT_LAW) {
            g.law.clear();
        }
        (g, limits)
    }
}

impl<A: Axes> Family for Links<A> {
    const KIND: ElementKind = ElementKind::Link;
    const SLOTS: usize = A::SLOTS;
    const GROUP: EnergyGroup = EnergyGroup::Line;

    fn build(bd: &mut Build) -> Result<Self> {
        let m = bd.model;
        let Some(b) = m.block(ElementKind::Link) else {
            return Ok(Self::default());
        };
        let (mut g, limits) = Self::build_from(m, b);
        if limits.iter().any(|l| l.0.is_finite() || l.1.is_finite()) {
            // `law.strain` holds the breaking force (∞: none).
            g.erosion = Erosion::watching(
                limits
                    .iter()
                    .map(|&(f, _)| FailureLaw {
                        strain: f,
                        ..FailureLaw::NONE
                    })
                    .collect(),
            );
            g.break_opening = limits.iter().map(|l| l.1).collect();
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
        self.nodes[e].as_ref()
    }
    fn stiffness(&self, e: usize) -> f64 {
        let p = &self.props[e];
        let k = bound_stiffness(p, law_of(&self.law, e));
        k.iter().chain(p.c.iter()).cloned().fold(0.0, f64::max)
    }
    fn forces(&mut self, ctx: &ForceCtx, fe: &mut [Vec3]) {
        A::forces(self, ctx, fe);
    }
    fn stiffness_sums(&self, ctx: &StiffCtx, s: &mut [f64], c: &mut [f64], _r: &mut [f64]) {
        let w = |other: u32| {
            if ctx.fixed[other as usize] == 0b111 {
                1.0
            } else {
                2.0
            }
        };
        for (e, nd) in self.nodes.iter().enumerate() {
            let nd = nd.as_ref();
            let (kmax, cmax) = self.bound(e);
            for (n, o) in [(nd[0], nd[1]), (nd[1], nd[0])] {
                s[n as usize] += w(o) * kmax;
                c[n as usize] += w(o) * cmax;
            }
            A::extra_rows(self, e, kmax, s);
        }
    }
    fn energies(&mut self, ctx: &ForceCtx) -> &[EnergyPartial] {
        let (x, nodes, d0, props, state) = (ctx.x, &self.nodes, &self.d0, &self.props, &self.state);
        let (law, er) = (&self.law, &self.erosion);
        chunk_partials(&mut self.partials, nodes.len(), |r| {
            let mut acc = [0.0; 4];
            for k in r {
                if er.alive(k) {
                    if let Some(d) = A::rel_disp(x, &nodes[k], &d0[k]) {
                        acc[0] += energy_law(&d, &props[k], law_of(law, k), &state[k].slip);
                    }
                }
                acc[1] += state[k].damping_energy;
                acc[2] += state[k].friction_energy;
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
}

impl LinkGroup {
    /// Current force of every link on its node 2 at the positions `x`: spring and
    /// slider (the slider return-mapped on a copy of its state), without the dashpot.
    pub fn elastic_forces(&self, x: &[[f64; 3]]) -> Vec<[f64; 3]> {
        (0..self.id.len())
            .map(|e| {
                let [a, b] = self.nodes[e];
                let d = rel_disp(&x[a as usize], &x[b as usize], &self.d0[e]);
                let mut st = self.state[e];
                force_update_law(
                    &d,
                    &[0.0; 3],
                    &self.props[e],
                    law_of(&self.law, e),
                    &mut st,
                    0.0,
                )
            })
            .collect()
    }
}

impl FramedLinkGroup {
    /// Current elastic forces of every framed link on its six nodes at positions `x`
    /// (the slider return-mapped on a copy of its state), without the dashpot.
    pub fn elastic_forces(&self, x: &[[f64; 3]]) -> Vec<[Vec3; 6]> {
        (0..self.id.len())
            .map(|e| {
                let xe = gather(x, &self.nodes[e]);
                let mut st = self.state[e];
                framed_force_update(
                    &xe,
                    &[[0.0; 3]; 2],
                    &self.d0[e],
                    &self.props[e],
                    law_of(&self.law, e),
                    &mut st,
                    0.0,
                )
            })
            .collect()
    }

    /// The elastic forces of link `e` on its six nodes at positions `xe`, springs only:
    /// a unilateral normal linearised as closed, no slip. What the linear statics
    /// assembles (by finite differences about the reference).
    pub fn reference_forces(&self, e: usize, xe: &FramedX) -> [Vec3; 6] {
        framed_elastic_forces(xe, &self.d0[e], &self.props[e], &DEFAULT_LAW, &[0.0; 2])
    }
}
