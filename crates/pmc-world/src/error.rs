//! Why a world file could not be created, opened, read or written.

use crate::format::{APPLICATION_ID, FORMAT_VERSION};
use pmc_edit::BrushError;
use rusqlite::ErrorCode;
use std::path::PathBuf;

/// A failure of the world file. Each variant says what happened and what to do about it.
///
/// Refusals ([`NotFound`](WorldError::NotFound) to [`Corrupt`](WorldError::Corrupt)) are decided
/// before anything is written: a file that is refused is left byte-for-byte as it was.
#[derive(Debug, thiserror::Error)]
pub enum WorldError {
    /// `open` on a path where no file exists.
    #[error("{}: no such world file; create it first (pmc edit with planet options, or World::create)", .path.display())]
    NotFound {
        /// The path that was opened.
        path: PathBuf,
    },
    /// `create` on a path that already exists (any file, world or not).
    #[error("{}: the file already exists and is never overwritten; open it instead, or choose another path", .path.display())]
    Exists {
        /// The path that was to be created.
        path: PathBuf,
    },
    /// The file is empty (0 bytes): not a world.
    #[error("{}: the file is empty, so it is not a PMC world; delete it or choose another path (it was left untouched)", .path.display())]
    Empty {
        /// The path that was opened.
        path: PathBuf,
    },
    /// The file is not an SQLite database (a text file, an image, random bytes, a directory).
    #[error("{}: not a PMC world: {detail}; check the path (the file was left untouched)", .path.display())]
    NotSqlite {
        /// The path that was opened.
        path: PathBuf,
        /// What was found instead.
        detail: String,
    },
    /// The file is an SQLite database of some other application.
    #[error(
        "{}: an SQLite database but not a PMC world (application_id {application_id:#010x}, a world has {:#010x}); check the path (the file was left untouched)",
        .path.display(), APPLICATION_ID
    )]
    Foreign {
        /// The path that was opened.
        path: PathBuf,
        /// The application id found in the file's header.
        application_id: u32,
    },
    /// The world was written in a newer format version than this program reads.
    #[error(
        "{}: a PMC world of format version {version}, newer than this program reads (version {}); upgrade pmc to open it (the file was left untouched)",
        .path.display(), FORMAT_VERSION
    )]
    Newer {
        /// The path that was opened.
        path: PathBuf,
        /// The version found (`PRAGMA user_version`).
        version: u32,
    },
    /// The file is shorter than its own header says: it was cut (an interrupted copy or download).
    #[error(
        "{}: the world file is truncated: its header says {expected} bytes but it holds {actual}; copy it again, or restore it from a backup",
        .path.display()
    )]
    Truncated {
        /// The path that was opened.
        path: PathBuf,
        /// Size in bytes the header announces.
        expected: u64,
        /// Size in bytes of the file.
        actual: u64,
    },
    /// The file is a PMC world whose structure is damaged (SQLite reports corruption, a table or
    /// a required value is missing or invalid).
    #[error("{}: the world file is corrupt: {detail}; restore it from a backup", .path.display())]
    Corrupt {
        /// The path of the world.
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },
    /// One stored edit does not decode to a valid brush operation (edited by hand or by another
    /// tool). Names the row.
    #[error(
        "{}: edit {id} (row {id} of table edits) is invalid: {detail}; fix or delete that row, or restore the world from a backup",
        .path.display()
    )]
    BadEdit {
        /// The path of the world.
        path: PathBuf,
        /// The row id of the edit.
        id: i64,
        /// What is wrong with it.
        detail: String,
    },
    /// `append` was given an operation that `BrushOp::new` would refuse.
    #[error("invalid edit, not stored: {0}")]
    InvalidEdit(#[from] BrushError),
    /// The world's planet is made of a terrain this program does not know (a preset added by a
    /// newer version, say). Fix: upgrade pmc.
    #[error("{}: the planet uses the terrain {terrain}, which this pmc does not know; upgrade pmc to open it (the file was left untouched)", .path.display())]
    UnknownTerrain {
        /// The world file.
        path: PathBuf,
        /// The terrain as stored.
        terrain: String,
    },
    /// The operating system refused a file operation.
    #[error("{}: {source}; check that the directory exists and is writable", .path.display())]
    Io {
        /// The path involved.
        path: PathBuf,
        /// The system's error.
        #[source]
        source: std::io::Error,
    },
    /// SQLite failed for another reason (locked by another program, read-only, disk full, ...).
    #[error("{}: SQLite error: {source}; {}", .path.display(), sqlite_hint(.source))]
    Sqlite {
        /// The path of the world.
        path: PathBuf,
        /// SQLite's error.
        #[source]
        source: rusqlite::Error,
    },
}

/// What to do about an SQLite error, in words.
fn sqlite_hint(e: &rusqlite::Error) -> &'static str {
    match e.sqlite_error_code() {
        Some(ErrorCode::DatabaseBusy | ErrorCode::DatabaseLocked) => {
            "another program holds the world locked; close it and try again"
        }
        Some(ErrorCode::ReadOnly) => "the world or its directory is read-only; make both writable",
        Some(ErrorCode::DiskFull) => {
            "the disk is full: could not write; nothing of it was saved: free some space and try again"
        }
        Some(ErrorCode::CannotOpen | ErrorCode::PermissionDenied) => {
            "check that the file and its directory exist and are readable and writable"
        }
        Some(ErrorCode::SystemIoFailure) if is_write_failure(e) => {
            "could not write to the disk (full, or past a file size limit); nothing of it was saved: free \
             some space and try again"
        }
        Some(ErrorCode::SystemIoFailure) => "the disk reported an I/O error; check it and try again",
        _ => "try again; if it persists, check the file with `sqlite3 FILE 'PRAGMA integrity_check'`",
    }
}

/// Whether `e` is SQLite failing to write, sync or grow a file (`SQLITE_IOERR_WRITE`, `_FSYNC`,
/// `_TRUNCATE`, `_SHORT_READ` aside): what a full disk or a file size limit gives.
fn is_write_failure(e: &rusqlite::Error) -> bool {
    use rusqlite::ffi;
    matches!(
        e,
        rusqlite::Error::SqliteFailure(f, _)
            if [ffi::SQLITE_IOERR_WRITE, ffi::SQLITE_IOERR_FSYNC, ffi::SQLITE_IOERR_TRUNCATE, ffi::SQLITE_IOERR_DIR_FSYNC]
                .contains(&f.extended_code)
    )
}

/// The result type of this crate.
pub type Result<T, E = WorldError> = std::result::Result<T, E>;

/// Maps an SQLite error on `path`: corruption becomes [`WorldError::Corrupt`], anything else
/// [`WorldError::Sqlite`].
pub(crate) fn sqlite(path: &std::path::Path, e: rusqlite::Error) -> WorldError {
    match e.sqlite_error_code() {
        Some(ErrorCode::DatabaseCorrupt | ErrorCode::NotADatabase) => WorldError::Corrupt {
            path: path.to_path_buf(),
            detail: format!("SQLite reports: {e}"),
        },
        _ => WorldError::Sqlite {
            path: path.to_path_buf(),
            source: e,
        },
    }
}
