//! Checks of one part's properties (parts.parquet), as the table is read: each
//! property's rule for the part's kind (the descriptors of [`super::props`]), a solid's
//! material built as the solver builds it, and what a link's or a membrane's properties
//! ask of each other; errors name the part, its kind, the column and the value.

use super::kinds::ElementKind;
use super::props;
use super::types::Part;
use crate::error::{Result, WeftError};

/// A value > 0 that one property needs because of another (a friction slider's
/// tangential stiffness).
fn require_pos(p: &Part, col: &str, v: Option<f64>, unit: &str) -> Result<()> {
    match v {
        Some(x) if x > 0.0 && x.is_finite() => Ok(()),
        Some(x) => Err(WeftError::input(format!(
            "part `{}` ({}) has {col} = `{x}`",
            p.name,
            p.kind.name()
        ))
        .in_column(col)
        .expected(format!("a value > 0 {unit}"))),
        None => Err(WeftError::input(format!(
            "part `{}` ({}) has no {col}",
            p.name,
            p.kind.name()
        ))
        .in_column(col)
        .expected(format!("a value > 0 {unit}"))
        .hint(format!("every {} part needs `{col}`", p.kind.name()))),
    }
}

/// Check the properties a part's kind needs: each against its rule in
/// [`props::PROPERTIES`], in table order, then the checks that involve two properties.
pub fn validate_part(p: &Part) -> Result<()> {
    for prop in props::PROPERTIES {
        prop.check(&p.name, p.kind, &p.props)?;
    }
    match p.kind {
        ElementKind::Link => validate_link_part(p),
        ElementKind::Tri | ElementKind::Quad => validate_membrane_part(p),
        // The material's constants that involve each other (E_t < E, T_room < T_melt,
        // Johnson–Cook's n ≤ 1, χ ≤ 1, one plasticity model).
        ElementKind::Hex => p.material().and_then(|_| p.selective_reduced()).map(|_| ()),
        _ => Ok(()),
    }
}

/// A link part's properties that involve each other: one slip law, the stiffnesses a
/// slider needs, one frame, a normal spring or dashpot for the unilateral law.
fn validate_link_part(p: &Part) -> Result<()> {
    let q = &p.props;
    let breaks = q.failure_force.is_some() || q.failure_opening.is_some();
    if breaks && (q.local_frame == Some(true) || q.sliding == Some(true)) {
        let (col, what) = if q.sliding == Some(true) {
            ("sliding", "sliding links")
        } else {
            ("local_frame", "links in a local frame")
        };
        return Err(WeftError::input(format!(
            "part `{}` (link) has a failure law (failure_force or failure_opening) and {col} = true",
            p.name
        ))
        .in_column(if q.failure_force.is_some() { "failure_force" } else { "failure_opening" })
        .expected(format!("failure on links in global axes only: this weft version cannot break {what}"))
        .hint(format!("set `{col}` of part `{}` to null (global axes), or leave the failure law null", p.name)));
    }
    if let (Some(f), Some(mu)) = (q.slip_force, q.friction) {
        return Err(WeftError::input(format!(
            "part `{}` (link) has both slip_force = `{f}` and friction = `{mu}`",
            p.name
        ))
        .in_column("friction")
        .expected("one slip law: a constant slip force or Coulomb friction μ")
        .hint("leave `slip_force` null to slip at μ·N, or `friction` null to slip at a constant force"));
    }
    if q.slip_force.is_some() || q.friction.is_some() {
        for (c, v) in [("kx", q.kx), ("ky", q.ky)] {
            require_pos(
                p,
                c,
                v,
                "in N/m (a friction slider needs tangential stiffness)",
            )?;
        }
    }
    if q.friction.is_some() {
        require_pos(
            p,
            "kz",
            q.kz,
            "in N/m (Coulomb friction takes its normal force N from the normal spring)",
        )?;
    }
    if q.sliding == Some(true) && q.local_frame == Some(true) {
        return Err(WeftError::input(format!(
            "part `{}` (link) has both sliding and local_frame",
            p.name
        ))
        .in_column("sliding")
        .expected("one frame: a sliding link's own (its yarns' tangents where its ends are), or the frame nodes' of `local_frame`")
        .hint("leave `local_frame` null for sliding links"));
    }
    if q.unilateral == Some(true) && q.kz.is_none() && q.cz.is_none() {
        return Err(WeftError::input(format!(
            "part `{}` (link) is unilateral but has no kz or cz",
            p.name
        ))
        .in_column("unilateral")
        .expected("a normal spring `kz` (or dashpot `cz`) for the unilateral law to act on")
        .hint("give `kz`, or leave `unilateral` null"));
    }
    Ok(())
}

/// A membrane part's Poisson's ratio against its two moduli.
fn validate_membrane_part(p: &Part) -> Result<()> {
    let q = &p.props;
    let nu = q.poisson_ratio_12.unwrap_or(0.0);
    // Both moduli are required, hence checked > 0 first (`validate_part`).
    let (e1, e2) = (q.youngs_modulus_1.unwrap(), q.youngs_modulus_2.unwrap());
    if !(nu.is_finite() && nu * nu * e2 / e1 < 1.0 && nu > -1.0) {
        return Err(
            WeftError::input(format!("part `{}` has poisson_ratio_12 = `{nu}`", p.name))
                .in_column("poisson_ratio_12")
                .expected(format!(
                    "−1 < ν₁₂ and ν₁₂² E₂/E₁ < 1 (here E₂/E₁ = {})",
                    e2 / e1
                )),
        );
    }
    Ok(())
}
