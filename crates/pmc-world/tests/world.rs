//! The world file: exact round trips, undo and redo across reopening, refusal of everything that
//! is not a readable world (without modifying it), and validation of rows edited by hand.

use pmc_density::presets::PresetKind;
use pmc_density::terrain::{DemSpec, Interpolation, TerrainSpec};
use pmc_edit::{BrushKind, BrushOp};
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use pmc_world::{EditId, World, WorldError, APPLICATION_ID};
use rusqlite::Connection;
use std::path::{Path, PathBuf};

/// A fresh, empty directory for one test.
fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-world-test-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn preset(name: &str, seed: u64) -> TerrainSpec {
    TerrainSpec::preset(name.parse::<PresetKind>().unwrap(), seed)
}

fn layout() -> Layout {
    Layout::new(2, 8, 200.0, 2.0, 1).unwrap()
}

fn new_world(d: &Path) -> (PathBuf, World) {
    let p = d.join("w.world");
    let w = World::create(&p, &preset("earthlike", 7), &layout()).unwrap();
    (p, w)
}

fn op(kind: BrushKind, x: f64, y: f64, z: f64, radius: f64, strength: f64) -> BrushOp {
    BrushOp::new(kind, DVec3::new(x, y, z), radius, strength).unwrap()
}

/// Deterministic pseudo-random numbers (SplitMix64).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn bits(o: &BrushOp) -> (String, Option<u8>, [u64; 5]) {
    let material = match o.kind {
        BrushKind::Paint { material } => Some(material),
        _ => None,
    };
    (
        o.kind.name().to_string(),
        material,
        [
            o.center.x.to_bits(),
            o.center.y.to_bits(),
            o.center.z.to_bits(),
            o.radius.to_bits(),
            o.strength.to_bits(),
        ],
    )
}

#[test]
fn every_brush_kind_round_trips_bit_for_bit() {
    let d = dir("round-trip");
    let (p, mut w) = new_world(&d);
    let mut rng = Rng(42);
    let mut ops = vec![
        // Values SQLite's REAL affinity would not keep: -0.0 (stored as integer 0), whole numbers.
        op(BrushKind::Add, -0.0, 0.0, -0.0, 4.0, 1.0),
        op(BrushKind::Remove, 1990.0, -3.0, 1e-300, 1e5, 5e-324),
        op(BrushKind::Smooth, f64::MAX, f64::MIN, f64::MIN_POSITIVE, 5e-324, 0.1),
        op(BrushKind::Flatten, 0.1 + 0.2, -(2f64.powi(60)), 1234.5678, 0.3, 0.7),
        op(BrushKind::Paint { material: 0 }, 1.0, 2.0, 3.0, 2.5, 1.0),
        op(BrushKind::Paint { material: 255 }, -1.0, -2.0, -3.0, 2.5, 0.5),
    ];
    let kinds = [
        BrushKind::Add,
        BrushKind::Remove,
        BrushKind::Smooth,
        BrushKind::Flatten,
        BrushKind::Paint { material: 3 },
    ];
    for i in 0..200 {
        let c = DVec3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5) * 4000.0;
        ops.push(op(
            kinds[i % 5],
            c.x,
            c.y,
            c.z,
            rng.unit() * 50.0 + 1e-3,
            rng.unit().max(1e-9),
        ));
    }
    let mut ids = Vec::new();
    for o in &ops {
        ids.push(w.append(o).unwrap());
    }
    assert!(ids.windows(2).all(|p| p[0] < p[1]), "ids grow: {ids:?}");
    assert_eq!(w.edit_count().unwrap(), ops.len() as u64);
    drop(w);
    let w = World::open(&p).unwrap();
    let back = w.active_edits().unwrap();
    assert_eq!(back.len(), ops.len());
    for (a, b) in ops.iter().zip(&back) {
        assert_eq!(bits(a), bits(b));
    }
    let entries = w.entries().unwrap();
    assert_eq!(entries.iter().map(|e| e.id).collect::<Vec<_>>(), ids);
    assert!(entries.iter().all(|e| e.active));
    w.integrity_check().unwrap();
}

