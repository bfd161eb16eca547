//! `pmc imagery` and `--imagery` as a user runs them: import a picture, describe it, look up a
//! colour, import it beside an elevation model; every bad input refused with a message naming
//! the file, and no output file left behind.

use pmc_imagery::Imagery;
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
    let d = std::env::temp_dir().join(format!("pmc-cli-imagery-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn fixture(crate_name: &str, name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(crate_name)
        .join("tests/fixtures")
        .join(name)
        .to_str()
        .unwrap()
        .to_string()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn import_info_and_probe_a_jpeg() {
    let d = dir("jpeg");
    let out = d.join("earth.pmcimg");
    let jpg = fixture("pmc-imagery", "earth64.jpg");
    let (_, err) = ok(&["imagery", "import", &jpg, "-o", s(&out)]);
    let img = Imagery::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (64, 32));
    assert!(img.extent().wraps());
    assert!(err.contains(img.digest()) && err.contains("64 x 32"), "{err}");
    // The same pixels as the library's import.
    assert_eq!(img, Imagery::import(&jpg, None).unwrap());

    let (json, _) = ok(&["imagery", "info", s(&out), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["width"], 64);
    assert_eq!(v["height"], 32);
    assert_eq!(v["extent"], serde_json::json!([-180.0, 180.0, -90.0, 90.0]));
    assert_eq!(v["digest"], img.digest());
    let (plain, _) = ok(&["imagery", "info", s(&out)]);
    assert!(
        plain.contains("64 x 32") && plain.contains("round the globe"),
        "{plain}"
    );

    // Pixel (10, 5)'s centre: 180 W + 10.5 x 5.625 degrees, 90 N - 5.5 x 5.625 degrees.
    let (lat, lon) = (90.0 - 5.5 * 5.625, -180.0 + 10.5 * 5.625);
    let (probe, _) = ok(&[
        "imagery",
        "probe",
        s(&out),
        "--lat",
        &lat.to_string(),
        "--lon",
        &lon.to_string(),
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&probe).unwrap();
    let [r, g, b] = img.pixel(10, 5);
    assert_eq!(v["rgb"], serde_json::json!([r, g, b]));
    let (plain, _) = ok(&[
        "imagery",
        "probe",
        s(&out),
        "--lat",
        &lat.to_string(),
        "--lon",
        &lon.to_string(),
    ]);
    assert_eq!(plain.trim(), format!("{r} {g} {b}"));
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn an_extent_west_of_greenwich_places_the_picture() {
    // "-10,35,5,44" starts with a minus: it must be read as the extent, not as an option.
    let d = dir("extent");
    let out = d.join("spain.pmcimg");
    let png = fixture("pmc-imagery", "earth64-libjpeg.png");
    ok(&[
        "imagery",
        "import",
        &png,
        "-o",
        s(&out),
        "--extent",
        "-10,35,5,44",
        "--quiet",
    ]);
    let img = Imagery::open(&out).unwrap();
    assert_eq!(img.extent().to_array(), [-10.0, 5.0, 35.0, 44.0]);
    let (probe, _) = ok(&["imagery", "probe", s(&out), "--lat", "0", "--lon", "0"]);
    assert!(probe.contains("outside the image"), "{probe}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn bad_inputs_are_refused_and_leave_no_file() {
    let d = dir("bad");
    let out = d.join("x.pmcimg");
    let jpg = fixture("pmc-imagery", "earth64.jpg");
    refused(
        &["imagery", "import", &jpg, "-o", s(&out), "--extent", "10,0,5,1"],
        "west (10) is not less than east (5)",
    );
    refused(
        &["imagery", "import", &jpg, "-o", s(&out), "--extent", "1,2,3"],
        "WEST,SOUTH,EAST,NORTH",
    );
    refused(
        &["imagery", "import", &jpg, "-o", s(&out), "--extent", "0,0,NaN,1"],
        "not a finite number",
    );
    let cdf = fixture("pmc-dem", "etopo60.cdf");
    refused(
        &["imagery", "import", &cdf, "-o", s(&out)],
        "not a JPEG, PNG or TIFF image",
    );
    let cut = d.join("cut.jpg");
    let bytes = std::fs::read(&jpg).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    refused(&["imagery", "import", s(&cut), "-o", s(&out)], "cut.jpg");
    refused(
        &["imagery", "import", s(&d.join("missing.jpg")), "-o", s(&out)],
        "missing.jpg",
    );
    assert!(!out.exists());
    // A .pmcimg that is not one, or damaged.
    refused(&["imagery", "info", &jpg], "it is a JPEG image: import it first");
    let good = d.join("good.pmcimg");
    ok(&["imagery", "import", &jpg, "-o", s(&good), "--quiet"]);
    let mut bytes = std::fs::read(&good).unwrap();
    bytes[200] ^= 4;
    std::fs::write(&good, &bytes).unwrap();
    refused(&["imagery", "info", s(&good)], "damaged");
    // The directory holds only what was written on purpose.
    let mut names: Vec<String> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["cut.jpg", "good.pmcimg"]);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn dem_import_writes_the_imagery_beside_the_elevation_file() {
    let d = dir("dem");
    let dem = d.join("earth.pmcdem");
    let jpg = fixture("pmc-imagery", "earth64.jpg");
    let cdf = fixture("pmc-dem", "etopo60.cdf");
    let (_, err) = ok(&["dem", "import", &cdf, "-o", s(&dem), "--level", "6", "--imagery", &jpg]);
    assert!(dem.exists());
    let img = Imagery::open(d.join("earth.pmcimg")).unwrap();
    assert_eq!(img, Imagery::import(&jpg, None).unwrap());
    assert!(err.contains("earth.pmcimg"), "{err}");

    // A bad picture is refused before the elevation model is imported.
    let dem2 = d.join("other.pmcdem");
    refused(
        &["dem", "import", &cdf, "-o", s(&dem2), "--level", "6", "--imagery", &cdf],
        "not a JPEG, PNG or TIFF image",
    );
    assert!(!dem2.exists() && !d.join("other.pmcimg").exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn serve_refuses_a_bad_imagery_file_before_listening() {
    let d = dir("serve");
    let jpg = fixture("pmc-imagery", "earth64.jpg");
    let e = refused(
        &["serve", "--port", "0", "--imagery", &jpg],
        "not a .pmcimg imagery file",
    );
    assert!(e.contains("earth64.jpg"), "{e}");
    refused(
        &["serve", "--port", "0", "--imagery", s(&d.join("none.pmcimg"))],
        "none.pmcimg",
    );
    let help = text(&pmc(&["serve", "--help"]).stdout);
    assert!(help.contains("--imagery"), "{help}");
    std::fs::remove_dir_all(&d).unwrap();
}
