//! Subcycling (`Analysis::subcycle`): the solids whose stable step is many times the
//! step are updated on a slow step T = ratio × Δt, their forces applied as the slow
//! step's impulse (docs/theory.md, "Subcycling").
//!
//! The scheme is the impulse form of multiple time stepping (Tuckerman, Berne & Martyna,
//! J. Chem. Phys. 97 (1992) 1990, "r-RESPA"; Grubmüller et al., Mol. Sim. 6 (1991) 121):
//! the forces are split into fast ones (every element that is not slow, contact, loads),
//! integrated by the central difference at Δt, and the slow elements' forces f_s, which
//! act only at the slow samples t_k, as a kick ½(T^{k−½} + T^{k+½}) f_s(x_k)/m: the
//! velocity Verlet scheme of step T for f_s, with the fast motion drifting in between.
//! For the slow forces alone it is the central difference of step T, so it is stable for
//! T within their stable step, and it conserves the energy as the central difference
//! does; the fast forces keep their own step. In the node update's kick of a sample step,
//! ½(Δt^{n−½} + Δt^{n+½}) a, this is the slow slots scaled by the weight
//! (T^{k−½} + T^{k+½}) / (Δt^{n−½} + Δt^{n+½}) and zero at the steps between
//! ([`SlowStep`]). A slow element's strain increment over T^{k−½} is that of its nodes'
//! displacement since its last update ([`crate::solver::solid::slow`]).
//!
//! The slow samples fall every `ratio` steps and, besides, at every output sample step,
//! so that the energies booked there are the slow elements' at that instant (their work
//! is booked at their updates). The ratio is chosen once ([`Family::choose_subcycle`]:
//! the fewest element updates a step) and lowered, never raised, when the slow elements'
//! stable step at their current shape falls below T (checked every
//! [`SLOW_CHECK_EVERY`] samples, as the variable step does for the fast one).
//!
//! [`Family::choose_subcycle`]: super::family::Family::choose_subcycle

use super::family::SlowStep;
use super::stable::{nodal_dt, StiffeningCheck};
use super::Solver;
use crate::error::{Result, WeftError};
use crate::vec3::{norm, sub};

/// Slow samples between two checks of the slow elements' stable step at their current
/// shape (one check costs about a slow update's geometry).
pub const SLOW_CHECK_EVERY: u64 = 4;

/// The subcycle of a run: the slow step's ratio and where the run stands in it.
#[derive(Debug, Clone, Default)]
pub struct Subcycle {
    /// Fast steps per slow step, now and as first chosen.
    pub ratio: u64,
    pub first_ratio: u64,
    /// How many elements are slow.
    pub elements: usize,
    /// The slow elements' nodes (ascending).
    pub nodes: Vec<usize>,
    /// Fast steps since the last slow sample.
    since: u64,
    /// The time of the last slow sample [s].
    t_last: f64,
    /// Slow samples so far.
    pub samples: u64,
    /// The interval planned at the last sample, T^{k+½} [s].
    t_next: f64,
    /// Per node, the slow acceleration f_s/m at an output sample, for the kinetic
    /// energy's form ([`Solver::slow_ke_shift`]).
    pub shift: Vec<[f64; 3]>,
}

/// The slow interval that follows a sample at time `t`: the time to the next sample,
/// which is `ratio` steps of `dt` on, or the first output sample step before that (the
/// time loop's rule: step n is an output sample step when k·Δt_out ≤ tⁿ + Δt, k the
/// first output not yet sent; `k` is the time loop's before this step's output). The
/// times are summed as the time loop sums them, so that the next sample's T^{k−½} is
/// this one to the last bit when the step stays.
pub fn next_interval(t: f64, dt: f64, mut k: u64, n_out: u64, out: f64, ratio: u64) -> f64 {
    let mut tt = t;
    for j in 1..=ratio {
        while k <= n_out && k as f64 * out <= tt {
            k += 1;
        }
        tt += dt;
        if j == ratio || (k <= n_out && k as f64 * out <= tt + dt) {
            break;
        }
    }
    tt - t
}

