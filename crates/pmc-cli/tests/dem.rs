//! `pmc dem` and `--dem` as a user runs them: import an elevation model, describe it, probe a
//! place, dig into the real planet in a world and walk on it; every bad input refused with a
//! message naming the file, and no output file left behind.

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

fn ok(args: &[&str]) -> (String, String) {
    let o = pmc(args);
    assert!(o.status.success(), "{args:?} failed: {}", text(&o.stderr));
    (text(&o.stdout), text(&o.stderr))
}

/// Runs `pmc ARGS`, expecting a clear refusal (exit code 2, no panic) containing `needle`.
fn refused(args: &[&str], needle: &str) -> String {
    let o = pmc(args);
    let e = text(&o.stderr);
    assert!(!o.status.success(), "{args:?} should fail");
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    assert!(!e.contains("panicked"), "{args:?} panicked: {e}");
    assert!(e.contains(needle), "{args:?}: expected '{needle}' in: {e}");
    e
}

fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-cli-dem-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn fixture(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../pmc-dem/tests/fixtures")
        .join(name)
        .to_str()
        .unwrap()
        .to_string()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Imports the one-degree ETOPO60 fixture at level 6 into `d`.
fn import_etopo60(d: &Path) -> PathBuf {
    let out = d.join("earth.pmcdem");
    let (_, err) = ok(&[
        "dem",
        "import",
        &fixture("etopo60.cdf"),
        "-o",
        s(&out),
        "--level",
        "6",
        "--quiet",
    ]);
    assert!(err.is_empty(), "--quiet prints nothing: {err}");
    out
}

#[test]
fn import_info_and_probe() {
    let d = dir("import");
    let out = d.join("earth.pmcdem");
    let (_, err) = ok(&["dem", "import", &fixture("etopo60.cdf"), "-o", s(&out), "--level", "6"]);
    assert!(
        err.contains("level 6 (65 samples a face side)") && err.contains("digest"),
        "{err}"
    );
    // The same input gives the same file.
    let again = d.join("again.pmcdem");
    ok(&[
        "dem",
        "import",
        &fixture("etopo60.cdf"),
        "-o",
        s(&again),
        "--level",
        "6",
        "--quiet",
    ]);
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());

    let (info, _) = ok(&["dem", "info", s(&out), "--verify"]);
    for needle in [
        "etopo60.cdf",
        "6371000",
        "2^6 + 1 = 65",
        "50.7 KB",
        "detail noise",
        "verified",
    ] {
        assert!(info.contains(needle), "{needle} missing from:\n{info}");
    }
    let (json, _) = ok(&["dem", "info", s(&out), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["data_level"], 6);
    assert_eq!(v["levels"][0]["samples_per_side"], 65);
    assert_eq!(v["levels"][0]["bytes_16bit"], 6 * 65 * 65 * 2);

    // Probing the Himalaya: the finest mesh within a metre of the interpolated surface.
    let (json, _) = ok(&["dem", "probe", s(&out), "--lat", "28", "--lon", "87", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let interpolated = v["interpolated"].as_f64().unwrap();
    assert!(interpolated > 2000.0, "{v}");
    let meshed = v["meshed"][0]["height"].as_f64().unwrap();
    assert!((meshed - interpolated).abs() <= 1.0, "{v}");
    assert!(v["nearest_sample"]["value"].as_f64().unwrap() > 2000.0);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn import_reports_the_error_at_every_data_point() {
    let d = dir("accuracy");
    let out = d.join("earth.pmcdem");
    let (json, err) = ok(&[
        "dem",
        "import",
        &fixture("etopo60.cdf"),
        "-o",
        s(&out),
        "--level",
        "5",
        "--json",
    ]);
    assert!(err.contains("error max") && err.contains("RMS"), "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["bytes"].as_u64(), Some(std::fs::metadata(&out).unwrap().len()));
    assert!(v["source_bytes"].as_u64().unwrap() > 360 * 180 * 2, "{v}");
    let checks = v["accuracy"].as_array().unwrap();
    assert_eq!(checks.len(), 2, "bilinear and bicubic");
    for c in checks {
        assert_eq!(c["samples"], 360 * 180, "{c}");
        for key in ["max_error_m", "p99_error_m", "rms_error_m"] {
            assert!(c[key].as_f64().unwrap() < 1e-6, "{key}: {c}");
        }
    }
    // The check can be skipped.
    let (json, _) = ok(&[
        "dem",
        "import",
        &fixture("etopo60.cdf"),
        "-o",
        s(&out),
        "--level",
        "5",
        "--json",
        "--no-check",
        "--quiet",
    ]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["accuracy"].as_array().map(Vec::len), Some(0));
    let (info, _) = ok(&["dem", "info", s(&out)]);
    assert!(info.contains("source grid  360 x 180 samples"), "{info}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_real_planet_is_edited_in_a_world_and_walked_on() {
    let d = dir("world");
    let dem = import_etopo60(&d);
    let world = d.join("earth.pmcw");
    // A world on the real Earth: dig a pit in the Alps.
    let (out, err) = ok(&[
        "edit",
        "--world",
        s(&world),
        "--dem",
        s(&dem),
        "remove",
        "--at",
        "46.5,8.0",
        "--radius",
        "6",
    ]);
    assert!(
        err.contains("created world") && err.contains("dem earth.pmcdem"),
        "{err}"
    );
    assert!(out.contains("applied edit 1"), "{out}");
    let (list, _) = ok(&["edit", "--world", s(&world), "--list", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&list).unwrap();
    assert!(v["terrain"].as_str().unwrap().starts_with("dem:bicubic:7:"), "{v}");
    assert_eq!(v["edits"].as_array().unwrap().len(), 1);
    // Another elevation file is refused for this world.
    let other = d.join("other.pmcdem");
    ok(&[
        "dem",
        "import",
        &fixture("etopo60.cdf"),
        "-o",
        s(&other),
        "--level",
        "7",
        "--quiet",
    ]);
    refused(
        &[
            "edit",
            "--world",
            s(&world),
            "--dem",
            s(&other),
            "remove",
            "--at",
            "46.5,8.0",
            "--radius",
            "3",
        ],
        "another elevation file",
    );
    // A walk on the real planet beside the pit (the lazy grid: the Earth is too large for a
    // whole-planet one).
    let (json, _) = ok(&[
        "path",
        "--world",
        s(&world),
        "--from",
        "46.5003,8.0",
        "--to",
        "46.5003,8.0003",
    ]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert!(v["found"].as_bool().unwrap_or(true), "{v}");
    // The file the world was made from, changed: the world refuses it rather than rebuild
    // another planet under its edits.
    std::fs::copy(&other, &dem).unwrap();
    refused(&["edit", "--world", s(&world), "--list"], "digest");
    std::fs::remove_dir_all(&d).unwrap();
}

/// `--extent -10,35,5,44` starts with a minus: clap took it for an option ("unexpected argument
/// '-1'") before the flag accepted values that start with a hyphen.
#[test]
fn an_extent_west_of_greenwich_is_read_as_the_extent() {
    let d = dir("extent-minus");
    let out = d.join("west.pmcdem");
    let png = fixture("etopo5deg.png");
    ok(&[
        "dem",
        "import",
        &png,
        "-o",
        s(&out),
        "--extent",
        "-10,-5,10,5",
        "--level",
        "4",
        "--quiet",
    ]);
    let (info, _) = ok(&["dem", "info", s(&out), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&info).unwrap();
    let extent: Vec<f64> = serde_json::from_value(v["source_extent"].clone()).unwrap();
    // west, east, south, north of the samples: cell centres inside the cell edges given
    assert!(extent[0] > -10.0 && extent[0] < -9.0, "{extent:?}");
    assert!(extent[1] < 10.0 && extent[1] > 9.0, "{extent:?}");
    assert!(extent[2] > -5.0 && extent[2] < -4.0, "{extent:?}");
    assert!(extent[3] < 5.0 && extent[3] > 4.0, "{extent:?}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn bad_input_is_refused_and_leaves_no_file() {
    let d = dir("bad");
    let out = d.join("x.pmcdem");
    let o = s(&out);
    refused(&["dem", "import", s(&d.join("missing.cdf")), "-o", o], "missing.cdf");
    let text_file = d.join("notes.txt");
    std::fs::write(&text_file, "not an elevation model").unwrap();
    refused(
        &["dem", "import", s(&text_file), "-o", o],
        "not a netCDF classic, GeoTIFF or PNG",
    );
    refused(
        &["dem", "import", s(&text_file), "-o", o, "--format", "netcdf"],
        "notes.txt",
    );
    refused(
        &["dem", "import", s(&text_file), "-o", o, "--format", "geotiff"],
        "notes.txt",
    );
    let cdf = fixture("etopo60.cdf");
    let bytes = std::fs::read(&cdf).unwrap();
    let cut = d.join("cut.cdf");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    refused(&["dem", "import", s(&cut), "-o", o], "cut.cdf");
    refused(&["dem", "import", &cdf, "-o", o, "--level", "17"], "level");
    refused(&["dem", "import", &cdf, "-o", o, "--radius", "NaN"], "radius");
    refused(
        &["dem", "import", &cdf, "-o", o, "--extent", "0,0,1,1"],
        "--extent applies to PNG",
    );
    assert!(!out.exists(), "a failed import left {o}");
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 2, "only the two inputs remain");

    refused(&["dem", "info", &cdf], "etopo60.cdf");
    let dem = import_etopo60(&d);
    let mut damaged = std::fs::read(&dem).unwrap();
    let at = damaged.len() - 100;
    damaged[at] ^= 0x40;
    let bad = d.join("damaged.pmcdem");
    std::fs::write(&bad, &damaged).unwrap();
    refused(&["dem", "info", s(&bad), "--verify"], "damaged.pmcdem");
    refused(&["dem", "probe", s(&dem), "--lat", "91", "--lon", "0"], "lat");
    refused(&["dem", "probe", s(&dem), "--lat", "NaN", "--lon", "0"], "lat");
    refused(&["info", "--dem", s(&text_file)], "notes.txt");
    refused(
        &["info", "--dem", s(&dem), "--radius", "5000"],
        "--radius does not apply to --dem",
    );
    std::fs::remove_dir_all(&d).unwrap();
}

/// `pmc dem info earth.pmcdem | head -3` panicked ("failed printing to stdout: Broken pipe") when
/// the reader went away before pmc wrote: now pmc stops quietly with the status a shell gives a
/// command stopped by SIGPIPE.
///
/// The pipe's reading end is closed before pmc starts. (The test closed it just after starting
/// pmc, and once in a fresh clone's run, on a busy machine, pmc had written its few lines into the
/// pipe's buffer first and rightly exited 0.)
#[test]
fn pmc_dem_info_into_head_panicked_on_the_closed_pipe() {
    use std::process::Stdio;
    let file = fixture("etopo60_l6_v1.pmcdem");
    let (reader, writer) = std::io::pipe().expect("a pipe");
    // the reader goes away before pmc has started, let alone written a line
    drop(reader);
    let child = Command::new(env!("CARGO_BIN_EXE_pmc"))
        .args(["dem", "info", &file])
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .spawn()
        .expect("pmc runs");
    let o = child.wait_with_output().expect("pmc ends");
    let e = text(&o.stderr);
    assert!(!e.contains("panicked"), "pmc panicked: {e}");
    assert_eq!(o.status.code(), Some(141), "{e}");
    assert!(e.is_empty(), "nothing on standard error either: {e}");
}
