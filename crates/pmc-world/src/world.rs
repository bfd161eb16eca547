//! [`World`]: one SQLite file holding a planet's parameters and its edits in order, with undo and
//! redo, every acknowledged change committed durably before the call returns.

use crate::error::{sqlite, Result, WorldError};
use crate::format::{self, APPLICATION_ID, FORMAT_NAME, FORMAT_VERSION, OLDEST_FORMAT_VERSION, SCHEMA_V2};
use pmc_density::presets::PresetKind;
use pmc_density::terrain::TerrainSpec;
use pmc_edit::{BrushKind, BrushOp};
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use rusqlite::types::ValueRef;
use rusqlite::{params, Connection, OpenFlags, Row, TransactionBehavior};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// How long a call waits for another program's lock on the world before giving up.
const BUSY_TIMEOUT: Duration = Duration::from_secs(5);

/// The columns of table `edits`, in the order [`decode`] reads them.
const EDIT_COLUMNS: &str = "id, kind, center_x, center_y, center_z, radius, strength, material, active";

/// The id of a stored edit: its row id in table `edits`. Ids grow with every edit appended and
/// are never reused within a world, not even after an undone edit was discarded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct EditId(pub u64);

impl std::fmt::Display for EditId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// One stored edit with its id and undo state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    /// The edit's id.
    pub id: EditId,
    /// The brush operation, exactly as appended (every `f64` bit for bit).
    pub op: BrushOp,
    /// `false` when the edit was undone (it is kept for redo until the next append discards it).
    pub active: bool,
}

/// An open world file: planet parameters and the edit history.
///
/// Every method that changes the world commits its change durably (SQLite rollback journal with
/// `synchronous = EXTRA`) before it returns; a process killed at any moment leaves every
/// acknowledged change in the file. Several programs may open the same world: SQLite's locks
/// serialise their writes (a call waits up to 5 s for a lock).
pub struct World {
    conn: Connection,
    path: PathBuf,
    terrain: TerrainSpec,
    layout: Layout,
    version: u32,
}

impl std::fmt::Debug for World {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("World")
            .field("path", &self.path)
            .field("terrain", &self.terrain)
            .field("layout", &self.layout)
            .field("version", &self.version)
            .finish_non_exhaustive()
    }
}

impl World {
    /// Creates a new world file (format version 2) at `path` for the planet made of `terrain` on
    /// `layout`, with no edits. Refuses with [`WorldError::Exists`] when anything exists at `path` (it is never
    /// overwritten). The file is built under a temporary name in the same directory and linked
    /// into place only when complete, so `path` never holds a half-made world.
    pub fn create(path: impl AsRef<Path>, terrain: &TerrainSpec, layout: &Layout) -> Result<World> {
        let path = path.as_ref();
        if std::fs::symlink_metadata(path).is_ok() {
            return Err(WorldError::Exists {
                path: path.to_path_buf(),
            });
        }
        let tmp = temporary_path(path);
        let made = write_new_world(&tmp, terrain, layout).and_then(|()| link_into_place(&tmp, path));
        // The temporary name is gone after a successful link; remove it on every path.
        let _ = std::fs::remove_file(&tmp);
        let _ = std::fs::remove_file(format::journal_path(&tmp));
        made?;
        World::open(path)
    }

    /// Opens an existing world. The file's first 100 bytes are checked before SQLite opens it, so
    /// a file that is not a world of a readable version ([`WorldError::Empty`],
    /// [`NotSqlite`](WorldError::NotSqlite), [`Foreign`](WorldError::Foreign),
    /// [`Newer`](WorldError::Newer), [`Truncated`](WorldError::Truncated)) is refused without
    /// being modified. A world interrupted in the middle of a write is recovered (SQLite rolls
    /// the unfinished transaction back); then it is checked whole (`PRAGMA quick_check`, tables,
    /// planet parameters, every edit, undo state): a value changed by hand to something invalid
    /// gives [`WorldError::BadEdit`] naming its row.
    pub fn open(path: impl AsRef<Path>) -> Result<World> {
        let path = path.as_ref();
        format::probe(path)?;
        let conn = Connection::open_with_flags(
            path,
            OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX,
        )
        .map_err(|e| sqlite(path, e))?;
        configure(&conn, path)?;
        let (terrain, layout, version) = verify(&conn, path)?;
        // Only now, with the file known to be a world, may anything be written to it.
        set_durability(&conn, path)?;
        Ok(World {
            conn,
            path: path.to_path_buf(),
            terrain,
            layout,
            version,
        })
    }

