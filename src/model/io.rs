//! Reading and writing a model folder of Parquet tables. Layout: `docs/tables.md`.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::*;
use crate::error::{Result, WeftError};
use crate::table::{batch, write_table, Col, Provenance, Table};

const NODES: &str = "node_id, x, y, z";
const PARTS: &str = "part_id, name, kind (+ property columns)";
const ELEMS2: &str = "element_id, part_id, n1, n2";
const ELEMS1: &str = "element_id, part_id, n1";
const ELEMS3: &str = "element_id, part_id, n1, n2, n3";
const ELEMS4: &str = "element_id, part_id, n1, n2, n3, n4";
const SETS: &str = "set, node_id, order";
const CONS: &str = "node_id, fix_x, fix_y, fix_z";
const LOADS: &str = "load_id, node_id, fx, fy, fz, law, start (+ duration, curve)";
const CURVES: &str = "curve, t, value";
const VELS: &str = "node_id, vx, vy, vz";
const ANALYSIS: &str = "end_time, output_interval (+ optional settings)";
const PROJ: &str =
    "projectile_id, shape, radius, mass, tip_x, tip_y, tip_z, vx, vy, vz (+ optional columns)";
const SYM: &str = "normal (+ position, tolerance)";
const TIES: &str = "slave, m1, m2 (+ m3, m4)";

/// Names of the model tables, in the order they are written.
pub const MODEL_TABLES: &[&str] = &[
    "nodes.parquet",
    "parts.parquet",
    "elements_truss.parquet",
    "elements_link.parquet",
    "elements_point_mass.parquet",
    "elements_tri.parquet",
    "elements_quad.parquet",
    "elements_beam.parquet",
    "node_sets.parquet",
    "constraints.parquet",
    "loads.parquet",
    "curves.parquet",
    "initial_velocities.parquet",
    "projectile.parquet",
    "symmetry.parquet",
    "ties.parquet",
    "contacts.parquet",
    "analysis.parquet",
];

fn opt_table(dir: &Path, name: &str) -> Result<Option<Table>> {
    let p = dir.join(name);
    if p.exists() {
        Table::read(&p).map(Some)
    } else {
        Ok(None)
    }
}

/// Map node ids of a column to node indices; a dangling id is an error naming the row.
fn node_refs(t: &Table, col: &str, ids: &[i64], map: &HashMap<i64, usize>) -> Result<Vec<usize>> {
    ids.iter()
        .enumerate()
        .map(|(row, id)| {
            map.get(id).copied().ok_or_else(|| {
                t.value_error(
                    col,
                    row,
                    format!("node id `{id}` does not exist in nodes.parquet"),
                )
                .expected("the id of a node in nodes.parquet")
                .hint("a dangling reference: regenerate the model or add the node")
            })
        })
        .collect()
}

/// Read and validate a model folder.
pub fn read_model(dir: &Path) -> Result<Model> {
    let nodes_path = dir.join("nodes.parquet");
    if !nodes_path.exists() {
        return Err(WeftError::input(format!(
            "`{}` is not a model folder: it has no nodes.parquet",
            dir.display()
        ))
        .expected("a folder of model tables (docs/tables.md)")
        .hint("create one with `weft-weave rod --out DIR`"));
    }
    read_model_inner(dir).map_err(|e| e.in_file(dir))
}

