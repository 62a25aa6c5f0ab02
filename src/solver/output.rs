//! Output sinks: in memory (tests, the fit stage) and streaming Parquet (the
//! `simulate` stage). Layouts of `history.parquet` and `energy.parquet`: docs/tables.md.

use std::path::Path;
use std::sync::Arc;

use arrow_array::{Float64Array, Int64Array, RecordBatch};
use arrow_schema::{DataType, Field, Schema, SchemaRef};

use super::{Energies, Sink};
use crate::error::Result;
use crate::table::{batch, AtomicTableWriter, Col, Provenance};

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
}

impl Sink for MemorySink {
    fn projectile(&mut self, t: f64, id: i64, s: &[f64; 9]) -> Result<()> {
        self.projectile.push((t, id, *s));
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

/// Streams `history.parquet` and collects `energy.parquet`; nothing appears under the
/// final names until [`ParquetSink::finish`].
pub struct ParquetSink {
    node_id: Vec<i64>,
    hist: AtomicTableWriter,
    cols: [Vec<f64>; 7],
    ids: Vec<i64>,
    energy_t: Vec<f64>,
    energy: Vec<Energies>,
    projectile: Vec<(f64, i64, [f64; 9])>,
}

impl ParquetSink {
    pub fn create(out: &Path, node_id: Vec<i64>, prov: &Provenance) -> Result<Self> {
        Ok(ParquetSink {
            node_id,
            hist: AtomicTableWriter::create(&out.join("history.parquet"), history_schema(), prov)?,
            cols: Default::default(),
            ids: Vec::new(),
            energy_t: Vec::new(),
            energy: Vec::new(),
            projectile: Vec::new(),
        })
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
        let e = &self.energy;
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
            Col::F64("t", self.energy_t.clone()),
            Col::F64("kinetic", col(|x| x.kinetic)),
            Col::F64("internal", col(|x| x.internal)),
            Col::F64("damping", col(|x| x.damping)),
            Col::F64("friction", col(|x| x.friction)),
            Col::F64("hourglass", col(|x| x.hourglass)),
            Col::F64("contact", col(|x| x.contact)),
            Col::F64("external_work", col(|x| x.external_work)),
            Col::F64("balance_error", col(|x| x.balance_error)),
            Col::F64("balance_error_relative", relative),
            Col::F64("energy_scale", col(|x| x.scale)),
        ]);
        let mut ew = AtomicTableWriter::create(&out.join("energy.parquet"), eb.schema(), prov)?;
        ew.write(&eb)?;
        let mut pw = None;
        if !self.projectile.is_empty() {
            let p = &self.projectile;
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
        ew.finish()?;
        if let Some(w) = pw {
            w.finish()?;
        }
        self.hist.finish()?;
        Ok(())
    }
}

impl Sink for ParquetSink {
    fn projectile(&mut self, t: f64, id: i64, s: &[f64; 9]) -> Result<()> {
        self.projectile.push((t, id, *s));
        Ok(())
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
        self.energy_t.push(t);
        self.energy.push(*e);
        Ok(())
    }
}
