//! The `.pmcdem` byte layout: header, tile table, level and tile geometry, and the v2 source
//! grid section (`docs/specs/pmcdem-v1.md`, `docs/specs/pmcdem-v2.md`).

use crate::error::DemError;

/// The eight bytes every `.pmcdem` file starts with (a non-ASCII byte, the name, a line feed, as
/// PNG does, so that text-mode transfers and foreign files are recognised).
pub const MAGIC: [u8; 8] = [0x89, b'P', b'M', b'C', b'D', b'E', b'M', b'\n'];
/// The format version written by this crate. It reads versions 1 (cube faces only) and 2 (cube
/// faces and the source grid).
pub const VERSION: u32 = 2;
/// Bytes of the fixed header of version 1, and of the part of a version 2 header laid out as in
/// version 1.
pub const HEADER_BYTES: usize = 512;
/// Bytes of the fixed header of version 2: the version 1 fields, then the source block.
pub const HEADER_BYTES_V2: usize = 640;
/// Samples along a side of a source tile written by [`import_cube`](crate::import_cube).
pub const DEFAULT_SOURCE_TILE_SIZE: u32 = 64;
/// Bytes of one tile-table entry.
pub const ENTRY_BYTES: usize = 24;
/// The finest data level accepted: `2^16 + 1` samples a face side (about 26 billion samples).
pub const MAX_DATA_LEVEL: u32 = 16;
/// The coarsest overview keeps `2^6 + 1 = 65` samples a side.
pub const COARSEST_OVERVIEW_LOG2: u32 = 6;
/// Samples along each side of a tile written by [`import_cube`](crate::import_cube) by default.
pub const DEFAULT_TILE_SIZE: u32 = 64;
/// Bytes of the source name field of the header.
pub(crate) const NAME_BYTES: usize = 256;

/// How samples are stored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SampleFormat {
    /// Signed 16-bit integers `q`; the height is `offset + scale * q` metres.
    I16 {
        /// Metres per integer step.
        scale: f64,
        /// Metres at `q = 0`.
        offset: f64,
    },
    /// 32-bit IEEE floats, metres.
    F32,
}

impl SampleFormat {
    /// Bytes per stored sample.
    pub fn bytes(self) -> usize {
        match self {
            SampleFormat::I16 { .. } => 2,
            SampleFormat::F32 => 4,
        }
    }
    pub(crate) fn code(self) -> u8 {
        match self {
            SampleFormat::I16 { .. } => 1,
            SampleFormat::F32 => 2,
        }
    }
    /// Encodes `v` (metres) as stored bytes, appended to `out`.
    pub(crate) fn encode(self, v: f32, out: &mut Vec<u8>) {
        match self {
            SampleFormat::I16 { .. } => out.extend_from_slice(&self.quantise(v).to_le_bytes()),
            SampleFormat::F32 => out.extend_from_slice(&v.to_le_bytes()),
        }
    }
    /// The integer stored for `v` in the i16 format (0 for F32).
    pub(crate) fn quantise(self, v: f32) -> i16 {
        match self {
            SampleFormat::I16 { scale, offset } => {
                ((f64::from(v) - offset) / scale).round().clamp(-32768.0, 32767.0) as i16
            }
            SampleFormat::F32 => 0,
        }
    }
    /// The value `v` becomes once stored and read back.
    pub(crate) fn round_trip(self, v: f32) -> f32 {
        match self {
            SampleFormat::I16 { .. } => self.decode(&self.quantise(v).to_le_bytes()),
            SampleFormat::F32 => v,
        }
    }
    /// Decodes one stored sample (`bytes()` bytes, little-endian).
    pub(crate) fn decode(self, b: &[u8]) -> f32 {
        match self {
            SampleFormat::I16 { scale, offset } => {
                (offset + scale * f64::from(i16::from_le_bytes([b[0], b[1]]))) as f32
            }
            SampleFormat::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        }
    }
}