    /// Opens the world at `path`, creating it with the given planet when no file exists there.
    /// Returns the world and whether it was created. The planet parameters of an existing world
    /// are not compared with the given ones: see [`World::planet_params`].
    pub fn open_or_create(path: impl AsRef<Path>, terrain: &TerrainSpec, layout: &Layout) -> Result<(World, bool)> {
        let path = path.as_ref();
        match World::create(path, terrain, layout) {
            Ok(w) => Ok((w, true)),
            Err(WorldError::Exists { .. }) => Ok((World::open(path)?, false)),
            Err(e) => Err(e),
        }
    }

    /// The path of the world file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The planet: its terrain and layout, as stored at creation (they never change).
    pub fn planet_params(&self) -> (TerrainSpec, Layout) {
        (self.terrain.clone(), self.layout)
    }

    /// The planet's terrain, as stored at creation.
    pub fn terrain(&self) -> &TerrainSpec {
        &self.terrain
    }

    /// The file's format version: 2 for worlds this program creates, 1 for older worlds (which
    /// are read and edited in place without being rewritten).
    pub fn format_version(&self) -> u32 {
        self.version
    }

    /// Appends an edit and returns its id. Any undone edits (the redo tail) are discarded first,
    /// in the same transaction. The edit is committed durably before this returns. Refuses an
    /// operation that [`BrushOp::new`] would refuse.
    pub fn append(&mut self, op: &BrushOp) -> Result<EditId> {
        let op = BrushOp::new(op.kind, op.center, op.radius, op.strength)?;
        let path = &self.path;
        let material = match op.kind {
            BrushKind::Paint { material } => Some(i64::from(material)),
            _ => None,
        };
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(|e| sqlite(path, e))?;
        tx.execute("DELETE FROM edits WHERE active = 0", [])
            .map_err(|e| sqlite(path, e))?;
        tx.execute(
            "INSERT INTO edits (kind, center_x, center_y, center_z, radius, strength, material, active)
             VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, 1)",
            params![
                op.kind.name(),
                op.center.x,
                op.center.y,
                op.center.z,
                op.radius,
                op.strength,
                material
            ],
        )
        .map_err(|e| sqlite(path, e))?;
        let id = tx.last_insert_rowid();
        tx.commit().map_err(|e| sqlite(path, e))?;
        edit_id(path, id)
    }

    /// Undoes the last active edit: marks it undone (kept for [`redo`](World::redo)) and returns
    /// its id, or `None` when no edit is active. Durable on return.
    pub fn undo(&mut self) -> Result<Option<EditId>> {
        self.step("SELECT max(id) FROM edits WHERE active = 1", 0)
    }

    /// Redoes the earliest undone edit and returns its id, or `None` when nothing is undone.
    /// Durable on return.
    pub fn redo(&mut self) -> Result<Option<EditId>> {
        self.step("SELECT min(id) FROM edits WHERE active = 0", 1)
    }

    /// Finds the edit `pick` selects and sets its `active` flag, in one write transaction.
    fn step(&mut self, pick: &str, active: i64) -> Result<Option<EditId>> {
        let path = &self.path;
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(|e| sqlite(path, e))?;
        check_undo_state(&tx, path)?;
        let id: Option<i64> = tx.query_row(pick, [], |r| r.get(0)).map_err(|e| sqlite(path, e))?;
        let Some(id) = id else { return Ok(None) };
        tx.execute("UPDATE edits SET active = ?1 WHERE id = ?2", params![active, id])
            .map_err(|e| sqlite(path, e))?;
        tx.commit().map_err(|e| sqlite(path, e))?;
        edit_id(path, id).map(Some)
    }

    /// The active edits, oldest first: the operations to apply, in order, to the planet.
    pub fn active_edits(&self) -> Result<Vec<BrushOp>> {
        Ok(self.read(true)?.into_iter().map(|e| e.op).collect())
    }

    /// Every stored edit, oldest first: the active ones, then the undone ones kept for redo.
    pub fn entries(&self) -> Result<Vec<Entry>> {
        self.read(false)
    }

    /// Reads and validates the edits (all, or the active ones) in one statement, so in one
    /// consistent snapshot of the file.
    fn read(&self, only_active: bool) -> Result<Vec<Entry>> {
        let path = &self.path;
        let filter = if only_active { "WHERE active = 1" } else { "" };
        let sql = format!("SELECT {EDIT_COLUMNS} FROM edits {filter} ORDER BY id");
        let mut stmt = self.conn.prepare_cached(&sql).map_err(|e| sqlite(path, e))?;
        let mut rows = stmt.query([]).map_err(|e| sqlite(path, e))?;
        let mut out = Vec::new();
        while let Some(row) = rows.next().map_err(|e| sqlite(path, e))? {
            out.push(decode(row, path)?);
        }
        Ok(out)
    }

    /// The number of active edits (those [`active_edits`](World::active_edits) returns).
    pub fn edit_count(&self) -> Result<u64> {
        self.count("SELECT count(*) FROM edits WHERE active = 1")
    }

    /// The number of undone edits kept for redo.
    pub fn redo_count(&self) -> Result<u64> {
        self.count("SELECT count(*) FROM edits WHERE active = 0")
    }

    fn count(&self, sql: &str) -> Result<u64> {
        let n: i64 = self
            .conn
            .query_row(sql, [], |r| r.get(0))
            .map_err(|e| sqlite(&self.path, e))?;
        Ok(n.unsigned_abs())
    }

    /// SQLite's `PRAGMA data_version` of this connection: it changes when another connection
    /// (another program, or another `World` on the same file) commits a change to the file, and
    /// stays the same for this world's own changes. A long-lived reader polls it to notice edits
    /// made by others, then reads the edits again.
    pub fn data_version(&self) -> Result<i64> {
        self.conn
            .query_row("PRAGMA data_version", [], |r| r.get(0))
            .map_err(|e| sqlite(&self.path, e))
    }

    /// Runs SQLite's full `PRAGMA integrity_check`; `Ok` when it answers "ok", else
    /// [`WorldError::Corrupt`] with its first findings.
    pub fn integrity_check(&self) -> Result<()> {
        pragma_check(&self.conn, &self.path, "integrity_check")
    }

    /// Closes the world, reporting an error SQLite meets while closing (dropping a `World` closes
    /// it too, silently). Nothing is pending: every change was committed when it returned.
    pub fn close(self) -> Result<()> {
        let path = self.path;
        self.conn.close().map_err(|(_, e)| sqlite(&path, e))
    }
}

