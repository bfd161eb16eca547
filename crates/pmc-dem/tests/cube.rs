//! `.pmcdem` import, reading and sampling: exactness at data samples, shared edges, continuity,
//! overviews, detail octaves, round trips, damaged files, bounded memory, no partial output.

use pmc_dem::cube::{import_cube, CubeDem, DetailNoise, FormatChoice, ImportOptions, Interpolation, SampleFormat};
use pmc_dem::{DemError, EquirectDem, EquirectSource};
use pmc_geometry::glam::{DVec3, IVec3};
use pmc_geometry::{cube_to_sphere, Face, LatLon};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};

fn fixture() -> &'static EquirectDem {
    static DEM: OnceLock<EquirectDem> = OnceLock::new();
    DEM.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/etopo60.cdf");
        EquirectDem::read_netcdf(&path, None).unwrap()
    })
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("pmcdem");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The etopo60 fixture imported at level 7 (129 samples a side, two stored levels).
fn small() -> &'static CubeDem {
    static CUBE: OnceLock<CubeDem> = OnceLock::new();
    CUBE.get_or_init(|| {
        let out = tmp("etopo60_l7.pmcdem");
        let opts = ImportOptions {
            level: Some(7),
            ..Default::default()
        };
        let report = import_cube(fixture(), &out, &opts, &|_, _| {}).unwrap();
        assert_eq!(report.level, 7);
        CubeDem::open(&out).unwrap()
    })
}

fn lattice(face: Face, r: i32, i: i32, j: i32) -> IVec3 {
    let f = face.frame();
    f.n * r + f.u * (2 * i - r) + f.v * (2 * j - r)
}

fn dir(p: IVec3, r: i32) -> DVec3 {
    cube_to_sphere(p.as_dvec3() / f64::from(r))
}

const INTERPS: [Interpolation; 2] = [Interpolation::Bilinear, Interpolation::Bicubic];

/// Version 2 takes heights from the source grid: at the face samples (no detail there) the
/// bilinear height is the reprojected value the face stores (to its whole metres), and every
/// height is the same at four times the resolution and along the direction.
#[test]
fn face_samples_hold_the_bilinear_heights_at_their_points() {
    let cube = small();
    let r = 1 << cube.data_level();
    let detail = DetailNoise::default();
    for face in [Face::South, Face::Top] {
        for i in 0..=r {
            for j in 0..=r {
                let stored = f64::from(cube.sample(0, face, i as u32, j as u32).unwrap());
                let p = lattice(face, r, i, j);
                let bilinear = cube.height_at_lattice(p, r, Interpolation::Bilinear, &detail);
                assert!(
                    (bilinear - stored).abs() <= 0.5,
                    "{face} {i} {j}: {bilinear} vs {stored}"
                );
                for interp in INTERPS {
                    let at = cube.height_at_lattice(p, r, interp, &detail);
                    assert_eq!(
                        cube.height_at_lattice(p * 4, r * 4, interp, &detail).to_bits(),
                        at.to_bits(),
                        "{face} {i} {j}"
                    );
                    let h = cube.height(dir(p, r), interp, &detail, 1.0);
                    assert!((h - at).abs() <= 1e-6, "{face} {i} {j} {interp:?}: {h} vs {at}");
                }
            }
        }
    }
}

#[test]
fn edge_and_corner_samples_are_identical_on_every_face() {
    let cube = small();
    let r = 1 << cube.data_level();
    for level in 0..cube.levels() {
        let rr = r >> level;
        let mut seen = std::collections::HashMap::new();
        for face in Face::ALL {
            for i in 0..=rr {
                for j in 0..=rr {
                    if i != 0 && j != 0 && i != rr && j != rr {
                        continue;
                    }
                    let v = cube.sample(level, face, i as u32, j as u32).unwrap();
                    let key = lattice(face, rr, i, j);
                    let prev = *seen.entry(key).or_insert(v);
                    assert_eq!(prev.to_bits(), v.to_bits(), "level {level} {face} {i} {j}");
                }
            }
        }
        assert_eq!(seen.len() as i32, 12 * (rr - 1) + 8);
    }
}