fn read_model_inner(dir: &Path) -> Result<Model> {
    let mut m = Model::default();
    let t = Table::read(&dir.join("nodes.parquet"))?;
    m.node_id = t.i64("node_id", NODES)?;
    let (x, y, z) = (t.f64("x", NODES)?, t.f64("y", NODES)?, t.f64("z", NODES)?);
    m.coords = (0..x.len()).map(|i| [x[i], y[i], z[i]]).collect();
    // Initial displacement ux0, uy0, uz0 (a formed state): all three or none, null → 0.
    let u0: Vec<_> = ["ux0", "uy0", "uz0"]
        .iter()
        .map(|c| t.f64_opt(c))
        .collect::<Result<Vec<_>>>()?;
    let present = u0.iter().filter(|c| c.is_some()).count();
    if present == 3 {
        let u: Vec<Vec<Option<f64>>> = u0.into_iter().flatten().collect();
        m.initial_displacement = (0..x.len())
            .map(|i| std::array::from_fn(|d| u[d][i].unwrap_or(0.0)))
            .collect();
    } else if present > 0 {
        return Err(WeftError::input(format!(
            "{present} of the initial displacement columns ux0, uy0, uz0 are present"
        ))
        .in_file(&t.path)
        .expected("all three or none"));
    }
    if m.node_id.is_empty() {
        return Err(WeftError::input("the model has no nodes")
            .in_file(&t.path)
            .expected("at least one node"));
    }
    // Duplicate node ids are checked here, where the file is known.
    let mut map = HashMap::new();
    for (row, id) in m.node_id.iter().enumerate() {
        if map.insert(*id, row).is_some() {
            return Err(t
                .value_error("node_id", row, format!("duplicate node id `{id}`"))
                .expected("unique node ids"));
        }
    }

    let t = Table::read(&dir.join("parts.parquet"))?;
    let ids = t.i64("part_id", PARTS)?;
    let names = t.str("name", PARTS)?;
    let kinds = t.str("kind", PARTS)?;
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
    let mut part_map = HashMap::new();
    for (row, p) in m.parts.iter().enumerate() {
        if part_map.insert(p.id, row).is_some() {
            return Err(t
                .value_error("part_id", row, format!("duplicate part id `{}`", p.id))
                .expected("unique part ids"));
        }
    }

    // Element tables: every elements_*.parquet must be a known kind.
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
    for kind in ElementKind::ALL {
        let Some(t) = opt_table(dir, &format!("elements_{}.parquet", kind.name()))? else {
            continue;
        };
        let exp = match kind.nodes_per_element() {
            1 => ELEMS1,
            2 => ELEMS2,
            3 => ELEMS3,
            _ => ELEMS4,
        };
        let eid = t.i64("element_id", exp)?;
        let pid = t.i64("part_id", exp)?;
        let mut cols = Vec::new();
        for c in ["n1", "n2", "n3", "n4"]
            .iter()
            .take(kind.nodes_per_element())
        {
            let ids = t.i64(c, exp)?;
            cols.push(node_refs(&t, c, &ids, &map)?);
        }
        // Nodal thickness of membranes: t1… (null: the part's thickness).
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
        // Initial stress of membranes: s0_11, s0_22, s0_12 (null: 0).
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
        // Cross-section area of trusses (null: the part's area).
        let acol = if kind == ElementKind::Truss {
            t.f64_opt("area")?
        } else {
            None
        };
        // Frame nodes of links: f1…f4 (all or none; see `ElementBlock::frame`).
        let mut fcols = Vec::new();
        if kind == ElementKind::Link {
            for c in ["f1", "f2", "f3", "f4"] {
                if t.has(c) {
                    let ids = t.i64(c, "f1, f2, f3, f4")?;
                    fcols.push(node_refs(&t, c, &ids, &map)?);
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
        let mut b = ElementBlock::default();
        for row in 0..eid.len() {
            let part = *part_map.get(&pid[row]).ok_or_else(|| {
                t.value_error(
                    "part_id",
                    row,
                    format!("part id `{}` does not exist in parts.parquet", pid[row]),
                )
                .expected("the id of a part in parts.parquet")
            })?;
            b.id.push(eid[row]);
            b.part.push(part);
            for c in &cols {
                b.nodes.push(c[row]);
            }
            for c in &tcols {
                let pt = m.parts[part].props.thickness.unwrap_or(0.0);
                b.thickness.push(c[row].unwrap_or(pt));
            }
            if let Some(c) = &acol {
                b.area
                    .push(c[row].unwrap_or(m.parts[part].props.area.unwrap_or(0.0)));
            }
            if !s0cols.is_empty() {
                b.stress0
                    .push(std::array::from_fn(|k| s0cols[k][row].unwrap_or(0.0)));
            }
            if !fcols.is_empty() {
                b.frame.push(std::array::from_fn(|k| fcols[k][row]));
            }
        }
        m.elements.insert(kind, b);
    }

    if let Some(t) = opt_table(dir, "node_sets.parquet")? {
        let names = t.str("set", SETS)?;
        let ids = t.i64("node_id", SETS)?;
        let order = t.i64("order", SETS)?;
        let idx = node_refs(&t, "node_id", &ids, &map)?;
        let mut sets: BTreeMap<String, Vec<(i64, usize)>> = BTreeMap::new();
        for row in 0..names.len() {
            sets.entry(names[row].clone())
                .or_default()
                .push((order[row], idx[row]));
        }
        for (name, mut v) in sets {
            v.sort_by_key(|p| p.0);
            m.node_sets
                .insert(name, v.into_iter().map(|p| p.1).collect());
        }
    }
    if let Some(t) = opt_table(dir, "constraints.parquet")? {
        let ids = t.i64("node_id", CONS)?;
        let idx = node_refs(&t, "node_id", &ids, &map)?;
        let (fx, fy, fz) = (
            t.bool("fix_x", CONS)?,
            t.bool("fix_y", CONS)?,
            t.bool("fix_z", CONS)?,
        );
        m.constraints = (0..idx.len())
            .map(|i| (idx[i], [fx[i], fy[i], fz[i]]))
            .collect();
        let r = |c: &str| -> Result<Vec<bool>> {
            Ok(t.bool_opt(c)?
                .map(|v| v.into_iter().map(|b| b.unwrap_or(false)).collect())
                .unwrap_or_else(|| vec![false; idx.len()]))
        };
        let (rx, ry, rz) = (r("fix_rx")?, r("fix_ry")?, r("fix_rz")?);
        m.rot_constraints = (0..idx.len())
            .filter(|&i| rx[i] || ry[i] || rz[i])
            .map(|i| (idx[i], [rx[i], ry[i], rz[i]]))
            .collect();
    }
    if let Some(t) = opt_table(dir, "curves.parquet")? {
        let names = t.str("curve", CURVES)?;
        let ts = t.f64("t", CURVES)?;
        let vs = t.f64("value", CURVES)?;
        let mut curves: BTreeMap<String, Curve> = BTreeMap::new();
        for row in 0..names.len() {
            let c = curves.entry(names[row].clone()).or_insert(Curve {
                t: vec![],
                value: vec![],
            });
            if let Some(&last) = c.t.last() {
                if ts[row] <= last {
                    return Err(t
                        .value_error(
                            "t",
                            row,
                            format!(
                                "curve `{}` time `{}` does not increase (previous {last})",
                                names[row], ts[row]
                            ),
                        )
                        .expected("strictly increasing times within a curve"));
                }
            }
            c.t.push(ts[row]);
            c.value.push(vs[row]);
        }
        m.curves = curves.into_iter().map(|(k, v)| (k, Arc::new(v))).collect();
    }
    if let Some(t) = opt_table(dir, "loads.parquet")? {
        let lid = t.i64("load_id", LOADS)?;
        let ids = t.i64("node_id", LOADS)?;
        let idx = node_refs(&t, "node_id", &ids, &map)?;
        let (fx, fy, fz) = (
            t.f64("fx", LOADS)?,
            t.f64("fy", LOADS)?,
            t.f64("fz", LOADS)?,
        );
        let law = t.str("law", LOADS)?;
        let start = t.f64("start", LOADS)?;
        let duration = t
            .f64_opt("duration")?
            .unwrap_or_else(|| vec![None; lid.len()]);
        let curve = t.str_opt("curve")?.unwrap_or_else(|| vec![None; lid.len()]);
        for row in 0..lid.len() {
            let need_duration = || {
                duration[row].filter(|d| *d > 0.0).ok_or_else(|| {
                    t.value_error(
                        "duration",
                        row,
                        format!(
                            "load `{}` ({}) has duration {:?}",
                            lid[row], law[row], duration[row]
                        ),
                    )
                    .expected("a duration > 0 s for sine_pulse and ramp")
                })
            };
            let l = match law[row].as_str() {
                "sine_pulse" => TimeLaw::SinePulse {
                    start: start[row],
                    duration: need_duration()?,
                },
                "ramp" => TimeLaw::Ramp {
                    start: start[row],
                    duration: need_duration()?,
                },
                "step" => TimeLaw::Step { start: start[row] },
                "tabulated" => {
                    let name = curve[row].clone().unwrap_or_default();
                    let c = m.curves.get(&name).cloned().ok_or_else(|| {
                        t.value_error("curve", row, format!("load `{}` names curve `{name}`, which curves.parquet does not define", lid[row]))
                            .expected("the name of a curve in curves.parquet")
                    })?;
                    TimeLaw::Tabulated { name, curve: c }
                }
                other => {
                    return Err(t
                        .value_error("law", row, format!("unknown time law `{other}`"))
                        .expected("one of `sine_pulse`, `step`, `ramp`, `tabulated`"))
                }
            };
            m.loads.push(Load {
                id: lid[row],
                node: idx[row],
                force: [fx[row], fy[row], fz[row]],
                law: l,
            });
        }
    }
    if let Some(t) = opt_table(dir, "initial_velocities.parquet")? {
        let ids = t.i64("node_id", VELS)?;
        let idx = node_refs(&t, "node_id", &ids, &map)?;
        let (vx, vy, vz) = (t.f64("vx", VELS)?, t.f64("vy", VELS)?, t.f64("vz", VELS)?);
        m.initial_velocities = (0..idx.len())
            .map(|i| (idx[i], [vx[i], vy[i], vz[i]]))
            .collect();
    }
    if let Some(t) = opt_table(dir, "projectile.parquet")? {
        let n = t.num_rows();
        let ids = t.i64("projectile_id", PROJ)?;
        let shape = t.str("shape", PROJ)?;
        let radius = t.f64("radius", PROJ)?;
        let mass = t.f64("mass", PROJ)?;
        let g = |c: &str| t.f64(c, PROJ);
        let (tx, ty, tz) = (g("tip_x")?, g("tip_y")?, g("tip_z")?);
        let (vx, vy, vz) = (g("vx")?, g("vy")?, g("vz")?);
        let o = |c: &str| -> Result<Vec<Option<f64>>> {
            Ok(t.f64_opt(c)?.unwrap_or_else(|| vec![None; n]))
        };
        let (ax, ay, az) = (o("axis_x")?, o("axis_y")?, o("axis_z")?);
        let (len, k, mu) = (o("length")?, o("contact_stiffness")?, o("friction")?);
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
                .expected("one of `sphere`, `flat`, `round`")
            })?;
            m.projectiles.push(ProjectileSpec {
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
                segment_contact: seg[row].unwrap_or(true),
            });
        }
    }
    if let Some(t) = opt_table(dir, "symmetry.parquet")? {
        let normal = t.str("normal", SYM)?;
        let n = normal.len();
        let pos = t.f64_opt("position")?.unwrap_or_else(|| vec![None; n]);
        let tol = t.f64_opt("tolerance")?.unwrap_or_else(|| vec![None; n]);
        for row in 0..n {
            let axis = ["x", "y", "z"]
                .iter()
                .position(|a| *a == normal[row])
                .ok_or_else(|| {
                    t.value_error(
                        "normal",
                        row,
                        format!("unknown symmetry plane normal `{}`", normal[row]),
                    )
                    .expected("`x`, `y` or `z` (the plane x = position, ...)")
                })?;
            m.symmetry.push(SymmetryPlane {
                normal: axis,
                position: pos[row].unwrap_or(0.0),
                tolerance: tol[row].unwrap_or(1e-9),
            });
        }
    }
    if let Some(t) = opt_table(dir, "ties.parquet")? {
        let sl = t.i64("slave", TIES)?;
        let n = sl.len();
        let sl = node_refs(&t, "slave", &sl, &map)?;
        let m1 = t.i64("m1", TIES)?;
        let m1 = node_refs(&t, "m1", &m1, &map)?;
        let m2 = t.i64("m2", TIES)?;
        let m2 = node_refs(&t, "m2", &m2, &map)?;
        let opt_nodes = |c: &str| -> Result<Vec<Option<usize>>> {
            let Some(a) = t.batch.column_by_name(c) else {
                return Ok(vec![None; n]);
            };
            let a = arrow_cast::cast(a, &arrow_schema::DataType::Int64).map_err(|e| {
                t.value_error(c, 0, format!("cannot read column `{c}` as integers: {e}"))
            })?;
            let a = a
                .as_any()
                .downcast_ref::<arrow_array::Int64Array>()
                .expect("int64");
            (0..n)
                .map(|row| {
                    if arrow_array::Array::is_null(a, row) {
                        Ok(None)
                    } else {
                        let id = a.value(row);
                        map.get(&id).copied().map(Some).ok_or_else(|| {
                            t.value_error(
                                c,
                                row,
                                format!("node id `{id}` does not exist in nodes.parquet"),
                            )
                            .expected("the id of a node in nodes.parquet, or null")
                        })
                    }
                })
                .collect()
        };
        let (m3, m4) = (opt_nodes("m3")?, opt_nodes("m4")?);
        for row in 0..n {
            let mut masters = vec![m1[row], m2[row]];
            masters.extend(m3[row]);
            masters.extend(m4[row]);
            m.ties.push(Tie {
                slave: sl[row],
                masters,
            });
        }
    }
    super::contacts::read(dir, &mut m)?;
    if let Some(t) = opt_table(dir, "analysis.parquet")? {
        if t.num_rows() != 1 {
            return Err(
                WeftError::input(format!("analysis table has {} rows", t.num_rows()))
                    .in_file(&t.path)
                    .expected("exactly one row"),
            );
        }
        let d = Analysis::default();
        let get = |c: &str, dflt: Option<f64>| -> Result<Option<f64>> {
            Ok(t.f64_opt(c)?.and_then(|v| v[0]).or(dflt))
        };
        let sets = t
            .str_opt("history_sets")?
            .and_then(|v| v[0].clone())
            .unwrap_or_default();
        m.analysis = Analysis {
            end_time: t.f64("end_time", ANALYSIS)?[0],
            output_interval: t.f64("output_interval", ANALYSIS)?[0],
            dt_safety: get("dt_safety", Some(d.dt_safety))?.unwrap(),
            mass_damping: get("mass_damping", Some(d.mass_damping))?.unwrap(),
            time_step: get("time_step", None)?,
            target_time_step: get("target_time_step", None)?,
            history_sets: sets
                .split(',')
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect(),
            max_energy_error: get("max_energy_error", Some(d.max_energy_error))?.unwrap(),
        };
    }
    m.validate()?;
    Ok(m)
}

