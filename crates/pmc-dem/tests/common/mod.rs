//! Writers of GeoTIFF and PNG test files, and the grids they hold.
#![allow(dead_code)]

use pmc_dem::EquirectDem;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use tiff::encoder::{colortype::ColorType, Compression, TiffEncoder, TiffValue};
use tiff::tags::Tag;

pub fn fixture_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

pub fn etopo60() -> EquirectDem {
    EquirectDem::read_netcdf(fixture_dir().join("etopo60.cdf"), None).unwrap()
}

/// A fresh, empty directory for one test.
pub fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-dem-readers-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every `k`-th column and row of ETOPO60 (from index `k / 2`), as whole metres, rows from the
/// **north** (as an image stores them): `(width, height, values)`. Column `c` is centred at
/// longitude `20.5 + k / 2 + k * c`, row `r` (from the north) at latitude
/// `-89.5 + k / 2 + k * (height - 1 - r)`, so that `k`-degree pixels about them cover the globe.
pub fn etopo_north_up(k: usize) -> (usize, usize, Vec<i16>) {
    let dem = etopo60();
    let (w, h) = (dem.width() / k, dem.height() / k);
    let mut v = Vec::with_capacity(w * h);
    for r in (0..h).rev() {
        for c in 0..w {
            v.push(dem.value(c * k + k / 2, r * k + k / 2).unwrap() as i16);
        }
    }
    (w, h, v)
}

/// GeoTIFF tags to write.
#[derive(Clone, Debug)]
pub struct Geo {
    pub scale: Option<Vec<f64>>,
    pub tiepoint: Option<Vec<f64>>,
    pub transform: Option<Vec<f64>>,
    pub keys: Option<Vec<u16>>,
    pub nodata: Option<String>,
}

/// GeoKeys of WGS 84 longitudes and latitudes; pixels are points (nodes) or areas.
pub fn geographic_keys(pixel_is_point: bool) -> Vec<u16> {
    vec![
        1,
        1,
        0,
        3, //
        1024,
        0,
        1,
        2, // GTModelTypeGeoKey: geographic
        1025,
        0,
        1,
        if pixel_is_point { 2 } else { 1 }, // GTRasterTypeGeoKey
        2048,
        0,
        1,
        4326, // GeographicTypeGeoKey: WGS 84
    ]
}

/// GeoKeys of a projected system (UTM zone 32N).
pub fn projected_keys() -> Vec<u16> {
    vec![1, 1, 0, 2, 1024, 0, 1, 1, 3072, 0, 1, 32632]
}

impl Geo {
    /// Pixel-is-area grid: the outer corner of the north-west pixel at (`west`, `north`), pixels
    /// of `step` degrees.
    pub fn area(west: f64, north: f64, step: f64) -> Geo {
        Geo {
            scale: Some(vec![step, step, 0.0]),
            tiepoint: Some(vec![0.0, 0.0, 0.0, west, north, 0.0]),
            transform: None,
            keys: Some(geographic_keys(false)),
            nodata: None,
        }
    }

    /// The grid of [`etopo_north_up`]`(k)`: pixels of `k` degrees centred as ETOPO60's samples.
    pub fn etopo(k: usize, h: usize) -> Geo {
        let step = k as f64;
        let half = (k / 2) as f64;
        let north = -89.5 + half + step * (h - 1) as f64 + step / 2.0;
        Geo::area(20.5 + half - step / 2.0, north, step)
    }

    pub fn nodata(mut self, text: &str) -> Geo {
        self.nodata = Some(text.to_owned());
        self
    }
}

/// A TIFF written by the `tiff` crate, in strips of `rows_per_strip` rows, with `geo`'s tags.
pub fn strip_tiff<C: ColorType>(
    w: usize,
    h: usize,
    data: &[C::Inner],
    compression: Compression,
    rows_per_strip: u32,
    geo: &Geo,
) -> Vec<u8>
where
    [C::Inner]: TiffValue,
{
    let mut out = Cursor::new(Vec::new());
    write_strips::<C>(&mut out, w, h, data, compression, rows_per_strip, geo);
    out.into_inner()
}

fn write_strips<C: ColorType>(
    out: &mut Cursor<Vec<u8>>,
    w: usize,
    h: usize,
    data: &[C::Inner],
    compression: Compression,
    rows_per_strip: u32,
    geo: &Geo,
) where
    [C::Inner]: TiffValue,
{
    let mut enc = TiffEncoder::new(out).unwrap().with_compression(compression);
    let mut img = enc.new_image::<C>(w as u32, h as u32).unwrap();
    img.rows_per_strip(rows_per_strip).unwrap();
    let e = img.encoder();
    if let Some(s) = &geo.scale {
        e.write_tag(Tag::ModelPixelScaleTag, &s[..]).unwrap();
    }
    if let Some(t) = &geo.tiepoint {
        e.write_tag(Tag::ModelTiepointTag, &t[..]).unwrap();
    }
    if let Some(m) = &geo.transform {
        e.write_tag(Tag::ModelTransformationTag, &m[..]).unwrap();
    }
    if let Some(k) = &geo.keys {
        e.write_tag(Tag::GeoKeyDirectoryTag, &k[..]).unwrap();
    }
    if let Some(n) = &geo.nodata {
        e.write_tag(Tag::GdalNodata, &n[..]).unwrap();
    }
    img.write_data(data).unwrap();
}