#[test]
fn planet_parameters_round_trip() {
    let d = dir("planet");
    let p = d.join("w.world");
    let l = Layout::new(3, 17, 1744.123456789012, 0.1 + 0.2, 5).unwrap();
    World::create(&p, &preset("mars", u64::MAX), &l).unwrap();
    let w = World::open(&p).unwrap();
    let (terrain, back) = w.planet_params();
    assert_eq!(terrain, TerrainSpec::preset(PresetKind::Mars, u64::MAX));
    assert_eq!(w.format_version(), 2);
    assert_eq!(back, l);
    assert_eq!(back.d_b().to_bits(), l.d_b().to_bits());
    assert_eq!(back.l_d().to_bits(), l.l_d().to_bits());
}

#[test]
fn undo_and_redo_persist_across_reopening() {
    let d = dir("undo");
    let (p, mut w) = new_world(&d);
    let a = op(BrushKind::Add, 0.0, 0.0, 201.0, 3.0, 1.0);
    let b = op(BrushKind::Remove, 0.0, 201.0, 0.0, 3.0, 1.0);
    let c = op(BrushKind::Paint { material: 2 }, 201.0, 0.0, 0.0, 3.0, 1.0);
    let ids: Vec<EditId> = [a, b, c].iter().map(|o| w.append(o).unwrap()).collect();
    assert_eq!(w.undo().unwrap(), Some(ids[2]));
    assert_eq!(w.undo().unwrap(), Some(ids[1]));
    drop(w);

    let mut w = World::open(&p).unwrap();
    assert_eq!(w.active_edits().unwrap(), vec![a]);
    assert_eq!(w.edit_count().unwrap(), 1);
    assert_eq!(w.redo_count().unwrap(), 2);
    let e = w.entries().unwrap();
    assert_eq!(e.iter().map(|e| e.active).collect::<Vec<_>>(), [true, false, false]);
    assert_eq!(w.redo().unwrap(), Some(ids[1]));
    drop(w);

    let mut w = World::open(&p).unwrap();
    assert_eq!(w.active_edits().unwrap(), vec![a, b]);
    assert_eq!(w.redo().unwrap(), Some(ids[2]));
    assert_eq!(w.redo().unwrap(), None, "nothing left to redo");
    assert_eq!(w.active_edits().unwrap(), vec![a, b, c]);
    for _ in 0..3 {
        assert!(w.undo().unwrap().is_some());
    }
    assert_eq!(w.undo().unwrap(), None, "nothing left to undo");
    drop(w);
    let w = World::open(&p).unwrap();
    assert!(w.active_edits().unwrap().is_empty());
    assert_eq!(w.redo_count().unwrap(), 3);
    w.integrity_check().unwrap();
}

#[test]
fn an_append_after_undo_discards_the_redo_tail_and_never_reuses_ids() {
    let d = dir("tail");
    let (p, mut w) = new_world(&d);
    let a = op(BrushKind::Add, 0.0, 0.0, 201.0, 3.0, 1.0);
    let b = op(BrushKind::Remove, 0.0, 201.0, 0.0, 3.0, 1.0);
    let c = op(BrushKind::Smooth, 201.0, 0.0, 0.0, 3.0, 0.5);
    let n = op(BrushKind::Flatten, 0.0, -201.0, 0.0, 3.0, 0.5);
    let ia = w.append(&a).unwrap();
    let ib = w.append(&b).unwrap();
    let ic = w.append(&c).unwrap();
    w.undo().unwrap();
    w.undo().unwrap();
    let id = w.append(&n).unwrap();
    assert!(id > ic, "a new edit gets a new id: {id} after {ic}");
    assert_eq!(w.redo().unwrap(), None, "the redo tail is gone");
    drop(w);
    let w = World::open(&p).unwrap();
    let e = w.entries().unwrap();
    assert_eq!(e.iter().map(|e| e.id).collect::<Vec<_>>(), [ia, id]);
    assert_eq!(w.active_edits().unwrap(), vec![a, n]);
    assert!(ib < ic);
}

