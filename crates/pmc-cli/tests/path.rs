//! `pmc path` as a user runs it: JSON and GeoJSON paths, paths on an edited world, "no path" as
//! an answer, and clear errors.

use serde_json::Value;
use std::path::PathBuf;
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

fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-cli-path-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A small earthlike planet: 16 columns per face side.
const SMALL: [&str; 10] = ["--n-c", "2", "--n-t", "8", "--d-b", "200", "--l-d", "2", "--seed", "3"];

fn json_out(args: &[&str]) -> Value {
    let o = pmc(args);
    assert!(o.status.success(), "{args:?}: {}", text(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(&o.stdout)))
}

/// The angle in degrees between two lat/lon places.
fn degrees_apart(a: (f64, f64), b: (f64, f64)) -> f64 {
    let unit = |(lat, lon): (f64, f64)| {
        let (la, lo) = (lat.to_radians(), lon.to_radians());
        [la.cos() * lo.sin(), la.sin(), la.cos() * lo.cos()]
    };
    let (p, q) = (unit(a), unit(b));
    let dot: f64 = p.iter().zip(q).map(|(x, y)| x * y).sum();
    dot.clamp(-1.0, 1.0).acos().to_degrees()
}

#[test]
fn a_path_is_written_as_json_and_as_geojson() {
    let mut args = vec!["path", "--from", "10,10", "--to", "12,40", "--quiet"];
    args.extend(SMALL);
    let v = json_out(&args);
    assert_eq!(
        (v["format"].as_str(), v["version"].as_u64()),
        (Some("pmc-path"), Some(1))
    );
    assert_eq!(v["found"], true, "{v}");
    let w = v["waypoints"].as_array().unwrap();
    assert_eq!(w.len() as u64, v["steps"].as_u64().unwrap() + 1);
    let ll = |x: &Value| (x["lat"].as_f64().unwrap(), x["lon"].as_f64().unwrap());
    // The ends are near the places asked for (a column is about 5 degrees wide here).
    assert!(degrees_apart(ll(&w[0]), (10.0, 10.0)) < 8.0);
    assert!(degrees_apart(ll(w.last().unwrap()), (12.0, 40.0)) < 8.0);
    // Consecutive waypoints are one column apart, and the length is at least the great circle.
    for pair in w.windows(2) {
        assert!(degrees_apart(ll(&pair[0]), ll(&pair[1])) < 8.0);
    }
    let radius = 200.0 + 2.0 * 8.0 * 2.0;
    let arc = degrees_apart(ll(&w[0]), ll(w.last().unwrap())).to_radians() * 200.0;
    let length = v["length"].as_f64().unwrap();
    assert!(length >= arc && length < 3.0 * radius, "{length} vs {arc}");
    assert_eq!(v["asked"]["from"]["lat"], 10.0);
    assert!(v["asked"]["from"]["alt"].is_null());

    args.extend(["--format", "geojson"]);
    let g = json_out(&args);
    assert_eq!(g["type"], "FeatureCollection");
    let f = g["features"].as_array().unwrap();
    assert_eq!(f[0]["geometry"]["type"], "LineString");
    let coords = f[0]["geometry"]["coordinates"].as_array().unwrap();
    assert_eq!(coords.len(), w.len());
    // GeoJSON order: longitude, latitude, altitude.
    assert_eq!(coords[0][0], w[0]["lon"]);
    assert_eq!(coords[0][1], w[0]["lat"]);
    assert_eq!(coords[0][2], w[0]["alt"]);
    assert_eq!(f[0]["properties"]["length"], v["length"]);
    assert_eq!(
        (f[1]["properties"]["role"].as_str(), f[2]["properties"]["role"].as_str()),
        (Some("from"), Some("to"))
    );
    assert_eq!(f[1]["geometry"]["coordinates"], serde_json::json!([10.0, 10.0]));
    assert_eq!(g["properties"]["found"], true);
}

#[test]
fn no_path_is_an_answer_not_an_error() {
    // An agent that can climb no slope at all: every node is a grid of its own.
    let mut args = vec![
        "path",
        "--from",
        "10,10",
        "--to",
        "12,40",
        "--max-slope",
        "0.0001",
        "--step-up",
        "0",
        "--step-down",
        "0",
    ];
    args.extend(SMALL);
    let o = pmc(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["found"], false);
    assert!(v["reason"].as_str().unwrap().contains("component"), "{v}");
    assert!(v["waypoints"].is_null());
    assert!(text(&o.stderr).contains("no path"));
    args.extend(["--format", "geojson"]);
    let g = json_out(&args);
    assert_eq!(g["properties"]["found"], false);
    assert_eq!(g["features"].as_array().unwrap().len(), 2, "only the two ends");
}

