//! Dynamic relaxation with local (non-viscous) damping: the static equilibrium of a
//! model reached by explicit steps in which each force component loses α|f| against the
//! motion of its degree of freedom (Cundall, "Distinct element models of rock and soil
//! structure", in *Analytical and Computational Methods in Engineering Rock Mechanics*,
//! 1987; the default static solver of FLAC and PFC, α = 0.8).
//!
//! Why not mass damping or kinetic damping: a woven patch's stiffnesses span 10⁴ (a
//! yarn's E·A against its tension and the contact penalty). Mass damping tuned for the
//! crimp waves over-damps the slow modes (the relaxation stalled at K/W ≈ 10⁻⁵ after
//! 8·10⁴ steps, measured); kinetic damping (velocities zeroed at every crest of the
//! total kinetic energy) is reset every 6–8 steps by the contact's fast modes, so the
//! slow ones never move (the residual stayed at 25 % of the contact forces, measured).
//! Local damping acts per degree of freedom, takes no frequency, and lets each move
//! freely while its force does work.
//!
//! Each step: f = f_ext + f_contact + Σ f_element at x^n; for each free component,
//! f_d ← f_d − α|f_d| sign(v_d^{n−½}); v^{n+½} = v^{n−½} + Δt f/m; x^{n+1} = x^n + Δt v^{n+½}.
//! The work the damping takes is booked as removed (the forming work W).
//!
//! Convergence is tested in two parts: the kinetic energy and the residual force, and
//! then a rest test: the velocities zeroed and the model run free (α = 0) for a window;
//! if no node moves further than a tolerance it is at rest, and the state where the
//! test started is the result. Why a free test rather than the motion under damping:
//! local damping with the contacts' chatter acts on a slow mode like friction, and the
//! mode crawls (a 10 × 10 woven quarter crawled 1.6 µm per 50 µs for 10⁵ steps, from
//! one equilibrium to another, measured) while free it would not move.
//!
//! Thread-independent: the force gather and the per-chunk sums are those of the time
//! integration (fixed chunks, summed in order).

use rayon::prelude::*;

use super::family::CHUNK;
use super::vec3::{add, dot};
use super::Solver;
use crate::error::{Result, WeftError};

/// When to stop.
#[derive(Debug, Clone)]
pub struct RelaxOptions {
    pub max_steps: u64,
    /// No convergence test before this many steps.
    pub min_steps: u64,
    /// Test every this many steps.
    pub check_every: u64,
    /// Local damping α (0 < α < 1; FLAC's default 0.8).
    pub alpha: f64,
    /// Converged when the largest kinetic energy since the last test is ≤ this × the
    /// energy removed so far (plus that kinetic energy) ...
    pub kinetic_tolerance: f64,
    /// ... and the largest residual force on a free degree of freedom is ≤ this × the
    /// largest contact force on a node (the largest seen so far: contacts that open as
    /// the model settles still set the scale) or `force_scale`, whichever is larger.
    pub force_tolerance: f64,
    /// A force scale of the loading [N] (the largest nodal load, say).
    pub force_scale: f64,
    /// ... and, left alone at rest from there (undamped), no node moves more than
    /// `creep_tolerance` [m] within `creep_window` steps: the slow modes (a pretensioned
    /// fabric's drum mode, driven by residuals far below the largest) have settled too.
    /// Tested once the first two hold; while the probe runs no energy is removed; if it
    /// fails, the relaxation goes on from where the probe left it.
    pub creep_window: u64,
    pub creep_tolerance: f64,
    /// Energy counted as removed before the first step [J] (a start that is already
    /// nearly formed: the work that formed it).
    pub work_offset: f64,
    /// Normal contact damping (fraction of critical) while relaxing; the rest test runs
    /// without, as the run that starts from the relaxed state will.
    pub contact_damping: f64,
    /// Degrees of freedom (node, bit mask x = 1, y = 2, z = 4) held during the rest test
    /// only: those that the run starting from the relaxed state holds (a formed yarn's
    /// pulled ends, held where they came to rest; free, a yarn slides along its crimped
    /// path through frictionless crossings, a motion the run does not have).
    pub hold_in_rest_test: Vec<(usize, u8)>,
    /// Run the rest test from the start, before any relaxation: a start that is already
    /// in equilibrium (a woven patch tiled from its formed periodic cell) is then taken
    /// as it is, its residual the one at the start; if it moves, relaxation goes on.
    pub probe_first: bool,
}

