//! Exporting to a file: pick the format from the extension, write a temporary file next to the
//! target, then rename it over the target.
//!
//! A failed export removes its temporary file and leaves the target as it was: no half-written
//! files, and an existing good file is never clobbered by a failed export.

use crate::{glb, obj, ply, ExportError, ExportMeta, Format};
use pmc_mesh::ChunkMesh;
use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// What an export wrote.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExportStats {
    /// Size of the file in bytes.
    pub bytes: u64,
    /// Terrain vertices written: per chunk for GLB, after welding for OBJ and PLY. The sea is not
    /// counted.
    pub vertices: u64,
    /// Terrain triangles written (the sea is not counted).
    pub triangles: u64,
    /// Chunk meshes written (those with triangles).
    pub meshes: usize,
}

/// Writes `meshes` to `path` in the format its extension names (`.glb`, `.obj`, `.ply`).
///
/// The data goes to a hidden temporary file in the same directory, which is flushed to disk and
/// then renamed over `path`; on any error the temporary file is removed and `path` is untouched.
/// Errors name the path and say how to fix the problem (missing directory, permission denied,
/// unsupported extension, inconsistent mesh, ...).
///
/// ```no_run
/// # fn main() -> Result<(), pmc_formats::ExportError> {
/// let meshes: Vec<pmc_mesh::ChunkMesh> = Vec::new();
/// let meta = pmc_formats::ExportMeta { generator: "pmc 0.1.0".into(), ..Default::default() };
/// let stats = pmc_formats::export(std::path::Path::new("out/planet.glb"), &meshes, &meta)?;
/// println!("{} bytes, {} triangles", stats.bytes, stats.triangles);
/// # Ok(())
/// # }
/// ```
pub fn export(path: &Path, meshes: &[ChunkMesh], meta: &ExportMeta) -> Result<ExportStats, ExportError> {
    let format = Format::from_path(path)?;
    if path.is_dir() {
        return Err(ExportError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    match fs::metadata(&dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            let e = io::Error::other(format!("'{}' is not a directory", dir.display()));
            return Err(file_error(path, e));
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(ExportError::DirectoryMissing {
                path: path.to_path_buf(),
                dir,
            });
        }
        Err(e) => return Err(file_error(path, e)),
    }

    let (tmp_path, mut file) = create_temp(&dir, path)?;
    let result = write_and_sync(format, meshes, meta, &mut file, path).and_then(|stats| {
        drop(file);
        if let Ok(m) = fs::metadata(path) {
            // Keep the permissions of the file being replaced.
            let _ = fs::set_permissions(&tmp_path, m.permissions());
        }
        fs::rename(&tmp_path, path).map_err(|e| file_error(path, e))?;
        Ok(stats)
    });
    if result.is_err() {
        let _ = fs::remove_file(&tmp_path);
    }
    result
}

fn write_and_sync(
    format: Format,
    meshes: &[ChunkMesh],
    meta: &ExportMeta,
    file: &mut File,
    path: &Path,
) -> Result<ExportStats, ExportError> {
    let stats = match format {
        Format::Glb => glb::write(meshes, meta, &mut *file),
        Format::Obj => obj::write(meshes, meta, &mut *file),
        Format::Ply => ply::write(meshes, meta, &mut *file),
    }
    .map_err(|e| match e {
        ExportError::Write(e) => file_error(path, e),
        e => e,
    })?;
    file.sync_all().map_err(|e| file_error(path, e))?;
    Ok(stats)
}

/// Creates a new, uniquely named hidden file next to `path`.
fn create_temp(dir: &Path, path: &Path) -> Result<(PathBuf, File), ExportError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.{}-{n}.tmp", std::process::id()));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => return Ok((tmp, f)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists && n < u64::from(u32::MAX) => continue,
            Err(e) => return Err(file_error(path, e)),
        }
    }
}

/// Maps an I/O error on `path` to the matching [`ExportError`].
fn file_error(path: &Path, e: io::Error) -> ExportError {
    match e.kind() {
        io::ErrorKind::PermissionDenied => ExportError::PermissionDenied {
            path: path.to_path_buf(),
            source: e,
        },
        io::ErrorKind::NotFound => ExportError::DirectoryMissing {
            path: path.to_path_buf(),
            dir: path.parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf),
        },
        _ => ExportError::File {
            path: path.to_path_buf(),
            source: e,
        },
    }
}

/// A writer that counts the bytes passed through it.
pub(crate) struct Counting<W> {
    inner: W,
    bytes: u64,
}

impl<W: Write> Counting<W> {
    pub(crate) fn new(inner: W) -> Self {
        Counting { inner, bytes: 0 }
    }

    /// Bytes written so far.
    pub(crate) fn bytes(&self) -> u64 {
        self.bytes
    }
}

impl<W: Write> Write for Counting<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.bytes += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn io_errors_map_to_variants_that_name_the_path() {
        let p = Path::new("some/dir/planet.glb");
        let e = file_error(p, io::Error::from(io::ErrorKind::PermissionDenied));
        assert!(matches!(e, ExportError::PermissionDenied { .. }));
        assert!(e.to_string().contains("some/dir/planet.glb") && e.to_string().contains("permission"));
        let e = file_error(p, io::Error::from(io::ErrorKind::NotFound));
        assert!(matches!(e, ExportError::DirectoryMissing { ref dir, .. } if dir == Path::new("some/dir")));
        let e = file_error(p, io::Error::other("disk full"));
        assert!(e.to_string().contains("disk full") && e.to_string().contains("unchanged"));
    }

    #[test]
    fn counting_counts() {
        let mut c = Counting::new(Vec::new());
        c.write_all(b"abcde").unwrap();
        assert_eq!(c.bytes(), 5);
    }
}
