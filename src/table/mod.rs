//! Parquet table layer: validated reading, atomic writing, provenance.
//!
//! Every weft table is a tidy Parquet file in SI units, zstd-compressed, documented
//! column by column in `docs/tables.md`. Readers accept what pandas and polars write
//! (Int32 or Int64 ids, Float32 or Float64 values, Utf8, LargeUtf8, Utf8View or
//! dictionary strings) and normalise it; every problem is reported with the file,
//! column, row and value. Writers write to a temporary file beside the target and
//! rename it into place only when the table is complete, so an interrupted run never
//! leaves a half-written table under the final name.
//!
//! Provenance (tool, version, stage, parameters, input hashes) is stored as JSON in the
//! Parquet key-value metadata under `weft.provenance`, and under `PANDAS_ATTRS` so that
//! pandas exposes it as `df.attrs["weft"]`.
//!
//! [`history`]: the reader of `history.parquet`, shared by every stage that takes one.

pub mod history;

use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use arrow_array::{
    Array, ArrayRef, BooleanArray, Float64Array, Int64Array, RecordBatch, StringArray,
};
use arrow_schema::{DataType, Field, Schema, SchemaRef};
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use parquet::arrow::ArrowWriter;
use parquet::basic::{Compression, ZstdLevel};
use parquet::file::properties::WriterProperties;
use serde::Serialize;

use crate::error::{Result, WeftError};

/// Key of the provenance JSON in the Parquet metadata.
pub const PROVENANCE_KEY: &str = "weft.provenance";

/// Where a table came from: which tool, which stage, which parameters and inputs.
#[derive(Debug, Clone, Serialize)]
pub struct Provenance {
    pub tool: &'static str,
    pub version: &'static str,
    pub stage: String,
    pub parameters: serde_json::Value,
    /// Input files with their blake3 content hashes.
    pub inputs: Vec<InputHash>,
}

#[derive(Debug, Clone, Serialize)]
pub struct InputHash {
    pub path: String,
    pub blake3: String,
}

impl Provenance {
    pub fn new(stage: &str, parameters: serde_json::Value) -> Self {
        Provenance {
            tool: "weft",
            version: env!("CARGO_PKG_VERSION"),
            stage: stage.to_string(),
            parameters,
            inputs: Vec::new(),
        }
    }
    /// Record an input file with its content hash.
    pub fn with_input(mut self, path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| WeftError::io(path, e))?;
        self.inputs.push(InputHash {
            path: path.display().to_string(),
            blake3: blake3::hash(&bytes).to_hex().to_string(),
        });
        Ok(self)
    }
    fn metadata(&self) -> Vec<(String, String)> {
        let json = serde_json::to_value(self).expect("provenance serialises");
        vec![
            (PROVENANCE_KEY.to_string(), json.to_string()),
            (
                "PANDAS_ATTRS".to_string(),
                serde_json::json!({ "weft": json }).to_string(),
            ),
        ]
    }
}