/// What the relaxation did.
#[derive(Debug, Clone, Copy, Default)]
pub struct RelaxStats {
    pub steps: u64,
    /// The step used [s].
    pub dt: f64,
    pub converged: bool,
    /// Energy taken by the damping [J]: the forming work dissipated.
    pub removed: f64,
    /// The largest kinetic energy in the last test window [J].
    pub kinetic: f64,
    /// Largest residual force on a free degree of freedom at the last test, and the
    /// largest contact force on a node at any test [N].
    pub residual: f64,
    pub contact_force: f64,
    /// Node with the largest residual.
    pub residual_node: usize,
    /// Largest node displacement in the last free probe [m] (∞ before one), and that
    /// node.
    pub creep: f64,
    pub creep_node: usize,
}

/// What one chunk of nodes adds up in a step: the kinetic energy and the work removed
/// [J], the largest squared residual force and its node, the largest squared contact
/// force, and the first node gone non-finite (usize::MAX: none).
#[derive(Clone, Copy, Default)]
struct Part {
    ke: f64,
    removed: f64,
    res: f64,
    res_node: usize,
    fc: f64,
    bad: usize,
}

/// A step's sums over the chunks (in chunk order): the kinetic energy and the work
/// removed [J], the largest squared residual force and its node, and the largest squared
/// contact force.
struct StepSums {
    ke: f64,
    removed: f64,
    res: f64,
    res_node: usize,
    fc: f64,
}

/// A rest test under way: a free (undamped) run from the relaxed state at rest,
/// `creep_window` steps long; its start position, the largest displacement from it so
/// far, and the step it started.
struct Probe {
    x0: Vec<[f64; 3]>,
    far: f64,
    since: u64,
}

/// What a rest test says after a step.
enum Verdict {
    /// Still running.
    Running,
    /// Over, and no node moved further than the tolerance: at rest.
    AtRest,
    /// Over, and the model moved: relaxation goes on.
    Moving,
}

impl Solver {
    /// Relax to static equilibrium under the model's loads (taken at t = 0) by local
    /// damping. `check` is called at every test with the stats so far (progress).
    pub fn relax(
        &mut self,
        o: &RelaxOptions,
        check: &mut dyn FnMut(&RelaxStats),
    ) -> Result<RelaxStats> {
        // The damped force ranges over (1 ± α)|f|: as if the stiffness were (1 + α) ×,
        // so the stable step shrinks by √(1 + α).
        let dt = self.stable.dt / (1.0 + o.alpha).sqrt();
        let nn = self.state.x.len();
        let nchunks = nn.div_ceil(CHUNK);
        let mut parts = vec![Part::default(); nchunks];
        let mut st = RelaxStats::default();
        st.dt = dt;
        let mut ke_window = 0.0f64;
        self.state.dt_prev = dt;
        let creep_window = o.creep_window.max(1);
        let mut probe: Option<Probe> = None;
        self.op.surfaces.set_normal_damping(o.contact_damping);
        let free_mask: Vec<u8> = o
            .hold_in_rest_test
            .iter()
            .map(|&(n, _)| self.fixed[n])
            .collect();
        let mut next_probe = 0u64;
        st.creep = f64::INFINITY;
        if o.probe_first {
            probe = Some(self.start_probe(o, 0));
        }
        for step in 0..o.max_steps {
            let alpha = if probe.is_some() { 0.0 } else { o.alpha };
            self.damped_step(alpha, dt, &mut parts);
            let sums = self.sum_parts(&parts, step, dt)?;
            if !self.op.ties.is_empty() {
                self.op
                    .ties
                    .update_slaves(&mut self.state.x, &mut self.state.v, None);
            }
            st.removed += sums.removed;
            ke_window = ke_window.max(sums.ke);
            self.state.step += 1;
            st.steps = step + 1;
            if step == 0 && o.probe_first {
                // The start's own balance (the forces of this first step are at the start
                // state): what the report gives if the start passes its rest test.
                st.residual = sums.res.sqrt();
                st.residual_node = sums.res_node;
                st.contact_force = sums.fc.sqrt();
            }
            if let Some(p) = &mut probe {
                match self.watch_probe(p, o, &free_mask, creep_window, &mut st) {
                    Verdict::Running => {}
                    Verdict::AtRest => break,
                    Verdict::Moving => {
                        // Still moving: relax on from here, and probe again later (after a
                        // fifth of the steps so far: at most a fifth of the work is probes).
                        probe = None;
                        ke_window = 0.0;
                        next_probe = st.steps + creep_window.max(st.steps / 5);
                    }
                }
            }
            if st.steps % o.check_every.max(1) == 0 {
                // While a probe runs, the stats stay those of the test that started it.
                if probe.is_none() {
                    st.kinetic = ke_window;
                    st.residual = sums.res.sqrt();
                    st.residual_node = sums.res_node;
                }
                st.contact_force = st.contact_force.max(sums.fc.sqrt());
                ke_window = 0.0;
                check(&st);
                let w = st.removed + st.kinetic + o.work_offset;
                if probe.is_none()
                    && st.steps >= o.min_steps.max(next_probe)
                    && st.kinetic <= o.kinetic_tolerance * w
                    && st.residual <= o.force_tolerance * st.contact_force.max(o.force_scale)
                {
                    // Left alone at rest from here, does the model stay? (Relaxation
                    // itself cannot tell: under local damping, the contacts' chatter
                    // holds a slow mode like friction, which then crawls.)
                    probe = Some(self.start_probe(o, st.steps));
                }
            }
        }
        // Whatever ended the loop, the model's own holds and contact damping are back.
        self.end_probe(o, &free_mask);
        // Leave the state at rest, with forces and velocities consistent (the contacts'
        // last evaluation, which reports such as the deepest overlap read, at the state
        // returned: a passed rest test returns the state it started from).
        self.state.v.iter_mut().for_each(|v| *v = [0.0; 3]);
        self.op
            .contact_and_ties(&self.state, &self.mass, self.stable.dt);
        Ok(st)
    }

