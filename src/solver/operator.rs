//! The physics operator: the forces on every node at a given state, f = f_ext + f_int +
//! f_contact (+ the tie transfer), and from them the accelerations the integrator uses.
//! It knows nothing of time stepping: the caller passes the state and the steps.
//!
//! Layout: every element family writes its per-element nodal forces into its own slots
//! of `fe`; loads go to `fext`; contact and tie transfers to `fcon` (with the list of the
//! nodes they touched, cleared on the next call). A node's force is gathered from these
//! in a fixed order (external, contact, then its element slots in ascending slot order
//! through the CSR index `slot_ptr`/`slots`), so the sum does not depend on the thread
//! count.

use super::contact::{ProjectileContact, SurfaceContact};
use super::families::Families;
use super::family::{ForceCtx, SlowStep};
use super::rotations::Rotations;
use super::ties::Ties;
use super::vec3::{add, dot};
use crate::model::Load;

/// The state the operator reads (the integrator owns and advances it).
#[derive(Debug, Clone)]
pub struct State {
    /// Positions x^n [m].
    pub x: Vec<[f64; 3]>,
    /// Half-step velocities v^{n−½} [m/s].
    pub v: Vec<[f64; 3]>,
    /// Positions and velocities at the last output sample step (x^n, v^n).
    pub xn: Vec<[f64; 3]>,
    pub vn: Vec<[f64; 3]>,
    /// Rotational nodes (beams).
    pub rot: Rotations,
    pub t: f64,
    pub step: u64,
    /// Δt^{n−½} [s].
    pub dt_prev: f64,
    /// The slow elements' part of this step ([`super::subcycle`]).
    pub slow: SlowStep,
}

/// Loads with their time laws, and the external work they do.
#[derive(Debug, Clone, Default)]
pub struct LoadSet {
    pub loads: Vec<Load>,
    /// Loaded nodes, sorted, each once.
    pub nodes: Vec<usize>,
    /// f_ext^{n−1} at the loaded nodes.
    prev: Vec<[f64; 3]>,
    /// External work so far [J].
    pub work: f64,
}

impl LoadSet {
    pub fn new(loads: &[Load]) -> LoadSet {
        let mut nodes: Vec<usize> = loads.iter().map(|l| l.node).collect();
        nodes.sort_unstable();
        nodes.dedup();
        LoadSet {
            loads: loads.to_vec(),
            prev: vec![[0.0; 3]; nodes.len()],
            nodes,
            work: 0.0,
        }
    }

    /// f_ext at t_n into `fext`, and the external work up to t_n, trapezoidal:
    /// W += ½ Δu^n · (f^{n−1} + f^n), Δu^n = Δt^{n−½} v^{n−½}.
    pub fn apply(&mut self, t: f64, dt_prev: f64, v: &[[f64; 3]], fext: &mut [[f64; 3]]) {
        for &n in &self.nodes {
            fext[n] = [0.0; 3];
        }
        for l in &self.loads {
            let g = l.law.eval(t);
            let f = &mut fext[l.node];
            f[0] += l.force[0] * g;
            f[1] += l.force[1] * g;
            f[2] += l.force[2] * g;
        }
        let mut w = 0.0;
        for (j, &n) in self.nodes.iter().enumerate() {
            let f = fext[n];
            let fp = self.prev[j];
            let vv = v[n];
            w += 0.5 * dt_prev * dot(&vv, &[f[0] + fp[0], f[1] + fp[1], f[2] + fp[2]]);
            self.prev[j] = f;
        }
        self.work += w;
    }
}

/// Node → element force slots, in ascending slot order (CSR).
#[derive(Debug, Clone, Default)]
pub struct Gather {
    pub ptr: Vec<u32>,
    pub slots: Vec<u32>,
}

impl Gather {
    pub fn new(nodes: usize, slot_nodes: &[u32]) -> Gather {
        let mut count = vec![0u32; nodes + 1];
        for &n in slot_nodes {
            count[n as usize + 1] += 1;
        }
        for i in 0..nodes {
            count[i + 1] += count[i];
        }
        let ptr = count.clone();
        let mut fill = count;
        let mut slots = vec![0u32; slot_nodes.len()];
        for (s, &n) in slot_nodes.iter().enumerate() {
            slots[fill[n as usize] as usize] = s as u32;
            fill[n as usize] += 1;
        }
        Gather { ptr, slots }
    }
    #[inline(always)]
    pub fn of(&self, node: usize) -> &[u32] {
        &self.slots[self.ptr[node] as usize..self.ptr[node + 1] as usize]
    }
}