fn edit_id(path: &Path, id: i64) -> Result<EditId> {
    u64::try_from(id)
        .ok()
        .filter(|&i| i > 0)
        .map(EditId)
        .ok_or_else(|| WorldError::BadEdit {
            path: path.to_path_buf(),
            id,
            detail: "edit ids are positive".into(),
        })
}

/// A name beside `path`, unique to this process and call, for building a new world.
fn temporary_path(path: &Path) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path.file_name().map(|s| s.to_string_lossy()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}-{n}.pmc-world-new", std::process::id()))
}

/// Writes a complete, empty world at `tmp` (which must not exist) in one transaction.
fn write_new_world(tmp: &Path, terrain: &TerrainSpec, layout: &Layout) -> Result<()> {
    let io = |source| WorldError::Io {
        path: tmp.to_path_buf(),
        source,
    };
    // Claim the name first: SQLite would happily open an existing file.
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(tmp)
        .map_err(io)?;
    let conn = Connection::open_with_flags(tmp, OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX)
        .map_err(|e| sqlite(tmp, e))?;
    set_durability(&conn, tmp)?;
    let sql = format!(
        "BEGIN IMMEDIATE;
         PRAGMA application_id = {APPLICATION_ID};
         PRAGMA user_version = {FORMAT_VERSION};
         {SCHEMA_V2}
         COMMIT;"
    );
    let write = || -> rusqlite::Result<()> {
        conn.execute_batch(&sql)?;
        let tx = conn.unchecked_transaction()?;
        tx.execute(
            "INSERT INTO meta (key, value) VALUES ('format', ?1), ('version', ?2), ('writer', ?3)",
            params![
                FORMAT_NAME,
                FORMAT_VERSION.to_string(),
                concat!("pmc-world ", env!("CARGO_PKG_VERSION"))
            ],
        )?;
        tx.execute(
            "INSERT INTO planet (id, terrain, n_c, n_t, d_b, l_d, d_c) VALUES (1, ?1, ?2, ?3, ?4, ?5, ?6)",
            params![
                terrain.to_string(),
                layout.n_c(),
                layout.n_t(),
                layout.d_b(),
                layout.l_d(),
                layout.d_c()
            ],
        )?;
        tx.commit()
    };
    write().map_err(|e| sqlite(tmp, e))?;
    conn.close().map_err(|(_, e)| sqlite(tmp, e))?;
    std::fs::File::open(tmp).and_then(|f| f.sync_all()).map_err(io)
}

