//! Output: what receives a run's samples on the fixed output grid ([`Sink`]), the
//! `Sampler` that interpolates the steps onto that grid, and the sinks: in memory (tests,
//! the fit stage) and streaming Parquet (the `simulate` stage). Layouts of
//! `history.parquet` and `energy.parquet`: docs/tables.md.
//!
//! Solver state that the nodal history cannot give (a hexahedron's stress, plastic strain
//! and temperature depend on the path) goes out the same way: the elements chosen with
//! [`crate::solver::Solver::sample_states_of`] (none unless element results of hex parts
//! were asked for: then nothing is collected) are read at the sample steps into the
//! snapshot ([`crate::solver::family::Family::sample_states`]) and interpolated onto the
//! grid like the nodes ([`Sink::element_states`]).

use std::path::Path;
use std::sync::Arc;

use arrow_array::{Float64Array, Int64Array, RecordBatch};
use arrow_schema::{DataType, Field, Schema, SchemaRef};

use super::crater::CraterRow;
use super::energy::Energies;
pub use super::family::StateValues;
use super::watch::LayerValues;
use crate::error::Result;
use crate::table::{batch, AtomicTableWriter, Col, Provenance};

/// Receives the output samples on the output time grid.
pub trait Sink {
    /// Displacements and velocities of the output nodes at time t.
    fn history(&mut self, t: f64, nodes: &[usize], u: &[[f64; 3]], v: &[[f64; 3]]) -> Result<()>;
    fn energy(&mut self, t: f64, e: &Energies) -> Result<()>;
    /// A projectile at time t: tip position, velocity, contact force on it.
    fn projectile(&mut self, _t: f64, _id: i64, _state: &[f64; 9]) -> Result<()> {
        Ok(())
    }
    /// The layers of a fabric at time t, layer 1 first (see [`super::watch`]).
    fn layers(&mut self, _t: f64, _rows: &[LayerValues]) -> Result<()> {
        Ok(())
    }
    /// The states of the sampled elements at time t, in the order they were chosen in
    /// (only when some were): one [`StateValues`] each (a hexahedron's σ, ε_p and T; an
    /// eroded element's σ is 0, its ε_p and T those it eroded with).
    fn element_states(&mut self, _t: f64, _rows: &[StateValues]) -> Result<()> {
        Ok(())
    }
    /// The backing clay's crater at time t, one row per point of `clay_profile` (only
    /// for a model with clay; see [`super::crater`]).
    fn crater(&mut self, _t: f64, _rows: &[CraterRow]) -> Result<()> {
        Ok(())
    }
}

/// One snapshot of the output nodes at a step.
#[derive(Debug, Clone, Default)]
pub(super) struct Snapshot {
    pub(super) t: f64,
    pub(super) u: Vec<[f64; 3]>,
    pub(super) v: Vec<[f64; 3]>,
    pub(super) e: Energies,
    /// Per projectile: tip x, y, z, velocity, contact force.
    pub(super) proj: Vec<[f64; 9]>,
    /// Per layer of a fabric (layer 1 first), its values (see [`super::watch`]).
    pub(super) layers: Vec<LayerValues>,
    /// The sampled elements' states (see [`StateValues`]).
    pub(super) states: Vec<StateValues>,
    /// The backing clay's crater (see [`CraterRow`]).
    pub(super) crater: Vec<CraterRow>,
}

/// Linear interpolation of the step snapshots onto the fixed output grid t_k = k·Δt_out.
pub(super) struct Sampler {
    prev: Snapshot,
    pub(super) cur: Snapshot,
    have_prev: bool,
    interp_u: Vec<[f64; 3]>,
    interp_v: Vec<[f64; 3]>,
    interp_layers: Vec<LayerValues>,
    interp_states: Vec<StateValues>,
    interp_crater: Vec<CraterRow>,
}

impl Sampler {
    pub(super) fn new(nout: usize) -> Sampler {
        let prev = Snapshot {
            u: vec![[0.0; 3]; nout],
            v: vec![[0.0; 3]; nout],
            ..Default::default()
        };
        Sampler {
            cur: prev.clone(),
            prev,
            have_prev: false,
            interp_u: vec![[0.0; 3]; nout],
            interp_v: vec![[0.0; 3]; nout],
            interp_layers: vec![],
            interp_states: vec![],
            interp_crater: vec![],
        }
    }

