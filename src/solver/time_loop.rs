//! The time loop ([`Solver::run`]): a short list of named steps. Per step: the forces
//! at tⁿ (loads, elements and their failures, contact and ties), the nodes' update (and
//! the rotations', the tied slaves', the projectiles'), and at an output sample the
//! energies booked and checked, the layers watched and the sample sent to the sink.

use std::time::Instant;

use super::integrator::{self, Nodal};
use super::output::Sampler;
use super::{ElementEnergies, Energies, PhaseTimes, RunStats, Sink, Solver};
use crate::error::Result;

/// Steps between two checks of the membranes' stiffening against the step
/// (`NodalBound::check_stiffening`, in `stable.rs`): often enough that a strain growing
/// towards the margin (1/dt_safety² − 1 = 0.23 at 0.9, in 1 + 3E₁₁) is caught before it
/// has run away; one check costs about one membrane force pass without the forces.
const STIFFENING_CHECK_EVERY: u64 = 20;

impl Solver {
    /// Run to the end time, sending samples on the output grid to `sink`. `progress` is
    /// called now and then with the fraction of simulated time done.
    pub fn run(
        &mut self,
        sink: &mut (dyn Sink + Send),
        progress: &mut (dyn FnMut(f64) + Send),
    ) -> Result<RunStats> {
        let a = self.analysis.clone();
        let n_out = (a.end_time / a.output_interval).round() as u64;
        let dt = self.stable.dt;
        let mut times = PhaseTimes::default();
        let mut sampler = Sampler::new(self.output_nodes.len());
        let proj_ids: Vec<i64> = self
            .op
            .projectiles
            .projectiles
            .iter()
            .map(|p| p.id)
            .collect();
        let mut k = 0u64;
        let progress_every = (n_out / 200).max(1);
        let mut last_e = Energies::default();
        let mut stiffening = self.nodal_bound().stiffening_check();
        // The step of the integration; `dt`, the first, stays the contact penalties' step.
        let mut dt_step = self.stable.dt_min.min(dt);
        while k <= n_out {
            if a.variable_time_step {
                dt_step = self.follow_solids(&mut stiffening, dt_step)?;
            }
            if self.state.step % STIFFENING_CHECK_EVERY == 0 {
                self.nodal_bound()
                    .check_stiffening(&mut stiffening, dt_step, a.dt_safety)?;
            }
            self.plan_slow_step(k, n_out, a.output_interval, dt_step, &mut stiffening)?;
            let t2 = self.compute_forces(dt, &mut times);
            let dt_next = dt_step;
            let snap = k as f64 * a.output_interval <= self.state.t + dt_next;
            let (ke, dp) = self.advance_nodes(snap, dt_next)?;
            // Element energies at t_n (x^n is in xn), before the rotations advance.
            let el_e = if snap {
                self.element_energies_at(true)
            } else {
                ElementEnergies::default()
            };
            let (ke_rot, dp_rot) = self.advance_rotations(dt_next)?;
            let (ke, dp) = (ke + ke_rot, dp + dp_rot);
            self.ledger.mass_damping += 0.5 * self.state.dt_prev * dp;
            self.update_tie_slaves(snap);
            let (contact_e, ke_proj) =
                self.advance_projectiles(snap, dt, dt_next, &mut sampler.cur.proj);
            let ke = ke + ke_proj;
            let t3 = Instant::now();
            times.update += t3 - t2;
            if snap {
                last_e = self.book_sample(ke, &el_e, contact_e, &mut sampler)?;
                self.op.el.sample_states(&mut sampler.cur.states);
                if self.watch.is_active() {
                    self.watch_sample(&mut sampler.cur.layers);
                }
                // The crater, and whether the clay is deep enough for it (the run stops
                // after this sample is sent when it is not).
                let mut too_deep = Ok(());
                if let Some(c) = &self.crater {
                    let log = &self.failures;
                    c.sample(
                        &self.state.xn,
                        |n| log.is_attached(n),
                        &mut sampler.cur.crater,
                    );
                    too_deep = c.check_depth(&sampler.cur.crater, self.state.step, self.state.t);
                }
                sampler.emit(
                    &mut k,
                    n_out,
                    a.output_interval,
                    &proj_ids,
                    &self.output_nodes,
                    sink,
                    |kk, tk| {
                        if kk % progress_every == 0 {
                            progress(tk / a.end_time);
                        }
                    },
                )?;
                if k > 0 {
                    self.sampled_to = (k - 1) as f64 * a.output_interval;
                }
                times.output += t3.elapsed();
                too_deep?;
            }
            self.ledger.mass_damping += 0.5 * dt_next * dp;
            self.state.t += dt_next;
            self.state.dt_prev = dt_next;
            self.state.step += 1;
            if snap && a.stop_on_outcome && self.watch.outcome.is_decided() {
                // Past the outcome's sample: the output grid ends at the last time sent.
                break;
            }
        }
        progress(1.0);
        let end_time = if self.watch.outcome.is_decided() && a.stop_on_outcome {
            (k.saturating_sub(1)) as f64 * a.output_interval
        } else {
            a.end_time
        };
        Ok(RunStats {
            steps: self.state.step,
            end_time,
            times,
            threads: rayon::current_num_threads(),
            max_balance_error_relative: self.ledger.reported(self.state.step),
            final_energies: last_e,
            elements: self.op.el.updated_elements(),
            nodes: self.x0.len(),
        })
    }