/// Gives the finished world at `tmp` the name `path`, refusing if `path` appeared meanwhile.
fn link_into_place(tmp: &Path, path: &Path) -> Result<()> {
    let exists = || WorldError::Exists {
        path: path.to_path_buf(),
    };
    match std::fs::hard_link(tmp, path) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => return Err(exists()),
        // A file system without hard links: check, then rename (a small race window).
        Err(_) => {
            if std::fs::symlink_metadata(path).is_ok() {
                return Err(exists());
            }
            std::fs::rename(tmp, path).map_err(|source| WorldError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        }
    }
    // Make the new directory entry durable too (best effort: not every platform can open a
    // directory).
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// Connection settings that write nothing.
fn configure(conn: &Connection, path: &Path) -> Result<()> {
    let run = || -> rusqlite::Result<()> {
        conn.busy_timeout(BUSY_TIMEOUT)?;
        // A world may come from anyone: its schema must not call functions with side effects.
        conn.pragma_update(None, "trusted_schema", false)?;
        conn.pragma_update(None, "cell_size_check", true)?;
        conn.set_db_config(rusqlite::config::DbConfig::SQLITE_DBCONFIG_DEFENSIVE, true)?;
        Ok(())
    };
    run().map_err(|e| sqlite(path, e))
}

/// Rollback journal, deleted at commit, and `synchronous = EXTRA`: a commit returns only after
/// the database file, the journal and the journal's deletion (the commit point) reached the disk.
fn set_durability(conn: &Connection, path: &Path) -> Result<()> {
    let mode: String = conn
        .query_row("PRAGMA journal_mode = DELETE", [], |r| r.get(0))
        .map_err(|e| sqlite(path, e))?;
    if !mode.eq_ignore_ascii_case("delete") {
        return Err(WorldError::Corrupt {
            path: path.to_path_buf(),
            detail: format!("SQLite kept journal mode {mode:?} instead of \"delete\""),
        });
    }
    conn.pragma_update(None, "synchronous", "EXTRA")
        .map_err(|e| sqlite(path, e))
}

/// The findings of `PRAGMA quick_check` or `PRAGMA integrity_check` (`["ok"]` for a sound file).
fn pragma_findings(conn: &Connection, path: &Path, pragma: &str) -> Result<Vec<String>> {
    let run = || -> rusqlite::Result<Vec<String>> {
        let mut stmt = conn.prepare(&format!("PRAGMA {pragma}(20)"))?;
        let rows = stmt.query_map([], |r| r.get::<_, String>(0))?;
        rows.collect()
    };
    run().map_err(|e| sqlite(path, e))
}

fn is_ok(findings: &[String]) -> bool {
    findings.len() == 1 && findings[0] == "ok"
}

fn findings_error(path: &Path, pragma: &str, findings: &[String]) -> WorldError {
    WorldError::Corrupt {
        path: path.to_path_buf(),
        detail: format!("PRAGMA {pragma} reports: {}", findings.join("; ")),
    }
}

/// Runs `PRAGMA quick_check` or `PRAGMA integrity_check` and turns findings into an error.
fn pragma_check(conn: &Connection, path: &Path, pragma: &str) -> Result<()> {
    let findings = pragma_findings(conn, path, pragma)?;
    if is_ok(&findings) {
        Ok(())
    } else {
        Err(findings_error(path, pragma, &findings))
    }
}

/// Checks, with SQL, everything the header check could not: the file is sound, it is a world of
/// a version this program reads, its planet parameters are valid, its tables have the columns of
/// its version, every edit decodes to a valid brush operation and the undo state is consistent.
/// Returns the planet parameters and the format version.
fn verify(conn: &Connection, path: &Path) -> Result<(TerrainSpec, Layout, u32)> {
    let corrupt = |detail: String| WorldError::Corrupt {
        path: path.to_path_buf(),
        detail,
    };
    // The first read rolls back a hot journal, then checks every page. Violated CHECK and NOT
    // NULL constraints (values changed by hand) are reported below with the row they are in.
    let findings = pragma_findings(conn, path, "quick_check")?;
    let constraints_only = findings
        .iter()
        .all(|f| f.starts_with("CHECK constraint failed") || f.starts_with("NULL value in"));
    if !is_ok(&findings) && !constraints_only {
        return Err(findings_error(path, "quick_check", &findings));
    }
    let header = |name: &str| -> Result<i64> {
        conn.pragma_query_value(None, name, |r| r.get(0))
            .map_err(|e| sqlite(path, e))
    };
    let application_id = header("application_id")? as u32;
    if application_id != APPLICATION_ID {
        return Err(WorldError::Foreign {
            path: path.to_path_buf(),
            application_id,
        });
    }
    let version = header("user_version")? as u32;
    if version > FORMAT_VERSION {
        return Err(WorldError::Newer {
            path: path.to_path_buf(),
            version,
        });
    }
    if version < OLDEST_FORMAT_VERSION {
        return Err(corrupt(format!("format version {version} in the header")));
    }
    let meta = |key: &str| -> Result<String> {
        conn.query_row("SELECT value FROM meta WHERE key = ?1", [key], |r| {
            r.get::<_, String>(0)
        })
        .map_err(|e| corrupt(format!("table meta has no readable {key:?} row ({e})")))
    };
    let name = meta("format")?;
    if name != FORMAT_NAME {
        return Err(corrupt(format!("meta format is {name:?}, not {FORMAT_NAME:?}")));
    }
    let v = meta("version")?;
    if v != version.to_string() {
        return Err(corrupt(format!(
            "meta version {v:?} disagrees with the header's format version {version}"
        )));
    }
    let (terrain, layout) = read_planet(conn, path, version)?;
    let mut stmt = conn
        .prepare(&format!("SELECT {EDIT_COLUMNS} FROM edits ORDER BY id"))
        .map_err(|e| corrupt(format!("table edits is missing or lacks columns ({e})")))?;
    let mut rows = stmt.query([]).map_err(|e| sqlite(path, e))?;
    while let Some(row) = rows.next().map_err(|e| sqlite(path, e))? {
        decode(row, path)?;
    }
    check_undo_state(conn, path)?;
    if !is_ok(&findings) {
        return Err(findings_error(path, "quick_check", &findings));
    }
    Ok((terrain, layout, version))
}

/// Reads and validates the single row of table `planet` of a world of format `version`.
fn read_planet(conn: &Connection, path: &Path, version: u32) -> Result<(TerrainSpec, Layout)> {
    let corrupt = |detail: String| WorldError::Corrupt {
        path: path.to_path_buf(),
        detail: format!("planet parameters: {detail}"),
    };
    // Version 1 named the terrain by a preset and a seed; version 2 stores its canonical text.
    let terrain_columns = if version == 1 { "preset, seed" } else { "terrain, ''" };
    type Raw = (String, String, i64, i64, f64, f64, i64);
    let raw: Raw = conn
        .query_row(
            &format!("SELECT {terrain_columns}, n_c, n_t, d_b, l_d, d_c FROM planet WHERE id = 1"),
            [],
            |r| {
                Ok((
                    r.get(0)?,
                    r.get(1)?,
                    r.get(2)?,
                    r.get(3)?,
                    r.get(4)?,
                    r.get(5)?,
                    r.get(6)?,
                ))
            },
        )
        .map_err(|e| corrupt(format!("table planet has no readable row 1 ({e})")))?;
    let (text, seed, n_c, n_t, d_b, l_d, d_c) = raw;
    let terrain = if version == 1 {
        let seed: u64 = seed
            .parse()
            .map_err(|_| corrupt(format!("seed {seed:?} is not a decimal number from 0 to 2^64-1")))?;
        let kind = text.parse::<PresetKind>().map_err(|_| WorldError::UnknownTerrain {
            path: path.to_path_buf(),
            terrain: format!("preset '{text}'"),
        })?;
        TerrainSpec::preset(kind, seed)
    } else {
        text.parse::<TerrainSpec>().map_err(|e| match text.split(':').next() {
            Some("preset" | "dem") => corrupt(e.to_string()),
            _ => WorldError::UnknownTerrain {
                path: path.to_path_buf(),
                terrain: format!("{text:?}"),
            },
        })?
    };
    let count = |name: &str, v: i64| u32::try_from(v).map_err(|_| corrupt(format!("{name} = {v} is out of range")));
    let layout = Layout::new(count("n_c", n_c)?, count("n_t", n_t)?, d_b, l_d, count("d_c", d_c)?)
        .map_err(|e| corrupt(e.to_string()))?;
    Ok((terrain, layout))
}

/// The undo state is consistent: every `active` is 0 or 1, and every active edit precedes every
/// undone one (undone edits form the redo tail).
fn check_undo_state(conn: &Connection, path: &Path) -> Result<()> {
    let (bad, last_active, first_undone): (Option<i64>, Option<i64>, Option<i64>) = conn
        .query_row(
            "SELECT
                (SELECT id FROM edits WHERE typeof(active) != 'integer' OR active NOT IN (0, 1) ORDER BY id LIMIT 1),
                (SELECT max(id) FROM edits WHERE active = 1),
                (SELECT min(id) FROM edits WHERE active = 0)",
            [],
            |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)),
        )
        .map_err(|e| sqlite(path, e))?;
    if let Some(id) = bad {
        return Err(WorldError::BadEdit {
            path: path.to_path_buf(),
            id,
            detail: "column active must be 0 (undone) or 1 (active)".into(),
        });
    }
    if let (Some(a), Some(u)) = (last_active, first_undone) {
        if a > u {
            return Err(WorldError::Corrupt {
                path: path.to_path_buf(),
                detail: format!(
                    "undo state: edit {a} is active but the earlier edit {u} is undone (undone edits must all come after the active ones)"
                ),
            });
        }
    }
    Ok(())
}

