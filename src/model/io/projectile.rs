//! `projectile.parquet`: rigid projectiles, one row each, with the defaults of their
//! optional columns.

use super::codec::{Reading, Writing};
use crate::error::Result;
use crate::model::types::{Model, ProjectileShape, ProjectileSpec};
use crate::table::{batch, Col};

pub const FILE: &str = "projectile.parquet";
/// Expected columns, for error messages.
const COLS: &str =
    "projectile_id, shape, radius, mass, tip_x, tip_y, tip_z, vx, vy, vz (+ optional columns)";

/// Reads the projectiles. A null length is 4 radii, a null axis −z, a null friction 0;
/// a projectile is free unless prescribed, and contacts the membrane faces unless told
/// not to.
pub fn read(r: &mut Reading) -> Result<()> {
    let Some(t) = r.optional(FILE)? else {
        return Ok(());
    };
    let n = t.num_rows();
    let ids = t.i64("projectile_id", COLS)?;
    let shape = t.str("shape", COLS)?;
    let radius = t.f64("radius", COLS)?;
    let mass = t.f64("mass", COLS)?;
    let g = |c: &str| t.f64(c, COLS);
    let (tx, ty, tz) = (g("tip_x")?, g("tip_y")?, g("tip_z")?);
    let (vx, vy, vz) = (g("vx")?, g("vy")?, g("vz")?);
    let o = |c: &str| -> Result<Vec<Option<f64>>> {
        Ok(t.f64_opt(c)?.unwrap_or_else(|| vec![None; n]))
    };
    let (ax, ay, az) = (o("axis_x")?, o("axis_y")?, o("axis_z")?);
    let (len, k, mu) = (o("length")?, o("contact_stiffness")?, o("friction")?);
    let damping = o("contact_damping")?;
    let presc = t
        .bool_opt("prescribed_velocity")?
        .unwrap_or_else(|| vec![None; n]);
    let seg = t
        .bool_opt("segment_contact")?
        .unwrap_or_else(|| vec![None; n]);
    for row in 0..n {
        let sh = ProjectileShape::parse(&shape[row]).ok_or_else(|| {
            t.value_error(
                "shape",
                row,
                format!("unknown projectile shape `{}`", shape[row]),
            )
            .expected("one of `sphere`, `flat`, `round`, `wall`")
        })?;
        r.model.projectiles.push(ProjectileSpec {
            id: ids[row],
            shape: sh,
            radius: radius[row],
            length: len[row].unwrap_or(4.0 * radius[row]),
            mass: mass[row],
            tip: [tx[row], ty[row], tz[row]],
            axis: [
                ax[row].unwrap_or(0.0),
                ay[row].unwrap_or(0.0),
                az[row].unwrap_or(-1.0),
            ],
            velocity: [vx[row], vy[row], vz[row]],
            prescribed_velocity: presc[row].unwrap_or(false),
            contact_stiffness: k[row],
            friction: mu[row].unwrap_or(0.0),
            contact_damping: damping[row].unwrap_or(0.0),
            segment_contact: seg[row].unwrap_or(true),
        });
    }
    Ok(())
}

/// Writes the projectiles when the model has any, every column.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    if m.projectiles.is_empty() {
        return Ok(());
    }
    let p = &m.projectiles;
    let c = |f: fn(&ProjectileSpec) -> f64| p.iter().map(f).collect::<Vec<_>>();
    w.table(
        FILE,
        &batch(vec![
            Col::I64("projectile_id", p.iter().map(|x| x.id).collect()),
            Col::Str(
                "shape",
                p.iter().map(|x| x.shape.name().to_string()).collect(),
            ),
            Col::F64("radius", c(|x| x.radius)),
            Col::F64("length", c(|x| x.length)),
            Col::F64("mass", c(|x| x.mass)),
            Col::F64("tip_x", c(|x| x.tip[0])),
            Col::F64("tip_y", c(|x| x.tip[1])),
            Col::F64("tip_z", c(|x| x.tip[2])),
            Col::F64("axis_x", c(|x| x.axis[0])),
            Col::F64("axis_y", c(|x| x.axis[1])),
            Col::F64("axis_z", c(|x| x.axis[2])),
            Col::F64("vx", c(|x| x.velocity[0])),
            Col::F64("vy", c(|x| x.velocity[1])),
            Col::F64("vz", c(|x| x.velocity[2])),
            Col::Bool(
                "prescribed_velocity",
                p.iter().map(|x| x.prescribed_velocity).collect(),
            ),
            Col::OptF64(
                "contact_stiffness",
                p.iter().map(|x| x.contact_stiffness).collect(),
            ),
            Col::F64("friction", c(|x| x.friction)),
            Col::F64("contact_damping", c(|x| x.contact_damping)),
            Col::Bool(
                "segment_contact",
                p.iter().map(|x| x.segment_contact).collect(),
            ),
        ]),
    )
}
