//! Reading `.pmcdem` files tile by tile, with checksums and a bounded cache of decoded tiles.

use super::detail::DetailNoise;
use super::format::{Entry, Header, SampleFormat, TileGrid, TileKind, ENTRY_BYTES, HEADER_BYTES_V2};
use super::import::{centre_spacing_radians, content_digest, tile_hash};
use super::source_grid::SourceGrid;
use crate::error::DemError;
use pmc_geometry::Face;
use std::collections::{HashMap, VecDeque};
use std::fs::File;
use std::os::unix::fs::FileExt;
use std::path::Path;
use std::sync::{Arc, Mutex};

/// Bytes of decoded tiles a [`CubeDem`] keeps by default: 256 MiB.
pub const DEFAULT_CACHE_BYTES: usize = 256 << 20;
/// Lock shards of the tile cache (tiles are spread over them by index).
const SHARDS: usize = 16;

/// A cube-face elevation model read from a `.pmcdem` file (`docs/specs/pmcdem-v2.md`; version 1
/// files, `docs/specs/pmcdem-v1.md`, are read too).
///
/// [`CubeDem::open`] reads and checks the header and the tile table only; tiles are read when
/// first needed, with positioned reads, their checksums checked, and kept decoded in a cache of
/// bounded size (first in, first out). `Send + Sync`: one `CubeDem` serves many threads.
///
/// Heights: a version 2 file keeps the source grid, and heights are interpolated from it
/// directly (exact at every source sample); a version 1 file has only the cube faces, and heights
/// are interpolated from the face samples (exact at the face samples).
#[derive(Debug)]
pub struct CubeDem {
    pub(crate) path: String,
    file: File,
    pub(crate) header: Header,
    pub(crate) grid: TileGrid,
    entries: Vec<Entry>,
    shards: Vec<Mutex<Shard>>,
    shard_budget: usize,
    spacing: f64,
    /// Version 2: the source grid's axes (where a place falls on it).
    pub(crate) source_grid: Option<SourceGrid>,
    /// Version 2: metres between the source's rows (the spacing of its relief weights).
    pub(crate) source_spacing: f64,
}

#[derive(Debug, Default)]
struct Shard {
    map: HashMap<u64, Arc<Vec<f32>>>,
    order: VecDeque<u64>,
    bytes: usize,
}

/// The axes of the source grid a version 2 `.pmcdem` file keeps ([`CubeDem::source_axes`]):
/// sample `(c, r)` lies at longitude `lon_first + c lon_step` and latitude
/// `lat_first + r lat_step` (degrees; rows from south to north).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SourceAxes {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Longitude of column 0, degrees.
    pub lon_first: f64,
    /// Degrees between columns.
    pub lon_step: f64,
    /// Latitude of row 0 (the southernmost), degrees.
    pub lat_first: f64,
    /// Degrees between rows.
    pub lat_step: f64,
    /// Whether the columns go round the whole circle (column `width` is column 0 again).
    pub wraps: bool,
}

/// One row of [`CubeDem::storage_table`]: a level of the file or a finer level made by the
/// detail noise alone (seed 003 Fig. 13).
#[derive(Clone, Debug, PartialEq)]
pub struct StorageRow {
    /// Resolution exponent: `2^log2 + 1` samples a face side.
    pub log2: u32,
    /// Samples along a face side.
    pub samples_per_side: u64,
    /// Bytes of six faces of this many samples at 16 bits a sample (as the paper's table).
    pub bytes_16bit: u64,
    /// Bytes this level takes in the file (tiles only); `None` for levels finer than the data.
    pub bytes_stored: Option<u64>,
    /// Metres between neighbouring samples at a face centre.
    pub metres_at_centre: f64,
    /// Metres between samples along the equator on average: `2 pi R / (4 (samples - 1))`.
    pub metres_at_equator: f64,
    /// Whether the level is stored (data or overview) rather than made by the detail noise.
    pub stored: bool,
}