/// A column builder description used by writers: name, values.
pub enum Col {
    F64(&'static str, Vec<f64>),
    OptF64(&'static str, Vec<Option<f64>>),
    I64(&'static str, Vec<i64>),
    OptI64(&'static str, Vec<Option<i64>>),
    Str(&'static str, Vec<String>),
    Bool(&'static str, Vec<bool>),
    OptBool(&'static str, Vec<Option<bool>>),
    OptStr(&'static str, Vec<Option<String>>),
    /// A float column whose name is only known at run time (a fitted parameter's).
    F64Named(String, Vec<f64>),
    /// A nullable float column named at run time.
    OptF64Named(String, Vec<Option<f64>>),
    /// A string column named at run time (a grouping column's).
    StrNamed(String, Vec<String>),
    /// An integer column named at run time (a grouping column's).
    I64Named(String, Vec<i64>),
}

impl Col {
    fn field_and_array(self) -> (Field, ArrayRef) {
        match self {
            Col::F64(n, v) => (
                Field::new(n, DataType::Float64, false),
                Arc::new(Float64Array::from(v)),
            ),
            Col::OptF64(n, v) => (
                Field::new(n, DataType::Float64, true),
                Arc::new(Float64Array::from(v)),
            ),
            Col::I64(n, v) => (
                Field::new(n, DataType::Int64, false),
                Arc::new(Int64Array::from(v)),
            ),
            Col::OptI64(n, v) => (
                Field::new(n, DataType::Int64, true),
                Arc::new(Int64Array::from(v)),
            ),
            Col::Str(n, v) => (
                Field::new(n, DataType::Utf8, false),
                Arc::new(StringArray::from(v)),
            ),
            Col::Bool(n, v) => (
                Field::new(n, DataType::Boolean, false),
                Arc::new(BooleanArray::from(v)),
            ),
            Col::OptBool(n, v) => (
                Field::new(n, DataType::Boolean, true),
                Arc::new(BooleanArray::from(v)),
            ),
            Col::OptStr(n, v) => (
                Field::new(n, DataType::Utf8, true),
                Arc::new(StringArray::from(v)),
            ),
            Col::F64Named(n, v) => (
                Field::new(n, DataType::Float64, false),
                Arc::new(Float64Array::from(v)),
            ),
            Col::OptF64Named(n, v) => (
                Field::new(n, DataType::Float64, true),
                Arc::new(Float64Array::from(v)),
            ),
            Col::StrNamed(n, v) => (
                Field::new(n, DataType::Utf8, false),
                Arc::new(StringArray::from(v)),
            ),
            Col::I64Named(n, v) => (
                Field::new(n, DataType::Int64, false),
                Arc::new(Int64Array::from(v)),
            ),
        }
    }
}

/// Build a record batch from columns (all of the same length).
pub fn batch(cols: Vec<Col>) -> RecordBatch {
    let (fields, arrays): (Vec<_>, Vec<_>) = cols.into_iter().map(|c| c.field_and_array()).unzip();
    RecordBatch::try_new(Arc::new(Schema::new(fields)), arrays).expect("columns of equal length")
}

fn writer_props(prov: &Provenance) -> WriterProperties {
    // Provenance goes into the file's key-value metadata, where every Parquet reader
    // (polars, arrow-rs, parquet-tools) finds it; the same keys also go into the Arrow
    // schema's metadata, which arrow-rs stores only inside its `ARROW:schema` blob and
    // from which pyarrow, hence pandas' `df.attrs`, takes them.
    let kv = prov
        .metadata()
        .into_iter()
        .map(|(k, v)| parquet::file::metadata::KeyValue::new(k, v))
        .collect::<Vec<_>>();
    WriterProperties::builder()
        .set_key_value_metadata(Some(kv))
        .set_compression(Compression::ZSTD(
            ZstdLevel::try_new(3).expect("valid level"),
        ))
        .set_max_row_group_size(1 << 20)
        .build()
}

fn tmp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "table".into());
    path.with_file_name(format!(".{name}.tmp-{}", std::process::id()))
}

/// A Parquet table being written: rows are appended in batches, the file appears under
/// its final name only on [`AtomicTableWriter::finish`]. Dropping an unfinished writer
/// removes the temporary file.
pub struct AtomicTableWriter {
    path: PathBuf,
    tmp: PathBuf,
    writer: Option<ArrowWriter<File>>,
    schema: SchemaRef,
}

impl AtomicTableWriter {
    pub fn create(path: &Path, schema: SchemaRef, prov: &Provenance) -> Result<Self> {
        if let Some(dir) = path.parent() {
            if !dir.as_os_str().is_empty() {
                std::fs::create_dir_all(dir).map_err(|e| WeftError::io(dir, e))?;
            }
        }
        let schema = Arc::new(
            schema
                .as_ref()
                .clone()
                .with_metadata(prov.metadata().into_iter().collect()),
        );
        let tmp = tmp_path(path);
        let file = File::create(&tmp).map_err(|e| WeftError::io(&tmp, e))?;
        let writer =
            ArrowWriter::try_new(file, schema.clone(), Some(writer_props(prov))).map_err(|e| {
                WeftError::Parquet {
                    path: path.to_path_buf(),
                    message: e.to_string(),
                }
            })?;
        Ok(AtomicTableWriter {
            path: path.to_path_buf(),
            tmp,
            writer: Some(writer),
            schema,
        })
    }

    pub fn schema(&self) -> SchemaRef {
        self.schema.clone()
    }

    pub fn write(&mut self, batch: &RecordBatch) -> Result<()> {
        let batch = batch
            .clone()
            .with_schema(self.schema.clone())
            .map_err(|e| WeftError::Parquet {
                path: self.path.clone(),
                message: e.to_string(),
            })?;
        self.writer
            .as_mut()
            .expect("writer open until finish")
            .write(&batch)
            .map_err(|e| WeftError::Parquet {
                path: self.path.clone(),
                message: e.to_string(),
            })
    }

    /// Close the file, flush it to disk and rename it into place.
    pub fn finish(mut self) -> Result<PathBuf> {
        let w = self.writer.take().expect("writer open until finish");
        let file = w.into_inner().map_err(|e| WeftError::Parquet {
            path: self.path.clone(),
            message: e.to_string(),
        })?;
        file.sync_all().map_err(|e| WeftError::io(&self.tmp, e))?;
        drop(file);
        std::fs::rename(&self.tmp, &self.path).map_err(|e| WeftError::io(&self.path, e))?;
        Ok(self.path.clone())
    }
}

impl Drop for AtomicTableWriter {
    fn drop(&mut self) {
        if self.writer.is_some() {
            self.writer = None;
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Write a whole table atomically.
pub fn write_table(path: &Path, batch: &RecordBatch, prov: &Provenance) -> Result<()> {
    let mut w = AtomicTableWriter::create(path, batch.schema(), prov)?;
    w.write(batch)?;
    w.finish()?;
    Ok(())
}

/// A table read into memory, with validated typed access to its columns.
pub struct Table {
    pub path: PathBuf,
    pub batch: RecordBatch,
    /// The table's provenance JSON, when it has one.
    pub provenance: Option<String>,
}

fn input_err(path: &Path, what: String) -> WeftError {
    WeftError::input(what).in_file(path)
}

impl Table {
    /// Read a whole Parquet file.
    pub fn read(path: &Path) -> Result<Table> {
        let file = File::open(path).map_err(|e| WeftError::io(path, e))?;
        let pq_err = |e: parquet::errors::ParquetError| {
            input_err(path, format!("cannot read the file as Parquet: {e}"))
                .hint("the file may be truncated or not a Parquet table; regenerate it")
        };
        let builder = ParquetRecordBatchReaderBuilder::try_new(file).map_err(pq_err)?;
        let provenance = builder
            .metadata()
            .file_metadata()
            .key_value_metadata()
            .and_then(|kv| kv.iter().find(|k| k.key == PROVENANCE_KEY))
            .and_then(|k| k.value.clone());
        let schema = builder.schema().clone();
        let reader = builder.build().map_err(pq_err)?;
        let batches = reader
            .collect::<std::result::Result<Vec<_>, _>>()
            .map_err(|e| input_err(path, format!("cannot decode the table: {e}")))?;
        let batch = arrow_select::concat::concat_batches(&schema, &batches)
            .map_err(|e| input_err(path, format!("cannot join row groups: {e}")))?;
        Ok(Table {
            path: path.to_path_buf(),
            batch,
            provenance,
        })
    }

    pub fn num_rows(&self) -> usize {
        self.batch.num_rows()
    }

    pub fn has(&self, col: &str) -> bool {
        self.batch.schema().index_of(col).is_ok()
    }

    fn err(&self, col: &str, what: String) -> WeftError {
        input_err(&self.path, what).in_column(col)
    }

    fn column(&self, col: &str, expected_cols: &str) -> Result<&ArrayRef> {
        self.batch.column_by_name(col).ok_or_else(|| {
            let have: Vec<String> = self
                .batch
                .schema()
                .fields()
                .iter()
                .map(|f| f.name().clone())
                .collect();
            input_err(&self.path, format!("missing column `{col}`"))
                .expected(format!("columns {expected_cols}"))
                .hint(format!(
                    "the table has columns [{}]; see docs/tables.md for the layout",
                    have.join(", ")
                ))
        })
    }

    fn cast(&self, col: &str, a: &ArrayRef, to: &DataType, accepted: &str) -> Result<ArrayRef> {
        let ok = match to {
            DataType::Float64 => a.data_type().is_numeric(),
            DataType::Int64 => a.data_type().is_integer(),
            DataType::Utf8 => matches!(
                a.data_type(),
                DataType::Utf8
                    | DataType::LargeUtf8
                    | DataType::Utf8View
                    | DataType::Dictionary(_, _)
            ),
            DataType::Boolean => matches!(a.data_type(), DataType::Boolean),
            _ => false,
        } || a.data_type() == &DataType::Null; // all nulls (pandas/pyarrow write a column of None so)
        if !ok {
            return Err(self
                .err(col, format!("column `{col}` has type {}", a.data_type()))
                .expected(accepted.to_string())
                .hint("write the column with the documented type (docs/tables.md)"));
        }
        arrow_cast::cast(a, to)
            .map_err(|e| self.err(col, format!("cannot convert column `{col}`: {e}")))
    }

    fn no_nulls(&self, col: &str, a: &dyn Array) -> Result<()> {
        if a.null_count() > 0 {
            let row = (0..a.len()).find(|&i| a.is_null(i)).unwrap_or(0);
            return Err(self
                .err(col, format!("null value in required column `{col}`"))
                .at_row(row)
                .expected("a value in every row")
                .hint("fill the missing value; only the columns marked nullable in docs/tables.md may be empty"));
        }
        Ok(())
    }

    /// A required, non-null, finite floating-point column.
    pub fn f64(&self, col: &str, expected_cols: &str) -> Result<Vec<f64>> {
        let a = self.column(col, expected_cols)?;
        let c = self.cast(
            col,
            a,
            &DataType::Float64,
            "a floating-point column (Float64)",
        )?;
        self.no_nulls(col, c.as_ref())?;
        let v: Vec<f64> = c
            .as_any()
            .downcast_ref::<Float64Array>()
            .expect("cast to f64")
            .values()
            .to_vec();
        for (row, x) in v.iter().enumerate() {
            if !x.is_finite() {
                return Err(self
                    .err(col, format!("non-finite value `{x}` in column `{col}`"))
                    .at_row(row)
                    .expected("a finite number")
                    .hint("NaN or infinity in an input table usually comes from a failed upstream computation"));
            }
        }
        Ok(v)
    }

    /// An optional nullable floating-point column: `None` when the column is absent.
    /// Present values must be finite.
    pub fn f64_opt(&self, col: &str) -> Result<Option<Vec<Option<f64>>>> {
        let Some(a) = self.batch.column_by_name(col) else {
            return Ok(None);
        };
        let c = self.cast(
            col,
            a,
            &DataType::Float64,
            "a floating-point column (Float64)",
        )?;
        let arr = c
            .as_any()
            .downcast_ref::<Float64Array>()
            .expect("cast to f64");
        let v: Vec<Option<f64>> = arr.iter().collect();
        for (row, x) in v.iter().enumerate() {
            if let Some(x) = x {
                if !x.is_finite() {
                    return Err(self
                        .err(col, format!("non-finite value `{x}` in column `{col}`"))
                        .at_row(row)
                        .expected("a finite number or null")
                        .hint("leave the cell null when the property does not apply"));
                }
            }
        }
        Ok(Some(v))
    }

    /// A required, non-null integer column.
    pub fn i64(&self, col: &str, expected_cols: &str) -> Result<Vec<i64>> {
        let a = self.column(col, expected_cols)?;
        let c = self.cast(
            col,
            a,
            &DataType::Int64,
            "an integer column (Int64 or Int32)",
        )?;
        self.no_nulls(col, c.as_ref())?;
        Ok(c.as_any()
            .downcast_ref::<Int64Array>()
            .expect("cast to i64")
            .values()
            .to_vec())
    }

    /// An optional nullable integer column: `None` when the column is absent.
    pub fn i64_opt(&self, col: &str) -> Result<Option<Vec<Option<i64>>>> {
        let Some(a) = self.batch.column_by_name(col) else {
            return Ok(None);
        };
        let c = self.cast(
            col,
            a,
            &DataType::Int64,
            "an integer column (Int64 or Int32)",
        )?;
        Ok(Some(
            c.as_any()
                .downcast_ref::<Int64Array>()
                .expect("cast to i64")
                .iter()
                .collect(),
        ))
    }

    /// A required, non-null string column.
    pub fn str(&self, col: &str, expected_cols: &str) -> Result<Vec<String>> {
        let a = self.column(col, expected_cols)?;
        let c = self.cast(col, a, &DataType::Utf8, "a string column")?;
        self.no_nulls(col, c.as_ref())?;
        Ok(c.as_any()
            .downcast_ref::<StringArray>()
            .expect("cast to utf8")
            .iter()
            .map(|s| s.unwrap_or_default().to_string())
            .collect())
    }

    /// An optional nullable string column.
    pub fn str_opt(&self, col: &str) -> Result<Option<Vec<Option<String>>>> {
        let Some(a) = self.batch.column_by_name(col) else {
            return Ok(None);
        };
        let c = self.cast(col, a, &DataType::Utf8, "a string column")?;
        Ok(Some(
            c.as_any()
                .downcast_ref::<StringArray>()
                .expect("cast to utf8")
                .iter()
                .map(|s| s.map(|s| s.to_string()))
                .collect(),
        ))
    }

    /// An optional nullable boolean column.
    pub fn bool_opt(&self, col: &str) -> Result<Option<Vec<Option<bool>>>> {
        let Some(a) = self.batch.column_by_name(col) else {
            return Ok(None);
        };
        let c = self.cast(col, a, &DataType::Boolean, "a boolean column")?;
        Ok(Some(
            c.as_any()
                .downcast_ref::<BooleanArray>()
                .expect("boolean")
                .iter()
                .collect(),
        ))
    }

    /// A required, non-null boolean column.
    pub fn bool(&self, col: &str, expected_cols: &str) -> Result<Vec<bool>> {
        let a = self.column(col, expected_cols)?;
        let c = self.cast(col, a, &DataType::Boolean, "a boolean column")?;
        self.no_nulls(col, c.as_ref())?;
        Ok(c.as_any()
            .downcast_ref::<BooleanArray>()
            .expect("boolean")
            .iter()
            .map(|b| b.unwrap_or(false))
            .collect())
    }

    /// Error for a value in a given row.
    pub fn value_error(&self, col: &str, row: usize, what: String) -> WeftError {
        self.err(col, what).at_row(row)
    }
}

/// blake3 hash of a file's content, as hex.
pub fn hash_file(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|e| WeftError::io(path, e))?;
    Ok(blake3::hash(&bytes).to_hex().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn provenance_is_in_the_parquet_key_value_metadata() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.parquet");
        let prov = Provenance::new("unit", serde_json::json!({ "cells": 10 }));
        write_table(&p, &batch(vec![Col::F64("x", vec![1.0, 2.0])]), &prov).unwrap();
        let t = Table::read(&p).unwrap();
        let j: serde_json::Value = serde_json::from_str(t.provenance.as_deref().unwrap()).unwrap();
        assert_eq!(j["stage"], "unit");
        assert_eq!(j["parameters"]["cells"], 10);
        assert_eq!(j["version"], env!("CARGO_PKG_VERSION"));
        // No temporary file is left beside the table.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn an_unfinished_writer_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.parquet");
        let b = batch(vec![Col::F64("x", vec![1.0])]);
        let mut w = AtomicTableWriter::create(
            &p,
            b.schema(),
            &Provenance::new("unit", serde_json::json!({})),
        )
        .unwrap();
        w.write(&b).unwrap();
        drop(w);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
