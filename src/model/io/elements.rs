//! `elements_<kind>.parquet`, one table per element kind: element ids, parts and nodes,
//! with the per-element columns some kinds carry (membranes' nodal thickness and initial
//! stress, trusses' area, links' frame nodes; any kind's failure-strain factor, layer and
//! yarn).

use super::codec::{Reading, Writing};
use crate::error::{Result, WeftError};
use crate::model::kinds::ElementKind;
use crate::model::types::{ElementBlock, Model};
use crate::table::{batch, Col, Table};

/// The element tables, in the order of [`ElementKind::ALL`].
pub const FILES: &[&str] = &[
    "elements_truss.parquet",
    "elements_link.parquet",
    "elements_point_mass.parquet",
    "elements_tri.parquet",
    "elements_quad.parquet",
    "elements_beam.parquet",
    "elements_hex.parquet",
];
/// Expected columns, for error messages, by nodes per element.
const ELEMS1: &str = "element_id, part_id, n1";
const ELEMS2: &str = "element_id, part_id, n1, n2";
const ELEMS3: &str = "element_id, part_id, n1, n2, n3";
const ELEMS4: &str = "element_id, part_id, n1, n2, n3, n4";
const ELEMS8: &str = "element_id, part_id, n1, n2, n3, n4, n5, n6, n7, n8";
/// The node columns, n1… (as many as the kind has nodes).
const NODE_COLUMNS: [&str; 8] = ["n1", "n2", "n3", "n4", "n5", "n6", "n7", "n8"];

/// The columns of one element table, read and checked, before its rows become a block.
struct ElementColumns {
    id: Vec<i64>,
    part_id: Vec<i64>,
    /// Node indices, one column per element node (n1…).
    nodes: Vec<Vec<usize>>,
    /// Membranes: the nodal thickness columns t1… (null: the part's thickness); empty
    /// when the table has none.
    thickness: Vec<Vec<Option<f64>>>,
    /// Membranes: the initial stress columns s0_11, s0_22, s0_12 (null: 0); empty when
    /// the table has none.
    stress0: Vec<Vec<Option<f64>>>,
    /// Trusses: the cross-section area column (null: the part's area).
    area: Option<Vec<Option<f64>>>,
    /// Links: the frame node columns f1…f4 as node indices; empty when the table has none.
    frame: Vec<Vec<usize>>,
    /// Elements that can fail: `failure_strain_factor` (null: 1).
    failure_factor: Option<Vec<Option<f64>>>,
    /// `layer` and `yarn` (null: none).
    layer: Option<Vec<Option<i64>>>,
    yarn: Option<Vec<Option<i64>>>,
}

/// Reads every element table the folder has (refusing one of an unknown kind) into a
/// block per kind.
pub fn read(r: &mut Reading) -> Result<()> {
    refuse_unknown_tables(r)?;
    for kind in ElementKind::ALL {
        let Some(t) = r.optional(&format!("elements_{}.parquet", kind.name()))? else {
            continue;
        };
        let cols = read_columns(r, &t, kind)?;
        let b = block(r, &t, &cols)?;
        r.model.elements.insert(kind, b);
    }
    Ok(())
}

/// Element tables: every elements_*.parquet must be a known kind.
fn refuse_unknown_tables(r: &Reading) -> Result<()> {
    let dir = r.dir;
    let entries = std::fs::read_dir(dir).map_err(|e| WeftError::io(dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| WeftError::io(dir, e))?;
        let name = entry.file_name().to_string_lossy().to_string();
        if let Some(kind) = name
            .strip_prefix("elements_")
            .and_then(|s| s.strip_suffix(".parquet"))
        {
            if ElementKind::parse(kind).is_none() {
                return Err(WeftError::input(format!("unknown element table `{name}`"))
                    .in_file(entry.path())
                    .expected(format!(
                        "one of {}",
                        ElementKind::ALL
                            .map(|k| format!("elements_{}.parquet", k.name()))
                            .join(", ")
                    ))
                    .hint("this weft version does not know that element kind"));
            }
        }
    }
    Ok(())
}