/// The stored (data and overview) levels of a file of data level `n`: level index `k` has
/// `2^(n-k) + 1` samples a side, from `k = 0` down to 65 samples (only `k = 0` when `n < 6`).
pub fn stored_levels(n: u32) -> u32 {
    if n > COARSEST_OVERVIEW_LOG2 {
        n - COARSEST_OVERVIEW_LOG2 + 1
    } else {
        1
    }
}

/// The geometry of the tiles of one file: where each tile sits and its index in the table.
#[derive(Clone, Debug)]
pub(crate) struct TileGrid {
    pub tile: u32,
    /// For each level: samples a side, tiles a side, index of its first tile.
    pub levels: Vec<LevelGrid>,
    pub total: u64,
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct LevelGrid {
    pub side: u32,
    pub tiles: u32,
    pub first: u64,
}

/// One tile: level, face index, tile column and row, first sample and extent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct TileRef {
    pub level: u32,
    pub face: usize,
    pub ti: u32,
    pub tj: u32,
    pub i0: u32,
    pub j0: u32,
    pub w: u32,
    pub h: u32,
}

impl TileGrid {
    pub fn new(n: u32, tile: u32) -> TileGrid {
        let mut levels = Vec::new();
        let mut first = 0u64;
        for k in 0..stored_levels(n) {
            let side = (1u32 << (n - k)) + 1;
            let tiles = side.div_ceil(tile);
            levels.push(LevelGrid { side, tiles, first });
            first += 6 * u64::from(tiles) * u64::from(tiles);
        }
        TileGrid {
            tile,
            levels,
            total: first,
        }
    }

    /// The index of the tile holding sample `(i, j)` of `face` at `level`.
    #[inline]
    pub fn index_of(&self, level: u32, face: usize, i: u32, j: u32) -> u64 {
        let l = self.levels[level as usize];
        let t = u64::from(l.tiles);
        l.first + face as u64 * t * t + u64::from(j / self.tile) * t + u64::from(i / self.tile)
    }

    /// The tile of index `idx` (which must be below `total`).
    pub fn tile(&self, idx: u64) -> TileRef {
        let level = self.levels.iter().rposition(|l| l.first <= idx).unwrap_or(0);
        let l = self.levels[level];
        let t = u64::from(l.tiles);
        let r = idx - l.first;
        let face = (r / (t * t)) as usize;
        let r = r % (t * t);
        let (tj, ti) = ((r / t) as u32, (r % t) as u32);
        let (i0, j0) = (ti * self.tile, tj * self.tile);
        TileRef {
            level: level as u32,
            face,
            ti,
            tj,
            i0,
            j0,
            w: self.tile.min(l.side - i0),
            h: self.tile.min(l.side - j0),
        }
    }
}

/// The source grid stored by a version 2 file (`docs/specs/pmcdem-v2.md`, "Source block"): its
/// axes (rows from south to north, columns from west to east) and its tiles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SourceLayout {
    pub lon_first: f64,
    pub lon_step: f64,
    pub lat_first: f64,
    pub lat_step: f64,
    pub width: u32,
    pub height: u32,
    pub tile: u32,
    pub wraps: bool,
}

/// One source tile: its first column and row and its extent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct SourceTileRef {
    pub c0: u32,
    pub r0: u32,
    pub w: u32,
    pub h: u32,
}

