//! The constants and schemas of format `pmc-world` versions 1 and 2 (docs/specs/world-sqlite-v2.md,
//! docs/specs/world-sqlite-v1.md), and
//! the recognition of a file from its first 100 bytes, before SQLite ever touches it.

use crate::error::{Result, WorldError};
use std::io::Read;
use std::path::Path;

/// `PRAGMA application_id` of every PMC world: the ASCII bytes "PMCW", big-endian.
pub const APPLICATION_ID: u32 = u32::from_be_bytes(*b"PMCW");

/// `PRAGMA user_version` of the format version written; also the `version` row of table `meta`.
pub const FORMAT_VERSION: u32 = 2;

/// The oldest format version read (and edited in place, keeping its version).
pub const OLDEST_FORMAT_VERSION: u32 = 1;

/// The `format` row of table `meta`.
pub const FORMAT_NAME: &str = "pmc-world";

/// The schema of version 2, created in one transaction together with the header values. Version
/// 1 differs only in table `planet`, which held `preset` and `seed` instead of `terrain`.
pub(crate) const SCHEMA_V2: &str = "
CREATE TABLE meta (
    key   TEXT PRIMARY KEY NOT NULL,
    value TEXT NOT NULL
) WITHOUT ROWID;

CREATE TABLE planet (
    id      INTEGER PRIMARY KEY CHECK (id = 1),
    terrain TEXT NOT NULL CHECK (length(terrain) BETWEEN 1 AND 4096),
    n_c    INTEGER NOT NULL CHECK (typeof(n_c) = 'integer' AND n_c >= 1),
    n_t    INTEGER NOT NULL CHECK (typeof(n_t) = 'integer' AND n_t >= 1),
    d_b    NOT NULL CHECK (typeof(d_b) = 'real'),
    l_d    NOT NULL CHECK (typeof(l_d) = 'real'),
    d_c    INTEGER NOT NULL CHECK (typeof(d_c) = 'integer' AND d_c >= 1)
);

CREATE TABLE edits (
    id       INTEGER PRIMARY KEY AUTOINCREMENT,
    kind     TEXT NOT NULL CHECK (kind IN ('add', 'remove', 'smooth', 'flatten', 'paint')),
    center_x CHECK (typeof(center_x) = 'real'),
    center_y CHECK (typeof(center_y) = 'real'),
    center_z CHECK (typeof(center_z) = 'real'),
    radius   CHECK (typeof(radius) = 'real'),
    strength CHECK (typeof(strength) = 'real'),
    material INTEGER CHECK ((kind = 'paint') = (material IS NOT NULL) AND (material IS NULL OR material BETWEEN 0 AND 255)),
    active   INTEGER NOT NULL DEFAULT 1 CHECK (active IN (0, 1))
);
";

/// Size of the SQLite database header.
const HEADER_LEN: usize = 100;
/// The first 16 bytes of every SQLite 3 database.
const SQLITE_MAGIC: &[u8; 16] = b"SQLite format 3\0";

/// Reads the first 100 bytes of `path` (read-only; nothing is written) and refuses everything
/// that is not a PMC world of a version this program reads.
pub(crate) fn probe(path: &Path) -> Result<()> {
    let io = |source| WorldError::Io {
        path: path.to_path_buf(),
        source,
    };
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(WorldError::NotFound {
                path: path.to_path_buf(),
            })
        }
        Err(e) => return Err(io(e)),
    };
    let not_sqlite = |detail: &str| WorldError::NotSqlite {
        path: path.to_path_buf(),
        detail: detail.to_string(),
    };
    if meta.is_dir() {
        return Err(not_sqlite("it is a directory"));
    }
    let len = meta.len();
    if len == 0 {
        return Err(WorldError::Empty {
            path: path.to_path_buf(),
        });
    }
    let mut head = Vec::with_capacity(HEADER_LEN);
    std::fs::File::open(path)
        .and_then(|f| f.take(HEADER_LEN as u64).read_to_end(&mut head))
        .map_err(io)?;
    if !head.starts_with(SQLITE_MAGIC) {
        return Err(not_sqlite(&describe(&head)));
    }
    if head.len() < HEADER_LEN {
        return Err(not_sqlite(&format!(
            "it starts like an SQLite database but holds only {len} bytes, fewer than one header"
        )));
    }
    let be32 = |at: usize| u32::from_be_bytes([head[at], head[at + 1], head[at + 2], head[at + 3]]);
    let application_id = be32(68);
    if application_id != APPLICATION_ID {
        return Err(WorldError::Foreign {
            path: path.to_path_buf(),
            application_id,
        });
    }
    let version = be32(60);
    if version > FORMAT_VERSION {
        return Err(WorldError::Newer {
            path: path.to_path_buf(),
            version,
        });
    }
    let corrupt = |detail: String| WorldError::Corrupt {
        path: path.to_path_buf(),
        detail,
    };
    if version == 0 {
        return Err(corrupt(
            "the header carries the PMC application id but no format version (user_version 0)".into(),
        ));
    }
    let page_size = match u16::from_be_bytes([head[16], head[17]]) {
        1 => 65536u64,
        p if p >= 512 && p.is_power_of_two() => u64::from(p),
        p => return Err(corrupt(format!("the header's page size {p} is invalid"))),
    };
    // SQLite only plays back a journal whose header is written (a zero first byte marks an
    // unfinished or finished one, which it ignores and overwrites).
    let mut first = [0u8; 1];
    let hot_journal = std::fs::File::open(journal_path(path))
        .and_then(|mut f| f.read(&mut first))
        .is_ok_and(|n| n == 1 && first[0] != 0);
    // The in-header page count is valid when the change counter (offset 24) equals the
    // version-valid-for number (offset 92). A hot journal may legitimately disagree with the file
    // size until SQLite rolls it back, so the size is only judged without one.
    let pages = u64::from(be32(28));
    if !hot_journal && pages > 0 && head[24..28] == head[92..96] && len < pages * page_size {
        return Err(WorldError::Truncated {
            path: path.to_path_buf(),
            expected: pages * page_size,
            actual: len,
        });
    }
    Ok(())
}

/// The rollback journal SQLite keeps beside `path` during a write transaction.
pub(crate) fn journal_path(path: &Path) -> std::path::PathBuf {
    let mut s = path.as_os_str().to_os_string();
    s.push("-journal");
    s.into()
}

/// A few words on what a non-SQLite file looks like.
fn describe(head: &[u8]) -> String {
    const KNOWN: &[(&[u8], &str)] = &[
        (b"\x89PNG\r\n\x1a\n", "a PNG image"),
        (b"glTF", "a GLB (binary glTF) file"),
        (b"ply\n", "a PLY mesh"),
        (b"PK\x03\x04", "a zip archive"),
        (b"\x1f\x8b", "a gzip file"),
        (b"%PDF", "a PDF document"),
        (b"\x7fELF", "an executable"),
    ];
    if let Some((_, what)) = KNOWN.iter().find(|(magic, _)| head.starts_with(magic)) {
        return format!("it is {what}, not an SQLite database");
    }
    // The 100-byte prefix may end inside a multi-byte character: judge the complete part.
    let text = match std::str::from_utf8(head) {
        Ok(s) => Some(s),
        Err(e) if e.error_len().is_none() => std::str::from_utf8(&head[..e.valid_up_to()]).ok(),
        Err(_) => None,
    };
    if text.is_some_and(|s| s.chars().all(|c| !c.is_control() || c.is_whitespace())) {
        "it is a text file, not an SQLite database".into()
    } else {
        "it does not start with the SQLite header (\"SQLite format 3\")".into()
    }
}
