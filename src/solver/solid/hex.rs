//! The hexahedron family: eight-node solids with one-point integration (LS-DYNA's
//! default solid, ELFORM 1), their materials and their share of the energy ledger.
//!
//! Each step (Belytschko, Liu & Moran, *Nonlinear Finite Elements*, Box 6.1; the
//! Flanagan–Belytschko element, IJNME 17 (1981)), with v = v^{n−½} and Δt = Δt^{n−½}:
//! 1. the rate of deformation D and the spin W from the mean gradient operator at the
//!    mid-step configuration x^{n−½} = x^n − ½Δt v ([`hex8::hex_geometry`]);
//! 2. the stress is rotated by the Hughes–Winget increment R = (I − ½WΔt)⁻¹(I + ½WΔt):
//!    exactly orthogonal, so a rigid rotation leaves its invariants unchanged (objective;
//!    chosen over the Jaumann rate's σ += (Wσ − σW)Δt, which is orthogonal only to first
//!    order and lets a long rigid spin grow the stress);
//! 3. the material updates the stress from the strain increment DΔt ([`Material::update`]:
//!    hypoelastic trial, radial return);
//! 4. the nodal forces f_a = −V σ̃ b_a at x^n with σ̃ = σ − q I, q the bulk viscosity
//!    (LS-DYNA's defaults Q₁ = 1.5, Q₂ = 0.06), plus the viscous hourglass forces of
//!    Flanagan & Belytschko's projected modes, coefficient 16 × Q_hg ρ c V^{2/3}/4 (the
//!    projected vectors are ¼ of LS-DYNA's ±1 base vectors, so the factor 16 gives the
//!    magnitude of LS-DYNA's IHQ = 1 for the same Q_hg; 0.1 by default, the part's
//!    `hourglass`).
//!
//! Energies, accumulated element by element each step (they depend on the path, not on
//! the positions alone): internal ΔW = ½(σ^{n−1} + σ^n):DΔt V^{n−½} (the trapezoid of
//! DYNA3D's energy update; it holds the elastic and the plastic work), bulk viscosity
//! −q tr D V Δt (reported as damping), hourglass Σ_α coef|q_α|² Δt.
//!
//! Stable step: the nodal Gershgorin bound of [`crate::solver::stable`], each element
//! adding to node a's row its stiffness matrix's row sum S_a = V max_i Σ_b Σ_j
//! |λ b_ai b_bj + μ b_aj b_bi + μ δ_ij b_a·b_b| (the one-point element's K = V BᵀCB).
//! For a cube of side h this gives Δt = 0.67 h/c at ν = 0 and 0.62 h/c at ν = 0.3, c the
//! dilatational speed: smaller than LS-DYNA's l/c (l = V/A_max), which a lone element
//! or a mesh's alternating dilatation (u = ((−1)^i, (−1)^j, (−1)^k) h: ω² = 8(1.5λ + μ)/(ρh²),
//! 1.36 × the uniaxial (2c/h)² at ν = 0.3) outruns: a cube crushed from one face went
//! unstable at 0.9 l/c within 20 steps. The damping row gets C_a = ρ V Q₂ c/(2 l) (the
//! linear bulk viscosity, LS-DYNA's Q = Q₂c in Δt = l/(Q + √(Q² + c²))).
//! The reference geometry sets them; a solid that is crushed shortens its l (the Taylor
//! test), which the fixed step does not follow: [`Family::add_stiffening`] lets the
//! run's stiffening check stop it, naming the element, before it goes unstable.

use super::kernel::{self, BULK_Q1, BULK_Q2};
use super::selective::Eroded;
use super::slow::{self, Slow};
use crate::error::Result;
use crate::material::{Material, PointState};
use crate::model::ElementKind;
use crate::shape::hex8::{self, HexGeometry};
use crate::solver::failure::{Criterion, Erosion, Failure, FailureLaw, Fate};
use crate::solver::family::{
    chunk_partials, for_chunks_of, Build, EnergyGroup, EnergyPartial, Family, ForceCtx, Per,
    SlowChoice, StateValues, StiffCtx, Stiffened, CHUNK,
};
use crate::solver::vec3::Vec3;