#[test]
fn create_refuses_any_existing_file_and_leaves_it_alone() {
    let d = dir("exists");
    let (p, mut w) = new_world(&d);
    w.append(&op(BrushKind::Add, 0.0, 0.0, 201.0, 3.0, 1.0)).unwrap();
    drop(w);
    let before = std::fs::read(&p).unwrap();
    let e = World::create(&p, &preset("moon", 1), &layout()).unwrap_err();
    assert!(matches!(e, WorldError::Exists { .. }), "{e}");
    assert!(e.to_string().contains("never overwritten"), "{e}");
    assert_eq!(std::fs::read(&p).unwrap(), before);

    let text = d.join("notes.txt");
    std::fs::write(&text, "my notes\n").unwrap();
    assert!(matches!(
        World::create(&text, &preset("moon", 1), &layout()),
        Err(WorldError::Exists { .. })
    ));
    assert_eq!(std::fs::read(&text).unwrap(), b"my notes\n");
    let empty = d.join("empty");
    std::fs::write(&empty, "").unwrap();
    assert!(matches!(
        World::create(&empty, &preset("moon", 1), &layout()),
        Err(WorldError::Exists { .. })
    ));
    assert_eq!(std::fs::read(&empty).unwrap(), b"");
    // Nothing but the files the test made is left in the directory (no temporary names).
    let mut names: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["empty", "notes.txt", "w.world"]);
}

#[test]
fn open_or_create_creates_only_when_missing() {
    let d = dir("open-or-create");
    let p = d.join("w.world");
    let (mut w, created) = World::open_or_create(&p, &preset("moon", 3), &layout()).unwrap();
    assert!(created);
    w.append(&op(BrushKind::Add, 0.0, 0.0, 201.0, 3.0, 1.0)).unwrap();
    drop(w);
    let (w, created) = World::open_or_create(&p, &preset("earthlike", 9), &Layout::default()).unwrap();
    assert!(!created);
    assert_eq!(
        w.planet_params().0,
        preset("moon", 3),
        "the existing world is kept as it is"
    );
    assert_eq!(w.edit_count().unwrap(), 1);
    let text = d.join("t.txt");
    std::fs::write(&text, "hello").unwrap();
    assert!(matches!(
        World::open_or_create(&text, &preset("moon", 3), &layout()),
        Err(WorldError::NotSqlite { .. })
    ));
    assert_eq!(std::fs::read(&text).unwrap(), b"hello");
}

#[test]
fn invalid_input_is_refused_before_writing() {
    let d = dir("invalid");
    let (_, mut w) = new_world(&d);
    let nan = BrushOp {
        kind: BrushKind::Add,
        center: DVec3::new(f64::NAN, 0.0, 0.0),
        radius: 1.0,
        strength: 1.0,
    };
    assert!(matches!(w.append(&nan), Err(WorldError::InvalidEdit(_))));
    let huge = BrushOp { radius: 1e9, ..nan };
    assert!(matches!(w.append(&huge), Err(WorldError::InvalidEdit(_))));
    assert_eq!(w.edit_count().unwrap(), 0);
}

/// Asserts that opening `p` fails as `want` says, and that the file is byte-identical afterwards
/// with no SQLite side file created beside it.
fn assert_refused(p: &Path, want: fn(&WorldError) -> bool, needle: &str) -> WorldError {
    let before = std::fs::read(p).unwrap();
    let e = World::open(p).unwrap_err();
    assert!(want(&e), "{}: unexpected error: {e:?}", p.display());
    assert!(e.to_string().contains(needle), "expected '{needle}' in: {e}");
    assert_eq!(std::fs::read(p).unwrap(), before, "{} was modified", p.display());
    for side in ["-journal", "-wal", "-shm"] {
        let mut s = p.as_os_str().to_os_string();
        s.push(side);
        assert!(!Path::new(&s).exists(), "{side} file created beside {}", p.display());
    }
    e
}

#[test]
fn files_that_are_not_worlds_are_refused_untouched() {
    let d = dir("not-worlds");
    let text = d.join("text.world");
    std::fs::write(&text, "preset = earthlike\nseed = 7\n").unwrap();
    assert_refused(&text, |e| matches!(e, WorldError::NotSqlite { .. }), "text file");

    let empty = d.join("empty.world");
    std::fs::write(&empty, "").unwrap();
    assert_refused(&empty, |e| matches!(e, WorldError::Empty { .. }), "empty");

    let random = d.join("random.world");
    let mut rng = Rng(7);
    let bytes: Vec<u8> = (0..10_000).map(|_| rng.next() as u8).collect();
    std::fs::write(&random, &bytes).unwrap();
    assert_refused(&random, |e| matches!(e, WorldError::NotSqlite { .. }), "SQLite header");

    let png = d.join("picture.world");
    let mut data = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x01\0\0\0\x01\x08\x06\0\0\0\x1f\x15\xc4\x89".to_vec();
    data.extend_from_slice(b"\0\0\0\0IEND\xaeB`\x82");
    std::fs::write(&png, &data).unwrap();
    assert_refused(&png, |e| matches!(e, WorldError::NotSqlite { .. }), "PNG");

    let short = d.join("short.world");
    std::fs::write(&short, b"SQLite format 3\0abc").unwrap();
    assert_refused(
        &short,
        |e| matches!(e, WorldError::NotSqlite { .. }),
        "fewer than one header",
    );

    let e = World::open(&d).unwrap_err();
    assert!(
        matches!(e, WorldError::NotSqlite { .. }) && e.to_string().contains("directory"),
        "{e}"
    );
    let e = World::open(d.join("missing.world")).unwrap_err();
    assert!(matches!(e, WorldError::NotFound { .. }), "{e}");
}