impl SourceLayout {
    /// Tiles along a row of tiles.
    pub fn tiles_x(&self) -> u32 {
        self.width.div_ceil(self.tile)
    }
    /// Rows of tiles.
    pub fn tiles_y(&self) -> u32 {
        self.height.div_ceil(self.tile)
    }
    /// Source tiles in all.
    pub fn total(&self) -> u64 {
        u64::from(self.tiles_x()) * u64::from(self.tiles_y())
    }
    /// The index (among the source tiles, from 0) of the tile holding column `c`, row `r`.
    #[inline]
    pub fn index_of(&self, c: u32, r: u32) -> u64 {
        u64::from(r / self.tile) * u64::from(self.tiles_x()) + u64::from(c / self.tile)
    }
    /// Source tile `k` (which must be below `total`).
    pub fn tile_ref(&self, k: u64) -> SourceTileRef {
        let tx = (k % u64::from(self.tiles_x())) as u32;
        let ty = (k / u64::from(self.tiles_x())) as u32;
        let (c0, r0) = (tx * self.tile, ty * self.tile);
        SourceTileRef {
            c0,
            r0,
            w: self.tile.min(self.width - c0),
            h: self.tile.min(self.height - r0),
        }
    }
    /// The block's bytes 512..560 (see the spec); the content digest covers them.
    pub fn geometry_bytes(&self) -> [u8; 48] {
        let mut b = [0u8; 48];
        b[0..8].copy_from_slice(&self.lon_first.to_le_bytes());
        b[8..16].copy_from_slice(&self.lon_step.to_le_bytes());
        b[16..24].copy_from_slice(&self.lat_first.to_le_bytes());
        b[24..32].copy_from_slice(&self.lat_step.to_le_bytes());
        b[32..36].copy_from_slice(&self.width.to_le_bytes());
        b[36..40].copy_from_slice(&self.height.to_le_bytes());
        b[40..44].copy_from_slice(&self.tile.to_le_bytes());
        b[44] = u8::from(self.wraps);
        b
    }
}

/// The fixed header (`docs/specs/pmcdem-v1.md`, "Header"; version 2 adds the source block).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Header {
    /// The format version: 1 or 2.
    pub version: u32,
    /// Version 2: the stored source grid.
    pub source: Option<SourceLayout>,
    pub n: u32,
    pub levels: u32,
    pub format: SampleFormat,
    pub tile: u32,
    pub radius: f64,
    pub datum: f64,
    pub min: f64,
    pub max: f64,
    pub filled: u64,
    pub tiles: u64,
    pub table_offset: u64,
    pub data_offset: u64,
    pub file_len: u64,
    /// West, east, south, north (degrees) of the source's samples.
    pub extent: [f64; 4],
    pub source_width: u32,
    pub source_height: u32,
    pub source_wraps: bool,
    pub digest: String,
    pub source_name: String,
}

fn put_u32(b: &mut [u8], at: usize, v: u32) {
    b[at..at + 4].copy_from_slice(&v.to_le_bytes());
}
fn put_u64(b: &mut [u8], at: usize, v: u64) {
    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
}
fn put_f64(b: &mut [u8], at: usize, v: f64) {
    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
}
pub(crate) fn get_u32(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"))
}
pub(crate) fn get_u64(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().expect("8 bytes"))
}
fn get_f64(b: &[u8], at: usize) -> f64 {
    f64::from_le_bytes(b[at..at + 8].try_into().expect("8 bytes"))
}

/// The longest prefix of `s` of at most `max` bytes that ends on a character boundary.
pub(crate) fn truncate_utf8(s: &str, max: usize) -> &str {
    let mut end = s.len().min(max);
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    &s[..end]
}

impl Header {
    /// Bytes of this header: [`HEADER_BYTES`] in version 1, [`HEADER_BYTES_V2`] in version 2.
    pub fn len(&self) -> usize {
        if self.source.is_some() {
            HEADER_BYTES_V2
        } else {
            HEADER_BYTES
        }
    }

