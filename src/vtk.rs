//! The `vtk` stage behind `weft-vtk`: a model folder and its `history.parquet` as a VTK
//! XML time series that ParaView opens (File → Open → `weft.pvd`).
//!
//! Layout of the output folder (written beside the target, then swapped into place):
//! - `weft.pvd`: the collection, one `DataSet` per output time (`timestep` = t in s),
//!   `part` 0 the mesh and `part` 1 the projectiles;
//! - `weft_NNNNNN.vtu`: the mesh at output sample N, an UnstructuredGrid;
//! - `weft_projectile_NNNNNN.vtu`: the projectiles' surfaces at that time (models with
//!   projectiles, from the `projectile.parquet` beside the history).
//!
//! The provenance (tool, version, stage, parameters, input hashes, as in the Parquet
//! tables) is a JSON comment `<!-- weft.provenance: … -->` at the top of `weft.pvd`.
//!
//! Cells, one per element: truss, link and beam → `VTK_LINE` (3), tri → `VTK_TRIANGLE`
//! (5), quad → `VTK_QUAD` (9), point mass → `VTK_VERTEX` (1), in the order of the
//! element tables (truss, link, point_mass, tri, quad, beam; each by row). Points: the
//! model's nodes in `nodes.parquet` order at their current positions X + u₀ + u(t) (or
//! the initial X + u₀ with `reference_points`, for ParaView's Warp By Vector).
//!
//! Point data: `displacement` and `velocity` (Float64 × 3, from the history),
//! `node_id` (Int64), and for models with membranes `thickness` (Float64: the nodal
//! thickness of the bands, the mean over the membrane elements at the node of their
//! thickness there, 0 at nodes without membranes). Cell data: `element_id`, `part_id`
//! (Int64), `kind` (Int32: 0 truss, 1 link, 2 point mass, 3 tri, 4 quad, 5 beam, 6 hex),
//! and the element results of `elements.parquet` when the run wrote them (`axial_force`,
//! `strain_11`, …, a hexahedron's `plastic_strain`, `temperature`, `pressure`,
//! `von_mises_stress`: NaN where a quantity does not apply to the element).
//!
//! Format: VTK XML, version 0.1, `binary` inline data (base64 of a UInt32 byte count
//! followed by the little-endian values), so values round-trip exactly. The writer is
//! the ~200 lines below rather than the `vtkio` crate: its last release is 0.6.3 (2021,
//! a 0.7 release candidate since 2024), it pulls nom, quick-xml and serde-xml for a
//! format this stage only writes, and it has no `.pvd` collections.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::error::{Result, WeftError};
use crate::model::io::read_model;
use crate::model::{ElementKind, Model, ProjectileShape, ProjectileSpec};
use crate::table::history::History;
use crate::table::{Provenance, Table};

/// Settings of one `vtk` run.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Config {
    /// Model folder.
    pub model: PathBuf,
    /// Its run's history.parquet (every node of an element must be in it).
    pub history: PathBuf,
    /// Output folder (replaced).
    pub out: PathBuf,
    /// Write every k-th output sample (1: all).
    pub every: usize,
    /// Points at the initial positions X + u₀ instead of the current ones.
    pub reference_points: bool,
}

/// What a run reports back to the binary.
#[derive(Debug, Clone)]
pub struct Report {
    /// Times written [s].
    pub times: Vec<f64>,
    /// Points and cells per .vtu.
    pub points: usize,
    pub cells: usize,
    /// Cells by VTK type: (type, count).
    pub cell_types: Vec<(u8, usize)>,
    /// Projectiles drawn (0: none, or no projectile.parquet beside the history).
    pub projectiles: usize,
    /// Element result columns carried as cell data.
    pub element_results: Vec<String>,
}