    /// One step of local damping `alpha` over `dt`: the forces at x^n, then each node's
    /// damped update, in parallel fixed chunks whose sums go to `parts`.
    fn damped_step(&mut self, alpha: f64, dt: f64, parts: &mut [Part]) {
        let nn = self.state.x.len();
        self.op.apply_loads(&self.state);
        self.op.element_forces(&self.state);
        // The contact penalty κ m*/Δt² with the run's step, so that a formed state
        // meets the same contact stiffness when an impact run starts from it.
        self.op
            .contact_and_ties(&self.state, &self.mass, self.stable.dt);
        let (op, inv_m, fixed, mass) = (&self.op, &self.inv_m, &self.fixed, &self.mass);
        // A tied slave carries no mass; its force went to its masters (the tie
        // transfer), so it has no residual of its own: it follows them below.
        let is_slave = &op.ties.is_slave;
        let fcon = op.has_fcon().then_some(&op.fcon);
        type Chunk<'c> = (
            usize,
            ((&'c mut [[f64; 3]], &'c mut [[f64; 3]]), &'c mut Part),
        );
        let body = |(ci, ((x, v), p)): Chunk| {
            let i0 = ci * CHUNK;
            let mut q = Part {
                bad: usize::MAX,
                ..Default::default()
            };
            for j in 0..x.len() {
                let i = i0 + j;
                let mut f = op.fext[i];
                if let Some(fc) = fcon {
                    add(&mut f, &fc[i]);
                    q.fc = q.fc.max(dot(&fc[i], &fc[i]));
                }
                for &s in op.gather.of(i) {
                    add(&mut f, &op.fe[s as usize]);
                }
                let fx = fixed[i];
                for (d, fd) in f.iter_mut().enumerate() {
                    if fx & (1 << d) != 0 {
                        *fd = 0.0;
                    }
                }
                let r = if is_slave.get(i).copied().unwrap_or(false) {
                    0.0
                } else {
                    dot(&f, &f)
                };
                if r > q.res {
                    q.res = r;
                    q.res_node = i;
                }
                let im = inv_m[i];
                // Local damping: each component of the force loses α|f| against the
                // motion (v^{n−½}); the work that takes is booked as removed.
                let mut vn = [0.0; 3];
                for d in 0..3 {
                    let vd = v[j][d];
                    let damp = if vd > 0.0 {
                        -alpha * f[d].abs()
                    } else if vd < 0.0 {
                        alpha * f[d].abs()
                    } else {
                        0.0
                    };
                    vn[d] = vd + dt * (f[d] + damp) * im;
                    q.removed -= damp * 0.5 * (vd + vn[d]) * dt;
                }
                q.ke += 0.5 * mass[i] * dot(&vn, &vn);
                let xn = [
                    x[j][0] + dt * vn[0],
                    x[j][1] + dt * vn[1],
                    x[j][2] + dt * vn[2],
                ];
                if !(xn[0] + xn[1] + xn[2]).is_finite() && q.bad == usize::MAX {
                    q.bad = i;
                }
                x[j] = xn;
                v[j] = vn;
            }
            *p = q;
        };
        let it = self
            .state
            .x
            .par_chunks_mut(CHUNK)
            .zip(self.state.v.par_chunks_mut(CHUNK))
            .zip(parts.par_iter_mut())
            .enumerate();
        if nn <= CHUNK {
            it.with_min_len(usize::MAX).for_each(body);
        } else {
            it.for_each(body);
        }
    }