/// A little-endian classic TIFF of uncompressed `i16` tiles of `tw` x `th`, written by hand (the
/// `tiff` crate's encoder writes strips only). Tiles on the right and bottom edges are padded.
pub fn tiled_tiff_i16(w: usize, h: usize, tw: usize, th: usize, data: &[i16], geo: &Geo) -> Vec<u8> {
    let across = w.div_ceil(tw);
    let down = h.div_ceil(th);
    let tile_bytes = tw * th * 2;
    let mut tiles = Vec::new();
    for ty in 0..down {
        for tx in 0..across {
            for r in 0..th {
                for c in 0..tw {
                    let (x, y) = (tx * tw + c, ty * th + r);
                    let v = if x < w && y < h { data[y * w + x] } else { 0 };
                    tiles.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
    }
    let n = across * down;
    // (tag, type, count, value bytes); SHORT 3, LONG 4, ASCII 2, DOUBLE 12.
    let short = |v: u16| v.to_le_bytes().to_vec();
    let long = |v: u32| v.to_le_bytes().to_vec();
    let mut entries: Vec<(u16, u16, u32, Vec<u8>)> = vec![
        (256, 4, 1, long(w as u32)),
        (257, 4, 1, long(h as u32)),
        (258, 3, 1, short(16)),
        (259, 3, 1, short(1)),
        (262, 3, 1, short(1)),
        (277, 3, 1, short(1)),
        (284, 3, 1, short(1)),
        (322, 4, 1, long(tw as u32)),
        (323, 4, 1, long(th as u32)),
        (324, 4, n as u32, vec![0; 4 * n]), // offsets, filled in below
        (
            325,
            4,
            n as u32,
            (0..n).flat_map(|_| (tile_bytes as u32).to_le_bytes()).collect(),
        ),
        (339, 3, 1, short(2)),
    ];
    let doubles = |v: &[f64]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    if let Some(s) = &geo.scale {
        entries.push((33550, 12, s.len() as u32, doubles(s)));
    }
    if let Some(t) = &geo.tiepoint {
        entries.push((33922, 12, t.len() as u32, doubles(t)));
    }
    if let Some(m) = &geo.transform {
        entries.push((34264, 12, m.len() as u32, doubles(m)));
    }
    if let Some(k) = &geo.keys {
        entries.push((
            34735,
            3,
            k.len() as u32,
            k.iter().flat_map(|x| x.to_le_bytes()).collect(),
        ));
    }
    if let Some(text) = &geo.nodata {
        let mut b = text.as_bytes().to_vec();
        b.push(0);
        entries.push((42113, 2, b.len() as u32, b));
    }
    entries.sort_by_key(|e| e.0);
    let ifd_len = 2 + 12 * entries.len() + 4;
    let extra: usize = entries
        .iter()
        .map(|e| if e.3.len() > 4 { e.3.len().div_ceil(2) * 2 } else { 0 })
        .sum();
    let data_at = 8 + ifd_len + extra;
    let offsets: Vec<u8> = (0..n)
        .flat_map(|i| ((data_at + i * tile_bytes) as u32).to_le_bytes())
        .collect();
    entries.iter_mut().find(|e| e.0 == 324).unwrap().3 = offsets;

    let mut out = b"II*\0".to_vec();
    out.extend_from_slice(&8u32.to_le_bytes());
    out.extend_from_slice(&(entries.len() as u16).to_le_bytes());
    let mut extra_bytes = Vec::new();
    for (tag, ty, count, bytes) in &entries {
        out.extend_from_slice(&tag.to_le_bytes());
        out.extend_from_slice(&ty.to_le_bytes());
        out.extend_from_slice(&count.to_le_bytes());
        if bytes.len() <= 4 {
            let mut v = bytes.clone();
            v.resize(4, 0);
            out.extend_from_slice(&v);
        } else {
            let at = 8 + ifd_len + extra_bytes.len();
            out.extend_from_slice(&(at as u32).to_le_bytes());
            extra_bytes.extend_from_slice(bytes);
            if extra_bytes.len() % 2 == 1 {
                extra_bytes.push(0);
            }
        }
    }
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&extra_bytes);
    assert_eq!(out.len(), data_at);
    out.extend_from_slice(&tiles);
    out
}

/// A PNG of `w` x `h` samples of `bit_depth` bits in `color`, rows as given.
pub fn png(w: usize, h: usize, color: png::ColorType, bit_depth: png::BitDepth, bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w as u32, h as u32);
        enc.set_color(color);
        enc.set_depth(bit_depth);
        let mut wr = enc.write_header().unwrap();
        wr.write_image_data(bytes).unwrap();
    }
    out
}

/// A 16-bit grayscale PNG of `values`, rows from the north.
pub fn png16(w: usize, h: usize, values: &[u16]) -> Vec<u8> {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
    png(w, h, png::ColorType::Grayscale, png::BitDepth::Sixteen, &bytes)
}