#[test]
fn a_foreign_sqlite_database_is_refused_untouched() {
    let d = dir("foreign");
    let p = d.join("app.db");
    {
        let c = Connection::open(&p).unwrap();
        c.execute_batch(
            "CREATE TABLE customers (id INTEGER PRIMARY KEY, name TEXT);
             INSERT INTO customers (name) VALUES ('Ada'), ('Grace');
             CREATE TABLE edits (x);",
        )
        .unwrap();
    }
    let e = assert_refused(
        &p,
        |e| matches!(e, WorldError::Foreign { application_id: 0, .. }),
        "not a PMC world",
    );
    assert!(e.to_string().contains("untouched"), "{e}");

    // Another application's id, in WAL mode.
    let wal = d.join("wal.db");
    {
        let c = Connection::open(&wal).unwrap();
        c.execute_batch("PRAGMA journal_mode = WAL; PRAGMA application_id = 1234; CREATE TABLE t (x);")
            .unwrap();
    }
    assert_refused(
        &wal,
        |e| {
            matches!(
                e,
                WorldError::Foreign {
                    application_id: 1234,
                    ..
                }
            )
        },
        "0x000004d2",
    );
}

#[test]
fn a_newer_world_is_refused_untouched() {
    let d = dir("newer");
    let (p, w) = new_world(&d);
    drop(w);
    Connection::open(&p)
        .unwrap()
        .pragma_update(None, "user_version", 3)
        .unwrap();
    let e = assert_refused(&p, |e| matches!(e, WorldError::Newer { version: 3, .. }), "upgrade pmc");
    assert!(e.to_string().contains("version 3"), "{e}");
}

#[test]
fn a_truncated_world_is_refused() {
    let d = dir("truncated");
    let (p, mut w) = new_world(&d);
    for i in 0..400 {
        w.append(&op(BrushKind::Smooth, f64::from(i), 1.0, 2.0, 3.0, 0.5))
            .unwrap();
    }
    drop(w);
    let full = std::fs::read(&p).unwrap();
    assert!(
        full.len() >= 4 * 4096,
        "the world spans several pages: {} bytes",
        full.len()
    );
    for cut in [full.len() / 2, full.len() / 2 + 123, full.len() - 1] {
        std::fs::write(&p, &full[..cut]).unwrap();
        let e = assert_refused(&p, |e| matches!(e, WorldError::Truncated { .. }), "truncated");
        let WorldError::Truncated { expected, actual, .. } = e else {
            unreachable!()
        };
        assert_eq!((expected, actual), (full.len() as u64, cut as u64));
    }
    std::fs::write(&p, &full[..60]).unwrap();
    assert_refused(
        &p,
        |e| matches!(e, WorldError::NotSqlite { .. }),
        "fewer than one header",
    );
}

#[test]
fn a_world_with_damaged_pages_is_reported_corrupt() {
    let d = dir("damaged");
    let (p, mut w) = new_world(&d);
    for i in 0..400 {
        w.append(&op(BrushKind::Add, f64::from(i), 1.0, 2.0, 3.0, 1.0)).unwrap();
    }
    drop(w);
    let mut bytes = std::fs::read(&p).unwrap();
    let mut rng = Rng(3);
    // Scribble over everything after the first two pages (the header and schema stay readable).
    for b in &mut bytes[2 * 4096..] {
        *b = rng.next() as u8;
    }
    std::fs::write(&p, &bytes).unwrap();
    let e = World::open(&p).unwrap_err();
    assert!(matches!(e, WorldError::Corrupt { .. }), "{e:?}");
    assert!(e.to_string().contains("restore it from a backup"), "{e}");
}

