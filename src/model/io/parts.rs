//! `parts.parquet`: part ids, names and kinds, and the property columns, read and written
//! from the one property definition ([`crate::model::props`]).

use super::codec::{Reading, Writing};
use crate::error::Result;
use crate::model::kinds::ElementKind;
use crate::model::props;
use crate::model::types::{Model, Part};
use crate::model::validate_part;
use crate::table::{batch, Col};

pub const FILE: &str = "parts.parquet";
/// Expected columns, for error messages.
const COLS: &str = "part_id, name, kind (+ property columns)";

/// Reads the parts, checks each one's properties ([`validate_part`]) and indexes them by
/// id, each id once.
pub fn read(r: &mut Reading) -> Result<()> {
    let t = r.table(FILE)?;
    let m = &mut r.model;
    let ids = t.i64("part_id", COLS)?;
    let names = t.str("name", COLS)?;
    let kinds = t.str("kind", COLS)?;
    let mut part_props = props::read_columns(&t, ids.len())?.into_iter();
    for row in 0..ids.len() {
        let kind = ElementKind::parse(&kinds[row]).ok_or_else(|| {
            t.value_error(
                "kind",
                row,
                format!("unknown element kind `{}`", kinds[row]),
            )
            .expected(format!(
                "one of {}",
                ElementKind::ALL
                    .map(|k| format!("`{}`", k.name()))
                    .join(", ")
            ))
        })?;
        let part = Part {
            id: ids[row],
            name: names[row].clone(),
            kind,
            props: part_props.next().expect("one per row"),
        };
        validate_part(&part).map_err(|err| err.in_file(&t.path).at_row(row))?;
        m.parts.push(part);
    }
    let part_map = &mut r.part_index;
    for (row, p) in m.parts.iter().enumerate() {
        if part_map.insert(p.id, row).is_some() {
            return Err(t
                .value_error("part_id", row, format!("duplicate part id `{}`", p.id))
                .expected("unique part ids"));
        }
    }
    Ok(())
}

/// Writes the parts: id, name, kind, then every property column in table order.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    let p = &m.parts;
    let mut cols = vec![
        Col::I64("part_id", p.iter().map(|x| x.id).collect()),
        Col::Str("name", p.iter().map(|x| x.name.clone()).collect()),
        Col::Str(
            "kind",
            p.iter().map(|x| x.kind.name().to_string()).collect(),
        ),
    ];
    cols.extend(props::columns(p.iter().map(|x| &x.props)));
    w.table(FILE, &batch(cols))
}
