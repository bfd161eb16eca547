//! A mutation fuzzer for the readers: damaged copies of real files, each parsed under
//! [`std::panic::catch_unwind`]. A reader may accept or refuse any input, but never panic.
//!
//! The list of [`Target`]s is the list of readers: to fuzz another reader, push a target with
//! its seed file and a function that parses bytes. Mutations are drawn from a deterministic
//! generator, so that the input of any execution is rebuilt from the run's seed, the target's
//! index and the iteration ([`input`]).
//!
//! Run it with `cargo run --release -p pmc-dem --example fuzz_readers -- --iterations N --seed S`.

use crate::{EquirectDem, EquirectSource, GeoTiffSource, NetcdfSource, PngExtent};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// One reader to fuzz: a seed file and a function that parses bytes (and may check what it
/// read; any panic is a failure).
pub struct Target {
    /// A short name, for reports and the names of saved inputs.
    pub name: &'static str,
    /// The real file whose damaged copies are parsed.
    pub seed: Vec<u8>,
    /// Parses one input; returns whether the reader accepted it.
    pub parse: fn(&[u8]) -> bool,
}

/// The files under `tests/fixtures` used as seeds (relative to the crate's directory).
pub const SEED_FILES: [&str; 6] = [
    "etopo60.cdf",
    "etopo5deg_i16_deflate.tif",
    "etopo5deg_f32_lzw.tif",
    "etopo5deg_i16_tiled.tif",
    "etopo5deg.png",
    "etopo60_l6_v1.pmcdem",
];

/// The extent given to the PNG reader: the seed's (ETOPO60 every 5 degrees, from 20 east).
pub const PNG_EXTENT: PngExtent = PngExtent {
    west: 20.0,
    south: -90.0,
    east: 380.0,
    north: 90.0,
    scale: 1.0,
    offset: -11_000.0,
    nodata: Some(0),
    cell_centres: true,
};

/// Checks that a refusal names the file (`fuzz`).
fn named(e: &crate::DemError) {
    assert_eq!(e.file(), "fuzz");
    assert!(e.to_string().starts_with("fuzz: "));
}

/// An error about the file at `path` names it.
fn named_path(e: &crate::DemError, path: &Path) {
    let file = path.display().to_string();
    assert_eq!(e.file(), file);
    assert!(e.to_string().starts_with(&file));
}

/// Checks a grid read in memory.
fn consistent(dem: &EquirectDem) {
    let (w, h) = (dem.width(), dem.height());
    assert!(w >= 1 && h >= 1);
    assert_eq!(dem.heights().len(), w * h);
    assert!(dem.lon_step() > 0.0 && dem.lat_step() > 0.0);
    assert!((-180.0..180.0).contains(&dem.lon_first()));
    let s = dem.stats();
    assert_eq!(s.valid + s.missing, w * h);
    for (lat, lon) in [(0.0, 0.0), (45.0, -170.0), (-89.0, 359.0), (91.0, 1e6)] {
        if let Some(v) = dem.sample_bilinear(lat, lon) {
            assert!(v.is_finite());
        }
    }
}

/// Reads every row of a source in bands of 16 (refusals must name the file); whether all were
/// read.
fn all_rows(src: &dyn EquirectSource) -> bool {
    let (w, h) = (src.width(), src.height());
    assert!(w >= 1 && h >= 1);
    let mut row0 = 0;
    while row0 < h {
        let rows = 16.min(h - row0);
        let mut band = vec![0.0f32; rows * w];
        if let Err(e) = src.read_rows(row0, rows, &mut band) {
            named(&e);
            return false;
        }
        row0 += rows;
    }
    true
}

/// Reads `bytes` as a netCDF classic grid in memory (a grid checked for consistency, or a refusal
/// naming the file `fuzz`); whether it was accepted. Panics only on a bug.
pub fn parse_netcdf(bytes: &[u8]) -> bool {
    match EquirectDem::from_netcdf_bytes("fuzz", bytes.to_vec(), None) {
        Ok(dem) => {
            consistent(&dem);
            true
        }
        Err(e) => {
            named(&e);
            false
        }
    }
}