    pub fn encode(&self) -> Vec<u8> {
        let mut b = vec![0u8; self.len()];
        b[0..8].copy_from_slice(&MAGIC);
        put_u32(&mut b, 8, self.version);
        put_u32(&mut b, 12, self.len() as u32);
        b[16] = self.n as u8;
        b[17] = self.levels as u8;
        b[18] = self.format.code();
        put_u32(&mut b, 20, self.tile);
        let (scale, offset) = match self.format {
            SampleFormat::I16 { scale, offset } => (scale, offset),
            SampleFormat::F32 => (1.0, 0.0),
        };
        put_f64(&mut b, 24, scale);
        put_f64(&mut b, 32, offset);
        put_f64(&mut b, 40, self.radius);
        put_f64(&mut b, 48, self.datum);
        put_f64(&mut b, 56, self.min);
        put_f64(&mut b, 64, self.max);
        put_u64(&mut b, 72, self.filled);
        put_u64(&mut b, 80, self.tiles);
        put_u64(&mut b, 88, self.table_offset);
        put_u64(&mut b, 96, self.data_offset);
        put_u64(&mut b, 104, self.file_len);
        for (k, v) in self.extent.iter().enumerate() {
            put_f64(&mut b, 112 + 8 * k, *v);
        }
        put_u32(&mut b, 144, self.source_width);
        put_u32(&mut b, 148, self.source_height);
        b[152] = u8::from(self.source_wraps);
        let d = self.digest.as_bytes();
        b[160..160 + d.len().min(64)].copy_from_slice(&d[..d.len().min(64)]);
        let name = truncate_utf8(&self.source_name, NAME_BYTES).as_bytes();
        b[224..224 + name.len()].copy_from_slice(name);
        let crc = crc32fast::hash(&b[..508]);
        put_u32(&mut b, 508, crc);
        if let Some(src) = &self.source {
            b[512..560].copy_from_slice(&src.geometry_bytes());
            let crc = crc32fast::hash(&b[512..636]);
            put_u32(&mut b, 636, crc);
        }
        b
    }

