//! The `pmc` command as a user runs it: outputs, determinism, and clear errors on bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pmc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pmc"))
        .args(args)
        .output()
        .expect("pmc runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pmc-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

const SMALL: [&str; 8] = ["--n-c", "2", "--n-t", "8", "--d-b", "200", "--l-d", "2"];

fn assert_refused(args: &[&str], needle: &str) {
    let o = pmc(args);
    let e = stderr(&o);
    assert!(!o.status.success(), "{args:?} should fail");
    assert!(!e.contains("panicked"), "{args:?} panicked: {e}");
    assert!(e.contains(needle), "{args:?}: expected '{needle}' in: {e}");
}

#[test]
fn info_prints_the_paper_formulas() {
    let o = pmc(&[
        "info", "--preset", "sphere", "--n-c", "4", "--n-t", "16", "--d-b", "100", "--l-d", "2", "--d-c", "3",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = String::from_utf8(o.stdout).unwrap();
    assert!(s.contains("chunks       288 "), "{s}");
    assert!(s.contains(&format!("voxels       {} ", 6 * 65 * 65 * 49)), "{s}");
    assert!(s.contains("radius       196 m"), "{s}");
    let o = pmc(&["info", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["chunks"], 768);
    assert_eq!(v["radius"], 2000.0);
    assert_eq!(v["preset"], "earthlike");
}

#[test]
fn info_describes_the_earth_and_its_levels_of_detail() {
    let o = pmc(&["info", "--preset", "earth"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = String::from_utf8(o.stdout).unwrap();
    for needle in [
        "n_c = 262144, n_t = 32, d_b = 6354616 m, l_d = 1 m, d_c = 1024",
        "sea          radius 6371000.00 m",
        "19 levels of detail, 0 to 18",
    ] {
        assert!(s.contains(needle), "no '{needle}' in:\n{s}");
    }
    // One table row per level, from 1 m voxels to one chunk per face side.
    let rows: Vec<Vec<&str>> = s
        .lines()
        .map(|l| l.split_whitespace().collect::<Vec<_>>())
        .filter(|w| w.len() > 3 && w[0].parse::<u8>().is_ok() && w[1].parse::<u64>().is_ok())
        .collect();
    assert_eq!(rows.len(), 19, "{s}");
    assert_eq!(rows[0][..3], ["0", "262144", "1024"]);
    assert_eq!(rows[18][..3], ["18", "1", "1"]);

    let o = pmc(&["info", "--preset", "earth", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["layout"]["n_c"], 262144);
    assert_eq!(v["layout"]["d_c"], 1024);
    assert_eq!(v["sea_radius"], 6_371_000.0);
    assert_eq!(v["max_level"], 18);
    let levels = v["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 19);
    for (l, level) in levels.iter().enumerate() {
        let f = |k: &str| level[k].as_f64().unwrap();
        let scale = (1u64 << l) as f64;
        assert_eq!(level["level"], l);
        assert_eq!(level["chunks_per_side"], 262144 >> l);
        assert_eq!(f("voxel_radial"), scale);
        assert_eq!(f("chunk_deep"), 32.0 * scale);
        // Voxels about 1.2 m across on average: between 0.8 and 1.6 m at level 0, doubling.
        let (lo, hi) = (f("voxel_across_min") / scale, f("voxel_across_max") / scale);
        assert!(0.8 < lo && lo < hi && hi < 1.6, "level {l}: {lo} .. {hi}");
        assert!((f("chunk_across") / (32.0 * scale) - 1.196).abs() < 0.01);
    }
    assert_eq!(levels[10]["depth_chunks"], 1);
}

#[test]
fn radius_picks_a_layout_for_any_preset() {
    let o = pmc(&["info", "--preset", "moon", "--radius", "1737400", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["preset"], "moon");
    assert_eq!(v["layout"]["n_c"], 65536);
    assert_eq!(v["layout"]["l_d"], 1.0);
    assert_eq!(v["layout"]["d_c"], 512);
    // The middle of the shell lies at the radius asked for.
    assert_eq!(v["layout"]["d_b"], 1_737_400.0 - 8192.0);
    assert_eq!(v["radius"], 1_737_400.0 + 8192.0);
    assert_eq!(v["levels"].as_array().unwrap().len(), 17);
    let o = pmc(&["info", "--preset", "moon", "--radius", "1737400"]);
    let s = String::from_utf8(o.stdout).unwrap();
    assert!(s.contains("17 levels of detail"), "{s}");
    // The earth preset shrunk: its sea at the radius.
    let o = pmc(&["info", "--preset", "earth", "--radius", "50000", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["sea_radius"], 50_000.0);
    // A typed layout option replaces that parameter of the preset's layout.
    let o = pmc(&["info", "--preset", "earth", "--d-c", "512", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["layout"]["n_c"], 262144);
    assert_eq!(v["layout"]["d_c"], 512);
}

#[test]
fn bad_radii_are_refused_clearly() {
    for (r, needle) in [
        ("0", "above 0"),
        ("-5", "above 0"),
        ("NaN", "finite"),
        ("inf", "finite"),
        ("50", "between 100 m"),
        ("1e9", "between 100 m"),
        ("abc", "--radius"),
    ] {
        assert_refused(&["info", "--radius", r], needle);
        assert_eq!(pmc(&["info", "--radius", r]).status.code(), Some(2), "{r}");
    }
    assert_refused(&["info", "--radius", "5000", "--n-c", "4"], "cannot be used with");
    assert_refused(&["generate", "--radius", "5000", "--d-b", "100"], "cannot be used with");
    // Planets too large to mesh whole stay refused before any work.
    assert_refused(&["generate", "--preset", "earth"], "too large");
    assert_refused(&["render", "--preset", "moon", "--radius", "1737400"], "too large");
}

#[test]
fn generate_writes_a_glb_and_is_deterministic_across_thread_counts() {
    let a = tmp("a.glb");
    let b = tmp("b.glb");
    let mut args1 = vec![
        "generate",
        "--quiet",
        "--preset",
        "earthlike",
        "--seed",
        "11",
        "--threads",
        "1",
        "-o",
    ];
    args1.push(a.to_str().unwrap());
    args1.extend(SMALL);
    let o = pmc(&args1);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut args2 = vec![
        "generate",
        "--quiet",
        "--preset",
        "earthlike",
        "--seed",
        "11",
        "--threads",
        "2",
        "-o",
    ];
    args2.push(b.to_str().unwrap());
    args2.extend(SMALL);
    assert!(pmc(&args2).status.success());
    let (x, y) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_eq!(&x[0..4], b"glTF");
    assert!(x.len() > 10_000);
    assert!(x == y, "output differs between 1 and 2 threads");
}

#[test]
fn every_format_is_written() {
    for ext in ["glb", "obj", "ply"] {
        let p = tmp(&format!("sphere.{ext}"));
        let mut args = vec!["generate", "--quiet", "--preset", "sphere", "-o", p.to_str().unwrap()];
        args.extend(SMALL);
        let o = pmc(&args);
        assert!(o.status.success(), "{ext}: {}", stderr(&o));
        assert!(std::fs::metadata(&p).unwrap().len() > 1000, "{ext} too small");
    }
}

#[test]
fn invalid_parameters_are_refused_clearly() {
    assert_refused(&["generate", "--n-t", "0"], "n_t");
    assert_refused(&["generate", "--n-c", "0"], "n_c");
    assert_refused(&["generate", "--d-c", "0"], "d_c");
    assert_refused(&["generate", "--d-b", "NaN"], "d_b");
    assert_refused(&["generate", "--d-b", "-5"], "d_b");
    assert_refused(&["generate", "--l-d", "-1"], "l_d");
    assert_refused(&["generate", "--l-d", "inf"], "l_d");
    assert_refused(&["generate", "--preset", "venus"], "unknown preset 'venus'");
    assert_refused(&["generate", "--seed", "-3"], "-3");
    assert_refused(&["generate", "--seed", "x"], "--seed");
    assert_refused(&["info", "--n-t", "100000"], "n_t");
    assert_refused(&["info", "--n-t", "129"], "n_t");
    // Valid layouts too large to mesh whole are refused before any work, never by running out
    // of memory.
    assert_refused(&["generate", "--n-c", "100000"], "too large");
    assert_refused(&["render", "--n-c", "64", "--n-t", "64"], "too large");
    let o = pmc(&["info", "--n-c", "100000"]);
    assert!(o.status.success(), "info describes any valid layout: {}", stderr(&o));
}

#[test]
fn unwritable_outputs_are_refused_before_any_work() {
    assert_refused(&["generate", "-o", "/nonexistent-dir/planet.glb"], "does not exist");
    assert_refused(&["generate", "-o", "planet.stl"], "planet.stl");
    assert_refused(&["generate", "-o", "planet"], "planet");
    let dir = tmp("adir.glb");
    std::fs::create_dir_all(&dir).unwrap();
    assert_refused(&["generate", "-o", dir.to_str().unwrap()], "directory");
    assert!(!Path::new("planet.stl").exists());
}

#[test]
fn help_explains_every_option() {
    let o = pmc(&["generate", "--help"]);
    let s = String::from_utf8(o.stdout).unwrap();
    for opt in [
        "--preset",
        "--seed",
        "--n-c",
        "--n-t",
        "--d-b",
        "--l-d",
        "--d-c",
        "--radius",
        "--output",
        "--threads",
        "--quiet",
    ] {
        assert!(s.contains(opt), "--help lacks {opt}");
    }
    assert!(s.contains("earthlike") && s.contains("moon") && s.contains("mars") && s.contains("earth ("));
}

#[test]
fn render_writes_a_png_and_refuses_bad_views() {
    let p = tmp("planet.png");
    let mut args = vec![
        "render",
        "--quiet",
        "--width",
        "160",
        "--height",
        "100",
        "-o",
        p.to_str().unwrap(),
    ];
    args.extend(SMALL);
    let o = pmc(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&p).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let mut ground = vec![
        "render",
        "--quiet",
        "--width",
        "64",
        "--height",
        "40",
        "--distance",
        "230",
        "--look-at=10,20",
    ];
    ground.push("-o");
    ground.push(p.to_str().unwrap());
    ground.extend(SMALL);
    assert!(pmc(&ground).status.success());
    assert_refused(&["render", "-o", "planet.jpg"], "PNG");
    assert_refused(&["render", "--look-at=100,0", "-o", "x.png"], "latitude");
    assert_refused(&["render", "--look-at", "abc", "-o", "x.png"], "LAT,LON");
    assert_refused(
        &[
            "render",
            "--width",
            "0",
            "-o",
            p.to_str().unwrap(),
            "--n-c",
            "1",
            "--n-t",
            "4",
        ],
        "0",
    );
    assert_refused(
        &[
            "render",
            "--distance",
            "NaN",
            "-o",
            p.to_str().unwrap(),
            "--n-c",
            "1",
            "--n-t",
            "4",
        ],
        "NaN",
    );
}