/// The columns of a kind's table, each optional group all there or none.
fn read_columns(r: &Reading, t: &Table, kind: ElementKind) -> Result<ElementColumns> {
    let exp = match kind.nodes_per_element() {
        1 => ELEMS1,
        2 => ELEMS2,
        3 => ELEMS3,
        4 => ELEMS4,
        _ => ELEMS8,
    };
    let id = t.i64("element_id", exp)?;
    let part_id = t.i64("part_id", exp)?;
    let mut nodes = Vec::new();
    for c in NODE_COLUMNS.iter().take(kind.nodes_per_element()) {
        let ids = t.i64(c, exp)?;
        nodes.push(r.node_refs(t, c, &ids)?);
    }
    let thickness = nodal_thickness(t, kind)?;
    let stress0 = initial_stress(t, kind)?;
    // Cross-section area of trusses (null: the part's area).
    let area = if kind == ElementKind::Truss {
        t.f64_opt("area")?
    } else {
        None
    };
    let frame = frame_nodes(r, t, kind)?;
    Ok(ElementColumns {
        id,
        part_id,
        nodes,
        thickness,
        stress0,
        area,
        frame,
        failure_factor: t.f64_opt("failure_strain_factor")?,
        layer: t.i64_opt("layer")?,
        yarn: t.i64_opt("yarn")?,
    })
}

/// Nodal thickness of membranes: t1… (null: the part's thickness).
fn nodal_thickness(t: &Table, kind: ElementKind) -> Result<Vec<Vec<Option<f64>>>> {
    let mut tcols = Vec::new();
    if matches!(kind, ElementKind::Tri | ElementKind::Quad) {
        for c in ["t1", "t2", "t3", "t4"]
            .iter()
            .take(kind.nodes_per_element())
        {
            if let Some(v) = t.f64_opt(c)? {
                tcols.push(v);
            }
        }
        if !tcols.is_empty() && tcols.len() != kind.nodes_per_element() {
            return Err(WeftError::input(format!(
                "{} of the nodal thickness columns t1…t{} are present",
                tcols.len(),
                kind.nodes_per_element()
            ))
            .in_file(&t.path)
            .expected("all of them or none"));
        }
    }
    Ok(tcols)
}

/// Initial stress of membranes: s0_11, s0_22, s0_12 (null: 0).
fn initial_stress(t: &Table, kind: ElementKind) -> Result<Vec<Vec<Option<f64>>>> {
    let mut s0cols = Vec::new();
    if matches!(kind, ElementKind::Tri | ElementKind::Quad) {
        for c in ["s0_11", "s0_22", "s0_12"] {
            if let Some(v) = t.f64_opt(c)? {
                s0cols.push(v);
            }
        }
        if !s0cols.is_empty() && s0cols.len() != 3 {
            return Err(WeftError::input(format!(
                "{} of the initial stress columns s0_11, s0_22, s0_12 are present",
                s0cols.len()
            ))
            .in_file(&t.path)
            .expected("all three or none"));
        }
    }
    Ok(s0cols)
}

/// Frame nodes of links: f1…f4 (all or none; see `ElementBlock::frame`).
fn frame_nodes(r: &Reading, t: &Table, kind: ElementKind) -> Result<Vec<Vec<usize>>> {
    let mut fcols = Vec::new();
    if kind == ElementKind::Link {
        for c in ["f1", "f2", "f3", "f4"] {
            if t.has(c) {
                let ids = t.i64(c, "f1, f2, f3, f4")?;
                fcols.push(r.node_refs(t, c, &ids)?);
            }
        }
        if !fcols.is_empty() && fcols.len() != 4 {
            return Err(WeftError::input(format!(
                "{} of the frame node columns f1, f2, f3, f4 are present",
                fcols.len()
            ))
            .in_file(&t.path)
            .expected("all four or none"));
        }
    }
    Ok(fcols)
}