/// Hexahedra, struct-of-arrays.
#[derive(Debug, Clone, Default)]
pub struct HexGroup {
    pub id: Vec<i64>,
    pub nodes: Vec<[u32; 8]>,
    /// Index into `materials`, per element.
    pub material: Vec<u32>,
    /// One per part that has hexahedra.
    pub materials: Vec<Material>,
    /// Q_hg of the element's part.
    pub q_hg: Vec<f64>,
    /// The integration point's state (stress, plastic strain, temperature); for a
    /// selective-reduced element the volume-weighted mean of its eight points' states.
    pub state: Vec<PointState>,
    /// Whether the element is selective-reduced (its part's `solid_formulation`).
    pub selective: Vec<bool>,
    /// The eight points' states of every element when some part is selective-reduced
    /// (the one-point elements' stay unused), empty otherwise.
    pub points: Vec<[PointState; 8]>,
    /// Accumulated [internal, bulk viscosity, hourglass] energy [J] per element.
    pub work: Vec<[f64; 3]>,
    /// The last step's bulk viscosity and hourglass forces, for the energy booking.
    pub previous: Vec<Previous>,
    /// Reference volume [m³] and characteristic length [m], for the stable step.
    pub v0: Vec<f64>,
    pub l0: Vec<f64>,
    /// The element's Gershgorin row sums S_a at the reference [N/m] (module docs).
    pub rows: Vec<[f64; 8]>,
    /// The elements (indices into this group, which are the rows of the model's hex
    /// table) whose state the run's output samples carry ([`Family::sample_states`]);
    /// empty (the default): none, and sampling costs nothing.
    pub output: Vec<u32>,
    /// The failure log's view of the erosion at `erosion_plastic_strain` (which the
    /// material flags at its point): active when some part has one; each element that
    /// erodes is reported as a `plastic_strain` failure taking no energy (its work stays
    /// in the internal energy, which its zero forces no longer change).
    pub erosion: Erosion,
    /// The slow elements of a subcycled run ([`crate::solver::subcycle`]); `None`:
    /// every element is updated every step.
    pub subcycle: Option<Slow>,
    partials: Vec<EnergyPartial>,
}

impl HexGroup {
    fn mat(&self, e: usize) -> &Material {
        &self.materials[self.material[e] as usize]
    }

    /// [`Family::add_stiffening`] for the elements `which` (ascending; `None`: all):
    /// each element's rows S_a at its current shape less the reference ones it was
    /// given, added to its nodes where they have grown (a crushed element: |b|²V grows
    /// as it flattens); `most` gets (added, kind, id, [V/V₀, l/l₀, 0]).
    fn stiffening_of(
        &self,
        which: Option<&[u32]>,
        x: &[Vec3],
        extra: &mut [f64],
        most: &mut [Option<Stiffened>],
    ) {
        use rayon::prelude::*;
        let count = which.map_or(self.nodes.len(), <[u32]>::len);
        let element = |i: usize| which.map_or(i, |w| w[i] as usize);
        let grown: Vec<([f64; 8], [f64; 3])> = (0..count)
            .into_par_iter()
            .with_min_len(1024)
            .map(|i| {
                let e = element(i);
                if self.state[e].eroded {
                    return ([0.0; 8], [0.0; 3]);
                }
                let ns = &self.nodes[e];
                let xe: [Vec3; 8] = std::array::from_fn(|a| x[ns[a] as usize]);
                let g = hex8::hex_geometry(&xe);
                let l = hex8::characteristic_length(&xe, g.volume);
                let (lam, mu) = self.mat(e).lame();
                let now = rows_at(self.selective[e], &xe, lam, mu);
                let add = std::array::from_fn(|a| now[a] - self.rows[e][a]);
                (add, [g.volume / self.v0[e], l / self.l0[e], 0.0])
            })
            .collect();
        for (i, (add, q)) in grown.iter().enumerate() {
            let e = element(i);
            for (a, &n) in self.nodes[e].iter().enumerate() {
                if add[a] <= 0.0 {
                    continue;
                }
                let n = n as usize;
                extra[n] += add[a];
                if most[n].is_none_or(|m| add[a] > m.added) {
                    most[n] = Some(Stiffened {
                        added: add[a],
                        id: self.id[e],
                        q: *q,
                        describe: Self::describe_stiffening,
                    });
                }
            }
        }
    }
}