    /// Sends every output time t_k ≤ `cur.t` not sent yet (k from `*k`), interpolated
    /// between the previous and the current snapshot; then the current becomes previous.
    pub(super) fn emit(
        &mut self,
        k: &mut u64,
        n_out: u64,
        dt_out: f64,
        ids: &[i64],
        nodes: &[usize],
        sink: &mut (dyn Sink + Send),
        mut progress: impl FnMut(u64, f64),
    ) -> Result<()> {
        let (prev, cur) = (&self.prev, &self.cur);
        while *k <= n_out && *k as f64 * dt_out <= cur.t {
            let tk = *k as f64 * dt_out;
            let w = if self.have_prev && prev.t < tk {
                (tk - prev.t) / (cur.t - prev.t)
            } else {
                1.0
            };
            for (j, id) in ids.iter().enumerate() {
                let row: [f64; 9] = if w >= 1.0 {
                    cur.proj[j]
                } else {
                    std::array::from_fn(|c| {
                        prev.proj[j][c] + w * (cur.proj[j][c] - prev.proj[j][c])
                    })
                };
                sink.projectile(tk, *id, &row)?;
            }
            let (src_u, src_v, e) = if w >= 1.0 {
                (&cur.u, &cur.v, cur.e)
            } else {
                for j in 0..cur.u.len() {
                    for d in 0..3 {
                        self.interp_u[j][d] = prev.u[j][d] + w * (cur.u[j][d] - prev.u[j][d]);
                        self.interp_v[j][d] = prev.v[j][d] + w * (cur.v[j][d] - prev.v[j][d]);
                    }
                }
                (&self.interp_u, &self.interp_v, prev.e.lerp(&cur.e, w))
            };
            sink.history(tk, nodes, src_u, src_v)?;
            sink.energy(tk, &e)?;
            if !cur.layers.is_empty() {
                // Energies and deflections interpolated; counts as of the earlier step.
                let rows = if w >= 1.0 || prev.layers.len() != cur.layers.len() {
                    &cur.layers
                } else {
                    self.interp_layers.clear();
                    for (a, b) in prev.layers.iter().zip(&cur.layers) {
                        let mut r: LayerValues = std::array::from_fn(|c| a[c] + w * (b[c] - a[c]));
                        // Counts and the first failure's time as of the earlier step.
                        r[5] = a[5];
                        r[6] = a[6];
                        r[8] = a[8];
                        // Perforated by t_k when the later step says so at or before it.
                        r[9] = if b[9] <= tk { b[9] } else { a[9] };
                        self.interp_layers.push(r);
                    }
                    &self.interp_layers
                };
                sink.layers(tk, rows)?;
            }
            if !cur.states.is_empty() {
                let rows = lerp_rows(&prev.states, &cur.states, w, &mut self.interp_states);
                sink.element_states(tk, rows)?;
            }
            if !cur.crater.is_empty() {
                let rows = lerp_rows(&prev.crater, &cur.crater, w, &mut self.interp_crater);
                sink.crater(tk, rows)?;
            }
            progress(*k, tk);
            *k += 1;
        }
        std::mem::swap(&mut self.prev, &mut self.cur);
        self.have_prev = true;
        Ok(())
    }
}

/// Rows of values interpolated between two snapshots at weight `w` (into `out`), or
/// the current ones where `w` ≥ 1 or the rows differ in number.
fn lerp_rows<'a, const N: usize>(
    prev: &[[f64; N]],
    cur: &'a [[f64; N]],
    w: f64,
    out: &'a mut Vec<[f64; N]>,
) -> &'a [[f64; N]] {
    if w >= 1.0 || prev.len() != cur.len() {
        return cur;
    }
    out.clear();
    out.extend(
        prev.iter()
            .zip(cur)
            .map(|(a, b)| std::array::from_fn(|c| a[c] + w * (b[c] - a[c]))),
    );
    out
}

