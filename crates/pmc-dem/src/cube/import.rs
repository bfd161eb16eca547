//! Reprojection of an equirectangular grid onto the six faces of the cube, written as a
//! `.pmcdem` file with bounded memory.

use super::format::{
    stored_levels, Entry, Header, SampleFormat, SourceLayout, TileGrid, TileKind, TileRef, DEFAULT_SOURCE_TILE_SIZE,
    DEFAULT_TILE_SIZE, ENTRY_BYTES, HEADER_BYTES_V2, MAX_DATA_LEVEL, VERSION,
};
use super::lattice::lattice_of;
use super::source_grid::{CoarseFill, GridPos, SourceGrid};
use crate::error::DemError;
use crate::source::EquirectSource;
use pmc_geometry::glam::DVec3;
use pmc_geometry::{cube_to_sphere, face_uv_to_sphere, Face, LatLon};
use rayon::prelude::*;
use sha2::{Digest, Sha256};
use std::collections::HashMap;
use std::fs::File;
use std::io::Write;
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The default memory budget of an import: 512 MiB.
pub const DEFAULT_MEMORY_BUDGET: usize = 512 << 20;
/// The most tiles an import writes (the tile table and the per-tile bookkeeping stay below about
/// 4 GiB): larger levels need larger tiles.
pub const MAX_TILES: u64 = 1 << 26;
/// The default body radius: the Earth's mean radius, 6 371 000 m.
pub const DEFAULT_RADIUS: f64 = 6_371_000.0;

/// Which sample format an import writes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FormatChoice {
    /// 16-bit integers in whole metres (scale 1, offset 0) when every valid source value (and
    /// the fill value, if any) is an integer within the i16 range, else 32-bit floats.
    #[default]
    Auto,
    /// 16-bit integers scaled to span the data's range (`scale = (max - min) / 65534`): lossy.
    I16,
    /// 32-bit floats: interpolated values kept to float precision.
    F32,
}

/// How [`import_cube`] reprojects a grid.
#[derive(Clone, Debug)]
pub struct ImportOptions {
    /// The data level `n` (faces of `2^n + 1` samples a side), 1 to
    /// [`MAX_DATA_LEVEL`](crate::cube::MAX_DATA_LEVEL). `None`: [`default_level`].
    pub level: Option<u32>,
    /// The sample format.
    pub format: FormatChoice,
    /// Bytes of source rows held at once (the import reads the source in bands of rows of at
    /// most half this; open output tiles take part of the other half). Must hold at least four
    /// source rows. Default [`DEFAULT_MEMORY_BUDGET`].
    pub memory_budget: usize,
    /// Body radius in metres, recorded in the file. Default [`DEFAULT_RADIUS`].
    pub radius: f64,
    /// Height of the datum (sea level) in the data's metres, recorded in the file. Default 0.
    pub datum: f64,
    /// Samples along a tile's side, 2 to 4096. Default
    /// [`DEFAULT_TILE_SIZE`](crate::cube::DEFAULT_TILE_SIZE) (64).
    pub tile_size: u32,
    /// The value given to missing samples. `None` (default): the value of the nearest valid
    /// cell of a coarse copy of the source (see the spec, "Missing samples").
    pub fill_value: Option<f32>,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            level: None,
            format: FormatChoice::Auto,
            memory_budget: DEFAULT_MEMORY_BUDGET,
            radius: DEFAULT_RADIUS,
            datum: 0.0,
            tile_size: DEFAULT_TILE_SIZE,
            fill_value: None,
        }
    }
}

/// What [`import_cube`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportReport {
    /// The data level `n`.
    pub level: u32,
    /// The sample format written.
    pub format: SampleFormat,
    /// Samples stored, all levels and faces (edge samples once per face).
    pub samples: u64,
    /// Samples of the finest level whose value was filled (missing in the source).
    pub filled: u64,
    /// Source samples stored (the source grid kept in the file, `width x height`).
    pub source_samples: u64,
    /// Source samples whose value was missing and filled.
    pub source_filled: u64,
    /// Bytes of the stored source grid: its tiles and their table entries.
    pub source_bytes: u64,
    /// Tiles written.
    pub tiles: u64,
    /// Tiles stored as one constant.
    pub constant_tiles: u64,
    /// Bytes of the file.
    pub bytes: u64,
    /// The content digest (SHA-256, hex).
    pub digest: String,
    /// Bands of rows the source was read in (after the pre-pass).
    pub bands: usize,
    /// The most source rows held at once.
    pub band_rows: usize,
}