#[test]
fn overview_samples_equal_finest_samples() {
    let cube = small();
    assert_eq!(cube.levels(), 2);
    let side = cube.samples_per_side(1);
    assert_eq!(side, 65);
    for face in Face::ALL {
        for i in 0..side {
            for j in 0..side {
                assert_eq!(
                    cube.sample(1, face, i, j).unwrap().to_bits(),
                    cube.sample(0, face, 2 * i, 2 * j).unwrap().to_bits()
                );
            }
        }
    }
    // Coarser than the coarsest overview: the height of the same place at the data resolution.
    let p = lattice(Face::East, 16, 3, 5);
    let v = cube.height_at_lattice(p, 16, Interpolation::Bilinear, &DetailNoise::default());
    assert_eq!(
        v,
        cube.height_at_lattice(p * 8, 128, Interpolation::Bilinear, &DetailNoise::default())
    );
}

#[test]
fn continuous_across_face_edges() {
    let cube = small();
    let detail = DetailNoise::default();
    let mut worst = 0.0f64;
    // Points along every cube edge, nudged 1e-12 cube units (a few micrometres) to either
    // side: the heights differ by the slope times that distance (about 2e-6 m), no jump.
    for a in Face::ALL {
        for b in Face::ALL {
            if !a.is_adjacent(b) || a.index() > b.index() {
                continue;
            }
            let (na, nb) = (a.normal(), b.normal());
            let along = na.cross(nb);
            for k in 0..=200 {
                let s = -1.0 + 2.0 * f64::from(k) / 200.0;
                let edge = na + nb + along * s;
                let d = cube_to_sphere(edge);
                let eps = 1e-12;
                let pa = cube_to_sphere(edge - nb * eps);
                let pb = cube_to_sphere(edge - na * eps);
                for interp in INTERPS {
                    let h0 = cube.height(d, interp, &detail, 1.0);
                    let ha = cube.height(pa, interp, &detail, 1.0);
                    let hb = cube.height(pb, interp, &detail, 1.0);
                    assert!(h0.is_finite());
                    worst = worst.max((ha - hb).abs()).max((ha - h0).abs());
                }
            }
        }
    }
    assert!(worst < 1e-5, "largest jump across a face edge: {worst} m");
}

#[test]
fn octaves_finer_than_a_lattice_are_zero_on_it() {
    let cube = small();
    let detail = DetailNoise {
        relief_slope: 0.0,
        ..Default::default()
    };
    let r = 1 << cube.data_level();
    let mut moved = 0;
    for j in 1..=3 {
        let m = r << j;
        for (face, i, jj) in [
            (Face::South, 37, 91),
            (Face::Top, 5, 77),
            (Face::West, m / 2 + 1, 3),
            (Face::North, 0, 17),
        ] {
            let p = lattice(face, m, i, jj);
            for interp in INTERPS {
                let coarse = cube.height_at_lattice(p, m, interp, &detail);
                let full = cube.height(dir(p, m), interp, &detail, 0.0);
                assert!(
                    (coarse - full).abs() <= 1e-6,
                    "{face} {i} {jj} m={m}: {coarse} vs {full}"
                );
                let bare = cube.height_at_lattice(p, m, interp, &DetailNoise::OFF);
                moved += usize::from(bare != coarse);
                // The same point named at a finer resolution: the same bits.
                assert_eq!(
                    cube.height_at_lattice(p * 2, m * 2, interp, &detail).to_bits(),
                    coarse.to_bits()
                );
            }
        }
    }
    assert!(moved > 10, "the detail changed only {moved} heights");
}

