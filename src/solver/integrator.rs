//! Explicit central difference with lumped masses: the time integrator. It reads the
//! operator's nodal forces and advances the state; it computes no force itself.
//!
//! One step (Belytschko, Liu, Moran, *Nonlinear Finite Elements*, Box 6.1, with the
//! damping force −α m v^n evaluated at the full step):
//!   v^n     = (v^{n−½} + ½ Δt^{n−½} a^n) / (1 + ½ α Δt^{n−½})
//!   v^{n+½} = v^n (1 − ½ α Δt^{n+½}) + ½ Δt^{n+½} a^n
//!   x^{n+1} = x^n + Δt^{n+½} v^{n+½}
//! At n = 0, Δt^{−½} = 0, so v^0 is the initial velocity and the first step is the
//! usual half step. Rotations (beam nodes) follow the same scheme with J and the
//! moments, the orientation updated by the exponential map.

use super::beam;
use super::family::{for_chunks_of, Each, Per, CHUNK};
use super::operator::{Gather, Operator, State};
use super::vec3::{add, dot};
use crate::error::{Result, WeftError};

/// Per-chunk sums of the node update.
#[derive(Debug, Clone, Copy, Default)]
pub struct NodePartial {
    pub ke: f64,
    pub damp_power: f64,
    /// First node whose state became non-finite (usize::MAX: none).
    pub bad: usize,
}

/// What the node update needs besides the state and the forces.
pub struct Nodal<'a> {
    pub inv_m: &'a [f64],
    pub mass: &'a [f64],
    /// Bit d set when direction d is fixed.
    pub fixed: &'a [u8],
    /// Mass-proportional damping α [1/s].
    pub alpha: f64,
    /// At an output sample that is a slow sample between two unequal slow intervals
    /// ([`super::subcycle`]): per node the slow forces' acceleration a_s and the
    /// coefficients (c₋, c₊) of the kinetic energy's form
    /// ½ m (v^{n−½} + c₋ a_s)·(v^{n+½} + c₊ a_s); `None`: no shift.
    pub ke_shift: Option<(&'a [[f64; 3]], f64, f64)>,
    /// Between slow samples ([`super::subcycle`]): the nodes on which only slow elements
    /// act, whose element slots are then zero and are skipped; `None`: none skipped.
    pub drift: Option<&'a [bool]>,
}

/// Gather forces and advance every node by one step; when `SNAP`, x^n and v^n are
/// kept in `st.xn`, `st.vn`. Returns (kinetic energy at t_n when `SNAP`, mass-damping
/// power α Σ m |v^n|²), or the first node that became non-finite.
///
/// The kinetic energy at t_n is ½ Σ m v^{n−½}·v^{n+½}, the form that the central
/// difference conserves exactly with the strain energy U(x^n) of a linear system (its
/// "shadow" energy: Hairer, Lubich & Wanner, *Geometric Numerical Integration*, §IX.8,
/// for the Störmer–Verlet scheme), rather than ½ m |v^n|², which misreports the energy of
/// the modes near the stable step by up to (ωΔt/2)² of it. So the ledger's balance checks
/// the implementation, not the scheme's O(Δt²) fluctuation: after a brittle failure, which
/// sets the nodes around it ringing at the highest frequencies, the full-step form gave a
/// balance error of 20 % of the failed truss's energy, this one 4·10⁻⁴ of it (measured,
/// `tests/failure.rs`).
pub fn advance_nodes<const SNAP: bool>(
    st: &mut State,
    op: &Operator,
    nd: &Nodal,
    dt_next: f64,
    partials: &mut [NodePartial],
) -> std::result::Result<(f64, f64), usize> {
    let (alpha, dt_prev) = (nd.alpha, st.dt_prev);
    let c1 = 1.0 / (1.0 + 0.5 * alpha * dt_prev);
    let c2 = 1.0 - 0.5 * alpha * dt_next;
    let (h_prev, h_next) = (0.5 * dt_prev, 0.5 * dt_next);
    let accel = Acceleration {
        fe: &op.fe,
        gather: &op.gather,
        fext: &op.fext,
        fcon: op.has_fcon().then_some(&op.fcon[..]),
        inv_m: nd.inv_m,
        fixed: nd.fixed,
    };
    let mass = nd.mass;
    let n = st.x.len();
    let slices = (
        (
            (Per(&mut st.x[..], 1), Per(&mut st.v[..], 1)),
            (Per(&mut st.xn[..], 1), Per(&mut st.vn[..], 1)),
        ),
        Each(partials),
    );
    for_chunks_of(n, slices, |ci, (((x, v), (xn, vn)), part)| {
        let i0 = ci * CHUNK;
        let (mut ke, mut dp, mut bad) = (0.0, 0.0, usize::MAX);
        for j in 0..x.len() {
            let i = i0 + j;
            let a = match nd.drift {
                Some(d) if d[i] => accel.without_slots(i),
                _ => accel.of(i),
            };
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
                // The kinetic energy the central difference conserves with the strain
                // energy at x^n: ½ m v^{n−½}·v^{n+½} (exactly, for a linear system; see
                // `advance_nodes`' doc).
                ke += 0.5
                    * mass[i]
                    * match nd.ke_shift {
                        None => dot(&vo, &vnew),
                        Some((acc, cm, cp)) => {
                            let a = acc[i];
                            dot(
                                &[vo[0] + cm * a[0], vo[1] + cm * a[1], vo[2] + cm * a[2]],
                                &[
                                    vnew[0] + cp * a[0],
                                    vnew[1] + cp * a[1],
                                    vnew[2] + cp * a[2],
                                ],
                            )
                        }
                    };
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
    });
    let (mut ke, mut dp) = (0.0, 0.0);
    for p in partials.iter() {
        if p.bad != usize::MAX {
            return Err(p.bad);
        }
        ke += p.ke;
        dp += p.damp_power;
    }
    Ok((ke, dp))
}

/// What a node's acceleration a^n = M⁻¹ f^n reads: its elements' force slots (through
/// the gather, in a fixed order), its load and contact force, its inverse mass and its
/// fixed directions.
struct Acceleration<'a> {
    fe: &'a [[f64; 3]],
    gather: &'a Gather,
    fext: &'a [[f64; 3]],
    fcon: Option<&'a [[f64; 3]]>,
    inv_m: &'a [f64],
    fixed: &'a [u8],
}

