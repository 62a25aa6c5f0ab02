//! Gathering: a sweep's per-instance tables into one Parquet table with the instance and
//! its parameters as columns; and the stage records as a table.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use arrow_array::{ArrayRef, BooleanArray, Float64Array, Int64Array, RecordBatch, StringArray};
use arrow_schema::{DataType, Field, Schema};

use super::record::RecordStore;
use super::spec::Pipeline;
use crate::error::{Result, WeftError};
use crate::table::{batch, write_table, Col, Provenance, Table};

/// Typed column of parameter values: Int64 if all parse as integers, else Float64 if all
/// parse as numbers, else Boolean if all are booleans, else Utf8.
fn param_column(name: &str, vals: &[String], rows: &[usize]) -> (Field, ArrayRef) {
    let expand = |i: usize| std::iter::repeat_n(i, rows[i]);
    let idx: Vec<usize> = (0..vals.len()).flat_map(expand).collect();
    if let Ok(v) = vals
        .iter()
        .map(|s| s.parse::<i64>())
        .collect::<std::result::Result<Vec<_>, _>>()
    {
        return (
            Field::new(name, DataType::Int64, false),
            Arc::new(Int64Array::from(
                idx.iter().map(|&i| v[i]).collect::<Vec<_>>(),
            )),
        );
    }
    if let Ok(v) = vals
        .iter()
        .map(|s| s.parse::<f64>())
        .collect::<std::result::Result<Vec<_>, _>>()
    {
        return (
            Field::new(name, DataType::Float64, false),
            Arc::new(Float64Array::from(
                idx.iter().map(|&i| v[i]).collect::<Vec<_>>(),
            )),
        );
    }
    if let Ok(v) = vals
        .iter()
        .map(|s| s.parse::<bool>())
        .collect::<std::result::Result<Vec<_>, _>>()
    {
        return (
            Field::new(name, DataType::Boolean, false),
            Arc::new(BooleanArray::from(
                idx.iter().map(|&i| v[i]).collect::<Vec<_>>(),
            )),
        );
    }
    (
        Field::new(name, DataType::Utf8, false),
        Arc::new(StringArray::from(
            idx.iter().map(|&i| vals[i].clone()).collect::<Vec<_>>(),
        )),
    )
}

/// Gather `table` (a file inside each instance's output, or the output itself when it is
/// a Parquet file) over every instance of `stage` into `out`. Returns the row count.
///
/// Columns: `instance`, then one column per stage param and sweep value (typed: Int64,
/// Float64, Boolean or Utf8 as the values allow; named `param_NAME` when the data has a
/// column NAME), then the data columns.
pub fn gather(
    p: &Pipeline,
    stage: &str,
    output: Option<&str>,
    table: Option<&str>,
    out: &Path,
) -> Result<usize> {
    let sel = p.select(stage)?;
    let mut tables = Vec::new();
    let mut prov = Provenance::new(
        "gather",
        serde_json::json!({ "pipeline": p.file.display().to_string(), "stage": stage, "output": output, "table": table }),
    );
    for &i in &sel {
        let path = instance_table(p, &p.instances[i], output, table)?;
        prov = prov.with_input(&path)?;
        tables.push((i, Table::read(&path)?));
    }
    let schema0 = tables[0].1.batch.schema();
    let batches = same_columns(p, &tables, &schema0)?;
    let data = arrow_select::concat::concat_batches(&schema0, &batches)
        .map_err(|e| WeftError::input(format!("cannot join the tables: {e}")))?;
    let rows: Vec<usize> = tables.iter().map(|(_, t)| t.num_rows()).collect();
    // Parameter columns: every param any instance uses (sweep values first, by name).
    let mut names: Vec<String> = Vec::new();
    for (i, _) in &tables {
        for k in p.instances[*i].own.keys() {
            if !names.contains(k) {
                names.push(k.clone());
            }
        }
    }
    let mut fields = vec![Field::new("instance", DataType::Utf8, false)];
    let mut arrays: Vec<ArrayRef> = vec![Arc::new(StringArray::from(
        tables
            .iter()
            .zip(&rows)
            .flat_map(|((i, _), &r)| std::iter::repeat_n(p.instances[*i].name.clone(), r))
            .collect::<Vec<_>>(),
    ))];
    for n in &names {
        // A parameter named like a data column gets a `param_` prefix.
        let col = if schema0.field_with_name(n).is_ok() || n == "instance" {
            format!("param_{n}")
        } else {
            n.clone()
        };
        let vals: Vec<String> = tables
            .iter()
            .map(|(i, _)| p.instances[*i].own.get(n).cloned().unwrap_or_default())
            .collect();
        let (f, a) = param_column(&col, &vals, &rows);
        fields.push(f);
        arrays.push(a);
    }
    for (f, a) in schema0.fields().iter().zip(data.columns()) {
        fields.push(f.as_ref().clone());
        arrays.push(a.clone());
    }
    let b = RecordBatch::try_new(Arc::new(Schema::new(fields)), arrays).expect("equal lengths");
    write_table(out, &b, &prov)?;
    Ok(b.num_rows())
}