impl Solver {
    /// Chooses the slow elements when the analysis asks to subcycle
    /// ([`Family::choose_subcycle`](super::family::Family::choose_subcycle)), from each
    /// node's stable step with the margin the step was set with.
    pub(super) fn start_subcycle(&mut self) {
        if !self.analysis.subcycle || !(self.stable.dt_stable > 0.0) {
            return;
        }
        let margin = self.stable.dt / self.stable.dt_stable;
        let (s, c) = self.nodal_bound().nodal_sums();
        let mut node_dt: Vec<f64> = (0..self.mass.len())
            .map(|i| {
                if self.fixed[i] == 0b111 || self.mass[i] <= 0.0 {
                    f64::INFINITY
                } else {
                    margin * nodal_dt(s[i], c[i], self.mass[i], self.alpha)
                }
            })
            .collect();
        // The nodes the contact acts on stay on the fast step, and with them the elements
        // they belong to: a slow element's impulses would jolt the surface the contact's
        // penalty and friction act on every step. (The faces erosion uncovers later
        // leave the slow step as they are uncovered: `slow::Slow::uncovered`.)
        let mut contact = self.contact_nodes();
        // So do the nodes that elements of other kinds share (a solid meeting trusses or
        // membranes): the slow impulses would ring those elements' stiff, light modes
        // at the junction; the solids there are the buffer, and the fast-slow junction
        // lies inside the solid, between cells of one stiffness.
        for (i, c) in contact.iter_mut().enumerate() {
            if !*c {
                *c = self.op.gather.of(i).iter().any(|&slot| {
                    self.op
                        .el
                        .slot_element(slot as usize)
                        .is_some_and(|(kind, _, _)| kind != crate::model::ElementKind::Hex)
                }) && self.op.gather.of(i).iter().any(|&slot| {
                    self.op
                        .el
                        .slot_element(slot as usize)
                        .is_some_and(|(kind, _, _)| kind == crate::model::ElementKind::Hex)
                });
            }
        }
        for (d, _) in node_dt.iter_mut().zip(&contact).filter(|(_, &c)| c) {
            *d = 0.0;
        }
        let dt = self.stable.dt;
        if let Some(ch) = self.op.el.choose_subcycle(&node_dt, dt, &self.state.x) {
            self.subcycle = Some(Subcycle {
                ratio: ch.ratio,
                first_ratio: ch.ratio,
                elements: ch.elements,
                nodes: ch.nodes,
                shift: vec![[0.0; 3]; self.mass.len()],
                ..Default::default()
            });
        }
    }

    /// The nodes the contact acts on: every slave, and the nodes of each live master
    /// face that a slave lies near (within the face's circumradius plus the thickest
    /// slave's contact thickness of its centroid: a solid's boundary faces far from
    /// anything that could strike them, the clay's sides and floor, are left out).
    fn contact_nodes(&self) -> Vec<bool> {
        let x = &self.state.x;
        let mut mark = vec![false; x.len()];
        let sides = &self.op.surfaces.sides;
        let mut reach = 0.0f64;
        for side in sides {
            for &n in &side.slaves {
                mark[n as usize] = true;
            }
            reach = reach.max(side.slave_t.iter().cloned().fold(0.0, f64::max));
        }
        let slaves: Vec<usize> = (0..x.len()).filter(|&i| mark[i]).collect();
        if slaves.is_empty() {
            return mark;
        }
        // The faces first (their centres and radii), then a grid of the slaves with cells
        // the largest reach, so that a face looks in its 27 cells only.
        let mut faces: Vec<([f64; 3], f64, Vec<u32>)> = vec![];
        for side in sides {
            side.for_live_faces(|f| {
                let k = f.len() as f64;
                let c: [f64; 3] =
                    std::array::from_fn(|d| f.iter().map(|&n| x[n as usize][d]).sum::<f64>() / k);
                let r = f
                    .iter()
                    .map(|&n| norm(&sub(&x[n as usize], &c)))
                    .fold(0.0, f64::max);
                faces.push((c, r + reach, f.to_vec()));
            });
        }
        let h = faces.iter().map(|f| f.1).fold(0.0, f64::max);
        if !(h > 0.0) {
            return mark;
        }
        let cell =
            |p: &[f64; 3]| -> [i64; 3] { std::array::from_fn(|d| (p[d] / h).floor() as i64) };
        let mut grid: std::collections::HashMap<[i64; 3], Vec<usize>> = Default::default();
        for &i in &slaves {
            grid.entry(cell(&x[i])).or_default().push(i);
        }
        for (c, r, nodes) in &faces {
            let k = cell(c);
            let near = (0..27).any(|j| {
                let o = [k[0] + j % 3 - 1, k[1] + (j / 3) % 3 - 1, k[2] + j / 9 - 1];
                grid.get(&o)
                    .is_some_and(|v| v.iter().any(|&i| norm(&sub(&x[i], c)) <= *r))
            });
            if near {
                for &n in nodes {
                    mark[n as usize] = true;
                }
            }
        }
        mark
    }

