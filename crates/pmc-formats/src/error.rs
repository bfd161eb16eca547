//! The one error type of every export function.

use std::path::PathBuf;

/// Why an export failed. Every message says what went wrong and how to fix it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The output path has no extension, or one that names no supported format.
    ///
    /// Happens in [`Format::from_path`](crate::Format::from_path) and so in
    /// [`export`](crate::export). Fix: end the file name in `.glb`, `.obj` or `.ply`.
    #[error(
        "cannot tell the export format of '{}': {}; use a file name ending in .glb, .obj or .ply",
        path.display(),
        match extension { Some(e) => format!("extension '.{e}' is not supported"), None => "it has no extension".to_string() }
    )]
    UnsupportedFormat {
        /// The path that was given.
        path: PathBuf,
        /// Its extension, if it has one.
        extension: Option<String>,
    },

    /// A chunk mesh's buffers disagree (for example fewer normals than positions, an index past
    /// the last vertex, or a non-finite coordinate).
    ///
    /// Happens before anything is written. It points at a bug in whatever built the mesh; fix the
    /// mesher, or drop the offending chunk.
    #[error("chunk mesh #{index} ({name}) cannot be exported: {reason}; this is a bug in whatever built the mesh")]
    InvalidMesh {
        /// Position of the mesh in the slice that was passed in.
        index: usize,
        /// The chunk key as text, or `chunk-N` when the mesh has none.
        name: String,
        /// What is inconsistent.
        reason: String,
    },

    /// The [`ExportMeta`](crate::ExportMeta) cannot be written (for example a sea radius that is
    /// not a positive finite number).
    ///
    /// Fix: pass a positive finite `sea_radius`, or `None` for no sea.
    #[error("invalid export metadata: {0}")]
    InvalidMeta(String),

    /// The output would exceed a hard limit of the format (a GLB larger than 4 GiB, more than
    /// 2^32 - 1 vertices in a welded OBJ/PLY mesh).
    ///
    /// Fix: export fewer chunks (a smaller region or a coarser level of detail), or split the
    /// planet over several files.
    #[error("the export is too large: {0}; export fewer chunks or split the planet over several files")]
    TooLarge(String),

    /// The directory the output file should go in does not exist.
    ///
    /// Happens in [`export`](crate::export) before anything is written. Fix: create the directory
    /// (`mkdir -p`) or choose another path.
    #[error("cannot write '{}': directory '{}' does not exist; create it first or choose another path", path.display(), dir.display())]
    DirectoryMissing {
        /// The output path.
        path: PathBuf,
        /// The missing directory.
        dir: PathBuf,
    },

    /// The output path names a directory.
    ///
    /// Fix: add a file name such as `planet.glb` to the path.
    #[error("cannot write '{}': it is a directory; add a file name such as 'planet.glb'", path.display())]
    IsDirectory {
        /// The output path.
        path: PathBuf,
    },

    /// The operating system refused to create or replace the file.
    ///
    /// Fix: check the permissions of the file and of its directory, or choose a directory you can
    /// write to.
    #[error(
        "cannot write '{}': permission denied; check the permissions of the file and its directory, or choose another path",
        path.display()
    )]
    PermissionDenied {
        /// The output path.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },

    /// Any other I/O failure while writing a file (disk full, device error, ...). The file at
    /// `path` is left as it was before the export.
    ///
    /// Fix: free disk space or check the device, then export again.
    #[error("cannot write '{}': {source}; the previous file (if any) is unchanged", path.display())]
    File {
        /// The output path.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },

    /// An I/O failure while streaming to the writer passed to `write_glb`, `write_obj` or
    /// `write_ply`.
    ///
    /// Fix: depends on the writer; for files, check disk space and permissions.
    #[error("write failed: {0}")]
    Write(#[from] std::io::Error),

    /// The glTF JSON could not be serialised. Should never happen; please report it.
    #[error("cannot serialise the glTF JSON: {0}; this is a bug in pmc-formats")]
    Json(#[from] serde_json::Error),
}