    /// The forces at t_n: loads, element forces, then contact and ties, timed into
    /// `times`; the instant they were done.
    fn compute_forces(&mut self, dt: f64, times: &mut PhaseTimes) -> Instant {
        let t0 = Instant::now();
        self.op.apply_loads(&self.state);
        let t1 = Instant::now();
        self.op.element_forces(&self.state);
        if self.failures.active {
            self.apply_failures();
        }
        let t1c = Instant::now();
        self.op.contact_and_ties(&self.state, &self.mass, dt);
        let t2 = Instant::now();
        times.contact += t2 - t1c;
        times.loads += t1 - t0;
        times.forces += t2 - t1;
        t2
    }

    /// What the run did so far (for a run that stopped: its steps, the last output time
    /// sent, its worst balance), without the phase times.
    pub fn stats_so_far(&self) -> RunStats {
        RunStats {
            steps: self.state.step,
            end_time: if self.sampled_to.is_nan() {
                0.0
            } else {
                self.sampled_to
            },
            times: PhaseTimes::default(),
            threads: rayon::current_num_threads(),
            max_balance_error_relative: self.ledger.reported(self.state.step),
            final_energies: Energies::default(),
            elements: self.op.el.updated_elements(),
            nodes: self.x0.len(),
        }
    }

    /// The nodes' update over `dt` (at a sample step, `snap`, also x^n and v^n kept): the
    /// kinetic energy and the mass-damping power, or the error that names a node gone
    /// non-finite.
    fn advance_nodes(&mut self, snap: bool, dt: f64) -> Result<(f64, f64)> {
        let shifted = if snap { self.slow_ke_shift() } else { None };
        let shift = match (&self.subcycle, shifted) {
            (Some(sc), Some((cm, cp))) => Some((&sc.shift[..], cm, cp)),
            _ => None,
        };
        let nd = Nodal {
            inv_m: &self.inv_m,
            mass: &self.mass,
            fixed: &self.fixed,
            alpha: self.alpha,
            ke_shift: shift,
            drift: if self.state.slow.sample {
                None
            } else {
                self.op.el.drift_nodes()
            },
        };
        let r = if snap {
            integrator::advance_nodes::<true>(
                &mut self.state,
                &self.op,
                &nd,
                dt,
                &mut self.partials,
            )
        } else {
            integrator::advance_nodes::<false>(
                &mut self.state,
                &self.op,
                &nd,
                dt,
                &mut self.partials,
            )
        };
        r.map_err(|node| self.nan_error(node))
    }

    /// The rotational nodes' update over `dt`: their kinetic energy and mass-damping
    /// power (zero without beams).
    fn advance_rotations(&mut self, dt: f64) -> Result<(f64, f64)> {
        if self.state.rot.is_empty() {
            return Ok((0.0, 0.0));
        }
        integrator::advance_rotations(
            &mut self.state,
            self.op.el.rotational().1,
            self.alpha,
            dt,
            &self.node_id,
        )
    }

    /// The tied slaves follow their masters (at a sample step, their v^n too).
    fn update_tie_slaves(&mut self, snap: bool) {
        if !self.op.ties.is_empty() {
            let st = &mut self.state;
            self.op
                .ties
                .update_slaves(&mut st.x, &mut st.v, snap.then_some(&mut st.vn[..]));
        }
    }

    /// The projectiles' update from `dt_prev` to `dt_next` (`dt`: the step of their
    /// penalty): their kinetic energy, and at a sample step their state at t_n into `rows`
    /// (tip and contact force, before the update) and their contact energy at t_n.
    /// Returns (contact energy, kinetic energy).
    fn advance_projectiles(
        &mut self,
        snap: bool,
        dt: f64,
        dt_next: f64,
        rows: &mut Vec<[f64; 9]>,
    ) -> (f64, f64) {
        let mut contact_e = 0.0;
        if snap {
            // Projectile states at t_n: tip and contact force before their update.
            rows.clear();
            for p in &self.op.projectiles.projectiles {
                rows.push([
                    p.tip[0], p.tip[1], p.tip[2], 0.0, 0.0, 0.0, p.force[0], p.force[1], p.force[2],
                ]);
            }
            if !self.op.projectiles.is_empty() {
                contact_e = self.op.projectiles.energy(&self.state.xn, &self.mass, dt);
            }
        }
        let ke_proj = if self.op.projectiles.is_empty() {
            0.0
        } else {
            self.op.projectiles.advance(self.state.dt_prev, dt_next)
        };
        (contact_e, ke_proj)
    }

    /// A sample at t_n: the projectiles' velocities, the energies booked in the ledger
    /// and checked (finite, balanced), and the output nodes' displacements and velocities,
    /// into the sampler's current snapshot. Returns the energies.
    fn book_sample(
        &mut self,
        ke: f64,
        el_e: &ElementEnergies,
        contact_e: f64,
        sampler: &mut Sampler,
    ) -> Result<Energies> {
        for (row, p) in sampler
            .cur
            .proj
            .iter_mut()
            .zip(&self.op.projectiles.projectiles)
        {
            row[3..6].copy_from_slice(&p.v_full);
        }
        let contact = contact_e
            + self.op.projectiles.friction_work
            + self.op.projectiles.damping_work
            + (self.op.surfaces.stored + self.op.surfaces.dissipated);
        let w_ext = self.op.loads.work + self.op.projectiles.prescribed_work;
        let e = self.ledger.book(ke, el_e, contact, w_ext, self.state.step);
        sampler.cur.t = self.state.t;
        sampler.cur.e = e;
        self.check_finite_energies(ke, el_e, contact, w_ext)?;
        self.check_balance(&e)?;
        for (j, &i) in self.output_nodes.iter().enumerate() {
            let (x, x0) = (self.state.xn[i], self.x0[i]);
            sampler.cur.u[j] = [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]];
            sampler.cur.v[j] = self.state.vn[i];
        }
        Ok(e)
    }
}