#[test]
fn round_trip_matches_a_fresh_reprojection() {
    let cube = small();
    let dem = fixture();
    let r = 1 << cube.data_level();
    for face in Face::ALL {
        for i in 0..=r {
            for j in 0..=r {
                let stored = f64::from(cube.sample(0, face, i as u32, j as u32).unwrap());
                let ll = LatLon::from_point(dir(lattice(face, r, i, j), r)).unwrap();
                let fresh = dem.sample_bilinear(ll.lat, ll.lon).unwrap();
                let tolerance = match cube.format() {
                    SampleFormat::I16 { scale, .. } => 0.5 * scale + 1e-6,
                    SampleFormat::F32 => 1e-3 + fresh.abs() * 1e-7,
                };
                assert!(
                    (stored - fresh).abs() <= tolerance,
                    "{face} {i} {j}: {stored} vs {fresh}"
                );
            }
        }
    }
    cube.verify().unwrap();
    assert_eq!(cube.filled_samples(), 0);
    assert_eq!(cube.source_name(), dem.source());
}

#[test]
fn f32_import_is_bilinear_to_float_precision_and_deterministic() {
    let dem = fixture();
    let opts = ImportOptions {
        level: Some(5),
        format: FormatChoice::F32,
        tile_size: 16,
        ..Default::default()
    };
    let out = tmp("etopo60_l5_f32.pmcdem");
    let a = import_cube(dem, &out, &opts, &|_, _| {}).unwrap();
    let bytes_a = std::fs::read(&out).unwrap();
    let b = import_cube(dem, &out, &opts, &|_, _| {}).unwrap();
    assert_eq!(a.digest, b.digest);
    assert!(bytes_a == std::fs::read(&out).unwrap());
    let cube = CubeDem::open(&out).unwrap();
    assert_eq!(cube.format(), SampleFormat::F32);
    assert_eq!(cube.levels(), 1);
    assert_eq!(cube.digest(), a.digest);
    let r = 32;
    for face in Face::ALL {
        for i in 0..=r {
            for j in 0..=r {
                let stored = cube.sample(0, face, i as u32, j as u32).unwrap();
                let ll = LatLon::from_point(dir(lattice(face, r, i, j), r)).unwrap();
                let fresh = dem.sample_bilinear(ll.lat, ll.lon).unwrap();
                assert!((f64::from(stored) - fresh).abs() <= 1e-3, "{stored} vs {fresh}");
            }
        }
    }
    // A different source value changes the digest.
    let opts16 = ImportOptions {
        format: FormatChoice::I16,
        ..opts
    };
    let c = import_cube(dem, &out, &opts16, &|_, _| {}).unwrap();
    assert_ne!(c.digest, a.digest);
    assert!(matches!(c.format, SampleFormat::I16 { .. }));
}

#[test]
fn storage_table_follows_the_paper() {
    let cube = small();
    let rows = cube.storage_table();
    assert_eq!(rows[0].samples_per_side, 65);
    assert_eq!(rows[1].samples_per_side, 129);
    assert!(rows[0].stored && rows[1].stored && !rows[2].stored);
    assert_eq!(rows[1].bytes_16bit, 6 * 129 * 129 * 2);
    assert!(rows[1].bytes_stored.unwrap() > 0 && rows[2].bytes_stored.is_none());
    let last = rows.last().unwrap();
    assert!(last.metres_at_centre <= 1.0 && rows[rows.len() - 2].metres_at_centre > 1.0);
    for w in rows.windows(2) {
        assert!((w[0].metres_at_equator / w[1].metres_at_equator - 2.0).abs() < 1e-9);
    }
    // Fig. 13: 16385^2 faces of Mars are 3.2 GB at 16 bits and 325.66 m a sample at the equator.
    let side: u64 = 16385;
    assert_eq!(6 * side * side * 2, 3_221_618_700);
    let (lo, hi) = cube.height_bounds();
    let (min, max) = cube.value_range();
    assert!(lo < min && hi > max && min < -7000.0 && max > 5000.0);
}