/// Write a model folder. The folder is assembled beside the target and swapped into
/// place, so a reader never sees a mix of old and new tables.
pub fn write_model(m: &Model, dir: &Path, prov: &Provenance) -> Result<()> {
    m.validate()?;
    let parent = dir
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| WeftError::io(parent, e))?;
    let name = dir
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "model".into());
    let tmp = parent.join(format!(".{name}.tmp-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(|e| WeftError::io(&tmp, e))?;
    let res = write_tables(m, &tmp, prov);
    if let Err(e) = res {
        let _ = std::fs::remove_dir_all(&tmp);
        return Err(e);
    }
    let old: PathBuf = parent.join(format!(".{name}.old-{}", std::process::id()));
    if dir.exists() {
        std::fs::rename(dir, &old).map_err(|e| WeftError::io(dir, e))?;
    }
    std::fs::rename(&tmp, dir).map_err(|e| WeftError::io(dir, e))?;
    let _ = std::fs::remove_dir_all(&old);
    Ok(())
}

fn write_tables(m: &Model, dir: &Path, prov: &Provenance) -> Result<()> {
    let ids = |v: &[usize]| v.iter().map(|&i| m.node_id[i]).collect::<Vec<_>>();
    let mut cols = vec![
        Col::I64("node_id", m.node_id.clone()),
        Col::F64("x", m.coords.iter().map(|c| c[0]).collect()),
        Col::F64("y", m.coords.iter().map(|c| c[1]).collect()),
        Col::F64("z", m.coords.iter().map(|c| c[2]).collect()),
    ];
    if !m.initial_displacement.is_empty() {
        for (d, c) in ["ux0", "uy0", "uz0"].into_iter().enumerate() {
            cols.push(Col::F64(
                c,
                m.initial_displacement.iter().map(|u| u[d]).collect(),
            ));
        }
    }
    write_table(&dir.join("nodes.parquet"), &batch(cols), prov)?;
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
    write_table(&dir.join("parts.parquet"), &batch(cols), prov)?;
    for (kind, b) in &m.elements {
        if b.is_empty() {
            continue;
        }
        let npe = kind.nodes_per_element();
        let mut cols = vec![
            Col::I64("element_id", b.id.clone()),
            Col::I64("part_id", b.part.iter().map(|&i| m.parts[i].id).collect()),
        ];
        for (j, c) in ["n1", "n2", "n3", "n4"].into_iter().take(npe).enumerate() {
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
        write_table(
            &dir.join(format!("elements_{}.parquet", kind.name())),
            &batch(cols),
            prov,
        )?;
    }
    if !m.node_sets.is_empty() {
        let (mut s, mut n, mut o) = (vec![], vec![], vec![]);
        for (name, set) in &m.node_sets {
            for (k, &i) in set.iter().enumerate() {
                s.push(name.clone());
                n.push(m.node_id[i]);
                o.push(k as i64);
            }
        }
        write_table(
            &dir.join("node_sets.parquet"),
            &batch(vec![
                Col::Str("set", s),
                Col::I64("node_id", n),
                Col::I64("order", o),
            ]),
            prov,
        )?;
    }
    if !m.constraints.is_empty() || !m.rot_constraints.is_empty() {
        // One row per node: translations and rotations merged.
        let mut rows: BTreeMap<usize, [bool; 6]> = BTreeMap::new();
        for (n, f) in &m.constraints {
            let r = rows.entry(*n).or_default();
            for d in 0..3 {
                r[d] |= f[d];
            }
        }
        for (n, f) in &m.rot_constraints {
            let r = rows.entry(*n).or_default();
            for d in 0..3 {
                r[3 + d] |= f[d];
            }
        }
        let col = |k: usize| rows.values().map(|r| r[k]).collect::<Vec<_>>();
        let mut cols = vec![
            Col::I64("node_id", rows.keys().map(|&n| m.node_id[n]).collect()),
            Col::Bool("fix_x", col(0)),
            Col::Bool("fix_y", col(1)),
            Col::Bool("fix_z", col(2)),
        ];
        if !m.rot_constraints.is_empty() {
            cols.push(Col::Bool("fix_rx", col(3)));
            cols.push(Col::Bool("fix_ry", col(4)));
            cols.push(Col::Bool("fix_rz", col(5)));
        }
        write_table(&dir.join("constraints.parquet"), &batch(cols), prov)?;
    }
    if !m.curves.is_empty() {
        let (mut n, mut t, mut v) = (vec![], vec![], vec![]);
        for (name, c) in &m.curves {
            for k in 0..c.t.len() {
                n.push(name.clone());
                t.push(c.t[k]);
                v.push(c.value[k]);
            }
        }
        write_table(
            &dir.join("curves.parquet"),
            &batch(vec![
                Col::Str("curve", n),
                Col::F64("t", t),
                Col::F64("value", v),
            ]),
            prov,
        )?;
    }
    if !m.loads.is_empty() {
        let l = &m.loads;
        let start = |law: &TimeLaw| match law {
            TimeLaw::SinePulse { start, .. }
            | TimeLaw::Ramp { start, .. }
            | TimeLaw::Step { start } => *start,
            TimeLaw::Tabulated { .. } => 0.0,
        };
        let duration = |law: &TimeLaw| match law {
            TimeLaw::SinePulse { duration, .. } | TimeLaw::Ramp { duration, .. } => Some(*duration),
            _ => None,
        };
        let curve = |law: &TimeLaw| match law {
            TimeLaw::Tabulated { name, .. } => Some(name.clone()),
            _ => None,
        };
        let mut cols = vec![
            Col::I64("load_id", l.iter().map(|x| x.id).collect()),
            Col::I64("node_id", l.iter().map(|x| m.node_id[x.node]).collect()),
            Col::F64("fx", l.iter().map(|x| x.force[0]).collect()),
            Col::F64("fy", l.iter().map(|x| x.force[1]).collect()),
            Col::F64("fz", l.iter().map(|x| x.force[2]).collect()),
            Col::Str("law", l.iter().map(|x| x.law.name().to_string()).collect()),
            Col::F64("start", l.iter().map(|x| start(&x.law)).collect()),
            Col::OptF64("duration", l.iter().map(|x| duration(&x.law)).collect()),
        ];
        let curves: Vec<Option<String>> = l.iter().map(|x| curve(&x.law)).collect();
        let (f, a) = (
            arrow_schema::Field::new("curve", arrow_schema::DataType::Utf8, true),
            Arc::new(arrow_array::StringArray::from(curves)) as arrow_array::ArrayRef,
        );
        let b = batch(std::mem::take(&mut cols));
        let mut fields: Vec<arrow_schema::Field> = b
            .schema()
            .fields()
            .iter()
            .map(|x| x.as_ref().clone())
            .collect();
        let mut arrays = b.columns().to_vec();
        fields.push(f);
        arrays.push(a);
        let b =
            arrow_array::RecordBatch::try_new(Arc::new(arrow_schema::Schema::new(fields)), arrays)
                .expect("equal lengths");
        write_table(&dir.join("loads.parquet"), &b, prov)?;
    }
    if !m.initial_velocities.is_empty() {
        let v = &m.initial_velocities;
        write_table(
            &dir.join("initial_velocities.parquet"),
            &batch(vec![
                Col::I64("node_id", v.iter().map(|x| m.node_id[x.0]).collect()),
                Col::F64("vx", v.iter().map(|x| x.1[0]).collect()),
                Col::F64("vy", v.iter().map(|x| x.1[1]).collect()),
                Col::F64("vz", v.iter().map(|x| x.1[2]).collect()),
            ]),
            prov,
        )?;
    }
    if !m.projectiles.is_empty() {
        let p = &m.projectiles;
        let c = |f: fn(&ProjectileSpec) -> f64| p.iter().map(f).collect::<Vec<_>>();
        write_table(
            &dir.join("projectile.parquet"),
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
                Col::Bool(
                    "segment_contact",
                    p.iter().map(|x| x.segment_contact).collect(),
                ),
            ]),
            prov,
        )?;
    }
    if !m.ties.is_empty() {
        let ti = &m.ties;
        let mid = |k: usize| {
            ti.iter()
                .map(|x| x.masters.get(k).map(|&i| m.node_id[i]))
                .collect::<Vec<_>>()
        };
        let opt = |name: &'static str, v: Vec<Option<i64>>| {
            (
                arrow_schema::Field::new(name, arrow_schema::DataType::Int64, true),
                Arc::new(arrow_array::Int64Array::from(v)) as arrow_array::ArrayRef,
            )
        };
        let b = batch(vec![
            Col::I64("slave", ti.iter().map(|x| m.node_id[x.slave]).collect()),
            Col::I64(
                "m1",
                mid(0).into_iter().map(|v| v.unwrap_or_default()).collect(),
            ),
            Col::I64(
                "m2",
                mid(1).into_iter().map(|v| v.unwrap_or_default()).collect(),
            ),
        ]);
        let mut fields: Vec<arrow_schema::Field> = b
            .schema()
            .fields()
            .iter()
            .map(|f| f.as_ref().clone())
            .collect();
        let mut arrays = b.columns().to_vec();
        for (f, a) in [opt("m3", mid(2)), opt("m4", mid(3))] {
            fields.push(f);
            arrays.push(a);
        }
        let b =
            arrow_array::RecordBatch::try_new(Arc::new(arrow_schema::Schema::new(fields)), arrays)
                .expect("equal lengths");
        write_table(&dir.join("ties.parquet"), &b, prov)?;
    }
    if !m.symmetry.is_empty() {
        let s = &m.symmetry;
        write_table(
            &dir.join("symmetry.parquet"),
            &batch(vec![
                Col::Str(
                    "normal",
                    s.iter()
                        .map(|x| ["x", "y", "z"][x.normal].to_string())
                        .collect(),
                ),
                Col::F64("position", s.iter().map(|x| x.position).collect()),
                Col::F64("tolerance", s.iter().map(|x| x.tolerance).collect()),
            ]),
            prov,
        )?;
    }
    super::contacts::write(m, dir, prov)?;
    let a = &m.analysis;
    write_table(
        &dir.join("analysis.parquet"),
        &batch(vec![
            Col::F64("end_time", vec![a.end_time]),
            Col::F64("output_interval", vec![a.output_interval]),
            Col::F64("dt_safety", vec![a.dt_safety]),
            Col::F64("mass_damping", vec![a.mass_damping]),
            Col::OptF64("time_step", vec![a.time_step]),
            Col::OptF64("target_time_step", vec![a.target_time_step]),
            Col::Str("history_sets", vec![a.history_sets.join(",")]),
            Col::F64("max_energy_error", vec![a.max_energy_error]),
        ]),
        prov,
    )?;
    Ok(())
}