    /// Decodes and checks a header. `file_len` is the actual length of the file. Checks, in
    /// order: magic, version, header checksum, then every field against the others and the file
    /// length, so that nothing is allocated from an unchecked size.
    pub fn decode(file: &str, b: &[u8], file_len: u64) -> Result<Header, DemError> {
        let corrupt = |detail: String| DemError::CubeCorrupt {
            file: file.to_owned(),
            detail,
        };
        if b.len() < 8 || b[0..8] != MAGIC {
            let what = if b.starts_with(b"CDF") {
                "a netCDF file (import it first with import_cube)".to_owned()
            } else if b.starts_with(b"\x89PNG") {
                "a PNG image".to_owned()
            } else if b.is_empty() {
                "an empty file".to_owned()
            } else {
                format!("the first bytes are {:02x?}", &b[..b.len().min(8)])
            };
            return Err(DemError::NotCubeDem {
                file: file.to_owned(),
                detail: what,
            });
        }
        if b.len() < HEADER_BYTES {
            return Err(DemError::Truncated {
                file: file.to_owned(),
                expected: HEADER_BYTES as u64,
                actual: file_len,
            });
        }
        let version = get_u32(b, 8);
        if version != 1 && version != 2 {
            return Err(DemError::UnsupportedVersion {
                file: file.to_owned(),
                version,
            });
        }
        let header_len = if version == 1 { HEADER_BYTES } else { HEADER_BYTES_V2 };
        if b.len() < header_len {
            return Err(DemError::Truncated {
                file: file.to_owned(),
                expected: header_len as u64,
                actual: file_len,
            });
        }
        let crc = crc32fast::hash(&b[..508]);
        if crc != get_u32(b, 508) {
            return Err(corrupt(format!(
                "the header checksum is {:08x} but the header's bytes give {crc:08x}",
                get_u32(b, 508)
            )));
        }
        if get_u32(b, 12) != header_len as u32 {
            return Err(corrupt(format!(
                "header length {} (v{version} headers are {header_len} bytes)",
                get_u32(b, 12)
            )));
        }
        let source = if version == 2 {
            Some(decode_source_block(b, &corrupt)?)
        } else {
            None
        };
        let n = u32::from(b[16]);
        if !(1..=MAX_DATA_LEVEL).contains(&n) {
            return Err(corrupt(format!("data level {n} (1 to {MAX_DATA_LEVEL} are valid)")));
        }
        let levels = u32::from(b[17]);
        if levels != stored_levels(n) {
            return Err(corrupt(format!(
                "{levels} levels stored where data level {n} has {}",
                stored_levels(n)
            )));
        }
        let tile = get_u32(b, 20);
        if !(2..=4096).contains(&tile) {
            return Err(corrupt(format!("tile size {tile} (2 to 4096 are valid)")));
        }
        let (scale, offset) = (get_f64(b, 24), get_f64(b, 32));
        let format = match b[18] {
            1 if scale.is_finite() && scale > 0.0 && offset.is_finite() => SampleFormat::I16 { scale, offset },
            1 => {
                return Err(corrupt(format!(
                    "16-bit samples with scale {scale} and offset {offset}"
                )))
            }
            2 => SampleFormat::F32,
            c => return Err(corrupt(format!("unknown sample format code {c}"))),
        };
        let radius = get_f64(b, 40);
        if !(radius.is_finite() && radius > 0.0) {
            return Err(corrupt(format!("body radius {radius} m")));
        }
        let (datum, min, max) = (get_f64(b, 48), get_f64(b, 56), get_f64(b, 64));
        if !(datum.is_finite() && min.is_finite() && max.is_finite() && min <= max) {
            return Err(corrupt(format!("datum {datum}, value range {min} to {max}")));
        }
        let grid = TileGrid::new(n, tile);
        let tiles = get_u64(b, 80);
        if tiles != grid.total {
            return Err(corrupt(format!(
                "{tiles} tiles listed where the levels hold {}",
                grid.total
            )));
        }
        let table_offset = get_u64(b, 88);
        let data_offset = get_u64(b, 96);
        let entries = tiles + source.map_or(0, |s| s.total());
        let table_end = header_len as u64 + entries * ENTRY_BYTES as u64 + 4;
        if table_offset != header_len as u64 || data_offset != table_end {
            return Err(corrupt(format!(
                "table at {table_offset} and data at {data_offset} where v{version} puts them at {header_len} and {table_end}"
            )));
        }
        let declared = get_u64(b, 104);
        if declared > file_len {
            return Err(DemError::Truncated {
                file: file.to_owned(),
                expected: declared,
                actual: file_len,
            });
        }
        if declared < data_offset || declared != file_len {
            return Err(corrupt(format!(
                "the header gives a length of {declared} bytes but the file holds {file_len}"
            )));
        }
        let mut extent = [0.0; 4];
        for (k, e) in extent.iter_mut().enumerate() {
            *e = get_f64(b, 112 + 8 * k);
        }
        let digest = std::str::from_utf8(&b[160..224])
            .ok()
            .filter(|d| d.bytes().all(|c| c.is_ascii_hexdigit()))
            .ok_or_else(|| corrupt("the digest is not 64 hexadecimal digits".to_owned()))?
            .to_owned();
        let name_bytes = &b[224..224 + NAME_BYTES];
        let name_len = name_bytes.iter().position(|&c| c == 0).unwrap_or(NAME_BYTES);
        let source_name = String::from_utf8_lossy(&name_bytes[..name_len]).into_owned();
        let (source_width, source_height) = (get_u32(b, 144), get_u32(b, 148));
        if let Some(src) = &source {
            if (src.width, src.height, src.wraps) != (source_width, source_height, b[152] != 0) {
                return Err(corrupt(format!(
                    "the source block gives a grid of {} x {} samples, the header {source_width} x {source_height}",
                    src.width, src.height
                )));
            }
        }
        Ok(Header {
            version,
            source,
            n,
            levels,
            format,
            tile,
            radius,
            datum,
            min,
            max,
            filled: get_u64(b, 72),
            tiles,
            table_offset,
            data_offset,
            file_len,
            extent,
            source_width,
            source_height,
            source_wraps: b[152] != 0,
            digest,
            source_name,
        })
    }
}