#[test]
fn bad_input_never_panics() {
    let cube = small();
    let d = DetailNoise::default();
    for v in [DVec3::ZERO, DVec3::NAN, DVec3::new(f64::INFINITY, 0.0, 1.0)] {
        assert!(cube.height(v, Interpolation::Bicubic, &d, 1.0).is_nan());
    }
    assert!(cube.height(DVec3::Y, Interpolation::Bicubic, &d, f64::NAN).is_nan());
    assert!(cube.height(DVec3::Y, Interpolation::Bicubic, &d, -1.0).is_finite());
    for (p, m) in [
        (IVec3::new(0, 0, 0), 8),
        (IVec3::new(9, 0, 0), 8),
        (IVec3::new(8, 1, 0), 8),
        (IVec3::new(8, 0, 0), 6),
        (IVec3::new(8, 0, 0), 0),
        (IVec3::new(8, 0, 0), -8),
        (IVec3::new(i32::MAX, 0, 0), i32::MIN),
    ] {
        assert!(
            cube.height_at_lattice(p, m, Interpolation::Bilinear, &d).is_nan(),
            "{p} {m}"
        );
    }
    assert!(matches!(
        cube.sample(2, Face::Top, 0, 0),
        Err(DemError::OutOfGrid { .. })
    ));
    assert!(matches!(
        cube.sample(0, Face::Top, 129, 0),
        Err(DemError::OutOfGrid { .. })
    ));
}

/// A file imported small, its bytes, and a place to write damaged copies.
fn damaged(name: &str, f: impl FnOnce(&mut Vec<u8>)) -> Result<CubeDem, DemError> {
    static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
    let good = BYTES.get_or_init(|| {
        let out = tmp("damage_src.pmcdem");
        let opts = ImportOptions {
            level: Some(3),
            tile_size: 4,
            ..Default::default()
        };
        import_cube(fixture(), &out, &opts, &|_, _| {}).unwrap();
        std::fs::read(&out).unwrap()
    });
    let mut bytes = good.clone();
    f(&mut bytes);
    let path = tmp(name);
    std::fs::write(&path, &bytes).unwrap();
    let cube = CubeDem::open(&path)?;
    cube.verify()?;
    Ok(cube)
}

fn assert_names_file(e: &DemError, name: &str) {
    assert!(e.file().ends_with(name), "{e}");
    assert!(e.to_string().contains(name), "{e}");
}