/// The Gershgorin row sums of the one-point element's stiffness V BᵀCB (isotropic C):
/// S_a = V max_i Σ_b Σ_j |λ b_ai b_bj + μ b_aj b_bi + μ δ_ij b_a·b_b|.
pub fn gershgorin_rows(g: &HexGeometry, lam: f64, mu: f64) -> [f64; 8] {
    let b = &g.b;
    std::array::from_fn(|a| {
        let mut best = 0.0f64;
        for i in 0..3 {
            let mut row = 0.0;
            for bb in b {
                let ab = b[a][0] * bb[0] + b[a][1] * bb[1] + b[a][2] * bb[2];
                for j in 0..3 {
                    let k = lam * b[a][i] * bb[j]
                        + mu * b[a][j] * bb[i]
                        + if i == j { mu * ab } else { 0.0 };
                    row += k.abs();
                }
            }
            best = best.max(row);
        }
        g.volume.abs() * best
    })
}

/// The element's Gershgorin rows at the shape `x`, by its formulation.
fn rows_at(selective: bool, x: &[Vec3; 8], lam: f64, mu: f64) -> [f64; 8] {
    if selective {
        super::selective::gershgorin_rows(&super::selective::gauss_geometry(x), lam, mu)
    } else {
        gershgorin_rows(&hex8::hex_geometry(x), lam, mu)
    }
}

/// What the energy booking of the next step needs of this one: the bulk viscosity q^n
/// [Pa] and the hourglass coefficient times the mode velocities, coef·q_α^n [N].
#[derive(Debug, Clone, Copy, Default)]
pub struct Previous {
    pub bulk: f64,
    pub hourglass: [Vec3; 4],
}

