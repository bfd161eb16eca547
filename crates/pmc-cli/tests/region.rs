//! `pmc generate --region`: a region of a planet at one level of detail, for planets too large
//! to mesh whole; and the refusal of whole-planet meshing that points to it.

use std::path::PathBuf;
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
    let dir = std::env::temp_dir().join(format!("pmc-region-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The triangle count `pmc generate` reports on stderr.
fn triangles(o: &Output) -> u64 {
    let e = stderr(o);
    let at = e
        .find(" triangles")
        .unwrap_or_else(|| panic!("no triangle count in: {e}"));
    e[..at].rsplit(' ').next().unwrap().parse().unwrap()
}

#[test]
fn a_region_exports_fewer_triangles_at_coarser_levels() {
    let mut counts = Vec::new();
    for level in ["0", "1", "2"] {
        let out = tmp(&format!("region-{level}.ply"));
        let o = pmc(&[
            "generate",
            "--region",
            "20,30,400",
            "--level",
            level,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(std::fs::metadata(&out).unwrap().len() > 0);
        counts.push(triangles(&o));
    }
    assert!(counts[0] > counts[1] && counts[1] > counts[2], "{counts:?}");
    let glb = tmp("region.glb");
    let o = pmc(&[
        "generate",
        "--region",
        "-45,120,150",
        "--max-error",
        "1000",
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(&std::fs::read(&glb).unwrap()[..4], b"glTF");
}

#[test]
fn bad_regions_are_refused_before_any_work() {
    let out = tmp("bad.glb");
    let out = out.to_str().unwrap();
    for (args, needle) in [
        (vec!["--region", "20,30"], "expected 3 numbers"),
        (vec!["--region", "95,30,100"], "latitude"),
        (vec!["--region", "20,30,-5"], "above 0"),
        (vec!["--region", "20,30,nan"], "above 0"),
        (vec!["--region", "20,x,100"], "not a number"),
        (vec!["--region", "20,30,100", "--level", "9"], "not a level"),
        (vec!["--region", "20,30,100", "--max-error", "-1"], "--max-error"),
        (
            vec!["--region", "20,30,100000", "--level", "0", "--n-c", "256"],
            "more than",
        ),
        (vec!["--level", "1"], "--region"),
    ] {
        let mut all = vec!["generate"];
        all.extend(args.iter());
        all.extend(["-o", out]);
        let o = pmc(&all);
        let e = stderr(&o);
        assert!(!o.status.success(), "{all:?} should fail");
        assert!(!e.contains("panicked"), "{all:?}: {e}");
        assert!(e.contains(needle), "{all:?}: expected '{needle}' in {e}");
    }
    assert!(!std::path::Path::new(out).exists());
}

#[test]
fn a_planet_too_large_to_mesh_whole_points_to_regions() {
    let o = pmc(&["generate", "--n-c", "4096", "-o", tmp("big.glb").to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--region"), "{}", stderr(&o));
    let out = tmp("big-region.ply");
    let o = pmc(&[
        "generate",
        "--n-c",
        "4096",
        "--region",
        "10,10,20",
        "--level",
        "4",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(triangles(&o) > 0);
}

#[test]
fn bench_flight_reports_every_stop_as_json() {
    let o = pmc(&["bench-flight", "--n-c", "4", "--n-t", "8", "--at", "-10,40", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let flights = v.as_array().unwrap();
    assert_eq!(flights.len(), 2);
    let stops: Vec<&str> = flights[1]["stops"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(stops, ["orbit", "10 km", "100 m", "2 m"]);
    for f in flights {
        for s in f["stops"].as_array().unwrap() {
            assert!(s["triangles"].as_u64().unwrap() > 0, "{s}");
            assert!(s["converged_s"].as_f64().unwrap() >= 0.0);
        }
    }
    let bad = pmc(&["bench-flight", "--at", "100,0"]);
    assert!(!bad.status.success() && stderr(&bad).contains("--at"));
}