#[test]
fn a_pmc_header_without_the_tables_is_reported_corrupt() {
    let d = dir("no-tables");
    let p = d.join("w.world");
    {
        let c = Connection::open(&p).unwrap();
        let sql = format!("PRAGMA application_id = {APPLICATION_ID}; PRAGMA user_version = 1; CREATE TABLE t (x);");
        c.execute_batch(&sql).unwrap();
    }
    let e = World::open(&p).unwrap_err();
    assert!(matches!(e, WorldError::Corrupt { .. }), "{e:?}");
    assert!(e.to_string().contains("meta"), "{e}");
}

/// Changes a world with plain SQL, bypassing its CHECK constraints as a careless tool would.
fn hand_edit(p: &Path, sql: &str, value: impl rusqlite::ToSql) {
    let c = Connection::open(p).unwrap();
    c.pragma_update(None, "ignore_check_constraints", true).unwrap();
    c.execute(sql, [value]).unwrap();
}

#[test]
fn rows_edited_by_hand_are_validated_and_named() {
    let d = dir("hand");
    let (p, mut w) = new_world(&d);
    for i in 0..3 {
        w.append(&op(BrushKind::Add, f64::from(i), 0.0, 201.0, 3.0, 1.0))
            .unwrap();
    }
    drop(w);
    let pristine = std::fs::read(&p).unwrap();
    use rusqlite::types::Value;
    let cases = [
        (
            "NaN centre",
            "UPDATE edits SET center_x = ?1 WHERE id = 2",
            Value::Real(f64::NAN),
            "center_x holds NULL",
        ),
        (
            "NaN as text",
            "UPDATE edits SET center_y = ?1 WHERE id = 2",
            Value::Text("NaN".into()),
            "center_y holds the text \"NaN\"",
        ),
        (
            "infinite centre",
            "UPDATE edits SET center_z = ?1 WHERE id = 2",
            Value::Real(f64::INFINITY),
            "not a finite point",
        ),
        (
            "unknown kind",
            "UPDATE edits SET kind = ?1 WHERE id = 2",
            Value::Text("explode".into()),
            "unknown brush kind \"explode\"",
        ),
        (
            "negative radius",
            "UPDATE edits SET radius = ?1 WHERE id = 2",
            Value::Real(-1.0),
            "radius -1",
        ),
        (
            "paint without material",
            "UPDATE edits SET kind = ?1 WHERE id = 2",
            Value::Text("paint".into()),
            "without a material",
        ),
        (
            "material out of range",
            "UPDATE edits SET kind = 'paint', material = ?1 WHERE id = 2",
            Value::Integer(300),
            "not a material id from 0 to 255",
        ),
    ];
    for (what, sql, value, needle) in cases {
        std::fs::write(&p, &pristine).unwrap();
        hand_edit(&p, sql, value);
        let e = World::open(&p).unwrap_err();
        assert!(matches!(e, WorldError::BadEdit { id: 2, .. }), "{what}: {e:?}");
        let msg = e.to_string();
        assert!(
            msg.contains("edit 2") && msg.contains(needle),
            "{what}: expected '{needle}' in: {msg}"
        );
    }

    // A row changed by another program while the world is open is caught when it is read.
    std::fs::write(&p, &pristine).unwrap();
    let w = World::open(&p).unwrap();
    hand_edit(&p, "UPDATE edits SET center_x = ?1 WHERE id = 3", f64::NAN);
    for e in [w.active_edits().unwrap_err(), w.entries().unwrap_err()] {
        assert!(matches!(e, WorldError::BadEdit { id: 3, .. }), "{e:?}");
        assert!(e.to_string().contains("center_x holds NULL"), "{e}");
    }
    drop(w);

    // An undo flag that is neither 0 nor 1 is found on open.
    std::fs::write(&p, &pristine).unwrap();
    hand_edit(&p, "UPDATE edits SET active = ?1 WHERE id = 3", 7);
    let e = World::open(&p).unwrap_err();
    assert!(matches!(e, WorldError::BadEdit { id: 3, .. }), "{e:?}");
    // An undone edit before an active one breaks the undo order.
    std::fs::write(&p, &pristine).unwrap();
    hand_edit(&p, "UPDATE edits SET active = ?1 WHERE id = 1", 0);
    let e = World::open(&p).unwrap_err();
    assert!(
        matches!(e, WorldError::Corrupt { .. }) && e.to_string().contains("undo state"),
        "{e:?}"
    );
    // A broken planet row.
    std::fs::write(&p, &pristine).unwrap();
    hand_edit(&p, "UPDATE planet SET terrain = ?1", "preset:earthlike:-5");
    let e = World::open(&p).unwrap_err();
    assert!(
        matches!(e, WorldError::Corrupt { .. }) && e.to_string().contains("seed"),
        "{e:?}"
    );
}