/// Angle in radians between neighbouring samples at the centre of a face of resolution `2^n`.
pub fn centre_spacing_radians(n: u32) -> f64 {
    let step = 2.0 / f64::from(1u32 << n);
    face_uv_to_sphere(Face::South, step, 0.0).angle_between(DVec3::Z)
}

/// The default data level for a source: the smallest `n` whose sample spacing at a face
/// centre is at most the source's spacing along the equator (`lon_step`), capped at
/// [`MAX_DATA_LEVEL`](crate::cube::MAX_DATA_LEVEL) (finer sources are then decimated).
pub fn default_level(source: &dyn EquirectSource) -> u32 {
    let want = source.lon_step().to_radians();
    (1..=MAX_DATA_LEVEL)
        .find(|&n| centre_spacing_radians(n) <= want * (1.0 + 1e-9))
        .unwrap_or(MAX_DATA_LEVEL)
}

/// What the streaming pre-pass learns of the source.
struct Survey {
    min: f64,
    max: f64,
    valid: u64,
    integers: bool,
    fill: CoarseFill,
}

/// A temporary file next to the output, removed when dropped unless renamed into place.
struct TempFile {
    path: PathBuf,
    file: Option<File>,
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if self.file.take().is_some() {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

fn invalid(source: &dyn EquirectSource, detail: String) -> DemError {
    DemError::InvalidOptions {
        file: source.name().to_owned(),
        detail,
    }
}

/// Reprojects `source` onto the six faces of the cube and writes a `.pmcdem` version 2 file at
/// `out` (format: `docs/specs/pmcdem-v2.md`) that also keeps the source grid itself, from which
/// [`CubeDem`](crate::CubeDem) takes its heights (exact at every source sample).
///
/// Each sample of each face is the lattice point `N n + (2i - N) u + (2j - N) v` of resolution
/// `N = 2^n`, mapped to the sphere by `cube_to_sphere`; its latitude and longitude are
/// interpolated bilinearly from the source (exact at source samples, wrapping across the
/// antimeridian for global grids). The value depends on the lattice point alone, so samples on
/// face edges and corners are bit-identical on every face that holds them, and overview samples
/// equal the finest samples at the same point. Missing samples (NaN, or outside a regional grid)
/// take [`ImportOptions::fill_value`] or the nearest valid coarse value, and are counted.
///
/// Memory: the source is read three times in bands of rows (a pre-pass for the range, the
/// sample format and the fill, the reprojection, then the source grid's own tiles), never more
/// than half of [`ImportOptions::memory_budget`] bytes of rows at once from the source; the last
/// pass also holds one row of source tiles
/// ([`DEFAULT_SOURCE_TILE_SIZE`](crate::cube::DEFAULT_SOURCE_TILE_SIZE) rows). Tiles are written
/// as soon as they are complete. Work is spread over rayon's threads. `progress(done, total)` is
/// called as face tiles are written.
///
/// The file is written to a temporary file next to `out` and renamed into place only on
/// success: on any error nothing is left at `out` (an existing file there is left as it was).
pub fn import_cube(
    source: &dyn EquirectSource,
    out: &Path,
    options: &ImportOptions,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<ImportReport, DemError> {
    let (w, h) = (source.width(), source.height());
    if w < 2 || h < 2 {
        return Err(invalid(
            source,
            format!("a grid of {w} x {h} samples; at least 2 x 2 are needed"),
        ));
    }
    for (what, v) in [
        ("longitude step", source.lon_step()),
        ("latitude step", source.lat_step()),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(
                source,
                format!("the source's {what} is {v}; it must be above 0"),
            ));
        }
    }
    let n = options.level.unwrap_or_else(|| default_level(source));
    if !(1..=MAX_DATA_LEVEL).contains(&n) {
        return Err(invalid(
            source,
            format!("data level {n} asked for; levels 1 to {MAX_DATA_LEVEL} are supported ({MAX_DATA_LEVEL} is 2^{MAX_DATA_LEVEL} + 1 samples a face side)"),
        ));
    }
    if !(2..=4096).contains(&options.tile_size) {
        return Err(invalid(
            source,
            format!("tile size {} asked for; 2 to 4096 are supported", options.tile_size),
        ));
    }
    if !(options.radius.is_finite() && options.radius > 0.0) {
        return Err(invalid(
            source,
            format!("radius {} m; it must be a number of metres above 0", options.radius),
        ));
    }
    if !options.datum.is_finite() || options.fill_value.is_some_and(|v| !v.is_finite()) {
        return Err(invalid(
            source,
            "the datum and the fill value must be finite numbers".to_owned(),
        ));
    }
    let row_bytes = w * 4;
    let max_rows = (options.memory_budget / 2 / row_bytes).min(h);
    if max_rows < 2 {
        return Err(invalid(
            source,
            format!(
                "a memory budget of {} bytes cannot hold two rows of {w} samples; give at least {}",
                options.memory_budget,
                4 * row_bytes
            ),
        ));
    }
    let grid = SourceGrid::new(source);
    let survey = survey(source, &grid, max_rows)?;
    let format = choose_format(options, &survey);

    let tiles = TileGrid::new(n, options.tile_size);
    if tiles.total > MAX_TILES {
        return Err(invalid(
            source,
            format!(
                "level {n} in tiles of {} samples makes {} tiles, more than the {MAX_TILES} supported; use larger tiles",
                options.tile_size, tiles.total
            ),
        ));
    }
    let big_n = 1i32 << n;
    // The source rows each tile needs: the range of the lower interpolation rows of its samples.
    let ranges: Vec<(u32, u32)> = (0..tiles.total)
        .into_par_iter()
        .map(|idx| {
            let t = tiles.tile(idx);
            let (mut lo, mut hi) = (u32::MAX, 0u32);
            for_each_sample(&t, big_n, |_, p| {
                let r = key_row(&grid, &position(&grid, p)) as u32;
                lo = lo.min(r);
                hi = hi.max(r);
            });
            (lo, hi)
        })
        .collect();

    // The output goes to a temporary file that is renamed into place on success.
    let dir = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = out
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let unique = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp_path = dir.join(format!(".{name}.tmp-{}-{unique}", std::process::id()));
    let out_name = out.display().to_string();
    let werr = |source: std::io::Error| DemError::Write {
        file: out_name.clone(),
        source,
    };
    let mut tmp = TempFile {
        file: Some(File::create(&tmp_path).map_err(werr)?),
        path: tmp_path,
    };
    let file = tmp.file.as_ref().expect("just created");

    if u32::try_from(w).is_err() || u32::try_from(h).is_err() {
        return Err(invalid(
            source,
            format!("a grid of {w} x {h} samples; at most 2^32 - 1 a side are supported"),
        ));
    }
    let src_layout = SourceLayout {
        lon_first: source.lon_first(),
        lon_step: source.lon_step(),
        lat_first: source.lat_first(),
        lat_step: source.lat_step(),
        width: w as u32,
        height: h as u32,
        tile: DEFAULT_SOURCE_TILE_SIZE,
        wraps: grid.wraps,
    };
    let all_tiles = tiles.total + src_layout.total();
    if all_tiles > MAX_TILES {
        return Err(invalid(
            source,
            format!("the faces and the source grid make {all_tiles} tiles, more than the {MAX_TILES} supported; use larger tiles or a larger memory budget"),
        ));
    }
    let data_offset = (HEADER_BYTES_V2 + all_tiles as usize * ENTRY_BYTES + 4) as u64;
    let mut write_at = data_offset;
    let mut entries: Vec<Entry> = vec![
        Entry {
            offset: 0,
            len: 0,
            crc: 0,
            kind: TileKind::Raw
        };
        all_tiles as usize
    ];
    let mut hashes: Vec<[u8; 32]> = vec![[0; 32]; all_tiles as usize];
    let filled = AtomicU64::new(0);
    let mut constant_tiles = 0u64;
    let mut done = 0u64;

    let band_cells = max_rows - 1; // cell rows per band: rows r and r + 1 both held
    let bands = (h - 1).div_ceil(band_cells);
    let mut band = vec![0f32; max_rows * w];
    let mut open: HashMap<u64, Vec<f32>> = HashMap::new();
    for b in 0..bands {
        let first = b * band_cells;
        let end = (first + band_cells).min(h - 1); // cell rows first..end
        let rows = end + 1 - first;
        let buf = &mut band[..rows * w];
        source.read_rows(first, rows, buf)?;
        let buf = &band[..rows * w];
        let last_band = b + 1 == bands;
        let candidates: Vec<u64> = (0..tiles.total)
            .filter(|&idx| {
                let (lo, hi) = ranges[idx as usize];
                (lo as usize) < end && hi as usize >= first
            })
            .collect();
        // A few tiles per thread at a time: bounded buffers, steady progress.
        let chunk = (rayon::current_num_threads() * 16).max(64);
        for ids in candidates.chunks(chunk) {
            let mut work: Vec<(u64, Vec<f32>)> = ids
                .iter()
                .map(|&idx| {
                    let t = tiles.tile(idx);
                    let v = open
                        .remove(&idx)
                        .unwrap_or_else(|| vec![f32::NAN; t.w as usize * t.h as usize]);
                    (idx, v)
                })
                .collect();
            work.par_iter_mut().for_each(|(idx, vals)| {
                let t = tiles.tile(*idx);
                let mut local_filled = 0;
                for_each_sample(&t, big_n, |k, p| {
                    let pos = position(&grid, p);
                    let r = key_row(&grid, &pos);
                    if r < first || r >= end {
                        return;
                    }
                    let v = if pos.inside {
                        grid.bilinear(&pos, buf, first)
                    } else {
                        None
                    };
                    vals[k] = match v {
                        Some(v) => v as f32,
                        None => {
                            local_filled += 1;
                            options.fill_value.unwrap_or_else(|| survey.fill.value(&pos))
                        }
                    };
                });
                if t.level == 0 {
                    filled.fetch_add(local_filled, Ordering::Relaxed);
                }
            });
            let (finished, still_open): (Vec<_>, Vec<_>) = work
                .into_iter()
                .partition(|(idx, _)| last_band || (ranges[*idx as usize].1 as usize) < end);
            open.extend(still_open);
            let encoded: Vec<(u64, TileKind, Vec<u8>, [u8; 32])> = finished
                .into_par_iter()
                .map(|(idx, vals)| {
                    let (kind, bytes) = encode_tile(format, &vals);
                    let hash = tile_hash(kind, &bytes);
                    (idx, kind, bytes, hash)
                })
                .collect();
            for (idx, kind, bytes, hash) in encoded {
                file.write_all_at(&bytes, write_at).map_err(werr)?;
                entries[idx as usize] = Entry {
                    offset: write_at,
                    len: bytes.len() as u32,
                    crc: crc32fast::hash(&bytes),
                    kind,
                };
                hashes[idx as usize] = hash;
                constant_tiles += u64::from(kind == TileKind::Constant);
                write_at += bytes.len() as u64;
                done += 1;
            }
            progress(done, tiles.total);
        }
    }
    debug_assert!(open.is_empty());

    // The source grid itself, a row of tiles at a time (read in bands of at most `max_rows`
    // rows), missing values filled.
    let mut source_filled = 0u64;
    let mut source_bytes = 0u64;
    let th = src_layout.tile as usize;
    let mut tile_rows = vec![0f32; th.min(h) * w];
    for ty in 0..src_layout.tiles_y() {
        let r0 = ty as usize * th;
        let rows = th.min(h - r0);
        let buf = &mut tile_rows[..rows * w];
        let mut done_rows = 0;
        while done_rows < rows {
            let n = max_rows.min(rows - done_rows);
            let b = &mut band[..n * w];
            source.read_rows(r0 + done_rows, n, b)?;
            buf[done_rows * w..(done_rows + n) * w].copy_from_slice(b);
            done_rows += n;
        }
        for (k, v) in buf.iter_mut().enumerate() {
            if !v.is_finite() {
                source_filled += 1;
                let pos = GridPos {
                    x: (k % w) as f64,
                    y: (r0 + k / w) as f64,
                    inside: true,
                };
                *v = options.fill_value.unwrap_or_else(|| survey.fill.value(&pos));
            }
        }
        let buf = &tile_rows[..rows * w];
        let first = u64::from(ty) * u64::from(src_layout.tiles_x());
        let encoded: Vec<(u64, TileKind, Vec<u8>, [u8; 32])> = (first..first + u64::from(src_layout.tiles_x()))
            .into_par_iter()
            .map(|k| {
                let t = src_layout.tile_ref(k);
                let mut vals = Vec::with_capacity(t.w as usize * t.h as usize);
                for r in 0..t.h as usize {
                    let at = r * w + t.c0 as usize;
                    vals.extend_from_slice(&buf[at..at + t.w as usize]);
                }
                let (kind, bytes) = encode_tile(format, &vals);
                let hash = tile_hash(kind, &bytes);
                (tiles.total + k, kind, bytes, hash)
            })
            .collect();
        for (idx, kind, bytes, hash) in encoded {
            file.write_all_at(&bytes, write_at).map_err(werr)?;
            entries[idx as usize] = Entry {
                offset: write_at,
                len: bytes.len() as u32,
                crc: crc32fast::hash(&bytes),
                kind,
            };
            hashes[idx as usize] = hash;
            write_at += bytes.len() as u64;
            source_bytes += (bytes.len() + ENTRY_BYTES) as u64;
        }
    }

    let digest = content_digest(n, format, &hashes, Some(&src_layout));
    let mut table = Vec::with_capacity(entries.len() * ENTRY_BYTES + 4);
    for e in &entries {
        e.encode(&mut table);
    }
    let crc = crc32fast::hash(&table);
    table.extend_from_slice(&crc.to_le_bytes());
    let (min, max) = value_range(format, &survey, options.fill_value);
    let header = Header {
        version: VERSION,
        source: Some(src_layout),
        n,
        levels: stored_levels(n),
        format,
        tile: options.tile_size,
        radius: options.radius,
        datum: options.datum,
        min,
        max,
        filled: filled.load(Ordering::Relaxed),
        tiles: tiles.total,
        table_offset: HEADER_BYTES_V2 as u64,
        data_offset,
        file_len: write_at,
        extent: grid.extent(),
        source_width: w as u32,
        source_height: h as u32,
        source_wraps: grid.wraps,
        digest: digest.clone(),
        source_name: source.name().to_owned(),
    };
    file.write_all_at(&table, HEADER_BYTES_V2 as u64).map_err(werr)?;
    file.write_all_at(&header.encode(), 0).map_err(werr)?;
    let mut f = tmp.file.take().expect("open");
    f.flush().map_err(werr)?;
    f.sync_all().map_err(werr)?;
    drop(f);
    if let Err(e) = std::fs::rename(&tmp.path, out) {
        let _ = std::fs::remove_file(&tmp.path);
        return Err(werr(e));
    }
    let samples = tiles.levels.iter().map(|l| 6 * u64::from(l.side).pow(2)).sum();
    Ok(ImportReport {
        level: n,
        format,
        samples,
        filled: header.filled,
        source_samples: w as u64 * h as u64,
        source_filled,
        source_bytes,
        tiles: tiles.total,
        constant_tiles,
        bytes: write_at,
        digest,
        bands,
        band_rows: max_rows.min(band_cells + 1),
    })
}

/// The lattice point (at resolution `N`) of each sample of tile `t`, with its index in the
/// tile's row-major buffer.
#[inline]
fn for_each_sample(t: &TileRef, big_n: i32, mut f: impl FnMut(usize, DVec3)) {
    let step = 1i32 << t.level;
    let r = big_n >> t.level;
    let face = Face::ALL[t.face];
    let inv = 1.0 / f64::from(big_n);
    for dj in 0..t.h {
        for di in 0..t.w {
            let p = lattice_of(face, r, (t.i0 + di) as i32, (t.j0 + dj) as i32) * step;
            f((dj * t.w + di) as usize, cube_to_sphere(p.as_dvec3() * inv));
        }
    }
}

/// The grid position of a unit direction.
#[inline]
fn position(grid: &SourceGrid, dir: DVec3) -> GridPos {
    let ll = LatLon::from_point(dir).unwrap_or(LatLon { lat: 0.0, lon: 0.0 });
    grid.position(ll.lat, ll.lon)
}

/// The band row a sample is computed in: its lower interpolation row, or 0 outside the grid
/// (no rows needed).
#[inline]
fn key_row(grid: &SourceGrid, p: &GridPos) -> usize {
    if p.inside {
        grid.key_row(p)
    } else {
        0
    }
}

/// The streaming pre-pass: range, validity, integer check and the coarse fill grid.
fn survey(source: &dyn EquirectSource, grid: &SourceGrid, max_rows: usize) -> Result<Survey, DemError> {
    let (w, h) = (grid.w, grid.h);
    let mut s = Survey {
        min: f64::INFINITY,
        max: f64::NEG_INFINITY,
        valid: 0,
        integers: true,
        fill: CoarseFill::new(w, h),
    };
    let mut buf = vec![0f32; max_rows * w];
    let mut r0 = 0;
    while r0 < h {
        let rows = max_rows.min(h - r0);
        let b = &mut buf[..rows * w];
        source.read_rows(r0, rows, b)?;
        for (k, &v) in b.iter().enumerate() {
            if v.is_finite() {
                s.valid += 1;
                let v64 = f64::from(v);
                s.min = s.min.min(v64);
                s.max = s.max.max(v64);
                s.integers &= v.fract() == 0.0 && (-32768.0..=32767.0).contains(&v);
                s.fill.add(k % w, r0 + k / w, v);
            }
        }
        r0 += rows;
    }
    if s.valid == 0 {
        return Err(DemError::EmptySource {
            file: source.name().to_owned(),
        });
    }
    s.fill.finish(grid.wraps);
    Ok(s)
}

fn value_range(format: SampleFormat, s: &Survey, fill: Option<f32>) -> (f64, f64) {
    let (mut min, mut max) = (s.min, s.max);
    if let Some(f) = fill {
        min = min.min(f64::from(f));
        max = max.max(f64::from(f));
    }
    // Stored values are rounded into the format; interpolation stays within the range.
    (
        f64::from(format.round_trip(min as f32)).min(min),
        f64::from(format.round_trip(max as f32)).max(max),
    )
}

fn choose_format(options: &ImportOptions, s: &Survey) -> SampleFormat {
    let fill_int = options
        .fill_value
        .is_none_or(|v| v.fract() == 0.0 && (-32768.0..=32767.0).contains(&v));
    match options.format {
        FormatChoice::F32 => SampleFormat::F32,
        FormatChoice::Auto if !(s.integers && fill_int) => SampleFormat::F32,
        FormatChoice::Auto => SampleFormat::I16 {
            scale: 1.0,
            offset: 0.0,
        },
        FormatChoice::I16 => {
            let (mut min, mut max) = (s.min, s.max);
            if let Some(f) = options.fill_value {
                min = min.min(f64::from(f));
                max = max.max(f64::from(f));
            }
            let scale = if max > min { (max - min) / 65534.0 } else { 1.0 };
            SampleFormat::I16 {
                scale,
                offset: 0.5 * (max + min),
            }
        }
    }
}

/// Encodes one tile's values; a tile whose stored samples are all equal becomes a constant.
pub(crate) fn encode_tile(format: SampleFormat, vals: &[f32]) -> (TileKind, Vec<u8>) {
    let mut bytes = Vec::with_capacity(vals.len() * format.bytes());
    for &v in vals {
        format.encode(v, &mut bytes);
    }
    let s = format.bytes();
    if bytes.chunks_exact(s).all(|c| c == &bytes[..s]) {
        bytes.truncate(s);
        return (TileKind::Constant, bytes);
    }
    (TileKind::Raw, bytes)
}

/// SHA-256 of a tile's kind and stored bytes.
pub(crate) fn tile_hash(kind: TileKind, bytes: &[u8]) -> [u8; 32] {
    let mut h = Sha256::new();
    h.update([kind as u8]);
    h.update(bytes);
    h.finalize().into()
}

/// The content digest: SHA-256 of `"pmcdem-v1"` (version 1) or `"pmcdem-v2"` (version 2), the
/// data level, the format code, scale and offset, in version 2 the source block's geometry
/// bytes, and the tile hashes in table order (version 2: the face tiles, then the source tiles);
/// as 64 lower-case hex digits.
pub(crate) fn content_digest(
    n: u32,
    format: SampleFormat,
    hashes: &[[u8; 32]],
    source: Option<&SourceLayout>,
) -> String {
    let mut h = Sha256::new();
    h.update(if source.is_some() { b"pmcdem-v2" } else { b"pmcdem-v1" });
    h.update([n as u8, format.code()]);
    let (scale, offset) = match format {
        SampleFormat::I16 { scale, offset } => (scale, offset),
        SampleFormat::F32 => (1.0, 0.0),
    };
    h.update(scale.to_le_bytes());
    h.update(offset.to_le_bytes());
    if let Some(src) = source {
        h.update(src.geometry_bytes());
    }
    for t in hashes {
        h.update(t);
    }
    let out: [u8; 32] = h.finalize().into();
    out.iter().map(|b| format!("{b:02x}")).collect()
}