    /// Sets the state's [`SlowStep`] for the step about to be taken over `dt_next`
    /// (`k`, `n_out`, `out`: the time loop's output counter, count and interval). At
    /// every [`SLOW_CHECK_EVERY`]-th sample the ratio is first checked against the slow
    /// elements' stable step at their current shape ([`Solver::follow_slow`]), so that
    /// the interval this sample's impulse is planned for is the one taken.
    pub(super) fn plan_slow_step(
        &mut self,
        k: u64,
        n_out: u64,
        out: f64,
        dt_next: f64,
        check: &mut StiffeningCheck,
    ) -> Result<()> {
        let Some(sc) = self.subcycle.as_mut() else {
            return Ok(());
        };
        let st = &mut self.state;
        let snap = k as f64 * out <= st.t + dt_next;
        if !(st.step == 0 || sc.since >= sc.ratio || snap) {
            st.slow.sample = false;
            sc.since += 1;
            return Ok(());
        }
        if st.step > 0 && sc.samples % SLOW_CHECK_EVERY == 0 {
            self.follow_slow(check, dt_next)?;
        }
        let (Some(sc), st) = (self.subcycle.as_mut(), &mut self.state) else {
            return Ok(());
        };
        let t_prev = if st.step == 0 { 0.0 } else { st.t - sc.t_last };
        let t_next = next_interval(st.t, dt_next, k, n_out, out, sc.ratio);
        st.slow = SlowStep {
            sample: true,
            dt: t_prev,
            weight: (t_prev + t_next) / (st.dt_prev + dt_next),
            close: (t_prev + dt_next) / (st.dt_prev + dt_next),
        };
        sc.t_last = st.t;
        sc.t_next = t_next;
        sc.since = 1;
        sc.samples += 1;
        Ok(())
    }

    /// The kinetic energy at an output sample that is also a slow sample. The ledger's
    /// ½ m v^{n−½}·v^{n+½} is the form the central difference conserves with the strain
    /// energy when both intervals are equal; an output forces a sample between two, and
    /// with T^{k−½} ≠ T^{k+½} the form counts ¼ (T^{k+½} − T^{k−½}) f_s·v of the slow
    /// forces' power besides, a first-order error. Both half-step velocities shifted by
    /// δ = −¼ (T^{k+½} − T^{k−½}) a_s (a_s = f_s/m) remove it: the form is then
    /// ½ m (v_k − ½T̄ a_s)·(v_k + ½T̄ a_s), v_k the velocity at the sample and T̄ the mean
    /// of the two intervals, with an error of second order. (The steady step's form,
    /// each half-step velocity shifted to a step ratio × Δt instead, was measured worse:
    /// a balance of 8.5e-3 and 2.6e-2 against 5.9e-3 and 4.9e-3 in tests/subcycle.rs.)
    /// Fills the per-node a_s; returns the shifts' coefficients (c₋, c₊) = (−¼ΔT, −¼ΔT),
    /// or `None` when there is none.
    pub(super) fn slow_ke_shift(&mut self) -> Option<(f64, f64)> {
        let sc = self.subcycle.as_mut()?;
        let slow = self.state.slow;
        let d = -0.25 * (sc.t_next - slow.dt);
        if !slow.sample || d == 0.0 {
            return None;
        }
        let f = self.op.el.slow_forces()?;
        for &i in &sc.nodes {
            let r = self.inv_m[i];
            sc.shift[i] = [r * f[i][0], r * f[i][1], r * f[i][2]];
        }
        Some((d, d))
    }

    /// The slow elements' stable step at their current shape, and the ratio lowered to
    /// keep T within it with the first step's margin; an error naming the element when
    /// even one fast step is too long.
    fn follow_slow(&mut self, k: &mut StiffeningCheck, dt_step: f64) -> Result<()> {
        let Some(sc) = self.subcycle.as_ref() else {
            return Ok(());
        };
        let Some((dt_now, node, most)) = self.nodal_bound().slow_step(k, &sc.nodes) else {
            return Ok(());
        };
        let margin = self.stable.dt / self.stable.dt_stable;
        let allowed = (margin * dt_now / dt_step).floor();
        if allowed < 1.0 {
            let what = match most {
                Some(w) => w.describe(self.analysis.dt_safety).0,
                None => "its elements".to_string(),
            };
            return Err(WeftError::Numerical {
                what: format!(
                    "the slow elements' stable step {:.4e} s at node `{}` fell below the step {dt_step:.4e} s: {what}",
                    margin * dt_now,
                    self.node_id[node]
                ),
                step: self.state.step,
                time: self.state.t,
                hint: Some("a slow solid crushed this far is near inversion: give its part erosion (erosion_plastic_strain), a finer mesh or a stiffer hourglass".into()),
            });
        }
        let sc = self.subcycle.as_mut().expect("checked above");
        sc.ratio = sc.ratio.min(allowed as u64);
        Ok(())
    }
}