#[test]
fn integrity_check_passes_after_normal_use_and_two_handles_share_a_world() {
    let d = dir("integrity");
    let (p, mut a) = new_world(&d);
    let mut b = World::open(&p).unwrap();
    let mut rng = Rng(11);
    for i in 0..300u32 {
        let w = if rng.next().is_multiple_of(2) { &mut a } else { &mut b };
        match rng.next() % 6 {
            0 => {
                w.undo().unwrap();
            }
            1 => {
                w.redo().unwrap();
            }
            _ => {
                w.append(&op(BrushKind::Remove, f64::from(i), 0.0, 201.0, 2.0, 1.0))
                    .unwrap();
            }
        }
    }
    a.integrity_check().unwrap();
    let ea = a.entries().unwrap();
    assert_eq!(ea, b.entries().unwrap(), "both handles see the same world");
    // The active edits form a prefix; the undone ones follow.
    let k = ea.iter().take_while(|e| e.active).count();
    assert!(ea[k..].iter().all(|e| !e.active));
    a.close().unwrap();
    b.close().unwrap();
    let w = World::open(&p).unwrap();
    w.integrity_check().unwrap();
    assert!(!Path::new(&format!("{}-journal", p.display())).exists());
}

#[test]
fn data_version_changes_only_for_changes_by_other_handles() {
    let d = dir("data-version");
    let (p, mut a) = new_world(&d);
    let mut b = World::open(&p).unwrap();
    let v0 = a.data_version().unwrap();
    a.append(&op(BrushKind::Add, 0.0, 0.0, 201.0, 2.0, 1.0)).unwrap();
    assert_eq!(
        a.data_version().unwrap(),
        v0,
        "a's own commit does not change a's data_version"
    );
    let b0 = b.data_version().unwrap();
    assert_eq!(b.data_version().unwrap(), b0, "reading does not change it");
    b.undo().unwrap();
    assert_ne!(a.data_version().unwrap(), v0, "b's commit is seen by a");
    let v1 = a.data_version().unwrap();
    assert_eq!(a.data_version().unwrap(), v1, "stable without further commits");
    b.redo().unwrap();
    assert_ne!(a.data_version().unwrap(), v1);
}

#[test]
fn an_elevation_model_terrain_round_trips() {
    let d = dir("dem-terrain");
    let p = d.join("w.world");
    let dem = TerrainSpec::Dem(DemSpec {
        path: "../data/earth: 5 minutes.pmcdem".into(),
        digest: "0123456789abcdef".into(),
        interpolation: Interpolation::Bilinear,
        seed: 42,
    });
    World::create(&p, &dem, &layout()).unwrap();
    let w = World::open(&p).unwrap();
    assert_eq!(w.terrain(), &dem);
    assert_eq!(w.planet_params(), (dem, layout()));
}

/// Writes a world of format version 1 (table `planet` with `preset` and `seed`), as pmc wrote
/// them before terrains became values, with one edit.
fn write_v1_world(p: &Path, preset: &str) {
    let conn = Connection::open(p).unwrap();
    conn.execute_batch(&format!(
        "PRAGMA application_id = {APPLICATION_ID};
         PRAGMA user_version = 1;
         CREATE TABLE meta (key TEXT PRIMARY KEY NOT NULL, value TEXT NOT NULL) WITHOUT ROWID;
         CREATE TABLE planet (
             id INTEGER PRIMARY KEY CHECK (id = 1), preset TEXT NOT NULL,
             seed TEXT NOT NULL CHECK (seed GLOB '[0-9]*' AND seed NOT GLOB '*[^0-9]*'),
             n_c INTEGER NOT NULL, n_t INTEGER NOT NULL, d_b NOT NULL, l_d NOT NULL, d_c INTEGER NOT NULL);
         CREATE TABLE edits (
             id INTEGER PRIMARY KEY AUTOINCREMENT,
             kind TEXT NOT NULL CHECK (kind IN ('add', 'remove', 'smooth', 'flatten', 'paint')),
             center_x CHECK (typeof(center_x) = 'real'), center_y CHECK (typeof(center_y) = 'real'),
             center_z CHECK (typeof(center_z) = 'real'), radius CHECK (typeof(radius) = 'real'),
             strength CHECK (typeof(strength) = 'real'),
             material INTEGER CHECK ((kind = 'paint') = (material IS NOT NULL) AND (material IS NULL OR material BETWEEN 0 AND 255)),
             active INTEGER NOT NULL DEFAULT 1 CHECK (active IN (0, 1)));
         INSERT INTO meta VALUES ('format', 'pmc-world'), ('version', '1'), ('writer', 'pmc-world 0.1.0');
         INSERT INTO planet VALUES (1, '{preset}', '9', 2, 8, 200.0, 2.0, 1);
         INSERT INTO edits (kind, center_x, center_y, center_z, radius, strength) VALUES ('remove', 0.0, 0.0, 210.0, 5.0, 1.0);"
    ))
    .unwrap();
}

