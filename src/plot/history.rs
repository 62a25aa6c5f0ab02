//! `weft-plot history`: the time laws of chosen nodes of several models, the first
//! model's nodes (by id or set) found in the others by position, or read through their
//! elements' shape functions (`--interpolate`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::chart::{label, readable, Chart, Series, Style};
use crate::analysis::interp::interpolation;
use crate::analysis::{components, read_nodes};
use crate::error::{Result, WeftError};
use crate::model::io::read_model;
use crate::model::Model;

/// Time laws of chosen nodes of several models.
#[derive(Debug, Clone)]
pub struct HistoryFigure {
    /// Model folders, one per model.
    pub model: Vec<PathBuf>,
    /// Their history.parquet, in the same order.
    pub history: Vec<PathBuf>,
    /// Legend name of each model (missing ones: the folder name).
    pub label: Vec<String>,
    /// Node ids, comma-separated (matched by position in the other models).
    pub nodes: Option<String>,
    /// A node set of the first model (at most 8 nodes), when `nodes` is `None`.
    pub set: Option<String>,
    /// Component: ux, uy, uz, vx, vy, vz.
    pub component: String,
    /// Position matching tolerance across models [m].
    pub tolerance: f64,
    /// The other models read at the chosen positions through their elements' shape
    /// functions (a coarser mesh, a membrane beyond a tied interface) instead of a node
    /// within `tolerance` (which then bounds the distance to an element).
    pub interpolate: bool,
}

/// One model's lines: its legend name and, per chosen node, that node's line.
struct ModelLines {
    label: String,
    lines: Vec<NodeLine>,
}

/// A chosen node's time law: its name in the legend, (t, value) points (SI).
struct NodeLine {
    node: String,
    points: Vec<(f64, f64)>,
}

/// The time laws of the chosen nodes in every model, one line style per model.
pub(super) fn history(a: &HistoryFigure) -> Result<Chart> {
    if a.model.len() != a.history.len() {
        return Err(WeftError::input(format!(
            "{} --model and {} --history given; expected one history per model, in the same order",
            a.model.len(),
            a.history.len()
        )));
    }
    let c = one_component(&a.component)?;
    // The first model fixes the nodes (by id or set); the others are matched by position.
    let first = read_model(&a.model[0])?;
    let ids = chosen_ids(a, &first)?;
    let positions = positions_of(a, &first, &ids)?;
    let mut raw: Vec<ModelLines> = vec![];
    for (k, (m, h)) in a.model.iter().zip(&a.history).enumerate() {
        let model = read_model(m)?;
        let lines = if k > 0 && a.interpolate {
            interpolated_lines(a, (m, &model), h, &ids, &positions, c)?
        } else {
            nearest_lines(a, (m, &model), h, &ids, &positions, c)?
        };
        raw.push(ModelLines {
            label: label(&a.label, k, m),
            lines,
        });
    }
    Ok(time_law_chart(raw, c, &a.component))
}

/// The one component `--component` names.
fn one_component(name: &str) -> Result<usize> {
    let comp = components(name)?;
    if comp.len() != 1 {
        return Err(WeftError::input(format!(
            "--component takes one component, got `{name}`"
        )));
    }
    Ok(comp[0])
}

