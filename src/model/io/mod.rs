//! Reading and writing a model folder of Parquet tables. Layout: `docs/tables.md`.
//!
//! Each table has one codec, its read and its write side by side, in a module of its
//! own; [`TABLES`] lists them in the order they are read (a table after those whose
//! references it resolves: elements after nodes and parts, loads after curves) and
//! written, and reading or writing a model is a walk down that list.

mod analysis;
mod codec;
mod constraints;
mod contacts;
mod curves;
mod elements;
mod initial_velocities;
mod loads;
mod node_sets;
mod nodes;
mod parts;
mod projectile;
mod symmetry;
mod ties;

use std::path::{Path, PathBuf};

use crate::error::{Result, WeftError};
use crate::model::types::Model;
use crate::model::validate::ValidatedModel;
use crate::table::Provenance;
use codec::{Codec, Reading, Writing};

/// Names of the model tables, in the order they are read and written: the files of
/// [`table_files`] as a constant (a unit test holds the two equal).
pub const MODEL_TABLES: &[&str] = &[
    "nodes.parquet",
    "parts.parquet",
    "elements_truss.parquet",
    "elements_link.parquet",
    "elements_point_mass.parquet",
    "elements_tri.parquet",
    "elements_quad.parquet",
    "elements_beam.parquet",
    "elements_hex.parquet",
    "node_sets.parquet",
    "constraints.parquet",
    "curves.parquet",
    "loads.parquet",
    "initial_velocities.parquet",
    "projectile.parquet",
    "symmetry.parquet",
    "ties.parquet",
    "contacts.parquet",
    "analysis.parquet",
];

/// The tables' codecs, in the order they are read and written.
const TABLES: &[Codec] = &[
    Codec {
        files: &[nodes::FILE],
        read: nodes::read,
        write: nodes::write,
    },
    Codec {
        files: &[parts::FILE],
        read: parts::read,
        write: parts::write,
    },
    Codec {
        files: elements::FILES,
        read: elements::read,
        write: elements::write,
    },
    Codec {
        files: &[node_sets::FILE],
        read: node_sets::read,
        write: node_sets::write,
    },
    Codec {
        files: &[constraints::FILE],
        read: constraints::read,
        write: constraints::write,
    },
    Codec {
        files: &[curves::FILE],
        read: curves::read,
        write: curves::write,
    },
    Codec {
        files: &[loads::FILE],
        read: loads::read,
        write: loads::write,
    },
    Codec {
        files: &[initial_velocities::FILE],
        read: initial_velocities::read,
        write: initial_velocities::write,
    },
    Codec {
        files: &[projectile::FILE],
        read: projectile::read,
        write: projectile::write,
    },
    Codec {
        files: &[symmetry::FILE],
        read: symmetry::read,
        write: symmetry::write,
    },
    Codec {
        files: &[ties::FILE],
        read: ties::read,
        write: ties::write,
    },
    Codec {
        files: &[contacts::FILE],
        read: contacts::read,
        write: contacts::write,
    },
    Codec {
        files: &[analysis::FILE],
        read: analysis::read,
        write: analysis::write,
    },
];

/// The model tables' files, from their codecs, in the order they are read and written.
pub fn table_files() -> impl Iterator<Item = &'static str> {
    TABLES.iter().flat_map(|c| c.files.iter().copied())
}

/// Read and validate a model folder.
pub fn read_model(dir: &Path) -> Result<Model> {
    read_validated(dir).map(ValidatedModel::into_model)
}

/// Read and validate a model folder, keeping the proof that it is valid.
pub fn read_validated(dir: &Path) -> Result<ValidatedModel> {
    read_tables(dir)?.validated().map_err(|e| e.in_file(dir))
}

/// Read a model folder's tables (each table's own checks) without the whole model's:
/// for a stage that changes the model before it validates it once
/// ([`Model::validated`]).
pub fn read_tables(dir: &Path) -> Result<Model> {
    let nodes_path = dir.join("nodes.parquet");
    if !nodes_path.exists() {
        return Err(WeftError::input(format!(
            "`{}` is not a model folder: it has no nodes.parquet",
            dir.display()
        ))
        .expected("a folder of model tables (docs/tables.md)")
        .hint("create one with `weft-weave rod --out DIR`"));
    }
    let mut r = Reading::new(dir);
    for table in TABLES {
        (table.read)(&mut r).map_err(|e| e.in_file(dir))?;
    }
    Ok(r.model)
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

/// Every table in turn, into `dir`.
fn write_tables(m: &Model, dir: &Path, prov: &Provenance) -> Result<()> {
    let w = Writing { dir, prov };
    for table in TABLES {
        (table.write)(m, &w)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_tables_are_the_codecs_files() {
        let files: Vec<&str> = table_files().collect();
        assert_eq!(files, MODEL_TABLES);
    }
}