/// A stored value, described for an error message.
fn describe(v: ValueRef<'_>) -> String {
    match v {
        ValueRef::Null => "NULL (SQLite stores a NaN as NULL)".into(),
        ValueRef::Integer(i) => format!("the integer {i}"),
        ValueRef::Real(f) => format!("the number {f}"),
        ValueRef::Text(t) => format!("the text {:?}", String::from_utf8_lossy(t)),
        ValueRef::Blob(b) => format!("a blob of {} bytes", b.len()),
    }
}

/// Decodes and validates one row of `SELECT {EDIT_COLUMNS}`.
fn decode(row: &Row<'_>, path: &Path) -> Result<Entry> {
    let get = |i: usize| row.get_ref(i).map_err(|e| sqlite(path, e));
    let id = match get(0)? {
        ValueRef::Integer(i) => i,
        v => {
            return Err(WorldError::Corrupt {
                path: path.to_path_buf(),
                detail: format!("an edit id is {}", describe(v)),
            })
        }
    };
    let bad = |detail: String| WorldError::BadEdit {
        path: path.to_path_buf(),
        id,
        detail,
    };
    let id = edit_id(path, id)?;
    let number = |i: usize, name: &str| -> Result<f64> {
        match get(i)? {
            ValueRef::Real(f) => Ok(f),
            // Exact: every integer up to 2^53 is an f64.
            ValueRef::Integer(n) if n.unsigned_abs() <= 1 << 53 => Ok(n as f64),
            v => Err(bad(format!("column {name} holds {}, not a number", describe(v)))),
        }
    };
    let material = match get(7)? {
        ValueRef::Null => None,
        ValueRef::Integer(m) => Some(
            u8::try_from(m).map_err(|_| bad(format!("column material holds {m}, not a material id from 0 to 255")))?,
        ),
        v => return Err(bad(format!("column material holds {}, not a material id", describe(v)))),
    };
    let kind = match get(1)? {
        ValueRef::Text(t) => match (t, material) {
            (b"add", None) => BrushKind::Add,
            (b"remove", None) => BrushKind::Remove,
            (b"smooth", None) => BrushKind::Smooth,
            (b"flatten", None) => BrushKind::Flatten,
            (b"paint", Some(material)) => BrushKind::Paint { material },
            (b"paint", None) => return Err(bad("a paint edit without a material (column material is NULL)".into())),
            (b"add" | b"remove" | b"smooth" | b"flatten", Some(m)) => {
                return Err(bad(format!(
                    "material {m} is set on a {} edit; only paint edits have one",
                    String::from_utf8_lossy(t)
                )))
            }
            _ => {
                return Err(bad(format!(
                    "unknown brush kind {:?} (known: add, remove, smooth, flatten, paint)",
                    String::from_utf8_lossy(t)
                )))
            }
        },
        v => return Err(bad(format!("column kind holds {}, not a brush name", describe(v)))),
    };
    let center = DVec3::new(number(2, "center_x")?, number(3, "center_y")?, number(4, "center_z")?);
    let op =
        BrushOp::new(kind, center, number(5, "radius")?, number(6, "strength")?).map_err(|e| bad(e.to_string()))?;
    let active = match get(8)? {
        ValueRef::Integer(0) => false,
        ValueRef::Integer(1) => true,
        v => return Err(bad(format!("column active holds {}, not 0 or 1", describe(v)))),
    };
    Ok(Entry { id, op, active })
}
