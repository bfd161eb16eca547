//! `pmc tiles bake`: a planet as a folder of 3D Tiles; a killed bake leaves only whole files
//! and resumes to the same bytes; bad options are refused before any work.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

fn pmc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pmc"))
        .args(args)
        .output()
        .expect("pmc runs")
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-cli-tiles-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// A small planet with five levels: 6 x 16^2 x 2 level-0 chunks.
const PLANET: [&str; 10] = [
    "--preset", "moon", "--n-c", "16", "--n-t", "8", "--d-c", "2", "--d-b", "900",
];

fn files(d: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut todo = vec![d.to_path_buf()];
    while let Some(x) = todo.pop() {
        let Ok(entries) = std::fs::read_dir(&x) else { continue };
        for e in entries {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else {
                out.insert(
                    p.strip_prefix(d).unwrap().to_string_lossy().into_owned(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

/// Every file of the tileset proper is whole: glTF and subtree files as long as their headers
/// say, JSON that parses.
fn assert_whole(all: &BTreeMap<String, Vec<u8>>) {
    for (name, bytes) in all {
        if name.starts_with(".partial") {
            continue;
        }
        if name.ends_with(".glb") {
            assert_eq!(&bytes[..4], b"glTF", "{name}");
            assert_eq!(
                u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
                bytes.len(),
                "{name}"
            );
        } else if name.ends_with(".subtree") {
            assert_eq!(&bytes[..4], b"subt", "{name}");
            let len = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
            assert_eq!(24 + len(8) + len(16), bytes.len(), "{name}");
        } else {
            assert!(name.ends_with(".json"), "{name}");
            serde_json::from_slice::<serde_json::Value>(bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }
}

#[test]
fn a_bake_writes_a_tileset_and_reports_each_level() {
    let d = dir("bake");
    let mut args = vec!["tiles", "bake"];
    args.extend(PLANET);
    args.extend(["-o", d.to_str().unwrap(), "--frame", "sphere"]);
    let out = pmc(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("level  4:"), "{text}");
    assert!(text.contains("frame sphere"), "{text}");
    let all = files(&d);
    assert_whole(&all);
    let ts: serde_json::Value = serde_json::from_slice(&all["tileset.json"]).unwrap();
    assert_eq!(ts["asset"]["version"], "1.1");
    assert_eq!(ts["extras"]["pmc"]["terrain"], "preset:moon:7");
    std::fs::remove_dir_all(&d).unwrap();
}

fn bake_args(out: &Path) -> Vec<String> {
    let mut v: Vec<String> = ["tiles", "bake"].iter().map(|s| s.to_string()).collect();
    v.extend(PLANET.iter().map(|s| s.to_string()));
    v.extend([
        "-o".to_string(),
        out.to_str().unwrap().to_string(),
        "--quiet".to_string(),
    ]);
    v
}

/// SIGKILL at a spread of moments: each time, every file in the tileset is whole; the bake run
/// again to the end gives the bytes of a bake never killed.
#[test]
fn a_killed_bake_resumes_to_the_same_bytes() {
    let clean = dir("clean");
    let o = Command::new(env!("CARGO_BIN_EXE_pmc"))
        .args(bake_args(&clean))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let want = files(&clean);
    let d = dir("killed");
    let mut killed = 0;
    for ms in [150u64, 400, 700, 1000, 1500] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_pmc"))
            .args(bake_args(&d))
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(ms));
        if child.try_wait().unwrap().is_none() {
            child.kill().unwrap();
            killed += 1;
        }
        child.wait().unwrap();
        assert_whole(&files(&d));
    }
    assert!(killed > 0, "no run was killed before it ended");
    let o = Command::new(env!("CARGO_BIN_EXE_pmc"))
        .args(bake_args(&d))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(files(&d), want);
    std::fs::remove_dir_all(&clean).unwrap();
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn bad_options_are_refused_before_any_work() {
    let d = dir("bad");
    let o = d.to_str().unwrap();
    for (args, says) in [
        (vec!["--region", "95,0,100"], "latitude"),
        (vec!["--region", "10,20"], "expected 3 numbers"),
        (vec!["--region", "10,20,-5"], "radius"),
        (vec!["--max-level", "40"], "--max-level 40"),
    ] {
        let mut all = vec!["tiles", "bake", "--preset", "moon", "--n-c", "4", "--n-t", "8", "-o", o];
        all.extend(args);
        let out = pmc(&all);
        assert_eq!(out.status.code(), Some(2), "{all:?}");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(e.contains(says), "{all:?}: {e}");
    }
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("mine.txt"), b"keep").unwrap();
    let out = pmc(&["tiles", "bake", "--preset", "moon", "--n-c", "4", "--n-t", "8", "-o", o]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not empty"));
    assert_eq!(std::fs::read(d.join("mine.txt")).unwrap(), b"keep");
    std::fs::remove_dir_all(&d).unwrap();
}
