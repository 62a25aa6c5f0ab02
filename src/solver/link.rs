//! Two-node discrete link: a spring and a dashpot per global axis, and an optional
//! friction slider in the global x–y (fabric) plane.
//!
//! Glossary: d = (x₂ − x₁) − (X₂ − X₁) relative displacement [m] (the initial offset
//! X₂ − X₁ is removed, so the nodes need not coincide); ḋ = v₂ − v₁ relative velocity
//! [m/s]; k = (k_x, k_y, k_z) [N/m]; c = (c_x, c_y, c_z) [N·s/m]; s = (s_x, s_y) slip of
//! the slider [m]; F_s slip force [N].
//!
//! Force on node 2 (node 1 gets the opposite):
//! - normal (z): f_z = −k_z d_z − c_z ḋ_z;
//! - tangential (x, y): the spring acts on the elastic part d − s; trial force
//!   f_t = −k ∘ (d_t − s); if |f_t| > F_s the slider slips: f_t is returned radially
//!   to |f_t| = F_s and s is updated so that f_t = −k ∘ (d_t − s) holds (elastic–
//!   perfectly-plastic, Coulomb-like with a constant limit); the dashpot adds −c ∘ ḋ_t.
//!
//! Energy: stored W = ½ Σ k (d − s)² (s = 0 along z); dissipated by the slider
//! Σ −f_t·Δs; by the dashpots Σ Δt c ḋ² with ḋ the half-step velocity v^{n−½} the
//! explicit scheme uses.
//!
//! The axes are global: exact for links between coincident nodes (the yarn crossings
//! of the reduced woven model), where a rigid rotation gives d = 0 and no force; links
//! between distant nodes are not rotation invariant. Reference for the slider: Simo &
//! Hughes, *Computational Inelasticity*, §1.2 (1-D frictional model, return mapping).

/// Per-element state that persists between steps.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinkState {
    /// Slider slip (x, y) [m].
    pub slip: [f64; 2],
    /// Energy dissipated by the dashpots [J].
    pub damping_energy: f64,
    /// Energy dissipated by the slider [J].
    pub friction_energy: f64,
}

/// Constant link properties.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkProps {
    pub k: [f64; 3],
    pub c: [f64; 3],
    /// Slip force; `f64::INFINITY` when the link has no slider.
    pub slip_force: f64,
}

/// Relative displacement d = (x₂ − x₁) − d₀.
#[inline(always)]
pub fn rel_disp(x1: &[f64; 3], x2: &[f64; 3], d0: &[f64; 3]) -> [f64; 3] {
    [
        x2[0] - x1[0] - d0[0],
        x2[1] - x1[1] - d0[1],
        x2[2] - x1[2] - d0[2],
    ]
}

/// Force on node 2 at the current positions and half-step velocities; advances the
/// slider and the dissipated energies in `state` (call once per time step).
/// `dt_prev` is the step Δt^{n−½} over which the velocities v^{n−½} acted.
#[inline(always)]
pub fn force_update(
    d: &[f64; 3],
    ddot: &[f64; 3],
    p: &LinkProps,
    state: &mut LinkState,
    dt_prev: f64,
) -> [f64; 3] {
    let mut ft = [
        -p.k[0] * (d[0] - state.slip[0]),
        -p.k[1] * (d[1] - state.slip[1]),
    ];
    if p.slip_force.is_finite() {
        let mag = (ft[0] * ft[0] + ft[1] * ft[1]).sqrt();
        if mag > p.slip_force {
            let r = p.slip_force / mag;
            ft = [ft[0] * r, ft[1] * r];
            let s_new = [d[0] + ft[0] / p.k[0], d[1] + ft[1] / p.k[1]];
            let ds = [s_new[0] - state.slip[0], s_new[1] - state.slip[1]];
            state.friction_energy -= ft[0] * ds[0] + ft[1] * ds[1];
            state.slip = s_new;
        }
    }
    let fd = [-p.c[0] * ddot[0], -p.c[1] * ddot[1], -p.c[2] * ddot[2]];
    state.damping_energy -= dt_prev * (fd[0] * ddot[0] + fd[1] * ddot[1] + fd[2] * ddot[2]);
    [ft[0] + fd[0], ft[1] + fd[1], -p.k[2] * d[2] + fd[2]]
}

/// Elastic force only (no dashpot, no slider update): the force the stored energy
/// [`energy`] derives, at a fixed slip.
#[inline(always)]
pub fn elastic_force(d: &[f64; 3], p: &LinkProps, slip: &[f64; 2]) -> [f64; 3] {
    [
        -p.k[0] * (d[0] - slip[0]),
        -p.k[1] * (d[1] - slip[1]),
        -p.k[2] * d[2],
    ]
}

/// Stored elastic energy ½ Σ k (d − s)² [J].
#[inline(always)]
pub fn energy(d: &[f64; 3], p: &LinkProps, slip: &[f64; 2]) -> f64 {
    let ex = d[0] - slip[0];
    let ey = d[1] - slip[1];
    0.5 * (p.k[0] * ex * ex + p.k[1] * ey * ey + p.k[2] * d[2] * d[2])
}