/// Reads `bytes` as a netCDF classic source, every row in bands; whether all were read.
pub fn parse_netcdf_source(bytes: &[u8]) -> bool {
    match NetcdfSource::from_bytes("fuzz", bytes.to_vec(), None) {
        Ok(src) => all_rows(&src),
        Err(e) => {
            named(&e);
            false
        }
    }
}

/// Reads `bytes` as a GeoTIFF grid in memory; whether it was accepted.
pub fn parse_geotiff(bytes: &[u8]) -> bool {
    match EquirectDem::from_geotiff_bytes("fuzz", bytes.to_vec()) {
        Ok(dem) => {
            consistent(&dem);
            true
        }
        Err(e) => {
            named(&e);
            false
        }
    }
}

/// Reads `bytes` as a GeoTIFF source, every row in bands; whether all were read.
pub fn parse_geotiff_source(bytes: &[u8]) -> bool {
    match GeoTiffSource::from_bytes("fuzz", bytes.to_vec()) {
        Ok(src) => all_rows(&src),
        Err(e) => {
            named(&e);
            false
        }
    }
}

/// Reads `bytes` as a 16-bit PNG grid with [`PNG_EXTENT`]; whether it was accepted.
pub fn parse_png(bytes: &[u8]) -> bool {
    match EquirectDem::from_png16_bytes("fuzz", bytes, &PNG_EXTENT) {
        Ok(dem) => {
            consistent(&dem);
            true
        }
        Err(e) => {
            named(&e);
            false
        }
    }
}

thread_local! {
    /// Where this thread writes a `.pmcdem` input (the reader opens files, not bytes).
    static PMCDEM_PATH: PathBuf = std::env::temp_dir().join(format!(
        "pmc-dem-fuzz-{}-{:?}.pmcdem",
        std::process::id(),
        std::thread::current().id()
    ));
}

/// Writes `bytes` to a file of this thread and opens it as a `.pmcdem`, asks for heights
/// anywhere and verifies every tile; whether it was accepted whole.
pub fn parse_pmcdem(bytes: &[u8]) -> bool {
    PMCDEM_PATH.with(|path| {
        if std::fs::write(path, bytes).is_err() {
            return false;
        }
        let accepted = match crate::CubeDem::open_with_cache(path, 1 << 20) {
            Ok(dem) => {
                // Heights anywhere must not panic, whatever the tiles hold; a damaged tile is
                // found by verify.
                let detail = crate::DetailNoise::default();
                for d in [
                    pmc_geometry::glam::DVec3::Y,
                    pmc_geometry::glam::DVec3::new(0.3, -0.2, 0.9),
                ] {
                    let _ = dem.height(d, crate::Interpolation::Bicubic, &detail, 1.0);
                }
                // A batch of lattice points (stencils inside source tiles, across their borders
                // and the antimeridian), and the stored source samples.
                let points: Vec<pmc_geometry::glam::IVec3> = (0..40)
                    .filter_map(|k| {
                        pmc_geometry::face_lattice(pmc_geometry::Face::ALL[k % 6], k as i64 * 97, 1000, 4096)
                    })
                    .collect();
                let mut out = vec![0.0; points.len()];
                dem.heights_at_lattice(&points, 4096, crate::Interpolation::Bilinear, &detail, &mut out);
                if let Some((w, h)) = dem.source_size() {
                    let _ = dem.source_sample(w - 1, h - 1);
                }
                match dem.verify() {
                    Ok(()) => true,
                    Err(e) => {
                        named_path(&e, path);
                        false
                    }
                }
            }
            Err(e) => {
                named_path(&e, path);
                false
            }
        };
        let _ = std::fs::remove_file(path);
        accepted
    })
}