#[test]
fn damaged_files_give_clear_errors() {
    damaged("d_good.pmcdem", |_| {}).unwrap();
    type Damage = Box<dyn FnOnce(&mut Vec<u8>)>;
    let cases: Vec<(&str, Damage, &str)> = vec![
        ("d_empty.pmcdem", Box::new(|b| b.clear()), "not a .pmcdem"),
        ("d_trunc_header.pmcdem", Box::new(|b| b.truncate(100)), "shorter"),
        (
            "d_trunc_tiles.pmcdem",
            Box::new(|b| {
                let n = b.len() - 10;
                b.truncate(n)
            }),
            "shorter",
        ),
        ("d_magic.pmcdem", Box::new(|b| b[1] = b'X'), "not a .pmcdem"),
        ("d_version.pmcdem", Box::new(|b| b[8] = 3), "version 3"),
        ("d_header_crc.pmcdem", Box::new(|b| b[41] ^= 0x10), "header checksum"),
        (
            "d_source_block.pmcdem",
            Box::new(|b| b[530] ^= 1),
            "source block's checksum",
        ),
        ("d_table.pmcdem", Box::new(|b| b[700] ^= 1), "table's checksum"),
        (
            "d_face_tile.pmcdem",
            Box::new(|b| {
                let data = u64::from_le_bytes(b[96..104].try_into().unwrap()) as usize;
                b[data + 1] ^= 0x40
            }),
            "level 0, face",
        ),
        (
            "d_tile.pmcdem",
            Box::new(|b| {
                let n = b.len() - 3;
                b[n] ^= 0x40
            }),
            "(source grid, columns from",
        ),
        ("d_appended.pmcdem", Box::new(|b| b.extend_from_slice(b"junk")), "holds"),
    ];
    for (name, f, needle) in cases {
        let e = damaged(name, f).unwrap_err();
        assert_names_file(&e, name);
        assert!(e.to_string().contains(needle), "{name}: {e}");
    }
    // Absurd sizes in a header with a valid checksum.
    for (at, value) in [(16usize, 40u8), (17, 9), (20, 0), (80, 0xff), (104, 0xff)] {
        let e = damaged("d_absurd.pmcdem", |b| {
            b[at] = value;
            let crc = crc(&b[..508]);
            b[508..512].copy_from_slice(&crc.to_le_bytes());
        })
        .unwrap_err();
        assert!(
            matches!(e, DemError::CubeCorrupt { .. } | DemError::Truncated { .. }),
            "{at}: {e}"
        );
    }
    // Absurd source blocks with a valid checksum: the width, the height, the tile size, a
    // step, an axis.
    let absurd: [(usize, &[u8]); 6] = [
        (544, &[0, 0, 0, 0]),
        (548, &[1, 0, 0, 0]),
        (552, &[0, 0, 0, 0]),
        (552, &[0xff, 0xff, 0, 0]),
        (520, &f64::NAN.to_le_bytes()),
        (512, &f64::INFINITY.to_le_bytes()),
    ];
    for (at, bytes) in absurd {
        let e = damaged("d_absurd_source.pmcdem", |b| {
            b[at..at + bytes.len()].copy_from_slice(bytes);
            let crc = crc(&b[512..636]);
            b[636..640].copy_from_slice(&crc.to_le_bytes());
        })
        .unwrap_err();
        assert!(matches!(e, DemError::CubeCorrupt { .. }), "{at}: {e}");
        assert_names_file(&e, "d_absurd_source.pmcdem");
    }
    // Foreign files.
    let cdf = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/etopo60.cdf");
    let e = CubeDem::open(&cdf).unwrap_err();
    assert!(
        matches!(e, DemError::NotCubeDem { .. }) && e.to_string().contains("netCDF"),
        "{e}"
    );
    let png = tmp("image.png");
    std::fs::write(&png, b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR").unwrap();
    let e = CubeDem::open(&png).unwrap_err();
    assert!(e.to_string().contains("PNG"), "{e}");
    let e = CubeDem::open(tmp("does_not_exist.pmcdem")).unwrap_err();
    assert!(matches!(e, DemError::Io { .. }));
}

/// CRC-32 (IEEE), bit by bit, to rewrite header checksums in tests.
fn crc(data: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in data {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 { (c >> 1) ^ 0xEDB8_8320 } else { c >> 1 };
        }
    }
    !c
}

mod flips {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]
        /// Any flipped byte is caught by open or verify, never a panic.
        #[test]
        fn any_flipped_byte_is_caught(pos in 0usize..100_000, bit in 0u8..8) {
            let r = damaged(&format!("flip_{pos}_{bit}.pmcdem"), |b| {
                let p = pos % b.len();
                // Reserved bytes are not checked beyond the header checksum; all are covered.
                b[p] ^= 1 << bit;
            });
            prop_assert!(r.is_err());
        }
    }
}

/// A synthetic global grid made on the fly, recording the rows requested.
struct Synthetic {
    w: usize,
    h: usize,
    outstanding: AtomicUsize,
    peak_bytes: AtomicUsize,
    reads: AtomicUsize,
    fail_after: Option<usize>,
    holes: bool,
}

impl Synthetic {
    fn new(w: usize, h: usize) -> Synthetic {
        Synthetic {
            w,
            h,
            outstanding: AtomicUsize::new(0),
            peak_bytes: AtomicUsize::new(0),
            reads: AtomicUsize::new(0),
            fail_after: None,
            holes: false,
        }
    }
    fn value(&self, c: usize, r: usize) -> f32 {
        if self.holes && (r * 7 / self.h == 3 || (c / 13 + r / 11).is_multiple_of(5)) {
            return f32::NAN;
        }
        ((c as f32 * 0.05).sin() * 2000.0 + (r as f32 * 0.031).cos() * 1500.0).round()
    }
}

