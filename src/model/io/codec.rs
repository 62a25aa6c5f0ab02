//! What every table codec shares: the [`Codec`] each table gives (its files, its read
//! and its write side by side), the model being read ([`Reading`]) with the node and part
//! indices the later tables look their references up in, and the folder being written
//! ([`Writing`]).

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use arrow_array::{ArrayRef, RecordBatch};
use arrow_schema::{Field, Schema};

use crate::error::Result;
use crate::model::types::Model;
use crate::table::{write_table, Provenance, Table};

/// One model table: its files, how it is read into a model and how it is written out of
/// one. The list of codecs in [`super`] drives both reading and writing a model folder.
pub struct Codec {
    /// The table's files (the element tables: one per element kind).
    pub files: &'static [&'static str],
    /// Reads the table into the model being read. Every table but nodes and parts may
    /// be absent; the codec then leaves the model as it is.
    pub read: fn(&mut Reading) -> Result<()>,
    /// Writes the table when the model has anything for it (nodes, parts and analysis
    /// always).
    pub write: fn(&Model, &Writing) -> Result<()>,
}

/// A model being read, table by table, with what the tables read so far give the next.
pub struct Reading<'a> {
    /// The model folder.
    pub dir: &'a Path,
    /// The model as read so far.
    pub model: Model,
    /// Node index by node id (from `nodes.parquet`), for the tables that name nodes.
    pub node_index: HashMap<i64, usize>,
    /// Part index by part id (from `parts.parquet`), for the element tables.
    pub part_index: HashMap<i64, usize>,
}

impl<'a> Reading<'a> {
    /// An empty model, to be read from `dir`.
    pub fn new(dir: &'a Path) -> Self {
        Reading {
            dir,
            model: Model::default(),
            node_index: HashMap::new(),
            part_index: HashMap::new(),
        }
    }

    /// A table the folder must have.
    pub fn table(&self, name: &str) -> Result<Table> {
        Table::read(&self.dir.join(name))
    }

    /// A table the folder may have; `None` when it has not.
    pub fn optional(&self, name: &str) -> Result<Option<Table>> {
        let p = self.dir.join(name);
        if p.exists() {
            Table::read(&p).map(Some)
        } else {
            Ok(None)
        }
    }

    /// Map node ids of a column to node indices; a dangling id is an error naming the row.
    pub fn node_refs(&self, t: &Table, col: &str, ids: &[i64]) -> Result<Vec<usize>> {
        ids.iter()
            .enumerate()
            .map(|(row, id)| {
                self.node_index.get(id).copied().ok_or_else(|| {
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
}

/// A model folder being written: where, and the provenance every table carries.
pub struct Writing<'a> {
    /// The folder the tables go to.
    pub dir: &'a Path,
    pub prov: &'a Provenance,
}

impl Writing<'_> {
    /// Write one table of the folder.
    pub fn table(&self, name: &str, batch: &RecordBatch) -> Result<()> {
        write_table(&self.dir.join(name), batch, self.prov)
    }
}

/// A batch with more columns appended (for column types [`crate::table::Col`] has not).
pub fn append_columns(b: RecordBatch, extra: Vec<(Field, ArrayRef)>) -> RecordBatch {
    let mut fields: Vec<Field> = b
        .schema()
        .fields()
        .iter()
        .map(|f| f.as_ref().clone())
        .collect();
    let mut arrays = b.columns().to_vec();
    for (f, a) in extra {
        fields.push(f);
        arrays.push(a);
    }
    RecordBatch::try_new(Arc::new(Schema::new(fields)), arrays).expect("equal lengths")
}