impl CubeDem {
    /// Opens a `.pmcdem` file with a tile cache of [`DEFAULT_CACHE_BYTES`].
    pub fn open(path: impl AsRef<Path>) -> Result<CubeDem, DemError> {
        CubeDem::open_with_cache(path, DEFAULT_CACHE_BYTES)
    }

    /// Opens a `.pmcdem` file keeping at most about `cache_bytes` of decoded tiles (at least one
    /// tile per lock shard is kept whatever the budget).
    ///
    /// Checks the signature, the version, the header checksum, every header field against the
    /// others and against the file's length, then reads the tile table (whose size is then known
    /// to fit in the file), its checksum and every entry against the tile geometry. Errors name
    /// the file; nothing is allocated from an unchecked size.
    pub fn open_with_cache(path: impl AsRef<Path>, cache_bytes: usize) -> Result<CubeDem, DemError> {
        let name = path.as_ref().display().to_string();
        let io = |source: std::io::Error| DemError::Io {
            file: name.clone(),
            source,
        };
        let file = File::open(path.as_ref()).map_err(io)?;
        let len = file.metadata().map_err(io)?.len();
        let mut head = vec![0u8; (HEADER_BYTES_V2 as u64).min(len) as usize];
        file.read_exact_at(&mut head, 0).map_err(io)?;
        let header = Header::decode(&name, &head, len)?;
        let grid = TileGrid::new(header.n, header.tile);
        let source = header.source;
        let mut table = vec![0u8; (header.data_offset - header.table_offset) as usize];
        file.read_exact_at(&mut table, header.table_offset).map_err(io)?;
        let (body, crc) = table.split_at(table.len() - 4);
        let stored = u32::from_le_bytes(crc.try_into().expect("4 bytes"));
        if crc32fast::hash(body) != stored {
            return Err(DemError::CubeCorrupt {
                file: name,
                detail: "the tile table's checksum does not match its bytes".to_owned(),
            });
        }
        let entries = body
            .chunks_exact(ENTRY_BYTES)
            .enumerate()
            .map(|(k, b)| {
                let k = k as u64;
                let samples = match (k.checked_sub(grid.total), &source) {
                    (Some(s), Some(src)) => {
                        let t = src.tile_ref(s);
                        t.w as usize * t.h as usize
                    }
                    _ => {
                        let t = grid.tile(k);
                        t.w as usize * t.h as usize
                    }
                };
                Entry::decode(&name, b, k, samples, header.format, (header.data_offset, len))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let spacing = centre_spacing_radians(header.n) * header.radius;
        let source_grid = source.map(|s| {
            SourceGrid::from_axes(
                s.width as usize,
                s.height as usize,
                [s.lon_first, s.lon_step, s.lat_first, s.lat_step],
                s.wraps,
            )
        });
        let source_spacing = source.map_or(f64::NAN, |s| s.lat_step.to_radians() * header.radius);
        Ok(CubeDem {
            source_grid,
            source_spacing,
            spacing,
            path: name,
            file,
            header,
            grid,
            entries,
            shards: (0..SHARDS).map(|_| Mutex::new(Shard::default())).collect(),
            shard_budget: cache_bytes / SHARDS,
        })
    }

    /// The format version of the file: 1 (cube faces only) or 2 (cube faces and the source grid,
    /// from which heights are taken).
    pub fn version(&self) -> u32 {
        self.header.version
    }
    /// Whether the file keeps the source grid (version 2), so that heights are exact at every
    /// source sample.
    pub fn keeps_source(&self) -> bool {
        self.header.source.is_some()
    }
    /// Columns and rows of the stored source grid (version 2), `None` in a version 1 file.
    pub fn source_size(&self) -> Option<(u32, u32)> {
        self.header.source.map(|s| (s.width, s.height))
    }
    /// Bytes the stored source grid takes in the file (its tiles and their table entries); 0 in
    /// a version 1 file.
    pub fn source_bytes(&self) -> u64 {
        self.entries[self.grid.total as usize..]
            .iter()
            .map(|e| u64::from(e.len) + ENTRY_BYTES as u64)
            .sum()
    }
    /// The stored value of source sample `(column, row)` (rows from south to north, columns from
    /// west to east, missing values filled at import). Errors: a version 1 file or indices
    /// outside the grid ([`DemError::OutOfGrid`]), or a tile that cannot be read.
    pub fn source_sample(&self, column: u32, row: u32) -> Result<f32, DemError> {
        match self.header.source {
            Some(s) if column < s.width && row < s.height => self.source_value(column, row),
            _ => Err(DemError::OutOfGrid {
                file: self.path.clone(),
                detail: format!(
                    "source sample ({column}, {row}) asked for; the file keeps {}",
                    self.header
                        .source
                        .map_or("no source grid (version 1)".to_owned(), |s| format!(
                            "a source grid of {} x {}",
                            s.width, s.height
                        ))
                ),
            }),
        }
    }

    /// The axes of the stored source grid (version 2), `None` in a version 1 file.
    pub fn source_axes(&self) -> Option<SourceAxes> {
        self.header.source.map(|s| SourceAxes {
            width: s.width,
            height: s.height,
            lon_first: s.lon_first,
            lon_step: s.lon_step,
            lat_first: s.lat_first,
            lat_step: s.lat_step,
            wraps: s.wraps,
        })
    }

    /// Every `stride`-th sample of the stored source grid in both directions: samples
    /// `(c * stride, r * stride)` for `c < ceil(width / stride)`, `r < ceil(height / stride)`,
    /// row by row from the south, as `(columns, rows, values)`. Read tile by tile (each tile
    /// holding a wanted sample once). Errors: a version 1 file, a stride of 0, or a tile that
    /// cannot be read.
    pub fn source_decimated(&self, stride: u32) -> Result<(u32, u32, Vec<f32>), DemError> {
        let Some(src) = self.header.source else {
            return Err(DemError::OutOfGrid {
                file: self.path.clone(),
                detail: "the source grid asked for; the file keeps none (version 1)".into(),
            });
        };
        if stride == 0 {
            return Err(DemError::OutOfGrid {
                file: self.path.clone(),
                detail: "a stride of 0 through the source grid".into(),
            });
        }
        let (w, h) = (src.width.div_ceil(stride), src.height.div_ceil(stride));
        let mut out = vec![0f32; w as usize * h as usize];
        // the first multiple of `stride` at or after `a`
        let first = |a: u32| a.div_ceil(stride) * stride;
        for k in 0..src.total() {
            let t = src.tile_ref(k);
            let (c_first, r_first) = (first(t.c0), first(t.r0));
            if c_first >= t.c0 + t.w || r_first >= t.r0 + t.h {
                continue;
            }
            let tile = self.tile(self.grid.total + k)?;
            for r in (r_first..t.r0 + t.h).step_by(stride as usize) {
                for c in (c_first..t.c0 + t.w).step_by(stride as usize) {
                    let v = if tile.len() == 1 {
                        tile[0]
                    } else {
                        tile[((r - t.r0) * t.w + (c - t.c0)) as usize]
                    };
                    out[(r / stride) as usize * w as usize + (c / stride) as usize] = v;
                }
            }
        }
        Ok((w, h, out))
    }

    /// The value of an in-range source sample of a version 2 file.
    #[inline]
    pub(crate) fn source_value(&self, c: u32, r: u32) -> Result<f32, DemError> {
        let src = self.header.source.as_ref().expect("a version 2 file");
        let k = src.index_of(c, r);
        let tile = self.tile(self.grid.total + k)?;
        if tile.len() == 1 {
            return Ok(tile[0]);
        }
        let t = src.tile;
        let w = src.width.min((c / t) * t + t) - (c / t) * t;
        Ok(tile[((r % t) * w + (c % t)) as usize])
    }

    /// The path the file was opened from.
    pub fn path(&self) -> &str {
        &self.path
    }
    /// The data level `n`: faces of `2^n + 1` samples a side.
    pub fn data_level(&self) -> u32 {
        self.header.n
    }
    /// Levels stored: the data level (index 0) and its overviews (index `k`: `2^(n-k) + 1`
    /// samples a side, down to 65).
    pub fn levels(&self) -> u32 {
        self.header.levels
    }
    /// Samples along a face side at level index `k` (0 for a level not stored).
    pub fn samples_per_side(&self, k: u32) -> u32 {
        self.grid.levels.get(k as usize).map_or(0, |l| l.side)
    }
    /// The body radius in metres.
    pub fn radius(&self) -> f64 {
        self.header.radius
    }
    /// The height of the datum (sea level) in the data's metres.
    pub fn datum(&self) -> f64 {
        self.header.datum
    }
    /// The content digest: SHA-256 (64 hex digits) of the tiles, see the spec.
    pub fn digest(&self) -> &str {
        &self.header.digest
    }
    /// The name of the source the file was imported from.
    pub fn source_name(&self) -> &str {
        &self.header.source_name
    }
    /// West, east, south, north bounds (degrees) of the source's samples.
    pub fn source_extent(&self) -> [f64; 4] {
        self.header.extent
    }
    /// The sample format.
    pub fn format(&self) -> SampleFormat {
        self.header.format
    }
    /// Samples a side of a tile.
    pub fn tile_size(&self) -> u32 {
        self.header.tile
    }
    /// Samples of the finest level that were missing in the source and filled.
    pub fn filled_samples(&self) -> u64 {
        self.header.filled
    }
    /// The smallest and largest stored value, metres.
    pub fn value_range(&self) -> (f64, f64) {
        (self.header.min, self.header.max)
    }

    /// Metres between data samples at a face centre (the spacing of detail octave 0).
    pub fn data_spacing(&self) -> f64 {
        self.spacing
    }

    /// Bounds of every height [`CubeDem::height`] can return with the default
    /// [`DetailNoise`]: the data range widened by the noise bound.
    pub fn height_bounds(&self) -> (f64, f64) {
        self.height_bounds_with(&DetailNoise::default())
    }

    /// Bounds of every height [`CubeDem::height`] can return with `detail`: the data range
    /// (bicubic interpolation is clamped to it), widened by [`DetailNoise::bound`].
    pub fn height_bounds_with(&self, detail: &DetailNoise) -> (f64, f64) {
        let (min, max) = (self.header.min, self.header.max);
        let widen = detail.bound(self.data_spacing());
        (min - widen, max + widen)
    }

    /// Storage and resolution per level, like seed 003 Fig. 13: the stored levels from the
    /// coarsest overview to the data level, then the levels the detail noise adds below the data
    /// resolution down to about one metre at a face centre.
    pub fn storage_table(&self) -> Vec<StorageRow> {
        let r = self.header.radius;
        let mut stored_bytes = vec![0u64; self.grid.levels.len()];
        for (k, e) in self.entries[..self.grid.total as usize].iter().enumerate() {
            let level = self.grid.tile(k as u64).level as usize;
            stored_bytes[level] += u64::from(e.len) + ENTRY_BYTES as u64;
        }
        let n = self.header.n;
        let first = n + 1 - self.header.levels;
        let mut rows = Vec::new();
        let mut log2 = first;
        loop {
            let side = (1u64 << log2) + 1;
            let centre = centre_spacing_radians(log2) * r;
            let stored = log2 <= n;
            rows.push(StorageRow {
                log2,
                samples_per_side: side,
                bytes_16bit: 6 * side * side * 2,
                bytes_stored: stored.then(|| stored_bytes[(n - log2) as usize]),
                metres_at_centre: centre,
                metres_at_equator: std::f64::consts::TAU * r / (4.0 * (side - 1) as f64),
                stored,
            });
            if (!stored && centre <= 1.0) || log2 >= 40 {
                break;
            }
            log2 += 1;
        }
        rows
    }

    /// The stored value of sample `(i, j)` of `face` at level index `level` (0 = data level).
    /// Errors: indices outside the level ([`DemError::OutOfGrid`]), or a tile that cannot be
    /// read or fails its checksum.
    pub fn sample(&self, level: u32, face: Face, i: u32, j: u32) -> Result<f32, DemError> {
        let side = self.samples_per_side(level);
        if i >= side || j >= side {
            return Err(DemError::OutOfGrid {
                file: self.path.clone(),
                detail: format!(
                    "sample ({i}, {j}) of level {level} asked for; it has {} levels of which this one has {side} samples a side",
                    self.header.levels
                ),
            });
        }
        self.value(level, face.index(), i, j)
    }

    /// The value of an in-range sample.
    #[inline]
    pub(crate) fn value(&self, level: u32, face: usize, i: u32, j: u32) -> Result<f32, DemError> {
        let idx = self.grid.index_of(level, face, i, j);
        let tile = self.tile(idx)?;
        if tile.len() == 1 {
            return Ok(tile[0]);
        }
        let t = self.header.tile;
        let w = self.grid.levels[level as usize].side.min((i / t) * t + t) - (i / t) * t;
        Ok(tile[((j % t) * w + (i % t)) as usize])
    }

    /// Reads and checks the stored bytes of tile `idx`.
    fn read_tile_bytes(&self, idx: u64) -> Result<(Entry, Vec<u8>), DemError> {
        let e = self.entries[idx as usize];
        let mut bytes = vec![0u8; e.len as usize];
        self.file
            .read_exact_at(&mut bytes, e.offset)
            .map_err(|source| DemError::Io {
                file: self.path.clone(),
                source,
            })?;
        if crc32fast::hash(&bytes) != e.crc {
            let detail = match (idx.checked_sub(self.grid.total), &self.header.source) {
                (Some(k), Some(src)) => {
                    let t = src.tile_ref(k);
                    format!(
                        "tile {idx} (source grid, columns from {}, rows from {}) fails its checksum",
                        t.c0, t.r0
                    )
                }
                _ => {
                    let t = self.grid.tile(idx);
                    format!(
                        "tile {idx} (level {}, face {}, tile column {}, row {}) fails its checksum",
                        t.level,
                        Face::ALL[t.face],
                        t.ti,
                        t.tj
                    )
                }
            };
            return Err(DemError::CubeCorrupt {
                file: self.path.clone(),
                detail,
            });
        }
        Ok((e, bytes))
    }

    /// The decoded tile `idx`, from the cache or the file.
    pub(crate) fn tile(&self, idx: u64) -> Result<Arc<Vec<f32>>, DemError> {
        let shard = &self.shards[(idx % SHARDS as u64) as usize];
        if let Some(t) = shard.lock().unwrap_or_else(|p| p.into_inner()).map.get(&idx) {
            return Ok(Arc::clone(t));
        }
        let (e, bytes) = self.read_tile_bytes(idx)?;
        let f = self.header.format;
        let vals: Vec<f32> = match e.kind {
            TileKind::Constant => vec![f.decode(&bytes)],
            TileKind::Raw => bytes.chunks_exact(f.bytes()).map(|c| f.decode(c)).collect(),
        };
        let tile = Arc::new(vals);
        let mut s = shard.lock().unwrap_or_else(|p| p.into_inner());
        if s.map.insert(idx, Arc::clone(&tile)).is_none() {
            s.order.push_back(idx);
            s.bytes += tile.len() * 4;
        }
        while s.bytes > self.shard_budget && s.order.len() > 1 {
            let old = s.order.pop_front().expect("non-empty");
            if let Some(t) = s.map.remove(&old) {
                s.bytes -= t.len() * 4;
            }
        }
        Ok(tile)
    }

    /// Reads every tile, checks its checksum and recomputes the content digest, which must equal
    /// the header's. Streams the file tile by tile (the cache is not used).
    pub fn verify(&self) -> Result<(), DemError> {
        let mut hashes = Vec::with_capacity(self.entries.len());
        for idx in 0..self.entries.len() as u64 {
            let (e, bytes) = self.read_tile_bytes(idx)?;
            hashes.push(tile_hash(e.kind, &bytes));
        }
        let digest = content_digest(self.header.n, self.header.format, &hashes, self.header.source.as_ref());
        if digest != self.header.digest {
            return Err(DemError::CubeCorrupt {
                file: self.path.clone(),
                detail: format!(
                    "the tiles' digest is {digest} but the header records {}",
                    self.header.digest
                ),
            });
        }
        Ok(())
    }
}
