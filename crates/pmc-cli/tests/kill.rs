//! SIGKILL at any moment never leaves a half-written file under the output's name: `pmc dem
//! import`, `pmc generate` (GLB, PLY, OBJ) and a world's first creation by `pmc edit` are each
//! killed after a spread of delays (from before the work starts to after it ends); after every
//! kill the output's name holds nothing, or a whole file that its reader accepts. Each writer
//! writes a temporary file beside the output and renames it at the end.

#![cfg(unix)]

use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

/// A test's folder, removed when the test passes (kept for a look when it fails): the exports of
/// ten runs are over 100 MB, and left behind they filled the disk of a machine that ran the
/// suite often.
struct TestDir(PathBuf);

impl std::ops::Deref for TestDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TestDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TestDir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

fn dir(test: &str) -> TestDir {
    let d = std::env::temp_dir().join(format!("pmc-cli-kill-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    TestDir(d)
}

fn fixture(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../pmc-dem/tests/fixtures")
        .join(name)
        .to_str()
        .unwrap()
        .to_string()
}

/// The delays (ms) the runs are killed after, from at once on; a last run is left to finish.
const DELAYS_MS: [u64; 9] = [0, 2, 5, 10, 20, 40, 80, 160, 320];

/// Runs `pmc args` (with `{out}` replaced by `out`) and kills it after each delay, checking the
/// output after each kill with `whole`; returns how many runs were killed before the file was
/// there, and how many ended (or were killed) with it whole. A run that finished before its kill
/// counts as whole; so does the last, never killed.
fn kill_runs(d: &Path, name: &str, args: &[&str], whole: fn(&Path)) -> (usize, usize) {
    let (mut absent, mut present) = (0, 0);
    let delays = DELAYS_MS.iter().map(|&ms| Some(ms)).chain([None]);
    for (n, delay) in delays.enumerate() {
        let out = d.join(format!("{n}-{name}"));
        let args: Vec<String> = args.iter().map(|a| a.replace("{out}", out.to_str().unwrap())).collect();
        let mut child = Command::new(env!("CARGO_BIN_EXE_pmc"))
            .args(&args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("pmc starts");
        if let Some(ms) = delay {
            std::thread::sleep(Duration::from_millis(ms));
            let _ = child.kill(); // SIGKILL on Unix; an error when it already ended
        }
        let status = child.wait().unwrap();
        assert!(
            status.success() || (delay.is_some() && status.signal() == Some(9)),
            "{name} killed after {delay:?} ms: {status:?}"
        );
        if out.exists() {
            whole(&out);
            present += 1;
        } else {
            assert!(
                status.signal() == Some(9),
                "{name}: pmc succeeded without writing {}",
                out.display()
            );
            absent += 1;
        }
    }
    eprintln!("{name}: {absent} killed before the file was there, {present} whole");
    (absent, present)
}

fn whole_pmcdem(p: &Path) {
    let dem = pmc_dem::CubeDem::open(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    dem.verify().unwrap_or_else(|e| panic!("{}: {e}", p.display()));
}

/// A GLB whose header's length is the file's and whose JSON chunk parses.
fn whole_glb(p: &Path) {
    let b = std::fs::read(p).unwrap();
    assert!(b.len() >= 20 && &b[0..4] == b"glTF", "{}: not a GLB", p.display());
    let le = |i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap()) as usize;
    assert_eq!(le(8), b.len(), "{}: the header's length is not the file's", p.display());
    let json_len = le(12);
    serde_json::from_slice::<serde_json::Value>(&b[20..20 + json_len]).expect("the JSON chunk parses");
}

/// A binary PLY whose header's counts match the file's length (positions, normals, colours:
/// `pmc generate`'s vertex layout, and triangles of three `u32`).
fn whole_ply(p: &Path) {
    let b = std::fs::read(p).unwrap();
    let end = b.windows(11).position(|w| w == b"end_header\n").expect("a PLY header") + 11;
    let header = String::from_utf8_lossy(&b[..end]);
    let count = |what: &str| -> usize {
        header
            .lines()
            .find_map(|l| l.strip_prefix(&format!("element {what} ")))
            .and_then(|n| n.trim().parse().ok())
            .unwrap_or_else(|| panic!("{}: no {what} count", p.display()))
    };
    let vertex_bytes: usize = header
        .lines()
        .skip_while(|l| !l.starts_with("element vertex"))
        .skip(1)
        .take_while(|l| l.starts_with("property"))
        .map(|l| match l.split_whitespace().nth(1) {
            Some("float") | Some("int") | Some("uint") => 4,
            Some("double") => 8,
            Some("uchar") | Some("char") => 1,
            Some("ushort") | Some("short") => 2,
            other => panic!("{}: property type {other:?}", p.display()),
        })
        .sum();
    let (v, f) = (count("vertex"), count("face"));
    assert_eq!(
        b.len(),
        end + v * vertex_bytes + f * 13,
        "{}: length against the header",
        p.display()
    );
}

/// An OBJ that ends with its last face line, whole.
fn whole_obj(p: &Path) {
    let t = std::fs::read_to_string(p).unwrap();
    assert!(t.ends_with('\n'), "{}: cut off", p.display());
    assert!(t.lines().any(|l| l.starts_with("f ")), "{}: no face", p.display());
}

fn whole_world(p: &Path) {
    let w = pmc_world::World::open(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    w.integrity_check().unwrap();
}

#[test]
fn a_killed_dem_import_leaves_nothing_or_a_whole_file() {
    let d = dir("dem");
    let (absent, present) = kill_runs(
        &d,
        "earth.pmcdem",
        &[
            "dem",
            "import",
            &fixture("etopo60.cdf"),
            "-o",
            "{out}",
            "--level",
            "6",
            "--quiet",
        ],
        whole_pmcdem,
    );
    assert!(
        absent > 0 && present > 0,
        "kills did not span the import: {absent} absent, {present} whole"
    );
    // nothing but the outputs and the writers' temporary files
    for e in std::fs::read_dir(&d).unwrap() {
        let name = e.unwrap().file_name().into_string().unwrap();
        assert!(
            name.ends_with(".pmcdem") || name.contains(".tmp") || name.starts_with('.'),
            "{name}"
        );
    }
}

#[test]
fn a_killed_export_leaves_nothing_or_a_whole_file() {
    let d = dir("export");
    for (name, whole) in [
        ("p.glb", whole_glb as fn(&Path)),
        ("p.ply", whole_ply),
        ("p.obj", whole_obj),
    ] {
        let (absent, present) = kill_runs(
            &d,
            name,
            &[
                "generate",
                "--quiet",
                "--preset",
                "earthlike",
                "--seed",
                "7",
                "--n-c",
                "4",
                "-o",
                "{out}",
            ],
            whole,
        );
        assert!(
            absent > 0 && present > 0,
            "{name}: kills did not span the export: {absent} absent, {present} whole"
        );
    }
}

#[test]
fn a_killed_world_creation_leaves_nothing_or_a_whole_world() {
    let d = dir("world");
    let (absent, present) = kill_runs(
        &d,
        "w.pmcw",
        &[
            "edit", "--world", "{out}", "--n-c", "2", "--n-t", "8", "add", "--at", "0,0", "--radius", "3",
        ],
        whole_world,
    );
    assert!(
        absent > 0 && present > 0,
        "kills did not span the creation: {absent} absent, {present} whole"
    );
}