impl Acceleration<'_> {
    /// Node i's acceleration: the load, the contact force and the elements' forces
    /// summed in that order, times 1/m, 0 along the fixed directions.
    #[inline(always)]
    fn of(&self, i: usize) -> [f64; 3] {
        let mut f = self.fext[i];
        if let Some(fc) = self.fcon {
            add(&mut f, &fc[i]);
        }
        for &s in self.gather.of(i) {
            add(&mut f, &self.fe[s as usize]);
        }
        self.finish(f, i)
    }

    /// Node i's acceleration without its element slots (a node whose only elements are
    /// slow, between slow samples: their slots are zero): the load and the contact force
    /// times 1/m, 0 along the fixed directions.
    #[inline(always)]
    fn without_slots(&self, i: usize) -> [f64; 3] {
        let mut f = self.fext[i];
        if let Some(fc) = self.fcon {
            add(&mut f, &fc[i]);
        }
        self.finish(f, i)
    }

    /// Node i's force `f` times 1/m, 0 along its fixed directions.
    #[inline(always)]
    fn finish(&self, f: [f64; 3], i: usize) -> [f64; 3] {
        let im = self.inv_m[i];
        let mut a = [f[0] * im, f[1] * im, f[2] * im];
        let fx = self.fixed[i];
        if fx != 0 {
            for (d, ad) in a.iter_mut().enumerate() {
                if fx & (1 << d) != 0 {
                    *ad = 0.0;
                }
            }
        }
        a
    }
}

/// Advance the rotations of the beam nodes by one step; returns (rotational kinetic
/// energy at t_n, mass-damping power α Σ J |ω^n|²). `moments`: the beams' end moments,
/// gathered per rotational node through `st.rot.slots`.
pub fn advance_rotations(
    st: &mut State,
    moments: &[[f64; 3]],
    alpha: f64,
    dt_next: f64,
    node_id: &[i64],
) -> Result<(f64, f64)> {
    let dt_prev = st.dt_prev;
    let c1 = 1.0 / (1.0 + 0.5 * alpha * dt_prev);
    let c2 = 1.0 - 0.5 * alpha * dt_next;
    let (mut ke, mut dp) = (0.0, 0.0);
    let (step, t) = (st.step, st.t);
    let rot = &mut st.rot;
    for k in 0..rot.node.len() {
        let mut mom = [0.0; 3];
        for &sl in &rot.slots[rot.ptr[k] as usize..rot.ptr[k + 1] as usize] {
            add(&mut mom, &moments[sl as usize]);
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
                    node_id[rot.node[k]]
                ),
                step,
                time: t,
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