/// The block of a table's rows: each element's part by id, its nodes, and its optional
/// columns with their nulls filled in.
fn block(r: &Reading, t: &Table, cols: &ElementColumns) -> Result<ElementBlock> {
    let (eid, pid, m) = (&cols.id, &cols.part_id, &r.model);
    let mut b = ElementBlock::default();
    for row in 0..eid.len() {
        let part = *r.part_index.get(&pid[row]).ok_or_else(|| {
            t.value_error(
                "part_id",
                row,
                format!("part id `{}` does not exist in parts.parquet", pid[row]),
            )
            .expected("the id of a part in parts.parquet")
        })?;
        b.id.push(eid[row]);
        b.part.push(part);
        for c in &cols.nodes {
            b.nodes.push(c[row]);
        }
        for c in &cols.thickness {
            let pt = m.parts[part].props.thickness.unwrap_or(0.0);
            b.thickness.push(c[row].unwrap_or(pt));
        }
        if let Some(c) = &cols.area {
            b.area
                .push(c[row].unwrap_or(m.parts[part].props.area.unwrap_or(0.0)));
        }
        if !cols.stress0.is_empty() {
            b.stress0
                .push(std::array::from_fn(|k| cols.stress0[k][row].unwrap_or(0.0)));
        }
        if !cols.frame.is_empty() {
            b.frame.push(std::array::from_fn(|k| cols.frame[k][row]));
        }
        if let Some(c) = &cols.failure_factor {
            b.failure_factor.push(c[row].unwrap_or(1.0));
        }
        if let Some(c) = &cols.layer {
            b.layer.push(c[row]);
        }
        if let Some(c) = &cols.yarn {
            b.yarn.push(c[row]);
        }
    }
    Ok(b)
}

/// Writes a table per non-empty block, with the optional columns the block carries.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    let ids = |v: &[usize]| v.iter().map(|&i| m.node_id[i]).collect::<Vec<_>>();
    for (kind, b) in &m.elements {
        if b.is_empty() {
            continue;
        }
        let npe = kind.nodes_per_element();
        let mut cols = vec![
            Col::I64("element_id", b.id.clone()),
            Col::I64("part_id", b.part.iter().map(|&i| m.parts[i].id).collect()),
        ];
        for (j, c) in NODE_COLUMNS.into_iter().take(npe).enumerate() {
            let v: Vec<usize> = b.nodes.iter().skip(j).step_by(npe).copied().collect();
            cols.push(Col::I64(c, ids(&v)));
        }
        if !b.thickness.is_empty() {
            for (j, c) in ["t1", "t2", "t3", "t4"].into_iter().take(npe).enumerate() {
                cols.push(Col::F64(
                    c,
                    b.thickness.iter().skip(j).step_by(npe).copied().collect(),
                ));
            }
        }
        if !b.area.is_empty() {
            cols.push(Col::F64("area", b.area.clone()));
        }
        if !b.stress0.is_empty() {
            for (j, c) in ["s0_11", "s0_22", "s0_12"].into_iter().enumerate() {
                cols.push(Col::F64(c, b.stress0.iter().map(|s| s[j]).collect()));
            }
        }
        if !b.frame.is_empty() {
            for (j, c) in ["f1", "f2", "f3", "f4"].into_iter().enumerate() {
                let v: Vec<usize> = b.frame.iter().map(|f| f[j]).collect();
                cols.push(Col::I64(c, ids(&v)));
            }
        }
        if !b.failure_factor.is_empty() {
            cols.push(Col::F64("failure_strain_factor", b.failure_factor.clone()));
        }
        if !b.layer.is_empty() {
            cols.push(Col::OptI64("layer", b.layer.clone()));
        }
        if !b.yarn.is_empty() {
            cols.push(Col::OptI64("yarn", b.yarn.clone()));
        }
        w.table(&format!("elements_{}.parquet", kind.name()), &batch(cols))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_follow_the_kinds() {
        let names: Vec<String> = ElementKind::ALL
            .map(|k| format!("elements_{}.parquet", k.name()))
            .to_vec();
        assert_eq!(FILES.to_vec(), names);
    }
}