/// One element's step: state and work updated, nodal forces into `out` (module docs).
///
/// The energies are booked as the work of the element's own nodal forces over the last
/// step, the trapezoid ½(fⁿ⁻¹ + fⁿ)·Δx^{n−½} of the central difference: for the stress,
/// ½(σⁿ⁻¹ + σⁿ):D^{n−½}Δt V (then the balance telescopes to round-off for small
/// strains); for the bulk viscosity ½(qⁿ⁻¹ + qⁿ)(−tr D^{n−½})Δt V; for the hourglass
/// forces −½(f_hgⁿ⁻¹ + f_hgⁿ)·v^{n−½}Δt.
#[inline]
#[allow(clippy::too_many_arguments)]
fn element_step(
    mat: &Material,
    q_hg: f64,
    st: &mut PointState,
    prev: &mut Previous,
    work: &mut [f64; 3],
    x: &[Vec3; 8],
    v: &[Vec3; 8],
    dt: f64,
    out: &mut [Vec3],
) -> bool {
    if st.eroded {
        out.iter_mut().for_each(|f| *f = [0.0; 3]);
        return false;
    }
    // 1–3: the stress at tⁿ from the increment over the last step.
    let mut d_mid = [0.0; 6];
    let mut v_mid = 0.0;
    if dt > 0.0 {
        let gm = hex8::hex_geometry(&kernel::mid_step_shape(x, v, dt));
        let l = kernel::velocity_gradient(&gm.b, v);
        let (d, w) = kernel::split_velocity_gradient(&l);
        let r = kernel::hughes_winget(&w, dt);
        kernel::rotate_stress(&mut st.stress, &r);
        let before = st.stress;
        let deps: [f64; 6] = std::array::from_fn(|i| d[i] * dt);
        mat.update(st, &deps, dt);
        let mid: [f64; 6] = std::array::from_fn(|i| 0.5 * (before[i] + st.stress[i]));
        work[0] += kernel::contract(&mid, &deps) * gm.volume;
        d_mid = d;
        v_mid = gm.volume;
    }
    // 4: forces at xⁿ.
    let g: HexGeometry = hex8::hex_geometry(x);
    let c = mat.dilatational_wave_speed();
    let mut s = st.stress;
    let mut f = [[0.0; 3]; 8];
    let mut q = 0.0;
    if dt > 0.0 {
        let l = kernel::velocity_gradient(&g.b, v);
        let d_kk = l[0][0] + l[1][1] + l[2][2];
        let le = hex8::characteristic_length(x, g.volume);
        q = kernel::bulk_viscosity(mat.density(), le, c, d_kk, BULK_Q1, BULK_Q2);
        s[0] -= q;
        s[1] -= q;
        s[2] -= q;
        let tr_mid = d_mid[0] + d_mid[1] + d_mid[2];
        work[1] += -0.5 * (prev.bulk + q) * tr_mid * v_mid * dt;
    }
    prev.bulk = q;
    kernel::internal_forces(&g.b, g.volume, &s, &mut f);
    // The viscous forces (hourglass, bulk) act from the first step on: at t = 0 (Δt^{n−½}
    // = 0) the velocities are the initial ones, not a step's, and the ledger's kinetic
    // energy ½ m v^{−½}·v^{½} at t = 0 would count their first half step twice.
    if q_hg > 0.0 && dt > 0.0 {
        let gamma = kernel::hourglass_gamma(x, &g.b);
        let coef = 16.0 * kernel::hourglass_coefficient(q_hg, mat.density(), c, g.volume);
        // Flanagan & Belytschko's viscous form: mode forces coef·q_α, nodal forces
        // f_a = −Σ_α γ_aα coef q_α.
        let cq = kernel::hourglass_mode_forces(&gamma, v, coef);
        kernel::add_hourglass_forces(&gamma, &cq, &mut f);
        // −½(f^{n−1} + fⁿ)·v^{n−½}: this step's force against v^{n−½} now, the last
        // step's through its mode forces (γ of this step).
        let mut p = 0.0;
        for a in 0..8 {
            for al in 0..4 {
                for i in 0..3 {
                    p += 0.5 * gamma[a][al] * (cq[al][i] + prev.hourglass[al][i]) * v[a][i];
                }
            }
        }
        work[2] += p * dt;
        prev.hourglass = cq;
    }
    out.copy_from_slice(&f);
    // Its material flagged it at this step's update (its forces at tⁿ are its last).
    st.eroded
}

/// Element `e` erodes at this step (`why`, its point's state `st`): reported once in its
/// fate, as the failure log's `plastic_strain` (at its material's erosion strain) or
/// `inverted` (a folded point).
fn report_erosion(
    mat: &Material,
    e: usize,
    why: Eroded,
    st: &PointState,
    fate: &mut Fate,
    any: &std::sync::atomic::AtomicBool,
) {
    if fate.eroded {
        return;
    }
    let (criterion, value, limit) = match why {
        Eroded::PlasticStrain => (
            Criterion::PlasticStrain,
            st.plastic_strain,
            mat.erosion_plastic_strain.unwrap_or(f64::NAN),
        ),
        Eroded::Inverted(ratio) => (Criterion::Inverted, ratio, 0.0),
    };
    let failure = Failure {
        kind: ElementKind::Hex,
        element: e,
        criterion,
        value,
        limit,
        eroded: true,
        energy: 0.0,
    };
    fate.fail(failure, any);
}