/// A small `.pmcdem` made from the ETOPO60 seed (data level 6, 16-sample tiles): the bytes of an
/// import, the same every time.
fn pmcdem_seed(fixtures: &Path) -> std::io::Result<Vec<u8>> {
    let src = EquirectDem::read_netcdf(fixtures.join(SEED_FILES[0]), None).map_err(std::io::Error::other)?;
    // A name of this call alone: tests build their targets concurrently.
    static CALLS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let out = std::env::temp_dir().join(format!("pmc-dem-fuzz-seed-{}-{call}.pmcdem", std::process::id()));
    let options = crate::ImportOptions {
        level: Some(6),
        tile_size: 16,
        ..crate::ImportOptions::default()
    };
    crate::import_cube(&src, &out, &options, &|_, _| {}).map_err(std::io::Error::other)?;
    let bytes = std::fs::read(&out);
    let _ = std::fs::remove_file(&out);
    bytes
}

/// Every reader, with the seed files read from `fixtures` (the crate's `tests/fixtures`): the
/// netCDF reader whole and windowed on ETOPO60; the GeoTIFF reader whole on strips compressed
/// with deflate and LZW and on tiles, and windowed on the tiles; the PNG reader; the `.pmcdem`
/// reader on a version 2 file (faces and source grid) and on a version 1 file.
pub fn targets(fixtures: &Path) -> std::io::Result<Vec<Target>> {
    let read = |name: &str| std::fs::read(fixtures.join(name));
    let cdf = read(SEED_FILES[0])?;
    let tiled = read(SEED_FILES[3])?;
    Ok(vec![
        Target {
            name: "netcdf",
            seed: cdf.clone(),
            parse: parse_netcdf,
        },
        Target {
            name: "netcdf-source",
            seed: cdf,
            parse: parse_netcdf_source,
        },
        Target {
            name: "geotiff-deflate",
            seed: read(SEED_FILES[1])?,
            parse: parse_geotiff,
        },
        Target {
            name: "geotiff-lzw",
            seed: read(SEED_FILES[2])?,
            parse: parse_geotiff,
        },
        Target {
            name: "geotiff-tiled",
            seed: tiled.clone(),
            parse: parse_geotiff,
        },
        Target {
            name: "geotiff-source",
            seed: tiled,
            parse: parse_geotiff_source,
        },
        Target {
            name: "png16",
            seed: read(SEED_FILES[4])?,
            parse: parse_png,
        },
        Target {
            name: "pmcdem",
            seed: pmcdem_seed(fixtures)?,
            parse: parse_pmcdem,
        },
        Target {
            name: "pmcdem-v1",
            seed: read(SEED_FILES[5])?,
            parse: parse_pmcdem,
        },
    ])
}

/// A small deterministic generator (SplitMix64).
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A number in `0..n` (`n` > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// Byte values that often reach edge cases.
const INTERESTING_BYTES: [u8; 6] = [0, 0xFF, 0x7F, 0x80, 1, 0xFE];
/// Word values that often reach edge cases in size and count fields.
const INTERESTING_WORDS: [u32; 10] = [
    0,
    1,
    2,
    0x7F,
    0xFFFF,
    0x8000,
    0x7FFF_FFFF,
    0x8000_0000,
    0xFFFF_FFFF,
    0x0001_0000,
];

/// A position in `0..len` (`len` > 0), half the time in the first KiB, where the headers are.
fn position(rng: &mut Rng, len: usize) -> usize {
    if rng.below(2) == 0 {
        rng.below(len.min(1024))
    } else {
        rng.below(len)
    }
}

/// Applies one to three mutations to a copy of `seed`: bit flips, bytes set to interesting
/// values, truncations, insertions of random bytes, duplicated or deleted ranges, and 16- or
/// 32-bit header fields (in either byte order) set to interesting values.
pub fn mutate(rng: &mut Rng, seed: &[u8]) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..1 + rng.below(3) {
        if b.is_empty() {
            b.push(rng.next_u64() as u8);
            continue;
        }
        let len = b.len();
        match rng.below(8) {
            0 => {
                let at = position(rng, len);
                b[at] ^= 1 << rng.below(8);
            }
            1 => {
                let at = position(rng, len);
                b[at] = INTERESTING_BYTES[rng.below(INTERESTING_BYTES.len())];
            }
            2 => {
                let keep = if rng.below(2) == 0 {
                    rng.below(len)
                } else {
                    len - 1 - rng.below(len.min(64))
                };
                b.truncate(keep);
            }
            3 => {
                let at = position(rng, len + 1);
                let n = 1 + rng.below(16);
                let bytes: Vec<u8> = (0..n).map(|_| rng.next_u64() as u8).collect();
                b.splice(at..at, bytes);
            }
            4 => {
                let from = position(rng, len);
                let n = 1 + rng.below(64.min(len - from));
                let range = b[from..from + n].to_vec();
                let to = position(rng, len + 1);
                b.splice(to..to, range);
            }
            5 => {
                let from = position(rng, len);
                let n = 1 + rng.below(16.min(len - from));
                b.drain(from..from + n);
            }
            _ => {
                let wide = rng.below(2) == 0;
                let size = if wide { 4 } else { 2 };
                if len < size {
                    continue;
                }
                let at = position(rng, len - size + 1);
                let mut v = INTERESTING_WORDS[rng.below(INTERESTING_WORDS.len())];
                if rng.below(4) == 0 {
                    v = v.wrapping_add(rng.below(3) as u32).wrapping_sub(1);
                }
                let bytes = match (wide, rng.below(2) == 0) {
                    (true, true) => v.to_be_bytes().to_vec(),
                    (true, false) => v.to_le_bytes().to_vec(),
                    (false, true) => (v as u16).to_be_bytes().to_vec(),
                    (false, false) => (v as u16).to_le_bytes().to_vec(),
                };
                b[at..at + size].copy_from_slice(&bytes);
            }
        }
    }
    b
}