/// Everything in memory: `u[k][j]` is the displacement of output node j at sample k.
#[derive(Debug, Clone, Default)]
pub struct MemorySink {
    pub t: Vec<f64>,
    pub nodes: Vec<usize>,
    pub u: Vec<Vec<[f64; 3]>>,
    pub v: Vec<Vec<[f64; 3]>>,
    pub energy_t: Vec<f64>,
    pub energy: Vec<Energies>,
    /// (t, projectile id, [tip x y z, v x y z, force x y z]).
    pub projectile: Vec<(f64, i64, [f64; 9])>,
    /// (t, per layer its values, layer 1 first).
    pub layers: Vec<(f64, Vec<LayerValues>)>,
    /// (t, the crater's points: r0, r, depth), for a model with clay.
    pub crater: Vec<(f64, Vec<CraterRow>)>,
}

impl Sink for MemorySink {
    fn projectile(&mut self, t: f64, id: i64, s: &[f64; 9]) -> Result<()> {
        self.projectile.push((t, id, *s));
        Ok(())
    }
    fn layers(&mut self, t: f64, rows: &[LayerValues]) -> Result<()> {
        self.layers.push((t, rows.to_vec()));
        Ok(())
    }
    fn crater(&mut self, t: f64, rows: &[CraterRow]) -> Result<()> {
        self.crater.push((t, rows.to_vec()));
        Ok(())
    }
    fn history(&mut self, t: f64, nodes: &[usize], u: &[[f64; 3]], v: &[[f64; 3]]) -> Result<()> {
        if self.nodes.is_empty() {
            self.nodes = nodes.to_vec();
        }
        self.t.push(t);
        self.u.push(u.to_vec());
        self.v.push(v.to_vec());
        Ok(())
    }
    fn energy(&mut self, t: f64, e: &Energies) -> Result<()> {
        self.energy_t.push(t);
        self.energy.push(*e);
        Ok(())
    }
}

impl MemorySink {
    /// Time series of one component (0..3 = ux, uy, uz) of output node `j`.
    pub fn series(&self, j: usize, comp: usize) -> Vec<f64> {
        self.u.iter().map(|s| s[j][comp]).collect()
    }
    pub fn velocity_series(&self, j: usize, comp: usize) -> Vec<f64> {
        self.v.iter().map(|s| s[j][comp]).collect()
    }
}

pub fn history_schema() -> SchemaRef {
    Arc::new(Schema::new(
        ["t", "node_id", "ux", "uy", "uz", "vx", "vy", "vz"]
            .iter()
            .map(|n| {
                Field::new(
                    *n,
                    if *n == "node_id" {
                        DataType::Int64
                    } else {
                        DataType::Float64
                    },
                    false,
                )
            })
            .collect::<Vec<_>>(),
    ))
}

const FLUSH_ROWS: usize = 1 << 18;

/// Streams `history.parquet`, and keeps the energies, the projectiles and the layers as
/// the [`MemorySink`] does (`rest`, its history unused) for `energy.parquet`,
/// `projectile.parquet` and `ballistic.parquet`; nothing appears under the final names
/// until [`ParquetSink::finish`].
pub struct ParquetSink {
    node_id: Vec<i64>,
    hist: AtomicTableWriter,
    cols: [Vec<f64>; 7],
    ids: Vec<i64>,
    rest: MemorySink,
    crater: Option<Crater>,
}

/// The backing clay's crater (`bfs.parquet`): its points along a radius from the shot's
/// axis (see [`super::crater`]) at every output time.
#[derive(Debug, Clone, Default)]
pub struct Crater {
    t: Vec<f64>,
    r0: Vec<f64>,
    r: Vec<f64>,
    depth: Vec<f64>,
}

impl Crater {
    fn sample(&mut self, t: f64, rows: &[CraterRow]) {
        for &[r0, r, depth] in rows {
            self.t.push(t);
            self.r0.push(r0);
            self.r.push(r);
            self.depth.push(depth);
        }
    }

    /// `bfs.parquet`'s columns: one row per output time and point.
    fn table(&self) -> RecordBatch {
        batch(vec![
            Col::F64("t", self.t.clone()),
            Col::F64("r0", self.r0.clone()),
            Col::F64("r", self.r.clone()),
            Col::F64("depth", self.depth.clone()),
        ])
    }
}