#[test]
fn the_path_follows_a_worlds_edits() {
    let d = dir("world");
    let w = d.join("w.pmcw");
    let ws = w.to_str().unwrap();
    let world_args = |from: &str, to: &str| -> Vec<String> {
        ["path", "--world", ws, "--from", from, "--to", to, "--quiet"]
            .map(String::from)
            .to_vec()
    };
    // A world of the sphere preset: the straight way is along the equator.
    let mut create = vec![
        "edit",
        "--world",
        ws,
        "paint",
        "--at",
        "0,0",
        "--radius",
        "1",
        "--material",
        "0",
    ];
    create.extend([
        "--preset", "sphere", "--n-c", "2", "--n-t", "8", "--d-b", "200", "--l-d", "2",
    ]);
    let o = pmc(&create);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let run = |args: Vec<String>| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        json_out(&args)
    };
    let straight = run(world_args("0,-20", "0,20"));
    assert_eq!(straight["found"], true);
    // Dig a deep pit with sheer walls across the way.
    let o = pmc(&["edit", "--world", ws, "remove", "--at", "0,0", "--radius", "20"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let around = run(world_args("0,-20", "0,20"));
    assert_eq!(around["found"], true);
    let (a, b) = (straight["length"].as_f64().unwrap(), around["length"].as_f64().unwrap());
    assert!(b > a + 1.0, "the pit makes the way longer: {a} -> {b}");
    // Planet options cannot be given with a world.
    let o = pmc(&["path", "--world", ws, "--from", "0,0", "--to", "1,1", "--seed", "4"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn bad_input_is_refused_clearly() {
    let d = dir("bad");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--from", "100,0", "--to", "0,0"], "--from 100,0: latitude 100"),
        (vec!["--from", "0,0", "--to", "1"], "--to 1: expected 2 or 3 numbers"),
        (vec!["--from", "0,x", "--to", "1,1"], "not a number"),
        (vec!["--from", "0,0", "--to", "1,1,NaN"], "altitude"),
        (vec!["--from", "0,0", "--to", "1,1", "--clearance", "0"], "clearance"),
        (vec!["--from", "0,0", "--to", "1,1", "--max-slope", "95"], "slope"),
        (vec!["--from", "0,0", "--to", "1,1", "--step-up", "-1"], "step"),
        (vec!["--from", "0,0", "--to", "1,1", "--n-t", "0"], "n_t"),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["path"];
        args.extend(extra.iter().copied());
        let o = pmc(&args);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains(needle), "{args:?}: '{needle}' not in {e}");
        assert!(!e.contains("panicked"));
    }
    let notes = d.join("notes.txt");
    std::fs::write(&notes, "x").unwrap();
    let o = pmc(&[
        "path",
        "--world",
        notes.to_str().unwrap(),
        "--from",
        "0,0",
        "--to",
        "1,1",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("not a PMC world"));
    let o = pmc(&[
        "path",
        "--from",
        "0,0",
        "--to",
        "1,1",
        "-o",
        d.join("no/such/dir/p.json").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
}

/// The Earth at true scale: 1 m layers, 6 x 8 388 608^2 columns, far too many for a whole-planet
/// grid; a walk of about 340 m over the lazy grid.
const EARTH: [&str; 6] = [
    "--preset",
    "earth",
    "--from=-59.7,41.7",
    "--to=-59.698,41.703",
    "--quiet",
    "--seed=7",
];

#[test]
fn a_path_on_the_earth_is_found_on_the_lazy_grid() {
    let mut args = vec!["path"];
    args.extend(EARTH);
    let v = json_out(&args);
    assert_eq!(
        (v["format"].as_str(), v["version"].as_u64(), v["found"].as_bool()),
        (Some("pmc-path"), Some(1), Some(true)),
        "{v}"
    );
    assert_eq!(v["grid"]["lazy"], true);
    assert!(v["grid"]["components"].is_null() && v["component"].is_null());
    let tiles = v["search"]["tiles_built"].as_u64().unwrap();
    assert!(
        tiles > 0 && tiles < 2000,
        "{tiles} tiles for a walk of a few hundred metres"
    );
    assert_eq!(v["grid"]["tiles"].as_u64(), Some(tiles));
    assert!(v["search"]["max_tiles"].as_u64().unwrap() >= tiles);
    let w = v["waypoints"].as_array().unwrap();
    assert_eq!(w.len() as u64, v["steps"].as_u64().unwrap() + 1);
    let ll = |x: &Value| (x["lat"].as_f64().unwrap(), x["lon"].as_f64().unwrap());
    let metres = |a: (f64, f64), b: (f64, f64)| degrees_apart(a, b).to_radians() * 6_371_000.0;
    // The ends within a few columns of the places asked for, consecutive waypoints one column
    // (about 1.2 m) apart, and the length at least the great circle between the ends.
    assert!(metres(ll(&w[0]), (-59.7, 41.7)) < 12.0);
    assert!(metres(ll(w.last().unwrap()), (-59.698, 41.703)) < 12.0);
    for pair in w.windows(2) {
        assert!(metres(ll(&pair[0]), ll(&pair[1])) < 2.0);
    }
    let length = v["length"].as_f64().unwrap();
    let arc = metres(ll(&w[0]), ll(w.last().unwrap()));
    assert!(
        arc > 250.0 && length >= arc * 0.999 && length < 2.0 * arc,
        "{length} vs {arc}"
    );
    // Altitudes above the sea, in metres: land here.
    assert!(w.iter().all(|x| x["alt"].as_f64().unwrap().abs() < 9000.0));

    args.extend(["--format", "geojson"]);
    let g = json_out(&args);
    let f = g["features"].as_array().unwrap();
    assert_eq!(f[0]["geometry"]["coordinates"].as_array().unwrap().len(), w.len());
    assert_eq!(f[0]["properties"]["length"], v["length"]);
    assert!(f[0]["properties"]["component"].is_null());
    assert_eq!(g["properties"]["found"], true);
    assert_eq!(g["properties"]["search"]["tiles_built"], v["search"]["tiles_built"]);
}

#[test]
fn the_search_bound_is_an_answer_of_its_own() {
    let mut args = vec!["path", "--max-tiles", "5"];
    args.extend(EARTH);
    let o = pmc(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["found"], false);
    assert_eq!(v["cause"], "search_bound");
    let reason = v["reason"].as_str().unwrap();
    assert!(reason.contains("no path found within the search bound"), "{reason}");
    assert!(v["waypoints"].is_null());
    // Bad bounds are refused before any work.
    for (flag, value, needle) in [
        ("--weight", "0.5", "weight"),
        ("--weight", "NaN", "weight"),
        ("--max-tiles", "0", "tiles"),
        ("--max-expanded", "0", "expanded"),
    ] {
        let mut args = vec!["path", flag, value];
        args.extend(EARTH);
        let o = pmc(&args);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}: {e}");
        assert!(e.contains(needle) && !e.contains("panicked"), "{flag} {value}: {e}");
    }
}

#[test]
fn a_small_planet_gives_the_same_walk_on_either_grid() {
    let mut args = vec!["path", "--from", "10,10", "--to", "12,40", "--quiet", "--weight", "1"];
    args.extend(SMALL);
    let mut exact = args.clone();
    exact.push("--exact");
    let whole = json_out(&exact);
    // The hierarchical search's walk is no shorter, and within its weight.
    let fast = json_out(&args)["length"].as_f64().unwrap();
    let shortest = whole["length"].as_f64().unwrap();
    assert!(
        fast >= shortest - 1e-9 && fast <= 1.5 * shortest,
        "{fast} vs {shortest}"
    );
    args.push("--lazy");
    let lazy = json_out(&args);
    assert_eq!(
        (whole["found"].as_bool(), lazy["found"].as_bool()),
        (Some(true), Some(true))
    );
    let (a, b) = (whole["length"].as_f64().unwrap(), lazy["length"].as_f64().unwrap());
    assert!((a - b).abs() < 1e-9 * a, "{a} vs {b}");
    assert!(whole["grid"]["components"].as_u64().is_some() && whole["search"].is_null());
    assert!(lazy["grid"]["components"].is_null() && lazy["search"]["expanded"].as_u64().is_some());
}