/// The seed of the generator for `iteration` of target `index` in a run seeded `seed`.
pub fn iteration_seed(seed: u64, index: usize, iteration: u64) -> u64 {
    let mut r = Rng::new(seed ^ ((index as u64) << 56) ^ iteration.wrapping_mul(0x2545_F491_4F6C_DD1D));
    r.next_u64()
}

/// The input of `iteration` of target `index` in a run seeded `seed`.
pub fn input(target: &Target, seed: u64, index: usize, iteration: u64) -> Vec<u8> {
    mutate(&mut Rng::new(iteration_seed(seed, index, iteration)), &target.seed)
}

/// What a run found for one target.
#[derive(Debug, Clone)]
pub struct Report {
    /// The target's name.
    pub name: &'static str,
    /// Inputs parsed.
    pub executions: u64,
    /// Inputs the reader accepted (a grid read, or every row of a source).
    pub accepted: u64,
    /// Time spent.
    pub elapsed: Duration,
    /// The iterations whose input made the reader panic, with where each input was saved.
    pub panics: Vec<(u64, Option<PathBuf>)>,
}

/// Parses `iterations` mutated inputs per target, each under `catch_unwind`. An input that makes
/// a reader panic is reported (its iteration and seed printed on standard error) and, with
/// `save_to`, written there as `NAME-SEED-ITERATION.bin`.
///
/// Panic messages still go to the panic hook: install a quiet one to silence them.
pub fn run(targets: &[Target], iterations: u64, seed: u64, save_to: Option<&Path>) -> Vec<Report> {
    let mut reports = Vec::new();
    for (index, target) in targets.iter().enumerate() {
        let start = Instant::now();
        let mut panics = Vec::new();
        let mut accepted = 0;
        for i in 0..iterations {
            let bytes = input(target, seed, index, i);
            let outcome = catch_unwind(AssertUnwindSafe(|| (target.parse)(&bytes)));
            accepted += u64::from(matches!(outcome, Ok(true)));
            if outcome.is_err() {
                let saved = save_to.and_then(|dir| {
                    let path = dir.join(format!("{}-{seed}-{i}.bin", target.name));
                    std::fs::create_dir_all(dir).ok()?;
                    std::fs::write(&path, &bytes).ok()?;
                    Some(path)
                });
                eprintln!(
                    "PANIC in {} with --seed {seed}, iteration {i} (input {} bytes{})",
                    target.name,
                    bytes.len(),
                    saved
                        .as_ref()
                        .map(|p| format!(", saved as {}", p.display()))
                        .unwrap_or_default()
                );
                panics.push((i, saved));
            }
        }
        reports.push(Report {
            name: target.name,
            executions: iterations,
            accepted,
            elapsed: start.elapsed(),
            panics,
        });
    }
    reports
}