impl Family for HexGroup {
    const KIND: ElementKind = ElementKind::Hex;
    const SLOTS: usize = 8;
    const GROUP: EnergyGroup = EnergyGroup::Solid;
    const VARIABLE_STEP: bool = true;
    /// At an output sample step: the state at tⁿ of the elements in `output`,
    /// in that order, into `rows` (σ, ε_p, T; an eroded element's σ as 0: its forces are
    /// zero from then on, while its point keeps the stress it eroded with).
    fn sample_states(&self, rows: &mut Vec<StateValues>) {
        for &e in &self.output {
            let st = &self.state[e as usize];
            let s = if st.eroded { [0.0; 6] } else { st.stress };
            rows.push([
                s[0],
                s[1],
                s[2],
                s[3],
                s[4],
                s[5],
                st.plastic_strain,
                st.temperature,
            ]);
        }
    }
    /// For the stiffening check of the fixed step ([`crate::solver::stable`]):
    /// [`HexGroup::stiffening_of`] the fast elements (all, without a subcycle).
    fn add_stiffening(&self, x: &[Vec3], extra: &mut [f64], most: &mut [Option<Stiffened>]) {
        match &self.subcycle {
            Some(sc) => self.stiffening_of(Some(&sc.fast_list), x, extra, most),
            None => self.stiffening_of(None, x, extra, most),
        }
    }
    fn add_slow_stiffening(&self, x: &[Vec3], extra: &mut [f64], most: &mut [Option<Stiffened>]) {
        if let Some(sc) = &self.subcycle {
            self.stiffening_of(Some(&sc.slow_list), x, extra, most);
        }
    }
    fn drift_nodes(&self) -> Option<&[bool]> {
        self.subcycle.as_ref().map(|s| &s.drift[..])
    }
    fn slow_forces(&self) -> Option<&[Vec3]> {
        self.subcycle.as_ref().map(|s| &s.force[..])
    }
    fn choose_subcycle(&mut self, node_dt: &[f64], dt: f64, x: &[Vec3]) -> Option<SlowChoice> {
        let (s, choice) = slow::choose(&self.nodes, node_dt, dt, x)?;
        self.subcycle = Some(s);
        Some(choice)
    }
    fn describe_stiffening(id: i64, q: [f64; 3], dt_safety: f64) -> (String, Option<String>) {
        (
            format!(
                "hex `{id}` has been compressed to {:.3} of its volume and {:.3} of its length V/A_max",
                q[0], q[1]
            ),
            Some(format!(
                "the stable step is set once, from the undeformed model, and a crushed solid needs a smaller one: lower dt_safety (now {dt_safety}) to run on"
            )),
        )
    }
    fn set_state_output(&mut self, elements: &[u32]) {
        self.output = elements.to_vec();
    }