/// Forces on the nodes of one model.
#[derive(Debug, Clone)]
pub struct Operator {
    pub el: Families,
    pub ties: Ties,
    pub projectiles: ProjectileContact,
    /// Node-to-surface contact between parts (`contacts.parquet`).
    pub surfaces: SurfaceContact,
    pub loads: LoadSet,
    pub gather: Gather,
    /// External forces at t_n [N].
    pub fext: Vec<[f64; 3]>,
    /// Per-element nodal forces, one slot per element node [N].
    pub fe: Vec<[f64; 3]>,
    /// Contact and tie-transfer forces [N], non-zero only at `touched`.
    pub fcon: Vec<[f64; 3]>,
    touched: Vec<usize>,
}

impl Operator {
    pub fn new(
        el: Families,
        ties: Ties,
        projectiles: ProjectileContact,
        loads: &[Load],
        nodes: usize,
    ) -> Operator {
        let gather = Gather::new(nodes, &el.slot_nodes());
        Operator {
            fe: vec![[0.0; 3]; el.slots()],
            el,
            ties,
            projectiles,
            surfaces: SurfaceContact::default(),
            loads: LoadSet::new(loads),
            gather,
            fext: vec![[0.0; 3]; nodes],
            fcon: vec![[0.0; 3]; nodes],
            touched: Vec::with_capacity(nodes),
        }
    }

    /// Whether `fcon` can be non-zero.
    #[inline]
    pub fn has_fcon(&self) -> bool {
        !self.projectiles.is_empty() || !self.ties.is_empty() || !self.surfaces.is_empty()
    }

    /// External loads at t_n (and their work).
    pub fn apply_loads(&mut self, st: &State) {
        self.loads.apply(st.t, st.dt_prev, &st.v, &mut self.fext);
    }

    /// Element forces at x^n.
    pub fn element_forces(&mut self, st: &State) {
        let ctx = ForceCtx {
            x: &st.x,
            v: &st.v,
            rot_r: &st.rot.r,
            dt_prev: st.dt_prev,
            slow: st.slow,
        };
        self.el.forces(&ctx, &mut self.fe);
    }

    /// Forces beside the elements' and the loads': contact (projectiles, then surfaces),
    /// then the tie transfer of the
    /// slaves' forces to their masters (so that contact on a slave reaches its masters).
    pub fn contact_and_ties(&mut self, st: &State, mass: &[f64], dt: f64) {
        if !self.has_fcon() {
            return;
        }
        if self.surfaces.is_empty() {
            for &i in &self.touched {
                self.fcon[i] = [0.0; 3];
            }
        } else {
            // Contact between parts touches many nodes: clear them all, in parallel.
            use rayon::prelude::*;
            if self.fcon.len() > 16 * 1024 {
                self.fcon
                    .par_chunks_mut(8 * 1024)
                    .for_each(|c| c.fill([0.0; 3]));
            } else {
                self.fcon.fill([0.0; 3]);
            }
        }
        self.touched.clear();
        if !self.projectiles.is_empty() {
            self.projectiles.forces(
                &st.x,
                &st.v,
                mass,
                dt,
                st.dt_prev,
                &mut self.fcon,
                &mut self.touched,
            );
        }
        if !self.surfaces.is_empty() {
            self.surfaces
                .forces(&st.x, &st.v, dt, st.dt_prev, &mut self.fcon);
        }
        let (fext, fe, gather) = (&self.fext, &self.fe, &self.gather);
        self.ties.transfer(
            |sl, fcon| {
                let mut f = fext[sl];
                add(&mut f, &fcon[sl]);
                for &slot in gather.of(sl) {
                    add(&mut f, &fe[slot as usize]);
                }
                f
            },
            &mut self.fcon,
            &mut self.touched,
        );
    }

    /// Every force of one step at the state `st`: loads, elements, contact, ties.
    pub fn assemble(&mut self, st: &State, mass: &[f64], dt: f64) {
        self.apply_loads(st);
        self.element_forces(st);
        self.contact_and_ties(st, mass, dt);
    }

    /// The total force on node i: external, contact, then its element slots in order.
    #[inline(always)]
    pub fn nodal_force(&self, i: usize) -> [f64; 3] {
        let mut f = self.fext[i];
        if self.has_fcon() {
            add(&mut f, &self.fcon[i]);
        }
        for &s in self.gather.of(i) {
            add(&mut f, &self.fe[s as usize]);
        }
        f
    }
}