    /// The chunks' sums in chunk order, or the error of a node gone non-finite at `step`.
    fn sum_parts(&self, parts: &[Part], step: u64, dt: f64) -> Result<StepSums> {
        let (mut ke, mut res, mut res_node, mut fc, mut removed) = (0.0, 0.0, 0, 0.0f64, 0.0);
        for p in parts {
            if p.bad != usize::MAX {
                return Err(WeftError::Numerical {
                    what: format!(
                        "node `{}` became non-finite during dynamic relaxation",
                        self.node_id[p.bad]
                    ),
                    step,
                    time: step as f64 * dt,
                    hint: Some("a contact or an element is unstable at this step; check the model's geometry and penalty_scale".into()),
                });
            }
            ke += p.ke;
            removed += p.removed;
            if p.res > res {
                res = p.res;
                res_node = p.res_node;
            }
            fc = fc.max(p.fc);
        }
        Ok(StepSums {
            ke,
            removed,
            res,
            res_node,
            fc,
        })
    }

    /// A rest test starts at step `since`: the velocities zeroed, the degrees of freedom
    /// of `hold_in_rest_test` held, the contacts undamped.
    fn start_probe(&mut self, o: &RelaxOptions, since: u64) -> Probe {
        self.state.v.iter_mut().for_each(|v| *v = [0.0; 3]);
        for &(n, mask) in &o.hold_in_rest_test {
            self.fixed[n] |= mask;
        }
        self.op.surfaces.set_normal_damping(0.0);
        Probe {
            x0: self.state.x.clone(),
            far: 0.0,
            since,
        }
    }

    /// The model's own holds (`free_mask`, as they were before the rest tests) and the
    /// relaxation's contact damping are back.
    fn end_probe(&mut self, o: &RelaxOptions, free_mask: &[u8]) {
        for (&(n, _), &f0) in o.hold_in_rest_test.iter().zip(free_mask) {
            self.fixed[n] = f0;
        }
        self.op.surfaces.set_normal_damping(o.contact_damping);
    }

    /// After a step of a rest test: the farthest any node has moved from where it
    /// started (into `st.creep_node`); once it passes the tolerance or the window is
    /// over, the test ends (`st.creep`), and a model at rest returns to where the test
    /// started (`st.converged`).
    fn watch_probe(
        &mut self,
        p: &mut Probe,
        o: &RelaxOptions,
        free_mask: &[u8],
        creep_window: u64,
        st: &mut RelaxStats,
    ) -> Verdict {
        let (d, node) = farthest(&self.state.x, &p.x0);
        if d.sqrt() > p.far {
            p.far = d.sqrt();
            st.creep_node = node;
        }
        if !(p.far > o.creep_tolerance || st.steps - p.since >= creep_window) {
            return Verdict::Running;
        }
        st.creep = p.far;
        self.end_probe(o, free_mask);
        if p.far <= o.creep_tolerance {
            // At rest where the probe started: that is the equilibrium.
            self.state.x.copy_from_slice(&p.x0);
            st.converged = true;
            return Verdict::AtRest;
        }
        Verdict::Moving
    }
}

/// The node furthest from where it started, and the square of that distance (ties: the
/// lower index, so that the answer does not depend on the threads).
fn farthest(x: &[[f64; 3]], x0: &[[f64; 3]]) -> (f64, usize) {
    x.par_iter()
        .zip(x0.par_iter())
        .enumerate()
        .map(|(i, (a, b))| {
            let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            (dot(&d, &d), i)
        })
        .reduce(
            || (0.0, usize::MAX),
            |p, q| {
                if q.0 > p.0 || (q.0 == p.0 && q.1 < p.1) {
                    q
                } else {
                    p
                }
            },
        )
}