    fn build(bd: &mut Build) -> Result<Self> {
        let (m, mass) = (bd.model, &mut *bd.mass);
        let mut g = HexGroup::default();
        let Some(b) = m.block(ElementKind::Hex) else {
            return Ok(g);
        };
        let mut by_part: Vec<Option<u32>> = vec![None; m.parts.len()];
        let mut selective_part: Vec<Option<bool>> = vec![None; m.parts.len()];
        for e in 0..b.len() {
            let pi = b.part[e];
            let part = &m.parts[pi];
            let mi = match by_part[pi] {
                Some(i) => i,
                None => {
                    g.materials.push(part.material()?);
                    let i = (g.materials.len() - 1) as u32;
                    by_part[pi] = Some(i);
                    i
                }
            };
            let ns: [usize; 8] = std::array::from_fn(|a| b.nodes[8 * e + a]);
            let x: [Vec3; 8] = std::array::from_fn(|a| m.coords[ns[a]]);
            let geo = hex8::hex_geometry(&x);
            let mat = &g.materials[mi as usize];
            // Lumped mass: an eighth of ρV to each node.
            for &n in &ns {
                mass[n] += 0.125 * mat.density() * geo.volume;
            }
            g.id.push(b.id[e]);
            g.nodes.push(ns.map(|n| n as u32));
            g.material.push(mi);
            let sel = match selective_part[pi] {
                Some(s) => s,
                None => *selective_part[pi].insert(part.selective_reduced()?),
            };
            g.q_hg.push(part.props.hourglass_coefficient());
            g.state.push(mat.initial_state());
            g.selective.push(sel);
            g.work.push([0.0; 3]);
            g.previous.push(Previous::default());
            g.l0.push(hex8::characteristic_length(&x, geo.volume));
            g.v0.push(geo.volume);
            let (lam, mu) = mat.lame();
            g.rows.push(rows_at(sel, &x, lam, mu));
        }
        if g.selective.iter().any(|&s| s) {
            g.points = g.state.iter().map(|&st| [st; 8]).collect();
        }
        if g.materials
            .iter()
            .any(|m| m.erosion_plastic_strain.is_some())
        {
            g.erosion = Erosion::watching(vec![FailureLaw::NONE; g.id.len()]);
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
        self.rows[e].iter().fold(0.0, |a: f64, &r| a.max(r))
    }
    fn forces(&mut self, ctx: &ForceCtx, fe: &mut [Vec3]) {
        let HexGroup {
            nodes,
            material,
            materials,
            q_hg,
            state,
            work,
            previous,
            erosion,
            selective,
            points,
            subcycle,
            ..
        } = self;
        let (nodes, material, materials) = (&*nodes, &*material, &*materials);
        let (q_hg, selective) = (&*q_hg, &*selective);
        let sub = subcycle.as_ref();
        let (sample, live) = (ctx.slow.sample, sub.is_some_and(|s| s.live));
        // Element e's step into its force slots (its node positions and velocities
        // gathered; its eight points' states when some part is selective-reduced);
        // why it eroded at this step, if it did. A slow element (subcycle) steps at the
        // slow samples only, over the slow interval with its nodes' mean velocities, its
        // forces the weighted impulse; between them its slots are zero.
        let step = |e: usize,
                    st: &mut PointState,
                    pv: &mut Previous,
                    wk: &mut [f64; 3],
                    pts: Option<&mut [PointState; 8]>,
                    slots: &mut [Vec3]|
         -> Option<Eroded> {
            let ns = &nodes[e];
            let slow = sub.filter(|s| s.slow[e]);
            if slow.is_some() && !sample {
                if live {
                    slots.iter_mut().for_each(|f| *f = [0.0; 3]);
                }
                return None;
            }
            let x: [Vec3; 8] = std::array::from_fn(|a| ctx.x[ns[a] as usize]);
            let (v, dt) = match slow {
                Some(s) => (s.velocities(ns, &x, ctx.slow.dt), ctx.slow.dt),
                None => (std::array::from_fn(|a| ctx.v[ns[a] as usize]), ctx.dt_prev),
            };
            let mat = &materials[material[e] as usize];
            let why = match pts {
                Some(p) if selective[e] => {
                    super::selective::element_step(mat, p, st, &mut pv.bulk, wk, &x, &v, dt, slots)
                }
                _ => element_step(mat, q_hg[e], st, pv, wk, &x, &v, dt, slots)
                    .then_some(Eroded::PlasticStrain),
            };
            if let Some(s) = slow {
                s.weigh(e, why.is_some(), &ctx.slow, slots);
            }
            why
        };
        let report = |e: usize, why, st: &PointState, fate: &mut Fate, any| {
            report_erosion(&materials[material[e] as usize], e, why, st, fate, any)
        };
        // Each chunk of force slots travels with its elements' state, previous forces,
        // work, points (when selective-reduced) and fates (when eroding).
        let n = nodes.len();
        let own = (
            (Per(fe, 8), Per(&mut state[..], 1)),
            (Per(&mut previous[..], 1), Per(&mut work[..], 1)),
        );
        match (erosion.active(), points.is_empty()) {
            (false, true) => for_chunks_of(n, own, |ci, ((out, st), (pv, wk))| {
                for (j, slots) in out.chunks_exact_mut(8).enumerate() {
                    step(
                        ci * CHUNK + j,
                        &mut st[j],
                        &mut pv[j],
                        &mut wk[j],
                        None,
                        slots,
                    );
                }
            }),
            (false, false) => {
                let slices = (own, Per(&mut points[..], 1));
                for_chunks_of(n, slices, |ci, (((out, st), (pv, wk)), pts)| {
                    for (j, slots) in out.chunks_exact_mut(8).enumerate() {
                        let p = Some(&mut pts[j]);
                        step(ci * CHUNK + j, &mut st[j], &mut pv[j], &mut wk[j], p, slots);
                    }
                })
            }
            (true, true) => {
                let any = &erosion.any;
                let slices = (own, Per(&mut erosion.fate[..], 1));
                for_chunks_of(n, slices, |ci, (((out, st), (pv, wk)), fates)| {
                    for (j, slots) in out.chunks_exact_mut(8).enumerate() {
                        let e = ci * CHUNK + j;
                        if let Some(why) = step(e, &mut st[j], &mut pv[j], &mut wk[j], None, slots)
                        {
                            report(e, why, &st[j], &mut fates[j], any);
                        }
                    }
                })
            }
            (true, false) => {
                let any = &erosion.any;
                let slices = (
                    own,
                    (Per(&mut points[..], 1), Per(&mut erosion.fate[..], 1)),
                );
                for_chunks_of(n, slices, |ci, (((out, st), (pv, wk)), (pts, fates))| {
                    for (j, slots) in out.chunks_exact_mut(8).enumerate() {
                        let e = ci * CHUNK + j;
                        let p = Some(&mut pts[j]);
                        if let Some(why) = step(e, &mut st[j], &mut pv[j], &mut wk[j], p, slots) {
                            report(e, why, &st[j], &mut fates[j], any);
                        }
                    }
                })
            }
        }
        if let Some(s) = subcycle.as_mut() {
            let eroding =
                erosion.active() && erosion.any.load(std::sync::atomic::Ordering::Relaxed);
            s.after_pass(
                ctx,
                nodes,
                fe,
                eroding.then_some(|e: usize| state[e].eroded),
            );
        }
    }
    fn erosion(&self) -> Option<&Erosion> {
        self.erosion.active().then_some(&self.erosion)
    }
    fn erosion_mut(&mut self) -> Option<&mut Erosion> {
        if self.erosion.active() {
            Some(&mut self.erosion)
        } else {
            None
        }
    }
    fn stiffness_sums(&self, _ctx: &StiffCtx, s: &mut [f64], c: &mut [f64], _r: &mut [f64]) {
        for (e, ns) in self.nodes.iter().enumerate() {
            let mat = self.mat(e);
            let (v, l) = (self.v0[e], self.l0[e]);
            let ce = mat.density() * v * BULK_Q2 * mat.dilatational_wave_speed() / (2.0 * l);
            for (a, &n) in ns.iter().enumerate() {
                s[n as usize] += self.rows[e][a];
                c[n as usize] += ce;
            }
        }
    }
    fn energies(&mut self, _ctx: &ForceCtx) -> &[EnergyPartial] {
        let work = &self.work;
        chunk_partials(&mut self.partials, work.len(), |r| {
            let mut p = [0.0; 4];
            for w in &work[r] {
                p[0] += w[0];
                p[1] += w[1];
                p[3] += w[2];
            }
            p
        });
        &self.partials
    }
}