impl ParquetSink {
    pub fn create(out: &Path, node_id: Vec<i64>, prov: &Provenance) -> Result<Self> {
        Ok(ParquetSink {
            node_id,
            hist: AtomicTableWriter::create(&out.join("history.parquet"), history_schema(), prov)?,
            cols: Default::default(),
            ids: Vec::new(),
            rest: MemorySink::default(),
            crater: None,
        })
    }

    /// Also writes `bfs.parquet`, the crater the solver samples ([`Sink::crater`]).
    pub fn with_crater(mut self) -> Self {
        self.crater = Some(Crater::default());
        self
    }

    /// `ballistic.parquet`: one row per output time and layer (see [`super::watch`]).
    fn ballistic_table(&self) -> Option<arrow_array::RecordBatch> {
        if self.rest.layers.is_empty() {
            return None;
        }
        let rows: Vec<(f64, usize, &LayerValues)> = self
            .rest
            .layers
            .iter()
            .flat_map(|(t, ls)| ls.iter().enumerate().map(move |(l, r)| (*t, l + 1, r)))
            .collect();
        let f = |c: usize| rows.iter().map(|r| r.2[c]).collect::<Vec<_>>();
        let i = |c: usize| rows.iter().map(|r| r.2[c] as i64).collect::<Vec<_>>();
        Some(batch(vec![
            Col::F64("t", rows.iter().map(|r| r.0).collect()),
            Col::I64("layer", rows.iter().map(|r| r.1 as i64).collect()),
            Col::F64("kinetic", f(0)),
            Col::F64("strain", f(1)),
            Col::F64("eroded", f(2)),
            Col::F64("friction", f(3)),
            Col::F64("absorbed", f(4)),
            Col::I64("failed_elements", i(5)),
            Col::I64("broken_yarns", i(6)),
            Col::F64("deflection", f(7)),
            Col::OptF64(
                "first_failure_time",
                rows.iter()
                    .map(|r| Some(r.2[8]).filter(|t| !t.is_nan()))
                    .collect(),
            ),
            Col::Bool(
                "perforated",
                rows.iter().map(|r| !r.2[9].is_nan()).collect(),
            ),
            Col::OptF64(
                "perforated_time",
                rows.iter()
                    .map(|r| Some(r.2[9]).filter(|t| !t.is_nan()))
                    .collect(),
            ),
        ]))
    }

    fn flush(&mut self) -> Result<()> {
        if self.ids.is_empty() {
            return Ok(());
        }
        let c = std::mem::take(&mut self.cols);
        let [t, ux, uy, uz, vx, vy, vz] = c;
        let b = RecordBatch::try_new(
            history_schema(),
            vec![
                Arc::new(Float64Array::from(t)),
                Arc::new(Int64Array::from(std::mem::take(&mut self.ids))),
                Arc::new(Float64Array::from(ux)),
                Arc::new(Float64Array::from(uy)),
                Arc::new(Float64Array::from(uz)),
                Arc::new(Float64Array::from(vx)),
                Arc::new(Float64Array::from(vy)),
                Arc::new(Float64Array::from(vz)),
            ],
        )
        .expect("history columns of equal length");
        self.hist.write(&b)
    }

    /// Move `history.parquet` into place without an energy table (static solves).
    pub fn finish_history_only(mut self) -> Result<()> {
        self.flush()?;
        self.hist.finish()?;
        Ok(())
    }

