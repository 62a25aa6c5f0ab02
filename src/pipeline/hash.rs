//! Content hashes (blake3) of files and folders, with a cache keyed by path, size and
//! modification time so that unchanged files are not read again.
//!
//! A folder's hash is the blake3 of its sorted `relative-path NUL file-hash` lines.
//! Names starting with `.` are skipped (temporary files of atomic writers).

use std::collections::{BTreeMap, HashMap};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::UNIX_EPOCH;

use crate::error::{Result, WeftError};

#[derive(Debug, Clone)]
struct Entry {
    size: u64,
    mtime_ns: i128,
    hash: String,
}

/// Hashes of a path: the combined hash and, for a folder, each file's.
#[derive(Debug, Clone, PartialEq)]
pub struct PathHash {
    pub hash: String,
    /// Relative file path (within the folder) → hash; empty for a plain file.
    pub files: BTreeMap<String, String>,
}

pub struct HashCache {
    file: PathBuf,
    map: HashMap<PathBuf, Entry>,
    dirty: bool,
    /// Files read and hashed (not served from the cache) since loading.
    pub hashed: usize,
}

fn stat(p: &Path) -> std::io::Result<(u64, i128)> {
    let md = std::fs::metadata(p)?;
    let mt = md
        .modified()?
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos() as i128)
        .unwrap_or(0);
    Ok((md.len(), mt))
}

impl HashCache {
    /// Load the cache from `file` (a missing or unreadable cache is an empty one).
    pub fn load(file: &Path) -> HashCache {
        let mut map = HashMap::new();
        if let Ok(s) = std::fs::read_to_string(file) {
            for line in s.lines() {
                let mut it = line.splitn(4, '\t');
                let (Some(sz), Some(mt), Some(h), Some(p)) =
                    (it.next(), it.next(), it.next(), it.next())
                else {
                    continue;
                };
                if let (Ok(size), Ok(mtime_ns)) = (sz.parse(), mt.parse()) {
                    map.insert(
                        PathBuf::from(p),
                        Entry {
                            size,
                            mtime_ns,
                            hash: h.to_string(),
                        },
                    );
                }
            }
        }
        HashCache {
            file: file.to_path_buf(),
            map,
            dirty: false,
            hashed: 0,
        }
    }

    /// Write the cache atomically (only if it changed).
    pub fn save(&mut self) -> Result<()> {
        if !self.dirty {
            return Ok(());
        }
        if let Some(d) = self.file.parent() {
            std::fs::create_dir_all(d).map_err(|e| WeftError::io(d, e))?;
        }
        let tmp = self
            .file
            .with_extension(format!("tmp-{}", super::host::process_tag()));
        let mut w = std::io::BufWriter::new(
            std::fs::File::create(&tmp).map_err(|e| WeftError::io(&tmp, e))?,
        );
        let mut keys: Vec<&PathBuf> = self.map.keys().collect();
        keys.sort();
        for k in keys {
            let e = &self.map[k];
            if let Some(ks) = k.to_str() {
                if !ks.contains('\n') {
                    writeln!(w, "{}\t{}\t{}\t{}", e.size, e.mtime_ns, e.hash, ks)
                        .map_err(|e| WeftError::io(&tmp, e))?;
                }
            }
        }
        w.flush().map_err(|e| WeftError::io(&tmp, e))?;
        drop(w);
        std::fs::rename(&tmp, &self.file).map_err(|e| WeftError::io(&self.file, e))?;
        self.dirty = false;
        Ok(())
    }

    /// Hash of one file.
    pub fn file(&mut self, p: &Path) -> Result<String> {
        let (size, mtime_ns) = stat(p).map_err(|e| WeftError::io(p, e))?;
        if let Some(e) = self.map.get(p) {
            if e.size == size && e.mtime_ns == mtime_ns {
                return Ok(e.hash.clone());
            }
        }
        let mut h = blake3::Hasher::new();
        let f = std::fs::File::open(p).map_err(|e| WeftError::io(p, e))?;
        h.update_reader(f).map_err(|e| WeftError::io(p, e))?;
        let hash = h.finalize().to_hex().to_string();
        self.hashed += 1;
        self.map.insert(
            p.to_path_buf(),
            Entry {
                size,
                mtime_ns,
                hash: hash.clone(),
            },
        );
        self.dirty = true;
        Ok(hash)
    }

    /// Hash of a file or folder; `None` when the path does not exist.
    pub fn path(&mut self, p: &Path) -> Result<Option<PathHash>> {
        let md = match std::fs::metadata(p) {
            Ok(m) => m,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(WeftError::io(p, e)),
        };
        if md.is_file() {
            return Ok(Some(PathHash {
                hash: self.file(p)?,
                files: BTreeMap::new(),
            }));
        }
        let mut files = BTreeMap::new();
        let mut stack = vec![p.to_path_buf()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).map_err(|e| WeftError::io(&d, e))? {
                let e = e.map_err(|e| WeftError::io(&d, e))?;
                let name = e.file_name();
                if name.to_string_lossy().starts_with('.') {
                    continue;
                }
                let path = e.path();
                let ft = e.file_type().map_err(|e| WeftError::io(&path, e))?;
                if ft.is_dir() {
                    stack.push(path);
                } else {
                    let rel = path
                        .strip_prefix(p)
                        .unwrap_or(&path)
                        .to_string_lossy()
                        .to_string();
                    files.insert(rel, self.file(&path)?);
                }
            }
        }
        let mut h = blake3::Hasher::new();
        for (k, v) in &files {
            h.update(k.as_bytes());
            h.update(b"\0");
            h.update(v.as_bytes());
            h.update(b"\n");
        }
        Ok(Some(PathHash {
            hash: h.finalize().to_hex().to_string(),
            files,
        }))
    }
}