/// The chosen node ids of the first model: `--nodes`, or the nodes of `--set` (at most 8).
fn chosen_ids(a: &HistoryFigure, first: &Model) -> Result<Vec<i64>> {
    match (&a.nodes, &a.set) {
        (Some(list), _) => list
            .split(',')
            .map(|s| {
                s.trim().parse::<i64>().map_err(|e| {
                    WeftError::input(format!(
                        "--nodes: `{s}` is not a node id (expected comma-separated integers): {e}"
                    ))
                })
            })
            .collect::<Result<_>>(),
        (None, Some(set)) => {
            let nodes = first.node_sets.get(set).ok_or_else(|| {
                WeftError::input(format!(
                    "model `{}` has no node set `{set}` (expected one of {})",
                    a.model[0].display(),
                    first
                        .node_sets
                        .keys()
                        .cloned()
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
            if nodes.len() > 8 {
                return Err(WeftError::input(format!(
                    "node set `{set}` has {} nodes; a time-law figure takes at most 8 (hint: --nodes ID,ID,...)",
                    nodes.len()
                )));
            }
            Ok(nodes.iter().map(|&i| first.node_id[i]).collect())
        }
        (None, None) => Err(WeftError::input("give --nodes ID,ID,... or --set NAME")),
    }
}

/// The positions of the chosen nodes in the first model.
fn positions_of(a: &HistoryFigure, first: &Model, ids: &[i64]) -> Result<Vec<[f64; 3]>> {
    let index: HashMap<i64, usize> = first
        .node_id
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, i))
        .collect();
    let mut positions = vec![];
    for id in ids {
        let i = index.get(id).ok_or_else(|| {
            WeftError::input(format!(
                "--nodes: model `{}` has no node `{id}`",
                a.model[0].display()
            ))
        })?;
        positions.push(first.coords[*i]);
    }
    Ok(positions)
}

/// Each chosen position read through the element of this model that holds it.
fn interpolated_lines(
    a: &HistoryFigure,
    (m, model): (&Path, &Model),
    h: &Path,
    ids: &[i64],
    positions: &[[f64; 3]],
    c: usize,
) -> Result<Vec<NodeLine>> {
    let (read, pairs) = interpolation(model, None, positions, ids, a.tolerance)
        .map_err(|e| e.context(format!("model `{}`", m.display())))?;
    // `pairs` index the nodes read, in the order read.
    let s = read_nodes(model, h, &read, "interpolated for the figure")?;
    Ok(ids
        .iter()
        .zip(&pairs)
        .map(|(id, w)| NodeLine {
            node: format!("node {id}"),
            points: s
                .t
                .iter()
                .zip(&s.values)
                .map(|(t, v)| (*t, w.iter().map(|&(j, wj)| wj * v[j][c]).sum()))
                .collect::<Vec<_>>(),
        })
        .collect())
}

/// A one-off node set of the nodes nearest the chosen positions (each within the
/// tolerance), read from this model's history.
fn nearest_lines(
    a: &HistoryFigure,
    (m, model): (&Path, &Model),
    h: &Path,
    ids: &[i64],
    positions: &[[f64; 3]],
    c: usize,
) -> Result<Vec<NodeLine>> {
    let mut chosen = vec![];
    for (id, p) in ids.iter().zip(positions) {
        let (i, d) = model
            .coords
            .iter()
            .enumerate()
            .map(|(i, x)| {
                (
                    i,
                    ((x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2) + (x[2] - p[2]).powi(2)).sqrt(),
                )
            })
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .ok_or_else(|| WeftError::input("empty model"))?;
        if d > a.tolerance {
            return Err(WeftError::input(format!(
                "model `{}` has no node at the position of node {id} {:?} (nearest {:.3e} m away; hint: raise --tolerance)",
                m.display(),
                p,
                d
            )));
        }
        chosen.push(i);
    }
    let s = read_nodes(model, h, &chosen, "chosen for the figure")?;
    Ok(ids
        .iter()
        .enumerate()
        .map(|(j, id)| NodeLine {
            node: format!("node {id}"),
            points: s
                .t
                .iter()
                .zip(&s.values)
                .map(|(t, v)| (*t, v[j][c]))
                .collect::<Vec<_>>(),
        })
        .collect())
}

/// The chart of every model's lines, time and values in readable units; the models
/// told apart by line style, the nodes by colour.
fn time_law_chart(raw: Vec<ModelLines>, c: usize, component: &str) -> Chart {
    let tmax = raw
        .iter()
        .flat_map(|r| {
            r.lines
                .iter()
                .flat_map(|l| l.points.iter().map(|p| p.0.abs()))
        })
        .fold(0.0, f64::max);
    let ymax = raw
        .iter()
        .flat_map(|r| {
            r.lines
                .iter()
                .flat_map(|l| l.points.iter().map(|p| p.1.abs()))
        })
        .fold(0.0, f64::max);
    let (ft, ut) = readable(tmax, "s");
    let (fy, uy) = readable(ymax, if c < 3 { "m" } else { "m/s" });
    let styles = [Style::Line, Style::Dashed, Style::LinePoints, Style::Points];
    let mut series = vec![];
    for (k, ModelLines { label: name, lines }) in raw.into_iter().enumerate() {
        for (j, NodeLine { node, points: pts }) in lines.into_iter().enumerate() {
            series.push(Series {
                label: format!("{name}, {node}"),
                points: pts.into_iter().map(|(t, y)| (t * ft, y * fy)).collect(),
                style: styles[k % styles.len()],
                color: j,
            });
        }
    }
    Chart {
        title: None,
        x_label: format!("t [{ut}]"),
        y_label: format!("{component} [{uy}]"),
        log_y: false,
        series,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::grid::rectangle;
    use crate::model::io::write_model;
    use crate::model::{ElementKind, Model, PartProps};
    use crate::table::{batch, write_table, Col, Provenance};

    /// A square [0, 1]² of `n` × `n` quads, node ids from 1, and its history.parquet with
    /// u_x(t, x, y) = t·(x + 2y) at t = 0, 1, 2 (the other components 0).
    fn square(dir: &Path, n: usize) -> (PathBuf, PathBuf) {
        let mut m = Model::default();
        let (nodes, elems) = rectangle(n, n, 1.0, 1.0, ElementKind::Quad);
        for (i, x) in nodes.iter().enumerate() {
            m.add_node(i as i64 + 1, *x);
        }
        let part = m.add_part(
            1,
            "sheet",
            ElementKind::Quad,
            PartProps {
                youngs_modulus_1: Some(1e9),
                youngs_modulus_2: Some(1e9),
                poisson_ratio_12: Some(0.3),
                shear_modulus_12: Some(4e8),
                thickness: Some(1e-3),
                density: Some(1e3),
                ..Default::default()
            },
        );
        for (e, ns) in elems.iter().enumerate() {
            m.add_element(e as i64 + 1, part, ns);
        }
        let prov = Provenance::new("test", serde_json::json!({}));
        let folder = dir.join(format!("m{n}"));
        write_model(&m, &folder, &prov).unwrap();
        let (mut t, mut id, mut ux) = (vec![], vec![], vec![]);
        for k in 0..3 {
            for (i, x) in nodes.iter().enumerate() {
                t.push(k as f64);
                id.push(i as i64 + 1);
                ux.push(k as f64 * (x[0] + 2.0 * x[1]));
            }
        }
        let zero = vec![0.0; t.len()];
        let h = dir.join(format!("h{n}.parquet"));
        let b = batch(vec![
            Col::F64("t", t),
            Col::I64("node_id", id),
            Col::F64("ux", ux),
            Col::F64("uy", zero.clone()),
            Col::F64("uz", zero.clone()),
            Col::F64("vx", zero.clone()),
            Col::F64("vy", zero.clone()),
            Col::F64("vz", zero),
        ]);
        write_table(&h, &b, &prov).unwrap();
        (folder, h)
    }

    /// `--interpolate` reads a coarser mesh at the fine nodes through its bilinear shape
    /// functions, which reproduce a field linear in x and y exactly (the patch test of
    /// the bilinear quad, e.g. Zienkiewicz & Taylor, *The Finite Element Method*, vol. 1,
    /// §9.4): the coarse model's lines equal the fine model's at nodes the coarse mesh
    /// does not have, to round-off. Without it, those positions have no coarse node.
    #[test]
    fn interpolated_lines_reproduce_a_linear_field() {
        let dir = tempfile::tempdir().unwrap();
        let (fine, hf) = square(dir.path(), 4);
        let (coarse, hc) = square(dir.path(), 2);
        // Fine nodes 2 (0.25, 0), 7 (0.25, 0.25) and 13 (0.5, 0.5): only the last is a
        // coarse node; given in this order so that the coarse nodes read are not in
        // the order of the chosen positions (the pairing indexes the nodes read).
        let mut fig = HistoryFigure {
            model: vec![fine, coarse],
            history: vec![hf, hc],
            label: vec!["fine".into(), "coarse".into()],
            nodes: Some("13,7,2".into()),
            set: None,
            component: "ux".into(),
            tolerance: 1e-9,
            interpolate: true,
        };
        let chart = history(&fig).unwrap();
        assert_eq!(chart.series.len(), 6);
        for j in 0..3 {
            let (f, c) = (&chart.series[j], &chart.series[3 + j]);
            assert_eq!(f.label.split(", ").nth(1), c.label.split(", ").nth(1));
            assert_eq!(f.points.len(), 3);
            for (p, q) in f.points.iter().zip(&c.points) {
                assert_eq!(p.0, q.0);
                // Measured: 0 (the weights are exact binary fractions here).
                assert!(
                    (p.1 - q.1).abs() <= 1e-12 * p.1.abs().max(1.0),
                    "{p:?} vs {q:?}"
                );
            }
        }
        // The fine lines themselves: t·(x + 2y) at t = 2 for node 7 (0.25, 0.25): 1.5,
        // scaled by the same unit factor as the others (max |u| = 3 m: factor 1).
        assert!((chart.series[1].points[2].1 - 1.5).abs() < 1e-12);
        fig.interpolate = false;
        let e = match history(&fig) {
            Ok(_) => panic!("positions without a coarse node were read"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains("no node at the position of node 7"), "{e}");
    }
}