    /// Write the energy table and move both tables into place.
    pub fn finish(mut self, out: &Path, prov: &Provenance) -> Result<()> {
        self.flush()?;
        let e = &self.rest.energy;
        let col = |f: fn(&Energies) -> f64| e.iter().map(f).collect::<Vec<_>>();
        // The written relative error is taken against the whole run's energy scale (its
        // last, largest value), so that the first samples, where the scale so far is
        // small, do not read as large errors.
        let scale = e.iter().map(|x| x.scale).fold(0.0, f64::max);
        let relative: Vec<f64> = e
            .iter()
            .map(|x| {
                if scale > 0.0 {
                    x.balance_error.abs() / scale
                } else {
                    0.0
                }
            })
            .collect();
        let eb = batch(vec![
            Col::F64("t", self.rest.energy_t.clone()),
            Col::F64("kinetic", col(|x| x.kinetic)),
            Col::F64("internal", col(|x| x.internal)),
            Col::F64("damping", col(|x| x.damping)),
            Col::F64("friction", col(|x| x.friction)),
            Col::F64("hourglass", col(|x| x.hourglass)),
            Col::F64("contact", col(|x| x.contact)),
            Col::F64("eroded", col(|x| x.eroded)),
            Col::F64("external_work", col(|x| x.external_work)),
            Col::F64("balance_error", col(|x| x.balance_error)),
            Col::F64("balance_error_relative", relative),
            Col::F64("energy_scale", col(|x| x.scale)),
        ]);
        let mut ew = AtomicTableWriter::create(&out.join("energy.parquet"), eb.schema(), prov)?;
        ew.write(&eb)?;
        let mut pw = None;
        if !self.rest.projectile.is_empty() {
            let p = &self.rest.projectile;
            let c = |k: usize| p.iter().map(|r| r.2[k]).collect::<Vec<_>>();
            let pb = batch(vec![
                Col::F64("t", p.iter().map(|r| r.0).collect()),
                Col::I64("projectile_id", p.iter().map(|r| r.1).collect()),
                Col::F64("x", c(0)),
                Col::F64("y", c(1)),
                Col::F64("z", c(2)),
                Col::F64("vx", c(3)),
                Col::F64("vy", c(4)),
                Col::F64("vz", c(5)),
                Col::F64("fx", c(6)),
                Col::F64("fy", c(7)),
                Col::F64("fz", c(8)),
            ]);
            let mut w =
                AtomicTableWriter::create(&out.join("projectile.parquet"), pb.schema(), prov)?;
            w.write(&pb)?;
            pw = Some(w);
        }
        let bw = match self.ballistic_table() {
            Some(b) => {
                let mut w =
                    AtomicTableWriter::create(&out.join("ballistic.parquet"), b.schema(), prov)?;
                w.write(&b)?;
                Some(w)
            }
            None => None,
        };
        let bfs = out.join("bfs.parquet");
        let cw = match &self.crater {
            Some(c) => {
                let b = c.table();
                let mut w = AtomicTableWriter::create(&bfs, b.schema(), prov)?;
                w.write(&b)?;
                Some(w)
            }
            // A stale one from an earlier run into the same folder would read as this
            // run's.
            None => {
                if bfs.exists() {
                    std::fs::remove_file(&bfs).map_err(|e| crate::error::WeftError::io(&bfs, e))?;
                }
                None
            }
        };
        ew.finish()?;
        if let Some(w) = cw {
            w.finish()?;
        }
        if let Some(w) = pw {
            w.finish()?;
        }
        if let Some(w) = bw {
            w.finish()?;
        }
        self.hist.finish()?;
        Ok(())
    }
}

impl Sink for ParquetSink {
    fn projectile(&mut self, t: f64, id: i64, s: &[f64; 9]) -> Result<()> {
        self.rest.projectile(t, id, s)
    }
    fn layers(&mut self, t: f64, rows: &[LayerValues]) -> Result<()> {
        self.rest.layers(t, rows)
    }
    fn history(&mut self, t: f64, nodes: &[usize], u: &[[f64; 3]], v: &[[f64; 3]]) -> Result<()> {
        for (j, &i) in nodes.iter().enumerate() {
            self.cols[0].push(t);
            self.ids.push(self.node_id[i]);
            for d in 0..3 {
                self.cols[1 + d].push(u[j][d]);
                self.cols[4 + d].push(v[j][d]);
            }
        }
        if self.ids.len() >= FLUSH_ROWS {
            self.flush()?;
        }
        Ok(())
    }
    fn energy(&mut self, t: f64, e: &Energies) -> Result<()> {
        self.rest.energy(t, e)
    }
    fn crater(&mut self, t: f64, rows: &[CraterRow]) -> Result<()> {
        if let Some(c) = &mut self.crater {
            c.sample(t, rows);
        }
        Ok(())
    }
}