impl EquirectSource for Synthetic {
    fn name(&self) -> &str {
        "synthetic"
    }
    fn width(&self) -> usize {
        self.w
    }
    fn height(&self) -> usize {
        self.h
    }
    fn lon_first(&self) -> f64 {
        -180.0 + 180.0 / self.w as f64
    }
    fn lon_step(&self) -> f64 {
        360.0 / self.w as f64
    }
    fn lat_first(&self) -> f64 {
        -90.0 + 90.0 / self.h as f64
    }
    fn lat_step(&self) -> f64 {
        180.0 / self.h as f64
    }
    fn wraps_in_longitude(&self) -> bool {
        true
    }
    fn read_rows(&self, row0: usize, rows: usize, out: &mut [f32]) -> Result<(), DemError> {
        let n = self.reads.fetch_add(1, Ordering::SeqCst);
        if self.fail_after.is_some_and(|f| n >= f) {
            return Err(DemError::Io {
                file: "synthetic".into(),
                source: std::io::Error::other("the disk went away"),
            });
        }
        let now = self.outstanding.fetch_add(rows * self.w * 4, Ordering::SeqCst) + rows * self.w * 4;
        self.peak_bytes.fetch_max(now, Ordering::SeqCst);
        assert!(row0 + rows <= self.h && out.len() == rows * self.w);
        for (k, v) in out.iter_mut().enumerate() {
            *v = self.value(k % self.w, row0 + k / self.w);
        }
        self.outstanding.fetch_sub(rows * self.w * 4, Ordering::SeqCst);
        Ok(())
    }
}

#[test]
fn import_memory_stays_within_the_budget() {
    let src = Synthetic::new(2048, 1024);
    let budget = 256 << 10; // 256 KiB: 32 rows, the grid is 8 MiB
    let opts = ImportOptions {
        level: Some(7),
        memory_budget: budget,
        ..Default::default()
    };
    let out = tmp("synthetic.pmcdem");
    let calls = Mutex::new(Vec::new());
    let report = import_cube(&src, &out, &opts, &|d, t| calls.lock().unwrap().push((d, t))).unwrap();
    let peak = src.peak_bytes.load(Ordering::SeqCst);
    assert!(peak <= budget, "{peak} bytes of rows held with a budget of {budget}");
    assert!(report.bands > 30, "{report:?}");
    let calls = calls.into_inner().unwrap();
    assert_eq!(calls.last(), Some(&(report.tiles, report.tiles)));
    assert!(calls.windows(2).all(|w| w[0].0 <= w[1].0));
    // The banded import equals an import in one band.
    let one = import_cube(
        &src,
        &tmp("synthetic_one.pmcdem"),
        &ImportOptions {
            level: Some(7),
            ..Default::default()
        },
        &|_, _| {},
    )
    .unwrap();
    assert_eq!(one.bands, 1);
    assert_eq!(one.digest, report.digest);
    // Tiles are written as they complete, so the order differs; the content does not.
    let (a, b) = (
        CubeDem::open(&out).unwrap(),
        CubeDem::open(tmp("synthetic_one.pmcdem")).unwrap(),
    );
    a.verify().unwrap();
    for face in Face::ALL {
        for i in (0..=128).step_by(7) {
            for j in (0..=128).step_by(3) {
                assert_eq!(a.sample(0, face, i, j).unwrap(), b.sample(0, face, i, j).unwrap());
            }
        }
    }
}