/// The table an instance wrote: its output `output` (or its only one), and inside it
/// `table` when the output is a folder; an error names the instance and what exists.
fn instance_table(
    p: &Pipeline,
    inst: &super::spec::Instance,
    output: Option<&str>,
    table: Option<&str>,
) -> Result<PathBuf> {
    let (_, opath) = match output {
        Some(o) => inst
            .outputs
            .iter()
            .find(|(k, _)| k == o)
            .cloned()
            .ok_or_else(|| {
                WeftError::input(format!("instance `{}` has no output `{o}`", inst.name))
                    .in_file(&p.file)
                    .expected(format!(
                        "one of [{}]",
                        inst.outputs
                            .iter()
                            .map(|(k, _)| k.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
            })?,
        None if inst.outputs.len() == 1 => inst.outputs[0].clone(),
        None => {
            return Err(WeftError::input(format!(
                "instance `{}` has {} outputs",
                inst.name,
                inst.outputs.len()
            ))
            .in_file(&p.file)
            .expected("`--output NAME` to choose one"))
        }
    };
    let mut path: PathBuf = p.root.join(&opath);
    if let Some(t) = table {
        path = path.join(t);
    }
    if !path.is_file() {
        return Err(WeftError::input(format!(
            "`{}` of instance `{}` does not exist",
            path.display(),
            inst.name
        ))
        .hint("run the pipeline first (`weft run`), or check --table"));
    }
    Ok(path)
}

/// The instances' tables as batches, each with the first one's columns and types, else
/// an error naming the instance and both column lists.
fn same_columns(
    p: &Pipeline,
    tables: &[(usize, Table)],
    schema0: &arrow_schema::SchemaRef,
) -> Result<Vec<RecordBatch>> {
    let columns = |s: &arrow_schema::Schema| -> Vec<String> {
        s.fields()
            .iter()
            .map(|f| format!("{}: {}", f.name(), f.data_type()))
            .collect()
    };
    let mut batches = Vec::new();
    for (i, t) in tables {
        if t.batch.schema().fields() != schema0.fields() {
            return Err(WeftError::input(format!(
                "the table of `{}` has columns {:?}, the first instance's has {:?}",
                p.instances[*i].name,
                columns(&t.batch.schema()),
                columns(schema0)
            ))
            .in_file(&t.path)
            .expected("the same columns and types in every instance"));
        }
        batches.push(t.batch.clone());
    }
    Ok(batches)
}

/// The records of a pipeline as a table, one row per instance, in file order.
pub fn records_table(p: &Pipeline) -> RecordBatch {
    let store = RecordStore::new(&p.root, &p.file);
    let by_name: BTreeMap<String, super::record::Record> = store
        .all()
        .into_iter()
        .map(|r| (r.instance.clone(), r))
        .collect();
    let recs: Vec<&super::record::Record> = p
        .instances
        .iter()
        .filter_map(|i| by_name.get(&i.name))
        .collect();
    batch(vec![
        Col::Str(
            "instance",
            recs.iter().map(|r| r.instance.clone()).collect(),
        ),
        Col::Str("stage", recs.iter().map(|r| r.stage.clone()).collect()),
        Col::I64(
            "exit_status",
            recs.iter().map(|r| r.exit_status as i64).collect(),
        ),
        Col::Str("start", recs.iter().map(|r| r.start.clone()).collect()),
        Col::Str("end", recs.iter().map(|r| r.end.clone()).collect()),
        Col::F64("start_unix", recs.iter().map(|r| r.start_unix).collect()),
        Col::F64("end_unix", recs.iter().map(|r| r.end_unix).collect()),
        Col::F64(
            "duration",
            recs.iter().map(|r| r.end_unix - r.start_unix).collect(),
        ),
        Col::Str("command", recs.iter().map(|r| r.command.clone()).collect()),
        Col::Str(
            "params",
            recs.iter()
                .map(|r| serde_json::to_string(&r.params).unwrap_or_default())
                .collect(),
        ),
        Col::Str(
            "inputs",
            recs.iter()
                .map(|r| serde_json::to_string(&r.inputs).unwrap_or_default())
                .collect(),
        ),
        Col::Str(
            "outputs",
            recs.iter()
                .map(|r| serde_json::to_string(&r.outputs).unwrap_or_default())
                .collect(),
        ),
        Col::Str(
            "binary",
            recs.iter()
                .map(|r| r.binary.clone().unwrap_or_default())
                .collect(),
        ),
        Col::Str(
            "binary_hash",
            recs.iter()
                .map(|r| r.binary_hash.clone().unwrap_or_default())
                .collect(),
        ),
        Col::Str(
            "tool_version",
            recs.iter().map(|r| r.tool_version.clone()).collect(),
        ),
        Col::Str("log", recs.iter().map(|r| r.log.clone()).collect()),
    ])
}
