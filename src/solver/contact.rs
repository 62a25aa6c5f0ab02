//! Rigid projectile against nodes: penalty contact with Coulomb friction.
//!
//! Glossary: P the nose tip [m]; a the unit axis, pointing in the direction of travel
//! (from the body to the tip); R radius; L_c body length behind the nose; for a node at
//! x: s = (x − P)·a (axial, < 0 inside the body), ρ = |x − P − s a| (radial); g ≥ 0 the
//! penetration depth and n the outward normal of the surface through which the node is
//! pushed out (the nearest one).
//!
//! Shapes: `sphere` (centre P − R a); `flat` (flat-nosed cylinder: face through P normal
//! to a, side ρ = R); `round` (round-nosed cylinder: hemisphere of centre P − R a, then
//! the cylinder ρ = R behind it).
//!
//! Force on the node f = k g n − friction, on the projectile the opposite (momentum is
//! exchanged exactly). Friction: f_t = −μ k g t̂ min(1, |v_t|/v_reg), t̂ along the
//! tangential relative velocity v_t; v_reg = 10⁻³ m/s regularises sticking. Penalty
//! k = κ_c m_i/Δt² per node (κ_c = 0.1: the contact spring alone has ω Δt ≈ 0.32, well
//! inside stability) unless the projectile gives `contact_stiffness`. Stored contact
//! energy ½ k g², friction work accumulated. Reference: Belytschko, Liu, Moran,
//! *Nonlinear Finite Elements*, §10.4 (penalty contact), Wriggers, *Computational
//! Contact Mechanics*, §5.2 (regularised Coulomb friction).

use crate::model::{ProjectileShape, ProjectileSpec};

/// Default κ_c of the penalty stiffness k = κ_c m/Δt².
pub const PENALTY_FACTOR: f64 = 0.1;
/// Friction regularisation velocity [m/s].
pub const V_REG: f64 = 1e-3;

/// A projectile's state during a run.
#[derive(Debug, Clone)]
pub struct Projectile {
    pub id: i64,
    pub shape: ProjectileShape,
    pub radius: f64,
    pub length: f64,
    pub mass: f64,
    /// Unit axis (direction of travel).
    pub axis: [f64; 3],
    /// Nose tip position P^n.
    pub tip: [f64; 3],
    /// Half-step velocity v^{n−½} (the constant velocity when prescribed).
    pub v: [f64; 3],
    pub prescribed: bool,
    /// Fixed penalty stiffness [N/m], or `None` for κ_c m/Δt².
    pub stiffness: Option<f64>,
    pub friction: f64,
    /// Contact force on the projectile at the last step [N].
    pub force: [f64; 3],
}

impl Projectile {
    pub fn new(p: &ProjectileSpec) -> Projectile {
        let n = (p.axis[0].powi(2) + p.axis[1].powi(2) + p.axis[2].powi(2)).sqrt();
        Projectile {
            id: p.id,
            shape: p.shape,
            radius: p.radius,
            length: p.length,
            mass: p.mass,
            axis: [p.axis[0] / n, p.axis[1] / n, p.axis[2] / n],
            tip: p.tip,
            v: p.velocity,
            prescribed: p.prescribed_velocity,
            stiffness: p.contact_stiffness,
            friction: p.friction,
            force: [0.0; 3],
        }
    }

    /// Penetration depth and outward normal of a point, if it is inside.
    #[inline]
    pub fn penetration(&self, x: &[f64; 3]) -> Option<(f64, [f64; 3])> {
        let (r, a, p) = (self.radius, &self.axis, &self.tip);
        let d = [x[0] - p[0], x[1] - p[1], x[2] - p[2]];
        let s = d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
        if s > 0.0 {
            return None; // ahead of the tip
        }
        let sphere = |c_off: f64| -> Option<(f64, [f64; 3])> {
            let dc = [
                d[0] + c_off * a[0],
                d[1] + c_off * a[1],
                d[2] + c_off * a[2],
            ];
            let rr = (dc[0] * dc[0] + dc[1] * dc[1] + dc[2] * dc[2]).sqrt();
            (rr < r && rr > 0.0).then(|| (r - rr, [dc[0] / rr, dc[1] / rr, dc[2] / rr]))
        };
        let radial = [d[0] - s * a[0], d[1] - s * a[1], d[2] - s * a[2]];
        let rho = (radial[0] * radial[0] + radial[1] * radial[1] + radial[2] * radial[2]).sqrt();
        let side_n = || {
            if rho > 0.0 {
                [radial[0] / rho, radial[1] / rho, radial[2] / rho]
            } else {
                [0.0; 3]
            }
        };
        match self.shape {
            ProjectileShape::Sphere => sphere(r),
            ProjectileShape::Flat => {
                if rho >= r || s < -self.length {
                    return None;
                }
                let (face, side) = (-s, r - rho);
                if face <= side {
                    Some((face, *a))
                } else {
                    Some((side, side_n()))
                }
            }
            ProjectileShape::Round => {
                if s >= -r {
                    sphere(r)
                } else if rho < r && s >= -self.length {
                    Some((r - rho, side_n()))
                } else {
                    None
                }
            }
        }
    }
}