#[test]
fn missing_samples_are_filled_and_counted() {
    let mut src = Synthetic::new(360, 180);
    src.holes = true;
    let out = tmp("holes.pmcdem");
    let opts = ImportOptions {
        level: Some(6),
        ..Default::default()
    };
    let report = import_cube(&src, &out, &opts, &|_, _| {}).unwrap();
    assert!(report.filled > 1000, "{report:?}");
    let cube = CubeDem::open(&out).unwrap();
    assert_eq!(cube.filled_samples(), report.filled);
    let (min, max) = cube.value_range();
    for face in Face::ALL {
        for i in 0..=64 {
            let v = f64::from(cube.sample(0, face, i, 64 - i).unwrap());
            assert!(v.is_finite() && v >= min && v <= max);
        }
    }
    // A constant fill: sparse tiles where nothing is known.
    let empty = Synthetic {
        holes: true,
        ..Synthetic::new(4, 4)
    };
    let e = import_cube(&AllMissing(empty), &tmp("none.pmcdem"), &opts, &|_, _| {}).unwrap_err();
    assert!(matches!(e, DemError::EmptySource { .. }), "{e}");
    assert!(!tmp("none.pmcdem").exists());
}

struct AllMissing(Synthetic);
impl EquirectSource for AllMissing {
    fn name(&self) -> &str {
        "all-missing"
    }
    fn width(&self) -> usize {
        self.0.w
    }
    fn height(&self) -> usize {
        self.0.h
    }
    fn lon_first(&self) -> f64 {
        self.0.lon_first()
    }
    fn lon_step(&self) -> f64 {
        self.0.lon_step()
    }
    fn lat_first(&self) -> f64 {
        self.0.lat_first()
    }
    fn lat_step(&self) -> f64 {
        self.0.lat_step()
    }
    fn wraps_in_longitude(&self) -> bool {
        true
    }
    fn read_rows(&self, _: usize, _: usize, out: &mut [f32]) -> Result<(), DemError> {
        out.fill(f32::NAN);
        Ok(())
    }
}

/// A regional grid: a 10 x 10 degree patch.
struct Regional;
impl EquirectSource for Regional {
    fn name(&self) -> &str {
        "regional"
    }
    fn width(&self) -> usize {
        101
    }
    fn height(&self) -> usize {
        101
    }
    fn lon_first(&self) -> f64 {
        10.0
    }
    fn lon_step(&self) -> f64 {
        0.1
    }
    fn lat_first(&self) -> f64 {
        40.0
    }
    fn lat_step(&self) -> f64 {
        0.1
    }
    fn wraps_in_longitude(&self) -> bool {
        false
    }
    fn read_rows(&self, row0: usize, rows: usize, out: &mut [f32]) -> Result<(), DemError> {
        for (k, v) in out.iter_mut().enumerate() {
            *v = 100.0 + ((k % 101) + row0 + k / 101) as f32;
        }
        let _ = rows;
        Ok(())
    }
}

#[test]
fn regional_grids_fill_outside_and_store_constant_tiles() {
    let out = tmp("regional.pmcdem");
    let opts = ImportOptions {
        level: Some(8),
        fill_value: Some(0.0),
        ..Default::default()
    };
    let report = import_cube(&Regional, &out, &opts, &|_, _| {}).unwrap();
    assert!(report.constant_tiles > report.tiles / 2, "{report:?}");
    let cube = CubeDem::open(&out).unwrap();
    cube.verify().unwrap();
    // Inside the patch the data; far away the fill.
    let inside = LatLon::new(45.0, 15.0).unwrap().to_unit();
    let h = cube.height(inside, Interpolation::Bilinear, &DetailNoise::OFF, 1.0);
    assert!((h - 200.0).abs() < 5.0, "{h}");
    let far = LatLon::new(-30.0, -100.0).unwrap().to_unit();
    assert_eq!(
        cube.height(far, Interpolation::Bicubic, &DetailNoise::default(), 1.0),
        0.0
    );
    assert_eq!(cube.source_extent(), [10.0, 20.0, 40.0, 50.0]);
    // Without a fill value the nearest data fill it.
    let report = import_cube(
        &Regional,
        &out,
        &ImportOptions {
            level: Some(6),
            ..Default::default()
        },
        &|_, _| {},
    )
    .unwrap();
    let cube = CubeDem::open(&out).unwrap();
    assert_eq!(cube.filled_samples(), report.filled);
    let h = cube.height(far, Interpolation::Bilinear, &DetailNoise::OFF, 1.0);
    assert!((100.0..=300.0).contains(&h), "{h}");
}

