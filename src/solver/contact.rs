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
/// Penalty of a face sample point relative to the interpolated nodal penalty: with a
/// quarter, the node and face contacts together stay well inside stability.
pub const SEGMENT_FACTOR: f64 = 0.25;

/// A contact point on a membrane face: x = Σ w_a x_a over up to four nodes.
#[derive(Debug, Clone, Copy)]
pub struct SamplePoint {
    pub nodes: [u32; 4],
    pub w: [f64; 4],
    pub n: usize,
    /// Tributary mass for the penalty k = κ_c·SEGMENT_FACTOR·m/Δt² [kg].
    pub mass: f64,
}

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
            ProjectileShape::Flat => None,
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

/// Closest point of the triangle (a, b, c) to p, as barycentric weights (w_a, w_b, w_c)
/// (Ericson, *Real-Time Collision Detection*, §5.1.5).
pub fn closest_on_triangle(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> [f64; 3] {
    let sub = |x: &[f64; 3], y: &[f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let dot = |x: &[f64; 3], y: &[f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(&ab, &ap), dot(&ac, &ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(&ab, &bp), dot(&ac, &bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(&ab, &cp), dot(&ac, &cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    [1.0 - v - w, v, w]
}
