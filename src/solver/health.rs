//! Numerical health: a run stops with a clear message when a node's motion or an energy
//! stops being finite (naming the node, the element or load behind it), or when the
//! energy balance drifts beyond the analysis' limit.

use super::{ElementEnergies, Energies, Solver, ENERGY_CHECK_AFTER};
use crate::error::{Result, WeftError};

impl Solver {
    pub(super) fn nan_error(&self, node: usize) -> WeftError {
        let mut culprit = String::new();
        for &slot in self.op.gather.of(node) {
            let f = self.op.fe[slot as usize];
            if !(f[0] + f[1] + f[2]).is_finite() {
                if let Some((k, id, _)) = self.op.el.slot_element(slot as usize) {
                    culprit = format!("; the force of {} `{id}` is not finite", k.name());
                }
                break;
            }
        }
        let fx = self.op.fext[node];
        if culprit.is_empty() && !(fx[0] + fx[1] + fx[2]).is_finite() {
            culprit = "; its external load is not finite".into();
        }
        if culprit.is_empty() {
            // A load on the node (or the largest one in the model) too large for the
            // model is the next suspect: name it.
            let big = self
                .op
                .loads
                .loads
                .iter()
                .map(|l| (l, l.force.iter().map(|f| f.abs()).fold(0.0, f64::max)))
                .max_by(|a, b| {
                    (a.0.node == node, a.1)
                        .partial_cmp(&(b.0.node == node, b.1))
                        .unwrap_or(std::cmp::Ordering::Equal)
                });
            if let Some((l, f)) = big {
                culprit = format!(
                    "; {} load `{}` (loads.parquet, node `{}`) peaks at {f:.3e} N",
                    if l.node == node { "its" } else { "the largest" },
                    l.id,
                    self.node_id[l.node]
                );
            }
        }
        WeftError::Numerical {
            what: format!("velocity or position of node `{}` became NaN or infinite{culprit}", self.node_id[node]),
            step: self.state.step,
            time: self.state.t,
            hint: Some(format!(
                "the step is {:.4e} s against a stable estimate of {:.4e} s; check for extreme properties or loads near this node",
                self.stable.dt, self.stable.dt_stable
            )),
        }
    }

    /// A non-finite energy is a broken run even when the nodes are finite (a comparison
    /// with NaN is false: it would pass the balance check): the error names the term and
    /// its likely cause.
    pub(super) fn check_finite_energies(
        &self,
        ke: f64,
        el_e: &ElementEnergies,
        contact: f64,
        w_ext: f64,
    ) -> Result<()> {
        let terms = [
            ("kinetic", ke),
            ("internal", el_e.internal),
            ("damping", el_e.damping),
            ("friction", el_e.friction),
            ("hourglass", el_e.hourglass),
            ("contact (stored and friction work)", contact),
            ("external work", w_ext),
        ];
        let Some((name, v)) = terms.iter().find(|(_, v)| !v.is_finite()) else {
            return Ok(());
        };
        let hint = if *name == "external work" {
            let big = self.op.loads.loads.iter().max_by(|a, b| {
                let m =
                    |l: &crate::model::Load| l.force.iter().map(|f| f.abs()).fold(0.0, f64::max);
                m(a).total_cmp(&m(b))
            });
            match big {
                Some(l) => format!(
                    "the loads' work overflowed: the largest is load `{}` (loads.parquet, node `{}`, force {:?} N)",
                    l.id, self.node_id[l.node], l.force
                ),
                None => "a projectile with prescribed velocity did non-finite work".to_string(),
            }
        } else if *name == "kinetic" {
            "a mass × velocity² overflowed: check the initial velocities, the element and point masses (parts.parquet) and the projectiles' mass and velocity (projectile.parquet)".to_string()
        } else {
            "a penalty or element with zero mass or zero length somewhere; the contact report names the definitions (run with the same model and a shorter end time to look at it)".to_string()
        };
        Err(WeftError::Numerical {
            what: format!("the {name} energy is {v}"),
            step: self.state.step,
            time: self.state.t,
            hint: Some(hint),
        })
    }

    /// The energy balance stops the run once its error passes the analysis' limit
    /// (from [`ENERGY_CHECK_AFTER`] steps on).
    pub(super) fn check_balance(&self, e: &Energies) -> Result<()> {
        let a = &self.analysis;
        if e.balance_error_relative > a.max_energy_error && self.state.step >= ENERGY_CHECK_AFTER {
            return Err(WeftError::Numerical {
                what: format!(
                    "energy balance error {:.3e} J is {} of the reference energy {:.3e} J (limit {}, max_energy_error): the run is unstable or a force is not conservative",
                    e.balance_error, percent(e.balance_error_relative), self.ledger.reference, percent(a.max_energy_error)
                ),
                step: self.state.step,
                time: self.state.t,
                hint: Some(format!(
                    "the step is {:.4e} s (stable estimate {:.4e} s); lower dt_safety, or raise max_energy_error if the loss is physical",
                    self.stable.dt, self.stable.dt_stable
                )),
            });
        }
        Ok(())
    }
}

/// A fraction as a percentage with three significant digits however small (0.1 → "10.0 %",
/// 5e-6 → "4.99e-4 %"), so that a small limit does not read "0.0 %".
fn percent(x: f64) -> String {
    let p = 100.0 * x;
    if p.abs() >= 0.1 || p == 0.0 {
        format!("{p:.1} %")
    } else {
        format!("{p:.2e} %")
    }
}