/// Decodes and checks the source block (bytes 512..640) of a version 2 header.
fn decode_source_block(b: &[u8], corrupt: &dyn Fn(String) -> DemError) -> Result<SourceLayout, DemError> {
    let crc = crc32fast::hash(&b[512..636]);
    if crc != get_u32(b, 636) {
        return Err(corrupt(format!(
            "the source block's checksum is {:08x} but its bytes give {crc:08x}",
            get_u32(b, 636)
        )));
    }
    let src = SourceLayout {
        lon_first: get_f64(b, 512),
        lon_step: get_f64(b, 520),
        lat_first: get_f64(b, 528),
        lat_step: get_f64(b, 536),
        width: get_u32(b, 544),
        height: get_u32(b, 548),
        tile: get_u32(b, 552),
        wraps: b[556] != 0,
    };
    let axes_ok = src.lon_first.is_finite()
        && src.lat_first.is_finite()
        && src.lon_step.is_finite()
        && src.lon_step > 0.0
        && src.lat_step.is_finite()
        && src.lat_step > 0.0;
    if !axes_ok {
        return Err(corrupt(format!(
            "source axes from {} by {} degrees of longitude and from {} by {} of latitude",
            src.lon_first, src.lon_step, src.lat_first, src.lat_step
        )));
    }
    if src.width < 2 || src.height < 2 {
        return Err(corrupt(format!(
            "a source grid of {} x {} samples (at least 2 x 2 are valid)",
            src.width, src.height
        )));
    }
    if !(2..=4096).contains(&src.tile) {
        return Err(corrupt(format!("source tile size {} (2 to 4096 are valid)", src.tile)));
    }
    if src.total() > super::import::MAX_TILES {
        return Err(corrupt(format!("{} source tiles", src.total())));
    }
    Ok(src)
}

/// How a tile's samples are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TileKind {
    /// Every sample, row by row.
    Raw = 0,
    /// One sample that every position of the tile holds.
    Constant = 1,
}

/// One entry of the tile table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Entry {
    pub offset: u64,
    pub len: u32,
    pub crc: u32,
    pub kind: TileKind,
}

impl Entry {
    pub fn encode(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.offset.to_le_bytes());
        out.extend_from_slice(&self.len.to_le_bytes());
        out.extend_from_slice(&self.crc.to_le_bytes());
        out.push(self.kind as u8);
        out.extend_from_slice(&[0u8; 7]);
    }

    /// Decodes entry `idx` of a tile of `samples` samples and checks it against the data area.
    pub fn decode(
        file: &str,
        b: &[u8],
        idx: u64,
        samples: usize,
        format: SampleFormat,
        data: (u64, u64),
    ) -> Result<Entry, DemError> {
        let offset = get_u64(b, 0);
        let len = get_u32(b, 8);
        let crc = get_u32(b, 12);
        let kind = match b[16] {
            0 => TileKind::Raw,
            1 => TileKind::Constant,
            k => {
                return Err(DemError::CubeCorrupt {
                    file: file.to_owned(),
                    detail: format!("tile {idx} has unknown kind {k}"),
                })
            }
        };
        let expected = match kind {
            TileKind::Raw => samples * format.bytes(),
            TileKind::Constant => format.bytes(),
        };
        let end = offset.checked_add(u64::from(len));
        if len as usize != expected || offset < data.0 || end.is_none_or(|e| e > data.1) {
            return Err(DemError::CubeCorrupt {
                file: file.to_owned(),
                detail: format!(
                    "tile {idx} is listed as {len} bytes at {offset}; it must hold {expected} bytes within the data area {}..{}",
                    data.0, data.1
                ),
            });
        }
        Ok(Entry { offset, len, crc, kind })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tile_indices_round_trip() {
        for n in [1, 5, 6, 7, 9] {
            let g = TileGrid::new(n, 64);
            let mut count = 0u64;
            for idx in 0..g.total {
                let t = g.tile(idx);
                assert_eq!(g.index_of(t.level, t.face, t.i0 + t.w - 1, t.j0 + t.h - 1), idx);
                count += u64::from(t.w) * u64::from(t.h);
            }
            let expect: u64 = g.levels.iter().map(|l| 6 * u64::from(l.side).pow(2)).sum();
            assert_eq!(count, expect, "n = {n}");
        }
        assert_eq!(stored_levels(10), 5);
        assert_eq!(TileGrid::new(10, 64).levels.last().unwrap().side, 65);
    }

    #[test]
    fn i16_round_trip() {
        let f = SampleFormat::I16 {
            scale: 1.0,
            offset: 0.0,
        };
        assert_eq!(f.round_trip(12.4), 12.0);
        assert_eq!(f.round_trip(-40000.0), -32768.0);
        let mut v = Vec::new();
        f.encode(-3.0, &mut v);
        assert_eq!(f.decode(&v), -3.0);
    }
}
