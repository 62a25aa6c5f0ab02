//! The rigid projectile itself ([`Projectile`]): its state, its shapes, the penetration
//! and outward normal of a point inside it, and the regularised Coulomb friction of a
//! contact point against it. The contact during a run is the parent module's
//! ([`super::ProjectileContact`]).
//!
//! Glossary: P the nose tip [m]; a the unit axis, pointing in the direction of travel
//! (from the body to the tip); R radius; L_c body length behind the nose; for a node at
//! x: s = (x − P)·a (axial, < 0 inside the body), ρ = |x − P − s a| (radial); g ≥ 0 the
//! penetration depth and n the outward normal of the surface through which the node is
//! pushed out (the nearest one).
//!
//! Shapes: `sphere` (centre P − R a); `flat` (flat-nosed cylinder: face through P normal
//! to a, side ρ = R); `round` (round-nosed cylinder: hemisphere of centre P − R a, then
//! the cylinder ρ = R behind it); `wall` (the plane through P normal to a, unbounded:
//! every point with s < 0 is inside, pushed out along a; the Taylor test's rigid wall).
//! The cylinders end at s = −L_c, a flat back face whose outward normal is −a.

use crate::model::{ProjectileShape, ProjectileSpec};

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
    /// Full-step velocity v^n of the last step (output).
    pub v_full: [f64; 3],
    pub prescribed: bool,
    /// Fixed penalty stiffness [N/m], or `None` for κ_c m/Δt².
    pub stiffness: Option<f64>,
    pub friction: f64,
    /// Normal viscous damping ζ of the contact springs (fraction of critical).
    pub damping: f64,
    /// Contact the membrane faces' sample points too.
    pub segments: bool,
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
            v_full: p.velocity,
            prescribed: p.prescribed_velocity,
            stiffness: p.contact_stiffness,
            friction: p.friction,
            damping: p.contact_damping,
            segments: p.segment_contact,
            force: [0.0; 3],
        }
    }

    /// Centre of the spherical nose (spheres and round-nosed cylinders).
    pub fn nose_centre(&self) -> Option<[f64; 3]> {
        match self.shape {
            ProjectileShape::Sphere | ProjectileShape::Round => Some(std::array::from_fn(|d| {
                self.tip[d] - self.radius * self.axis[d]
            })),
            ProjectileShape::Flat | ProjectileShape::Wall => None,
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
        if self.shape == ProjectileShape::Wall {
            return Some((-s, *a));
        }
        let radial = [d[0] - s * a[0], d[1] - s * a[1], d[2] - s * a[2]];
        let rho2 = radial[0] * radial[0] + radial[1] * radial[1] + radial[2] * radial[2];
        // Every shape lies within the radius of the axis: a point farther out is not
        // inside (most of a fabric's nodes, each step). The margin keeps the points whose
        // distance to the nose centre might still round below the radius.
        if rho2 > r * r * (1.0 + 1e-9) {
            return None;
        }
        let rho = rho2.sqrt();
        let side_n = || {
            if rho > 0.0 {
                [radial[0] / rho, radial[1] / rho, radial[2] / rho]
            } else {
                [0.0; 3]
            }
        };
        let inside = match self.shape {
            ProjectileShape::Sphere => return sphere(r),
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
            ProjectileShape::Wall => return Some((-s, *a)),
        };
        // A cylinder's back face: a node nearer to it than to the other surfaces is pushed
        // out backwards. Without it, a node that came in from behind (a broken yarn end
        // whipping past a perforating nose) went from no penetration to r − ρ in one
        // step, millimetres: measured, 0.054 J out of nothing on a chain patch.
        let back = s + self.length;
        match inside {
            Some((g, _)) if back >= 0.0 && back < g => Some((back, [-a[0], -a[1], -a[2]])),
            other => other,
        }
    }
}

/// Regularised Coulomb friction at a contact point with normal `n` and normal force
/// `fnorm`, for the point's velocity `vr` relative to the projectile: the force on the
/// point, −μ f_n t̂ min(1, |v_t|/v_reg), and the power it dissipates (≥ 0).
#[inline]
pub fn friction(n: &[f64; 3], fnorm: f64, vr: &[f64; 3], mu: f64) -> ([f64; 3], f64) {
    let vn = vr[0] * n[0] + vr[1] * n[1] + vr[2] * n[2];
    let vt = [vr[0] - vn * n[0], vr[1] - vn * n[1], vr[2] - vn * n[2]];
    let vtm = (vt[0] * vt[0] + vt[1] * vt[1] + vt[2] * vt[2]).sqrt();
    if vtm == 0.0 {
        return ([0.0; 3], 0.0);
    }
    let ft = mu * fnorm * (vtm / V_REG).min(1.0);
    (
        [-ft * vt[0] / vtm, -ft * vt[1] / vtm, -ft * vt[2] / vtm],
        ft * vtm,
    )
}
