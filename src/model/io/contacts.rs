//! `contacts.parquet`: contact definitions, one row each, the parts named by name.

use super::codec::{Reading, Writing};
use crate::error::Result;
use crate::model::contacts::{names, ContactDef, InitialPenetration, Slave};
use crate::model::types::Model;
use crate::table::{batch, Col};

pub const FILE: &str = "contacts.parquet";
/// Expected columns, for error messages.
const COLS: &str = "contact_id, master_part, slave_part or slave_set (+ optional columns)";

/// Reads `contacts.parquet` when present.
pub fn read(r: &mut Reading) -> Result<()> {
    let Some(t) = r.optional(FILE)? else {
        return Ok(());
    };
    let m = &mut r.model;
    let id = t.i64("contact_id", COLS)?;
    let n = id.len();
    let master = t.str("master_part", COLS)?;
    let sp = t.str_opt("slave_part")?.unwrap_or_else(|| vec![None; n]);
    let ss = t.str_opt("slave_set")?.unwrap_or_else(|| vec![None; n]);
    let f = |c: &str| -> Result<Vec<Option<f64>>> {
        Ok(t.f64_opt(c)?.unwrap_or_else(|| vec![None; n]))
    };
    let (mus, mud, dc, ps, ts, tm) = (
        f("static_friction")?,
        f("dynamic_friction")?,
        f("friction_decay")?,
        f("penalty_scale")?,
        f("slave_thickness")?,
        f("master_thickness")?,
    );
    let tw = t.bool_opt("two_way")?.unwrap_or_else(|| vec![None; n]);
    let ip = t
        .str_opt("initial_penetration")?
        .unwrap_or_else(|| vec![None; n]);
    let part = |row: usize, col: &str, name: &str| -> Result<usize> {
        m.part_index(name).ok_or_else(|| {
            t.value_error(
                col,
                row,
                format!("part `{name}` does not exist in parts.parquet"),
            )
            .expected(format!(
                "the name of a part: {}",
                names(m.parts.iter().map(|p| &p.name))
            ))
        })
    };
    let mut defs = Vec::with_capacity(n);
    for row in 0..n {
        let master = part(row, "master_part", &master[row])?;
        let slave =
            match (&sp[row], &ss[row]) {
                (Some(p), None) => Slave::Part(part(row, "slave_part", p)?),
                (None, Some(s)) => Slave::Set(s.clone()),
                _ => return Err(t
                    .value_error(
                        "slave_part",
                        row,
                        "a contact needs exactly one of slave_part and slave_set".into(),
                    )
                    .expected(
                        "a part name in slave_part or a node set name in slave_set, the other null",
                    )),
            };
        let initial_penetration = match ip[row].as_deref() {
            None | Some("track") => InitialPenetration::Track,
            Some("error") => InitialPenetration::Error,
            Some("keep") => InitialPenetration::Keep,
            Some(o) => {
                return Err(t
                    .value_error(
                        "initial_penetration",
                        row,
                        format!("unknown initial_penetration `{o}`"),
                    )
                    .expected("`track` (default), `error` or `keep`"))
            }
        };
        let mu_s = mus[row].unwrap_or(0.0);
        defs.push(ContactDef {
            id: id[row],
            slave,
            master,
            static_friction: mu_s,
            dynamic_friction: mud[row].unwrap_or(mu_s),
            friction_decay: dc[row].unwrap_or(0.0),
            penalty_scale: ps[row].unwrap_or(1.0),
            slave_thickness: ts[row],
            master_thickness: tm[row],
            two_way: tw[row].unwrap_or(false),
            initial_penetration,
        });
    }
    m.contacts = defs;
    Ok(())
}

/// Writes `contacts.parquet` when the model has contact definitions.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    if m.contacts.is_empty() {
        return Ok(());
    }
    let c = &m.contacts;
    let pname = |i: usize| m.parts[i].name.clone();
    w.table(
        FILE,
        &batch(vec![
            Col::I64("contact_id", c.iter().map(|d| d.id).collect()),
            Col::Str("master_part", c.iter().map(|d| pname(d.master)).collect()),
            Col::OptStr(
                "slave_part",
                c.iter()
                    .map(|d| match &d.slave {
                        Slave::Part(p) => Some(pname(*p)),
                        _ => None,
                    })
                    .collect(),
            ),
            Col::OptStr(
                "slave_set",
                c.iter()
                    .map(|d| match &d.slave {
                        Slave::Set(s) => Some(s.clone()),
                        _ => None,
                    })
                    .collect(),
            ),
            Col::F64(
                "static_friction",
                c.iter().map(|d| d.static_friction).collect(),
            ),
            Col::F64(
                "dynamic_friction",
                c.iter().map(|d| d.dynamic_friction).collect(),
            ),
            Col::F64(
                "friction_decay",
                c.iter().map(|d| d.friction_decay).collect(),
            ),
            Col::F64("penalty_scale", c.iter().map(|d| d.penalty_scale).collect()),
            Col::OptF64(
                "slave_thickness",
                c.iter().map(|d| d.slave_thickness).collect(),
            ),
            Col::OptF64(
                "master_thickness",
                c.iter().map(|d| d.master_thickness).collect(),
            ),
            Col::Bool("two_way", c.iter().map(|d| d.two_way).collect()),
            Col::Str(
                "initial_penetration",
                c.iter()
                    .map(|d| d.initial_penetration.name().to_string())
                    .collect(),
            ),
        ]),
    )
}
