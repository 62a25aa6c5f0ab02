//! Checks of the contact definitions (contacts.parquet): unique ids, each one's master
//! and slave side and its coefficients, with errors that name the column, row and value.

use std::collections::HashMap;

use super::contacts::{self, ContactDef, Slave};
use super::kinds::ElementKind;
use super::types::Model;
use crate::error::{Result, WeftError};

impl Model {
    /// Contact definitions: unique ids, then each one's master, slave side and
    /// coefficients; the messages name contacts.parquet, the column, row and value.
    pub(super) fn validate_contacts(&self) -> Result<()> {
        let mut ids = HashMap::new();
        for (row, c) in self.contacts.iter().enumerate() {
            if let Some(first) = ids.insert(c.id, row) {
                return Err(contact_err(
                    row,
                    "contact_id",
                    format!("duplicate contact id `{}` (first at row {first})", c.id),
                )
                .expected("unique contact ids"));
            }
            self.validate_contact_master(row, c)?;
            self.validate_contact_slave(row, c)?;
            self.validate_solid_self_contact(row, c)?;
            validate_contact_coefficients(row, c)?;
        }
        Ok(())
    }

    /// A contact's master: a part of a kind that forms a surface, with elements.
    fn validate_contact_master(&self, row: usize, c: &ContactDef) -> Result<()> {
        let m = self;
        let Some(mp) = m.parts.get(c.master) else {
            return Err(contact_err(
                row,
                "master_part",
                format!("master part index {} out of range", c.master),
            ));
        };
        if !contacts::is_surface_kind(mp.kind) {
            return Err(contact_err(
                row,
                "master_part",
                format!(
                    "master part `{}` is a {} part and has no faces or segments",
                    mp.name,
                    mp.kind.name()
                ),
            )
            .expected("a part of triangles, quads, trusses, beams or hexahedra")
            .hint("a contact surface is made of membrane faces, rod segments or a solid's boundary faces"));
        }
        let has_elements = m
            .elements
            .get(&mp.kind)
            .is_some_and(|b| b.part.contains(&c.master));
        if !has_elements {
            return Err(contact_err(
                row,
                "master_part",
                format!(
                    "master part `{}` has no elements: the surface has no faces",
                    mp.name
                ),
            )
            .expected("a part with at least one element"));
        }
        Ok(())
    }

    /// A contact's slave side: a part (one that forms a surface too when two-way), or a
    /// node set of the model (one-way only).
    fn validate_contact_slave(&self, row: usize, c: &ContactDef) -> Result<()> {
        let m = self;
        match &c.slave {
            Slave::Part(p) => {
                if m.parts.get(*p).is_none() {
                    return Err(contact_err(
                        row,
                        "slave_part",
                        format!("slave part index {p} out of range"),
                    ));
                }
                if c.two_way && !contacts::is_surface_kind(m.parts[*p].kind) {
                    return Err(contact_err(row, "two_way", format!("two-way contact needs a surface on the slave side, but `{}` is a {} part", m.parts[*p].name, m.parts[*p].kind.name()))
                        .expected("false, or a slave part of triangles, quads, trusses, beams or hexahedra"));
                }
            }
            Slave::Set(s) => {
                if !m.node_sets.contains_key(s) {
                    return Err(contact_err(
                        row,
                        "slave_set",
                        format!("node set `{s}` does not exist"),
                    )
                    .expected(format!(
                        "one of the model's node sets: {}",
                        contacts::names(m.node_sets.keys())
                    )));
                }
                if c.two_way {
                    return Err(contact_err(
                        row,
                        "two_way",
                        "two-way contact needs a slave part, not a node set".into(),
                    )
                    .expected("false with slave_set"));
                }
            }
        }
        Ok(())
    }
}

impl Model {
    /// A solid (hexahedron part) against itself is refused: its one-sided faces would
    /// meet its own boundary nodes across an element (a node one element under a face
    /// lies behind it), and a bullet does not fold onto itself. Self-contact is a slave
    /// part equal to the master, or a slave set holding one of the master's nodes.
    fn validate_solid_self_contact(&self, row: usize, c: &ContactDef) -> Result<()> {
        let mp = &self.parts[c.master];
        if mp.kind != ElementKind::Hex {
            return Ok(());
        }
        let (col, what) = match &c.slave {
            Slave::Part(p) if *p == c.master => (
                "slave_part",
                format!(
                    "contact `{}` is self-contact of the hexahedron part `{}` (slave_part = master_part)",
                    c.id, mp.name
                ),
            ),
            Slave::Set(s) => {
                let b = &self.elements[&ElementKind::Hex];
                let mut own = vec![false; self.num_nodes()];
                for e in (0..b.len()).filter(|&e| b.part[e] == c.master) {
                    for &n in &b.nodes[8 * e..8 * e + 8] {
                        own[n] = true;
                    }
                }
                let Some(&n) = self.node_sets[s].iter().find(|&&n| own[n]) else {
                    return Ok(());
                };
                (
                    "slave_set",
                    format!(
                        "contact `{}`: node `{}` of slave set `{s}` belongs to the hexahedron part `{}`, its own master surface",
                        c.id, self.node_id[n], mp.name
                    ),
                )
            }
            _ => return Ok(()),
        };
        Err(contact_err(row, col, what)
            .expected("slave nodes of other parts than the solid master part (a solid has no self-contact)")
            .hint("make the slaves another part, or split the solid into two parts that meet by a two-way contact"))
    }
}

/// A contact's friction coefficients, penalty scale and thicknesses.
fn validate_contact_coefficients(row: usize, c: &ContactDef) -> Result<()> {
    for (col, v) in [
        ("static_friction", c.static_friction),
        ("dynamic_friction", c.dynamic_friction),
        ("friction_decay", c.friction_decay),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(
                contact_err(row, col, format!("{col} is `{v}`")).expected("a finite value ≥ 0")
            );
        }
    }
    if c.dynamic_friction > c.static_friction {
        return Err(contact_err(
            row,
            "dynamic_friction",
            format!(
                "dynamic_friction {} exceeds static_friction {}",
                c.dynamic_friction, c.static_friction
            ),
        )
        .expected("μ_d ≤ μ_s")
        .hint("leave dynamic_friction empty for one coefficient"));
    }
    if !(c.penalty_scale.is_finite() && c.penalty_scale > 0.0) {
        return Err(contact_err(
            row,
            "penalty_scale",
            format!("penalty_scale is `{}`", c.penalty_scale),
        )
        .expected("a finite value > 0 (null = 1)"));
    }
    for (col, v) in [
        ("slave_thickness", c.slave_thickness),
        ("master_thickness", c.master_thickness),
    ] {
        if let Some(v) = v {
            if !(v.is_finite() && v >= 0.0) {
                return Err(contact_err(row, col, format!("{col} is `{v}`"))
                    .expected("a thickness ≥ 0 in m, or null (from the elements)"));
            }
        }
    }
    Ok(())
}

/// An error in a row and column of `contacts.parquet`.
fn contact_err(row: usize, col: &str, what: String) -> WeftError {
    WeftError::input(what)
        .in_file("contacts.parquet")
        .in_column(col)
        .at_row(row)
}