#[test]
fn a_version_1_world_opens_and_stays_version_1() {
    let d = dir("v1");
    let p = d.join("old.world");
    write_v1_world(&p, "moon");
    let mut w = World::open(&p).unwrap();
    assert_eq!(w.format_version(), 1);
    assert_eq!(w.planet_params(), (preset("moon", 9), layout()));
    assert_eq!(
        w.active_edits().unwrap(),
        vec![op(BrushKind::Remove, 0.0, 0.0, 210.0, 5.0, 1.0)]
    );
    // Edits go on in place; the file keeps its version.
    w.append(&op(BrushKind::Add, 0.0, 0.0, 215.0, 3.0, 1.0)).unwrap();
    drop(w);
    let w = World::open(&p).unwrap();
    assert_eq!((w.format_version(), w.edit_count().unwrap()), (1, 2));
}

#[test]
fn an_unknown_terrain_is_refused_untouched() {
    let d = dir("unknown-terrain");
    let p = d.join("venus.world");
    write_v1_world(&p, "venus");
    let e = assert_refused(&p, |e| matches!(e, WorldError::UnknownTerrain { .. }), "upgrade pmc");
    assert!(e.to_string().contains("venus"), "{e}");
    let q = d.join("v2.world");
    World::create(&q, &preset("earth", 1), &layout()).unwrap();
    Connection::open(&q)
        .unwrap()
        .execute("UPDATE planet SET terrain = 'crater:1'", [])
        .unwrap();
    assert_refused(&q, |e| matches!(e, WorldError::UnknownTerrain { .. }), "upgrade pmc");
    Connection::open(&q)
        .unwrap()
        .execute("UPDATE planet SET terrain = 'dem:bicubic:x:00:a.pmcdem'", [])
        .unwrap();
    assert_refused(&q, |e| matches!(e, WorldError::Corrupt { .. }), "seed");
}

/// Another program holding the world locked (an exclusive transaction, as `sqlite3` leaves one
/// open): opening it, and an edit on a world already open, are refused after the busy timeout
/// with the reason and the file's name; the edits already in it are all there once the lock goes.
#[test]
fn a_world_locked_by_another_program_is_refused_with_the_reason_and_loses_nothing() {
    let d = dir("locked");
    let (p, mut w) = new_world(&d);
    let a = op(BrushKind::Add, 0.0, 0.0, 201.0, 3.0, 1.0);
    w.append(&a).unwrap();
    let other = Connection::open(&p).unwrap();
    other.execute_batch("BEGIN EXCLUSIVE").unwrap();
    let e = World::open(&p).unwrap_err();
    let shown = e.to_string();
    assert!(shown.contains("another program holds the world locked"), "{shown}");
    assert!(shown.contains(&p.display().to_string()), "{shown}");
    let e = w.append(&op(BrushKind::Remove, 0.0, 201.0, 0.0, 3.0, 1.0)).unwrap_err();
    assert!(e.to_string().contains("another program holds the world locked"), "{e}");
    other.execute_batch("ROLLBACK").unwrap();
    drop(other);
    assert_eq!(w.active_edits().unwrap(), vec![a]);
    drop(w);
    let w = World::open(&p).unwrap();
    assert_eq!(w.active_edits().unwrap(), vec![a]);
    w.integrity_check().unwrap();
}
