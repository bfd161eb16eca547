//! `pmc edit` as a user runs it: worlds created and edited, undo and redo, refusals that leave
//! files alone, and durability: every edit `pmc edit` acknowledged survives a SIGKILL at a
//! random moment.

use pmc_edit::{BrushKind, BrushOp};
use pmc_geometry::{LatLon, Layout};
use pmc_planet::{Planet, PresetKind};
use pmc_world::World;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pmc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pmc"))
        .args(args)
        .output()
        .expect("pmc runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// A fresh directory for one test.
fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-cli-edit-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A small sphere planet: radius 140 m, datum (the middle of the shell) 120 m.
const PLANET: [&str; 12] = [
    "--preset", "sphere", "--seed", "5", "--n-c", "1", "--n-t", "8", "--d-b", "100", "--l-d", "2.5",
];

fn planet() -> Planet {
    Planet::new(PresetKind::Sphere, 5, Layout::new(1, 8, 100.0, 2.5, 2).unwrap())
}

/// Runs `pmc edit --world W ARGS...`, expecting success; returns stdout.
fn edit_ok(world: &Path, args: &[&str]) -> (String, String) {
    let mut all = vec!["edit", "--world", world.to_str().unwrap()];
    all.extend_from_slice(args);
    let o = pmc(&all);
    assert!(o.status.success(), "{all:?} failed: {}", text(&o.stderr));
    (text(&o.stdout), text(&o.stderr))
}

/// Runs `pmc edit --world W ARGS...`, expecting a clear refusal containing `needle`.
fn edit_refused(world: &Path, args: &[&str], needle: &str) {
    let mut all = vec!["edit", "--world", world.to_str().unwrap()];
    all.extend_from_slice(args);
    let o = pmc(&all);
    let e = text(&o.stderr);
    assert!(!o.status.success(), "{all:?} should fail");
    assert_ne!(o.status.code(), Some(101), "{all:?} panicked: {e}");
    assert!(!e.contains("panicked"), "{all:?} panicked: {e}");
    assert!(e.contains(needle), "{all:?}: expected '{needle}' in: {e}");
}

/// The ids in `applied edit N: ...` lines.
fn applied_ids(stdout: &str) -> Vec<u64> {
    stdout
        .lines()
        .filter_map(|l| l.strip_prefix("applied edit "))
        .map(|l| l[..l.find(':').unwrap()].parse().unwrap())
        .collect()
}

#[test]
fn a_world_is_created_edited_and_listed() {
    let d = dir("create");
    let w = d.join("w.world");
    let mut args = PLANET.to_vec();
    args.extend(["add", "--at", "10,20,1.5", "--radius", "3"]);
    let (out, err) = edit_ok(&w, &args);
    assert!(err.contains("created world"), "{err}");
    assert_eq!(applied_ids(&out), [1]);
    // On the ground (no altitude) and with a named material.
    let (out, err) = edit_ok(&w, &["paint", "--at=-30,-40", "--radius", "2", "--material", "stone"]);
    assert!(!err.contains("created"), "{err}");
    assert_eq!(applied_ids(&out), [2]);
    let (out, _) = edit_ok(
        &w,
        &[
            "smooth",
            "--at",
            "0,0,0",
            "--radius",
            "4",
            "--strength",
            "0.25",
            "--repeat",
            "3",
        ],
    );
    assert_eq!(applied_ids(&out), [3, 4, 5]);

    let (list, _) = edit_ok(&w, &["--list"]);
    assert!(list.contains("5 active edits, 0 undone"), "{list}");
    assert!(
        list.contains("add") && list.contains("paint") && list.contains("material stone (0)"),
        "{list}"
    );
    let (json, _) = edit_ok(&w, &["--list", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["preset"], "sphere");
    assert_eq!(v["seed"], 5);
    let edits = v["edits"].as_array().unwrap();
    assert_eq!(edits.len(), 5);
    assert_eq!(edits[0]["kind"], "add");
    assert!((edits[0]["lat"].as_f64().unwrap() - 10.0).abs() < 1e-9);
    assert!((edits[0]["alt"].as_f64().unwrap() - 1.5).abs() < 1e-9);
    assert_eq!(edits[1]["material"]["name"], "stone");
    // Without ALT the centre is on the ground: the sphere preset's surface lies 0.37 l_d above
    // the middle of the shell (the datum).
    assert!(
        (edits[1]["alt"].as_f64().unwrap() - 0.37 * 2.5).abs() < 1e-6,
        "{}",
        edits[1]
    );
    let lons: Vec<f64> = edits[2..].iter().map(|e| e["lon"].as_f64().unwrap()).collect();
    assert!(
        (lons[1] - 0.01).abs() < 1e-9 && (lons[2] - 0.02).abs() < 1e-9,
        "--repeat steps 0.01 deg: {lons:?}"
    );

    // The file holds exactly what was asked.
    let world = World::open(&w).unwrap();
    let ops = world.active_edits().unwrap();
    let dir = LatLon::new(10.0, 20.0).unwrap().to_unit();
    let want = BrushOp::new(BrushKind::Add, dir * (planet().datum_radius() + 1.5), 3.0, 1.0).unwrap();
    assert_eq!(ops[0], want);
    assert_eq!(ops[1].kind, BrushKind::Paint { material: 0 });
    assert_eq!(ops[2].strength, 0.25);
}

#[test]
fn undo_and_redo_through_the_command_line() {
    let d = dir("undo");
    let w = d.join("w.world");
    let mut args = PLANET.to_vec();
    args.extend(["remove", "--at", "0,0,0", "--radius", "3", "--repeat", "3"]);
    edit_ok(&w, &args);
    let (out, _) = edit_ok(&w, &["--undo"]);
    assert!(out.contains("undid edit 3"), "{out}");
    let (out, _) = edit_ok(&w, &["--undo"]);
    assert!(out.contains("undid edit 2"), "{out}");
    let (list, _) = edit_ok(&w, &["--list"]);
    assert!(list.contains("1 active edits, 2 undone"), "{list}");
    let (out, _) = edit_ok(&w, &["--redo"]);
    assert!(out.contains("redid edit 2"), "{out}");
    // A new edit discards what is left to redo.
    let (out, _) = edit_ok(&w, &["flatten", "--at", "5,5,0", "--radius", "2", "--strength", "0.5"]);
    assert_eq!(applied_ids(&out), [4]);
    let (out, _) = edit_ok(&w, &["--redo"]);
    assert!(out.contains("nothing to redo"), "{out}");
    let (json, _) = edit_ok(&w, &["--list", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let ids: Vec<u64> = v["edits"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["id"].as_u64().unwrap())
        .collect();
    assert_eq!(ids, [1, 2, 4]);
    assert_eq!(v["undone"], 0);
    for _ in 0..3 {
        edit_ok(&w, &["--undo"]);
    }
    let (out, _) = edit_ok(&w, &["--undo"]);
    assert!(out.contains("nothing to undo"), "{out}");
}

#[test]
fn planet_options_that_disagree_with_the_world_are_refused() {
    let d = dir("mismatch");
    let w = d.join("w.world");
    let mut args = PLANET.to_vec();
    args.extend(["add", "--at", "0,0,0", "--radius", "3"]);
    edit_ok(&w, &args);
    let before = std::fs::read(&w).unwrap();
    edit_refused(
        &w,
        &["--preset", "moon", "add", "--at", "0,0,0", "--radius", "3"],
        "--preset moon (the world has sphere)",
    );
    edit_refused(
        &w,
        &["--seed", "6", "--d-b", "90", "--list"],
        "--seed 6 (the world has 5), --d-b 90.0 (the world has 100.0)",
    );
    edit_refused(&w, &["--n-t", "16", "--undo"], "--n-t 16 (the world has 8)");
    assert_eq!(std::fs::read(&w).unwrap(), before, "refused commands change nothing");
    // Options equal to the world's are fine; so is leaving them out.
    edit_ok(&w, &["--preset", "sphere", "--d-b", "100.0", "--n-t", "8", "--list"]);
    let mut again = PLANET.to_vec();
    again.extend(["add", "--at", "1,1,0", "--radius", "3"]);
    let (out, _) = edit_ok(&w, &again);
    assert_eq!(applied_ids(&out), [2]);
}

#[test]
fn files_that_are_not_worlds_are_refused_and_left_alone() {
    let d = dir("foreign");
    let db = d.join("shop.db");
    {
        let c = rusqlite::Connection::open(&db).unwrap();
        c.execute_batch(
            "CREATE TABLE orders (id INTEGER PRIMARY KEY, item TEXT); INSERT INTO orders (item) VALUES ('tea');",
        )
        .unwrap();
    }
    let notes = d.join("notes.txt");
    std::fs::write(&notes, "not a world\n").unwrap();
    let empty = d.join("empty.world");
    std::fs::write(&empty, "").unwrap();
    for (file, needle) in [
        (&db, "an SQLite database but not a PMC world"),
        (&notes, "text file"),
        (&empty, "empty"),
    ] {
        let before = std::fs::read(file).unwrap();
        edit_refused(file, &["add", "--at", "0,0,0", "--radius", "3"], needle);
        edit_refused(file, &["--undo"], needle);
        edit_refused(file, &["--list"], needle);
        assert_eq!(std::fs::read(file).unwrap(), before, "{} was modified", file.display());
    }
    let mut names: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["empty.world", "notes.txt", "shop.db"],
        "no side files were created"
    );
}

#[test]
fn bad_edits_are_refused_before_anything_is_written() {
    let d = dir("bad");
    let w = d.join("w.world");
    let mut create = PLANET.to_vec();
    create.extend(["add", "--at", "95,0", "--radius", "3"]);
    edit_refused(&w, &create, "latitude 95");
    assert!(!w.exists(), "a refused edit does not create the world");
    create.truncate(PLANET.len());
    create.extend(["add", "--at", "0,0,0", "--radius", "3"]);
    edit_ok(&w, &create);
    let before = std::fs::read(&w).unwrap();
    for (args, needle) in [
        (vec!["add", "--at", "0,NaN", "--radius", "3"], "longitude NaN"),
        (vec!["add", "--at", "0,0,inf", "--radius", "3"], "altitude"),
        (
            vec!["add", "--at", "0,0,-500", "--radius", "3"],
            "below the planet's centre",
        ),
        (vec!["add", "--at", "zero,0", "--radius", "3"], "not a number"),
        (vec!["add", "--at", "0,0", "--radius", "NaN"], "radius NaN"),
        (vec!["add", "--at", "0,0", "--radius", "-2"], "radius -2"),
        (vec!["add", "--at", "0,0", "--radius", "1e9"], "at most 100000"),
        (
            vec!["smooth", "--at", "0,0", "--radius", "2", "--strength", "2"],
            "strength 2",
        ),
        (
            vec!["paint", "--at", "0,0", "--radius", "2", "--material", "lava"],
            "unknown material 'lava'",
        ),
        (
            vec!["paint", "--at", "0,0", "--radius", "2", "--material", "7"],
            "unknown material '7'",
        ),
        (vec!["paint", "--at", "0,0", "--radius", "2"], "needs --material"),
        (
            vec!["add", "--at", "0,0", "--radius", "2", "--material", "stone"],
            "paint only",
        ),
        (vec!["add", "--radius", "2"], "needs --at"),
        (
            vec!["add", "--at", "0,0", "--radius", "2", "--repeat", "0"],
            "at least 1",
        ),
    ] {
        edit_refused(&w, &args, needle);
    }
    assert_eq!(std::fs::read(&w).unwrap(), before, "refused edits change nothing");
}

/// Deterministic pseudo-random numbers (SplitMix64), so every run kills at the same moments.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

/// Round `r` of the durability test: which brush `pmc edit` applies and where.
struct Round {
    brush: &'static str,
    kind: BrushKind,
    lat: f64,
    lon: f64,
    alt: f64,
    radius: f64,
    strength: f64,
}

impl Round {
    fn new(r: u32) -> Round {
        let (brush, kind) = [
            ("add", BrushKind::Add),
            ("remove", BrushKind::Remove),
            ("smooth", BrushKind::Smooth),
            ("flatten", BrushKind::Flatten),
            ("paint", BrushKind::Paint { material: 0 }),
        ][r as usize % 5];
        let r = f64::from(r);
        Round {
            brush,
            kind,
            lat: -70.0 + 9.5 * r,
            lon: -170.0 + 23.0 * r,
            alt: -3.0 + 0.5 * r,
            radius: 1.5 + 0.25 * r,
            strength: 1.0 - 0.05 * r,
        }
    }

    /// The operation `pmc edit --repeat` sends as its `k`-th edit (documented: longitude steps
    /// 0.01 degrees east per edit, centre at the datum plus the altitude).
    fn op(&self, datum: f64, k: u64) -> BrushOp {
        let dir = LatLon::new(self.lat, self.lon + k as f64 * 0.01).unwrap().to_unit();
        BrushOp::new(self.kind, dir * (datum + self.alt), self.radius, self.strength).unwrap()
    }
}

fn op_bits(o: &BrushOp) -> (String, [u64; 5]) {
    (
        format!("{:?}", o.kind),
        [o.center.x, o.center.y, o.center.z, o.radius, o.strength].map(f64::to_bits),
    )
}

/// The durability test. 15 rounds; each spawns `pmc edit ... --repeat 1000000`, which appends
/// edits in a tight loop and prints `applied edit ID` (flushed) after each append returns, and
/// kills it with SIGKILL after a pseudo-random 20-300 ms (SplitMix64, fixed seed: the same
/// sleeps every run). Then the world is reopened in this process: `PRAGMA integrity_check` must
/// pass and every acknowledged id must hold exactly the operation sent (recomputed from the
/// round and the edit's index); at most one more edit, committed but killed before it was
/// printed, may follow, and it too must be exact.
#[cfg(unix)]
#[test]
fn every_acknowledged_edit_survives_sigkill() {
    use std::io::{BufRead, BufReader};
    use std::os::unix::process::ExitStatusExt;
    use std::process::Stdio;
    use std::time::{Duration, Instant};

    const ROUNDS: u32 = 15;
    let start = Instant::now();
    let d = dir("durability");
    let w = d.join("w.world");
    let ws = w.to_str().unwrap().to_string();
    let mut args = PLANET.to_vec();
    args.extend(["add", "--at", "0,0,0", "--radius", "1"]);
    edit_ok(&w, &args);
    let datum = planet().datum_radius();
    let mut known = 1u64; // the highest id checked so far
    let mut rng = Rng(0x5EED_D15C);
    let (mut acked_total, mut unacked_total) = (0usize, 0usize);
    for r in 0..ROUNDS {
        let round = Round::new(r);
        let at = format!("--at={},{},{}", round.lat, round.lon, round.alt);
        let (radius, strength) = (round.radius.to_string(), round.strength.to_string());
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_pmc"));
        cmd.args(["edit", "--world", &ws])
            .args(PLANET)
            .args([round.brush, at.as_str(), "--radius", &radius, "--strength", &strength])
            .args(["--repeat", "1000000"]);
        if round.brush == "paint" {
            cmd.args(["--material", "stone"]);
        }
        let mut child = cmd
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("pmc starts");
        // Drain stdout as it comes, keeping only complete lines: an id is acknowledged once its
        // line is out.
        let stdout = child.stdout.take().unwrap();
        let reader = std::thread::spawn(move || {
            let mut ids = Vec::new();
            let mut r = BufReader::new(stdout);
            let mut line = Vec::new();
            while r.read_until(b'\n', &mut line).unwrap_or(0) > 0 {
                if line.ends_with(b"\n") {
                    ids.extend(applied_ids(&String::from_utf8_lossy(&line)));
                }
                line.clear();
            }
            ids
        });
        let sleep = 20 + rng.next() % 281;
        std::thread::sleep(Duration::from_millis(sleep));
        child.kill().expect("SIGKILL"); // std sends SIGKILL on Unix
        let status = child.wait().unwrap();
        let acked = reader.join().unwrap();
        let mut err = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
        assert_eq!(
            status.signal(),
            Some(9),
            "round {r}: pmc ended before the kill: {status:?}, {err}"
        );

        let world = World::open(&w).unwrap_or_else(|e| panic!("round {r}: reopening after SIGKILL: {e}"));
        world.integrity_check().unwrap();
        let entries = world.entries().unwrap();
        let new: Vec<_> = entries.iter().filter(|e| e.id.0 > known).collect();
        assert!(
            new.len() == acked.len() || new.len() == acked.len() + 1,
            "round {r}: {} edits acknowledged, {} in the file",
            acked.len(),
            new.len()
        );
        for (k, e) in new.iter().enumerate() {
            if let Some(&id) = acked.get(k) {
                assert_eq!(e.id.0, id, "round {r}: acknowledged edit {k} has another id");
            }
            assert!(e.active, "round {r}: edit {} is not active", e.id);
            let want = round.op(datum, k as u64);
            assert_eq!(
                op_bits(&e.op),
                op_bits(&want),
                "round {r}: edit {} differs from what was sent",
                e.id
            );
        }
        eprintln!(
            "round {r:2}: {:<7} killed after {sleep:3} ms: {:4} acknowledged, {} committed but unacknowledged",
            round.brush,
            acked.len(),
            new.len() - acked.len()
        );
        acked_total += acked.len();
        unacked_total += new.len() - acked.len();
        known = entries.last().map_or(known, |e| e.id.0.max(known));
        drop(world);
    }
    eprintln!(
        "{ROUNDS} rounds: {acked_total} acknowledged edits, all present and exact; {unacked_total} committed after the last acknowledgement; {:.1} s",
        start.elapsed().as_secs_f64()
    );
    assert!(acked_total >= 15, "too few edits to prove anything: {acked_total}");
    // The command line reads the world the kills left behind.
    let (json, _) = edit_ok(&w, &["--list", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(
        v["edits"].as_array().unwrap().len() as u64,
        World::open(&w).unwrap().edit_count().unwrap()
    );
    // The world goes on after the kills: an undo is a write, and a write leaves no journal.
    let (out, _) = edit_ok(&w, &["--undo"]);
    assert!(out.contains(&format!("undid edit {known}")), "{out}");
    assert!(
        !Path::new(&format!("{ws}-journal")).exists(),
        "a journal remains after a commit"
    );
}

/// Without an altitude a brush lands on the surface of the edited planet: digging twice in one
/// place goes deeper instead of hitting the untouched terrain again.
#[test]
fn digging_twice_in_one_place_goes_deeper() {
    let d = dir("dig-twice");
    let world = d.join("w.pmcw");
    let mut args: Vec<&str> = PLANET.to_vec();
    args.extend(["remove", "--at", "10,20", "--radius", "6"]);
    edit_ok(&world, &args);
    edit_ok(&world, &["remove", "--at", "10,20", "--radius", "6"]);
    let w = World::open(&world).unwrap();
    let ops = w.active_edits().unwrap();
    assert_eq!(ops.len(), 2);
    let (r1, r2) = (ops[0].center.length(), ops[1].center.length());
    assert!(
        r1 - r2 > 4.0,
        "the second dig starts at the bottom of the first: {r1} then {r2}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `pmc generate --world` exports the edited planet: a dig changes the exported mesh, and
/// planet options cannot be mixed with a world.
#[test]
fn generate_exports_the_edited_world() {
    let d = dir("generate-world");
    let world = d.join("w.pmcw");
    let plain = d.join("plain.ply");
    let edited = d.join("edited.ply");
    let mut gen: Vec<&str> = vec!["generate", "--quiet", "-o", plain.to_str().unwrap()];
    gen.extend(PLANET);
    let o = pmc(&gen);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let mut args: Vec<&str> = PLANET.to_vec();
    args.extend(["remove", "--at", "10,20", "--radius", "12"]);
    edit_ok(&world, &args);
    let o = pmc(&[
        "generate",
        "--quiet",
        "--world",
        world.to_str().unwrap(),
        "-o",
        edited.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let (a, b) = (std::fs::read(&plain).unwrap(), std::fs::read(&edited).unwrap());
    assert!(a != b, "the dig shows in the export");
    let o = pmc(&[
        "generate",
        "--world",
        world.to_str().unwrap(),
        "--preset",
        "moon",
        "-o",
        edited.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains("--preset"), "{}", text(&o.stderr));
    let o = pmc(&["generate", "--world", d.join("missing.pmcw").to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(!text(&o.stderr).contains("panicked"));
    let _ = std::fs::remove_dir_all(&d);
}

/// The disk filling during edits: `pmc edit --repeat` appends edits under a file size limit
/// (`prlimit --fsize`, with SIGXFSZ ignored, so that a write past the limit fails as on a full
/// disk) a few pages over the world's size. The edit that no longer fits is refused with a clear
/// error naming the world, the command fails with exit code 1 (not a panic, not a signal), and the world reopens
/// sound with every acknowledged edit exact; then, the limit gone, editing goes on.
#[cfg(target_os = "linux")]
#[test]
fn the_disk_filling_refuses_the_edit_and_keeps_every_acknowledged_one() {
    use std::process::Stdio;
    if Command::new("prlimit").arg("--version").output().is_err() {
        panic!("this test needs prlimit (util-linux)");
    }
    let d = dir("disk-full");
    let w = d.join("w.world");
    let mut args = PLANET.to_vec();
    args.extend(["add", "--at", "0,0,0", "--radius", "1"]);
    edit_ok(&w, &args);
    let size = std::fs::metadata(&w).unwrap().len();
    let limit = size + 16 * 1024;
    let round = Round::new(3);
    let at = format!("--at={},{},{}", round.lat, round.lon, round.alt);
    let script = format!("trap '' XFSZ; exec prlimit --fsize={limit} -- \"$0\" \"$@\"",);
    let o = Command::new("sh")
        .arg("-c")
        .arg(&script)
        .arg(env!("CARGO_BIN_EXE_pmc"))
        .args(["edit", "--world", w.to_str().unwrap()])
        .args(PLANET)
        .args([round.brush, at.as_str(), "--radius", &round.radius.to_string()])
        .args(["--strength", &round.strength.to_string(), "--repeat", "100000"])
        .stdin(Stdio::null())
        .output()
        .expect("pmc runs under prlimit");
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    let acked = applied_ids(&out);
    // exit code 1: the system failed (2 is for bad input)
    assert_eq!(
        o.status.code(),
        Some(1),
        "pmc did not refuse the edit cleanly: {:?}: {err}",
        o.status
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains(w.to_str().unwrap()),
        "the error does not name the world: {err}"
    );
    assert!(
        err.contains("could not write") && err.contains("nothing of it was saved"),
        "{err}"
    );
    assert!(
        acked.len() >= 5,
        "too few edits before the disk filled: {}",
        acked.len()
    );
    eprintln!(
        "{} edits acknowledged before the limit ({limit} bytes): {}",
        acked.len(),
        err.trim()
    );

    let world = World::open(&w).unwrap();
    world.integrity_check().unwrap();
    let entries = world.entries().unwrap();
    let new: Vec<_> = entries.iter().filter(|e| e.id.0 > 1).collect();
    assert_eq!(
        new.len(),
        acked.len(),
        "acknowledged {}, in the file {}",
        acked.len(),
        new.len()
    );
    let datum = planet().datum_radius();
    for (k, e) in new.iter().enumerate() {
        assert_eq!(e.id.0, acked[k]);
        assert_eq!(
            op_bits(&e.op),
            op_bits(&round.op(datum, k as u64)),
            "edit {} differs",
            e.id
        );
    }
    drop(world);
    // no journal left beside it, and editing goes on once there is room
    assert!(!d.join("w.world-journal").exists());
    let (out, _) = edit_ok(&w, &["--undo"]);
    assert!(out.contains("undid"), "{out}");
}