/// VTK cell type of an element kind.
pub fn vtk_cell_type(k: ElementKind) -> u8 {
    match k {
        ElementKind::Truss | ElementKind::Link | ElementKind::Beam => 3,
        ElementKind::PointMass => 1,
        ElementKind::Tri => 5,
        ElementKind::Quad => 9,
        // VTK_HEXAHEDRON: the same node order as LS-DYNA's (and weft's) hexahedron.
        ElementKind::Hex => 12,
    }
}

/// The `kind` cell code of an element kind (its position in [`ElementKind::ALL`]).
pub fn kind_code(k: ElementKind) -> i32 {
    ElementKind::ALL
        .iter()
        .position(|&x| x == k)
        .expect("every kind is listed") as i32
}

/// Base64 (RFC 4648, with padding) of `bytes`.
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// One `DataArray` of binary inline data.
enum Data<'a> {
    F64(&'a [f64]),
    I64(&'a [i64]),
    I32(&'a [i32]),
    U8(&'a [u8]),
}

fn data_array(xml: &mut String, name: &str, components: usize, d: Data) {
    let (ty, mut bytes): (&str, Vec<u8>) = match d {
        Data::F64(v) => ("Float64", v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        Data::I64(v) => ("Int64", v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        Data::I32(v) => ("Int32", v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        Data::U8(v) => ("UInt8", v.to_vec()),
    };
    // Header: the data's byte count as UInt32 (header_type="UInt32"), then the data, in
    // one base64 block.
    let mut block = (bytes.len() as u32).to_le_bytes().to_vec();
    block.append(&mut bytes);
    let _ = writeln!(
        xml,
        r#"        <DataArray type="{ty}" Name="{name}" NumberOfComponents="{components}" format="binary">"#
    );
    xml.push_str("          ");
    xml.push_str(&base64(&block));
    xml.push_str("\n        </DataArray>\n");
}

/// An unstructured grid in memory: points, cells, point and cell data.
struct Grid<'a> {
    points: &'a [f64],
    connectivity: &'a [i64],
    offsets: &'a [i64],
    types: &'a [u8],
    point_data: Vec<(&'a str, usize, Data<'a>)>,
    cell_data: Vec<(&'a str, usize, Data<'a>)>,
}

fn vtu(g: Grid) -> String {
    let mut xml = String::new();
    xml.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt32\">\n  <UnstructuredGrid>\n");
    let _ = writeln!(
        xml,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        g.points.len() / 3,
        g.types.len()
    );
    xml.push_str("      <Points>\n");
    data_array(&mut xml, "Points", 3, Data::F64(g.points));
    xml.push_str("      </Points>\n      <Cells>\n");
    data_array(&mut xml, "connectivity", 1, Data::I64(g.connectivity));
    data_array(&mut xml, "offsets", 1, Data::I64(g.offsets));
    data_array(&mut xml, "types", 1, Data::U8(g.types));
    xml.push_str("      </Cells>\n");
    for (tag, list) in [("PointData", g.point_data), ("CellData", g.cell_data)] {
        if list.is_empty() {
            continue;
        }
        let _ = writeln!(xml, "      <{tag}>");
        for (name, c, d) in list {
            data_array(&mut xml, name, c, d);
        }
        let _ = writeln!(xml, "      </{tag}>");
    }
    xml.push_str("    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    xml
}

/// The history by output time: (t, node id → [ux, uy, uz, vx, vy, vz]) per sample.
type Samples = Vec<(f64, HashMap<i64, [f64; 6]>)>;

fn read_history(path: &Path) -> Result<Samples> {
    let h = History::read(path)?;
    let mut out: Samples = vec![];
    h.by_time(|k, r| {
        if k == out.len() {
            out.push((h.t[r], HashMap::new()));
        }
        out[k].1.insert(h.node_id[r], h.row(r));
        Ok(())
    })?;
    Ok(out)
}

/// Projectile tips by (time, id) from a result `projectile.parquet`.
fn read_projectile_tips(path: &Path) -> Result<HashMap<(u64, i64), [f64; 3]>> {
    let p = Table::read(path)?;
    const COLS: &str = "t, projectile_id, x, y, z";
    let t = p.f64("t", COLS)?;
    let id = p.i64("projectile_id", COLS)?;
    let (x, y, z) = (p.f64("x", COLS)?, p.f64("y", COLS)?, p.f64("z", COLS)?);
    Ok((0..t.len())
        .map(|r| ((t[r].to_bits(), id[r]), [x[r], y[r], z[r]]))
        .collect())
}

/// Points around the axis at each profile station (s back from the tip, radius r) of a
/// projectile: a lathe surface, one apex point where r = 0, rings of `n` points
/// elsewhere, quads between rings and triangles to an apex.
pub fn projectile_surface(
    p: &ProjectileSpec,
    tip: [f64; 3],
    n: usize,
) -> (Vec<[f64; 3]>, Vec<Vec<usize>>) {
    let r = p.radius;
    let len = p.length.max(r);
    let arc = |from: f64, to: f64, k: usize| -> Vec<(f64, f64)> {
        // Stations on the nose sphere (centre R behind the tip) at polar angles from..to.
        (0..=k)
            .map(|i| {
                let th = from + (to - from) * i as f64 / k as f64;
                (r - r * th.cos(), r * th.sin())
            })
            .collect()
    };
    use std::f64::consts::{FRAC_PI_2, PI};
    let profile: Vec<(f64, f64)> = match p.shape {
        ProjectileShape::Sphere => arc(0.0, PI, 12),
        ProjectileShape::Round => {
            let mut v = arc(0.0, FRAC_PI_2, 6);
            v.push((len, r));
            v.push((len, 0.0));
            v
        }
        ProjectileShape::Flat => vec![(0.0, 0.0), (0.0, r), (len, r), (len, 0.0)],
        // A disc of the radius drawn in the plane (the wall has no edge).
        ProjectileShape::Wall => vec![(0.0, 0.0), (0.0, r)],
    };
    // An orthonormal frame (a, e1, e2), a pointing from the body to the tip.
    let norm = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [v[0] / l, v[1] / l, v[2] / l]
    };
    let a = norm(p.axis);
    let helper = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let cross = |u: [f64; 3], v: [f64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let e1 = norm(cross(a, helper));
    let e2 = cross(a, e1);
    let mut pts = vec![];
    let mut rings: Vec<Vec<usize>> = vec![];
    for &(s, rad) in &profile {
        let base: [f64; 3] = std::array::from_fn(|d| tip[d] - s * a[d]);
        if rad <= 1e-12 * r {
            rings.push(vec![pts.len()]);
            pts.push(base);
        } else {
            let ring: Vec<usize> = (0..n)
                .map(|k| {
                    let ph = 2.0 * PI * k as f64 / n as f64;
                    let (c, sn) = (ph.cos(), ph.sin());
                    pts.push(std::array::from_fn(|d| {
                        base[d] + rad * (c * e1[d] + sn * e2[d])
                    }));
                    pts.len() - 1
                })
                .collect();
            rings.push(ring);
        }
    }
    let mut cells = vec![];
    for w in rings.windows(2) {
        let (p, q) = (&w[0], &w[1]);
        for k in 0..n {
            let k1 = (k + 1) % n;
            match (p.len(), q.len()) {
                (1, 1) => {}
                (1, _) => cells.push(vec![p[0], q[k], q[k1]]),
                (_, 1) => cells.push(vec![p[k], q[0], p[k1]]),
                _ => cells.push(vec![p[k], q[k], q[k1], p[k1]]),
            }
        }
    }
    (pts, cells)
}

/// Nodal thickness of the membranes: the mean over the membrane elements at a node of
/// their thickness there; `None` when the model has no membranes.
fn nodal_thickness(m: &Model) -> Option<Vec<f64>> {
    let mut sum = vec![0.0; m.num_nodes()];
    let mut count = vec![0usize; m.num_nodes()];
    let mut any = false;
    for kind in [ElementKind::Tri, ElementKind::Quad] {
        let Some(b) = m.block(kind) else { continue };
        any = true;
        let npe = kind.nodes_per_element();
        for e in 0..b.len() {
            for k in 0..npe {
                let n = b.nodes[npe * e + k];
                sum[n] += if b.thickness.is_empty() {
                    m.parts[b.part[e]].props.thickness.unwrap_or(0.0)
                } else {
                    b.thickness[npe * e + k]
                };
                count[n] += 1;
            }
        }
    }
    any.then(|| {
        sum.iter()
            .zip(&count)
            .map(|(s, &c)| if c > 0 { s / c as f64 } else { 0.0 })
            .collect()
    })
}

/// Element results (`elements.parquet` beside the history): per output time, the
/// columns by element id.
struct ElementResults {
    columns: Vec<String>,
    /// (t bits, element id) → row.
    rows: HashMap<(u64, i64), usize>,
    values: Vec<Vec<f64>>,
}

fn read_element_results(path: &Path) -> Result<ElementResults> {
    let t = Table::read(path)?;
    const COLS: &str = "t, element_id, ...";
    let time = t.f64("t", COLS)?;
    let id = t.i64("element_id", COLS)?;
    let schema = t.batch.schema();
    let columns: Vec<String> = schema
        .fields()
        .iter()
        .map(|f| f.name().clone())
        .filter(|n| !matches!(n.as_str(), "t" | "element_id" | "kind" | "part_id"))
        .collect();
    let values = columns
        .iter()
        .map(|c| {
            Ok(t.f64_opt(c)?
                .expect("listed from the schema")
                .into_iter()
                .map(|v| v.unwrap_or(f64::NAN))
                .collect())
        })
        .collect::<Result<Vec<Vec<f64>>>>()?;
    let rows = (0..time.len())
        .map(|r| ((time[r].to_bits(), id[r]), r))
        .collect();
    Ok(ElementResults {
        columns,
        rows,
        values,
    })
}

/// Write the time series. Nothing appears under `c.out` unless every file was written.
pub fn run(c: &Config) -> Result<Report> {
    if c.every == 0 {
        return Err(WeftError::input("--every 0").expected("1 or more (1: every sample)"));
    }
    let m = read_model(&c.model)?;
    let samples = read_history(&c.history)?;
    let dir = c.history.parent().unwrap_or(Path::new("."));
    let proj_path = dir.join("projectile.parquet");
    let tips = if !m.projectiles.is_empty() && proj_path.exists() {
        Some(read_projectile_tips(&proj_path)?)
    } else {
        None
    };
    let er_path = dir.join("elements.parquet");
    let results = if er_path.exists() {
        Some(read_element_results(&er_path)?)
    } else {
        None
    };
    // Cells in element-table order.
    let (mut conn, mut offsets, mut types) = (vec![], vec![], vec![]);
    let (mut eid, mut pid, mut kinds) = (vec![], vec![], vec![]);
    for (&kind, b) in &m.elements {
        let npe = kind.nodes_per_element();
        for e in 0..b.len() {
            conn.extend(b.nodes[npe * e..npe * (e + 1)].iter().map(|&n| n as i64));
            offsets.push(conn.len() as i64);
            types.push(vtk_cell_type(kind));
            eid.push(b.id[e]);
            pid.push(m.parts[b.part[e]].id);
            kinds.push(kind_code(kind));
        }
    }
    // Every node of an element must have a value at every time.
    let n = m.num_nodes();
    let mut used = vec![false; n];
    for &i in &conn {
        used[i as usize] = true;
    }
    for (t, s) in &samples {
        if let Some(i) = (0..n).find(|&i| used[i] && !s.contains_key(&m.node_id[i])) {
            return Err(WeftError::input(format!(
                "node `{}` of the model's elements has no value at t = {t:e} s",
                m.node_id[i]
            ))
            .in_file(&c.history)
            .expected("every element node at every output time")
            .hint("write the whole mesh: weft-simulate --all-nodes (a run with --history-set holds only that set)"));
        }
    }
    let thickness = nodal_thickness(&m);
    let x0: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let u0 = m.initial_displacement.get(i).copied().unwrap_or([0.0; 3]);
            std::array::from_fn(|d| m.coords[i][d] + u0[d])
        })
        .collect();

    // Assemble beside the target, then swap into place.
    let parent = c
        .out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| WeftError::io(parent, e))?;
    let name = c
        .out
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "vtk".into());
    let tmp = parent.join(format!(".{name}.tmp-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(|e| WeftError::io(&tmp, e))?;
    let mut prov = Provenance::new("vtk", serde_json::to_value(c).expect("config serialises"))
        .with_input(&c.history)?;
    for p in [&proj_path, &er_path] {
        if p.exists() {
            prov = prov.with_input(p)?;
        }
    }
    for entry in std::fs::read_dir(&c.model).map_err(|e| WeftError::io(&c.model, e))? {
        let p = entry.map_err(|e| WeftError::io(&c.model, e))?.path();
        if p.extension().is_some_and(|x| x == "parquet") {
            prov = prov.with_input(&p)?;
        }
    }
    // JSON has "--" only inside strings, where "-\u002d" means the same.
    let prov = serde_json::to_string(&prov)
        .expect("provenance serialises")
        .replace("--", "-\\u002d");
    let written = write_series(
        c,
        &m,
        &samples,
        &tmp,
        &prov,
        &Series {
            conn: &conn,
            offsets: &offsets,
            types: &types,
            eid: &eid,
            pid: &pid,
            kinds: &kinds,
            thickness: thickness.as_deref(),
            x0: &x0,
            tips: tips.as_ref(),
            results: results.as_ref(),
        },
    );
    let times = match written {
        Ok(t) => t,
        Err(e) => {
            let _ = std::fs::remove_dir_all(&tmp);
            return Err(e);
        }
    };
    let old = parent.join(format!(".{name}.old-{}", std::process::id()));
    if c.out.exists() {
        std::fs::rename(&c.out, &old).map_err(|e| WeftError::io(&c.out, e))?;
    }
    std::fs::rename(&tmp, &c.out).map_err(|e| WeftError::io(&c.out, e))?;
    let _ = std::fs::remove_dir_all(&old);
    let mut cell_types: Vec<(u8, usize)> = vec![];
    for &t in &types {
        match cell_types.iter_mut().find(|x| x.0 == t) {
            Some(x) => x.1 += 1,
            None => cell_types.push((t, 1)),
        }
    }
    Ok(Report {
        times,
        points: n,
        cells: types.len(),
        cell_types,
        projectiles: if tips.is_some() {
            m.projectiles.len()
        } else {
            0
        },
        element_results: results.map(|r| r.columns).unwrap_or_default(),
    })
}

/// The fixed parts of every .vtu.
struct Series<'a> {
    conn: &'a [i64],
    offsets: &'a [i64],
    types: &'a [u8],
    eid: &'a [i64],
    pid: &'a [i64],
    kinds: &'a [i32],
    thickness: Option<&'a [f64]>,
    x0: &'a [[f64; 3]],
    tips: Option<&'a HashMap<(u64, i64), [f64; 3]>>,
    results: Option<&'a ElementResults>,
}

fn write_file(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(|e| WeftError::io(path, e))
}

fn write_series(
    c: &Config,
    m: &Model,
    samples: &Samples,
    dir: &Path,
    prov: &str,
    s: &Series,
) -> Result<Vec<f64>> {
    let n = m.num_nodes();
    let mut pvd = format!(
        "<?xml version=\"1.0\"?>\n<!-- weft.provenance: {prov} -->\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n"
    );
    let mut times = vec![];
    for (k, (t, vals)) in samples.iter().enumerate().step_by(c.every) {
        let mut disp = vec![0.0; 3 * n];
        let mut vel = vec![0.0; 3 * n];
        let mut pts = vec![0.0; 3 * n];
        for i in 0..n {
            let v = vals.get(&m.node_id[i]).copied().unwrap_or([0.0; 6]);
            for d in 0..3 {
                disp[3 * i + d] = v[d];
                vel[3 * i + d] = v[3 + d];
                pts[3 * i + d] = s.x0[i][d] + if c.reference_points { 0.0 } else { v[d] };
            }
        }
        let mut point_data = vec![
            ("displacement", 3, Data::F64(&disp)),
            ("velocity", 3, Data::F64(&vel)),
            ("node_id", 1, Data::I64(&m.node_id)),
        ];
        if let Some(th) = s.thickness {
            point_data.push(("thickness", 1, Data::F64(th)));
        }
        let mut cell_data = vec![
            ("element_id", 1, Data::I64(s.eid)),
            ("part_id", 1, Data::I64(s.pid)),
            ("kind", 1, Data::I32(s.kinds)),
        ];
        let er: Vec<Vec<f64>> = match s.results {
            Some(r) => r
                .values
                .iter()
                .map(|col| {
                    s.eid
                        .iter()
                        .map(|&e| {
                            r.rows
                                .get(&(t.to_bits(), e))
                                .map_or(f64::NAN, |&row| col[row])
                        })
                        .collect()
                })
                .collect(),
            None => vec![],
        };
        if let Some(r) = s.results {
            for (name, col) in r.columns.iter().zip(&er) {
                cell_data.push((name.as_str(), 1, Data::F64(col)));
            }
        }
        let file = format!("weft_{k:06}.vtu");
        write_file(
            &dir.join(&file),
            &vtu(Grid {
                points: &pts,
                connectivity: s.conn,
                offsets: s.offsets,
                types: s.types,
                point_data,
                cell_data,
            }),
        )?;
        let _ = writeln!(
            pvd,
            "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{file}\"/>"
        );
        if let Some(tips) = s.tips {
            let (mut ppts, mut conn, mut offs, mut types, mut ids) =
                (vec![], vec![], vec![], vec![], vec![]);
            for p in &m.projectiles {
                let tip = tips.get(&(t.to_bits(), p.id)).ok_or_else(|| {
                    WeftError::input(format!(
                        "projectile `{}` has no position at t = {t:e} s",
                        p.id
                    ))
                    .in_file(c.history.with_file_name("projectile.parquet"))
                    .expected("one row per output time and projectile, as weft-simulate writes it")
                })?;
                let (pp, cells) = projectile_surface(p, *tip, 24);
                let base = ppts.len() / 3;
                ppts.extend(pp.iter().flatten());
                for cell in cells {
                    types.push(if cell.len() == 3 { 5u8 } else { 9 });
                    conn.extend(cell.iter().map(|&q| (q + base) as i64));
                    offs.push(conn.len() as i64);
                    ids.push(p.id);
                }
            }
            let file = format!("weft_projectile_{k:06}.vtu");
            write_file(
                &dir.join(&file),
                &vtu(Grid {
                    points: &ppts,
                    connectivity: &conn,
                    offsets: &offs,
                    types: &types,
                    point_data: vec![],
                    cell_data: vec![("projectile_id", 1, Data::I64(&ids))],
                }),
            )?;
            let _ = writeln!(
                pvd,
                "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"1\" file=\"{file}\"/>"
            );
        }
        times.push(*t);
    }
    pvd.push_str("  </Collection>\n</VTKFile>\n");
    write_file(&dir.join("weft.pvd"), &pvd)?;
    Ok(times)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// RFC 4648 §10 test vectors.
    #[test]
    fn base64_matches_rfc_4648() {
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(i.as_bytes()), o, "{i}");
        }
    }
}
