//! Contact definitions (`contacts.parquet`): which nodes meet which surface, with what
//! friction and penalty. One row per definition; see `docs/tables.md`.
//!
//! A definition pairs slave nodes — the nodes of a part (`slave_part`) or a node set
//! (`slave_set`) — with the master surface of a part (`master_part`): the faces of a
//! membrane part (triangles, quads) offset by ± half the nodal thickness, or the
//! segments of a truss or beam part with a radius. `two_way` also checks the master
//! part's nodes against the slave part's surface; a part against itself is self-contact
//! (a node never meets the faces it belongs to).

use std::path::Path;

use super::kinds::ElementKind;
use super::types::Model;
use crate::error::Result;
use crate::table::{batch, write_table, Col, Provenance, Table};

/// Expected columns, for error messages.
pub const CONTACT_COLS: &str =
    "contact_id, master_part, slave_part or slave_set (+ optional columns)";

/// What to do with a slave node that starts inside the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InitialPenetration {
    /// Remember the depth and push only beyond it (the offset shrinks as the node leaves;
    /// LS-DYNA's IGNORE = 1): the node is reported, not launched.
    Track,
    /// Stop with an error naming the node.
    Error,
    /// The penalty acts from the start with the full depth: a formed state whose contact
    /// forces are part of its equilibrium (`weft-form` writes this).
    Keep,
}

impl InitialPenetration {
    pub fn name(self) -> &'static str {
        match self {
            InitialPenetration::Track => "track",
            InitialPenetration::Error => "error",
            InitialPenetration::Keep => "keep",
        }
    }
}

/// The slave side of a contact.
#[derive(Debug, Clone, PartialEq)]
pub enum Slave {
    /// The nodes of a part's elements (index into `Model::parts`).
    Part(usize),
    /// A node set.
    Set(String),
}

/// One contact definition.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactDef {
    pub id: i64,
    pub slave: Slave,
    /// Part whose faces or segments form the surface (index into `Model::parts`).
    pub master: usize,
    /// Static and dynamic Coulomb coefficients μ_s, μ_d (≥ 0).
    pub static_friction: f64,
    pub dynamic_friction: f64,
    /// Exponential decay coefficient d_c [s/m]: μ = μ_d + (μ_s − μ_d) e^{−d_c |v_t|}.
    pub friction_decay: f64,
    /// Multiplies the penalty factor κ_c = 0.1 of k = κ_c m*/Δt².
    pub penalty_scale: f64,
    /// Contact thickness of the slave nodes [m] (None: from their elements).
    pub slave_thickness: Option<f64>,
    /// Contact thickness of the surface [m] (None: from its elements).
    pub master_thickness: Option<f64>,
    /// Also the master part's nodes against the slave part's surface.
    pub two_way: bool,
    pub initial_penetration: InitialPenetration,
}

impl ContactDef {
    /// A one-way, frictionless definition with the default penalty.
    pub fn new(id: i64, slave: Slave, master: usize) -> ContactDef {
        ContactDef {
            id,
            slave,
            master,
            static_friction: 0.0,
            dynamic_friction: 0.0,
            friction_decay: 0.0,
            penalty_scale: 1.0,
            slave_thickness: None,
            master_thickness: None,
            two_way: false,
            initial_penetration: InitialPenetration::Track,
        }
    }
    /// Coulomb friction with one coefficient.
    pub fn with_friction(mut self, mu: f64) -> ContactDef {
        self.static_friction = mu;
        self.dynamic_friction = mu;
        self
    }
}

/// Part kinds that can form a contact surface.
pub fn is_surface_kind(k: ElementKind) -> bool {
    matches!(
        k,
        ElementKind::Tri | ElementKind::Quad | ElementKind::Truss | ElementKind::Beam
    )
}

/// Names, each in backticks, comma-separated (for messages that list the choices).
pub(super) fn names<'a>(it: impl Iterator<Item = &'a String>) -> String {
    it.map(|k| format!("`{k}`")).collect::<Vec<_>>().join(", ")
}

/// Reads `contacts.parquet` when present.
pub fn read(dir: &Path, m: &mut Model) -> Result<()> {
    let p = dir.join("contacts.parquet");
    if !p.exists() {
        return Ok(());
    }
    let t = Table::read(&p)?;
    let id = t.i64("contact_id", CONTACT_COLS)?;
    let n = id.len();
    let master = t.str("master_part", CONTACT_COLS)?;
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
pub fn write(m: &Model, dir: &Path, prov: &Provenance) -> Result<()> {
    if m.contacts.is_empty() {
        return Ok(());
    }
    let c = &m.contacts;
    let pname = |i: usize| m.parts[i].name.clone();
    write_table(
        &dir.join("contacts.parquet"),
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
        prov,
    )
}