#[test]
fn a_failed_import_leaves_nothing() {
    let out = tmp("failed.pmcdem");
    let _ = std::fs::remove_file(&out);
    let dir_before: Vec<_> = std::fs::read_dir(out.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    for fail_after in [0, 1, 5, 20] {
        let mut src = Synthetic::new(512, 256);
        src.fail_after = Some(fail_after);
        let opts = ImportOptions {
            level: Some(6),
            memory_budget: 64 << 10,
            ..Default::default()
        };
        let e = import_cube(&src, &out, &opts, &|_, _| {}).unwrap_err();
        assert!(e.to_string().contains("disk went away"), "{e}");
        assert!(!out.exists());
    }
    // Refused options write nothing either.
    for opts in [
        ImportOptions {
            level: Some(17),
            ..Default::default()
        },
        ImportOptions {
            level: Some(0),
            ..Default::default()
        },
        ImportOptions {
            memory_budget: 100,
            ..Default::default()
        },
        ImportOptions {
            radius: -1.0,
            ..Default::default()
        },
        ImportOptions {
            tile_size: 1,
            ..Default::default()
        },
        ImportOptions {
            level: Some(16),
            tile_size: 2,
            ..Default::default()
        },
    ] {
        let e = import_cube(fixture(), &out, &opts, &|_, _| {}).unwrap_err();
        assert!(matches!(e, DemError::InvalidOptions { .. }), "{e}");
        assert!(e.file().ends_with("etopo60.cdf"), "{e}");
        assert!(!out.exists());
    }
    // An existing file survives a failed import.
    std::fs::write(&out, b"keep").unwrap();
    let mut src = Synthetic::new(512, 256);
    src.fail_after = Some(3);
    assert!(import_cube(
        &src,
        &out,
        &ImportOptions {
            level: Some(6),
            memory_budget: 64 << 10,
            ..Default::default()
        },
        &|_, _| {}
    )
    .is_err());
    assert!(std::fs::read(&out).unwrap() == b"keep");
    std::fs::remove_file(&out).unwrap();
    let dir_after: Vec<_> = std::fs::read_dir(out.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    let leftovers: Vec<_> = dir_after
        .iter()
        .filter(|n| n.to_string_lossy().contains("failed.pmcdem.tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?} (before: {})", dir_before.len());
}

#[test]
fn many_threads_share_one_reader() {
    use rayon::prelude::*;
    let out = tmp("etopo60_l7.pmcdem");
    let _ = small();
    let cube = CubeDem::open_with_cache(&out, 64 << 10).unwrap(); // a few tiles only
    let sums: Vec<f64> = (0..64)
        .into_par_iter()
        .map(|k| {
            let lat = -80.0 + 2.5 * f64::from(k);
            (0..90)
                .map(|l| {
                    let d = LatLon::new(lat, -180.0 + 4.0 * f64::from(l)).unwrap().to_unit();
                    cube.height(d, Interpolation::Bicubic, &DetailNoise::default(), 100.0)
                })
                .sum()
        })
        .collect();
    assert!(sums.iter().all(|s| s.is_finite()));
    let again: Vec<f64> = (0..64)
        .map(|k| {
            let lat = -80.0 + 2.5 * f64::from(k);
            (0..90)
                .map(|l| {
                    let d = LatLon::new(lat, -180.0 + 4.0 * f64::from(l)).unwrap().to_unit();
                    small().height(d, Interpolation::Bicubic, &DetailNoise::default(), 100.0)
                })
                .sum()
        })
        .collect();
    assert_eq!(sums, again);
}
