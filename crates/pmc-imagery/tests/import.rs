//! Importing JPEG, PNG and GeoTIFF images (made here or small fixtures), the `.pmcimg` round
//! trip, and every refusal naming the file.

use pmc_imagery::{Extent, Imagery, ImageryError};
use std::io::Cursor;
use std::path::PathBuf;
use tiff::encoder::colortype::{ColorType, RGB16, RGB8};
use tiff::encoder::TiffEncoder;
use tiff::tags::Tag;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

fn temp_dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-imagery-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `w x h` RGB pixels, all different in a small image: `(7c + r, 3r + 11c, c * r)`.
fn pattern(w: u32, h: u32) -> Vec<u8> {
    let mut px = Vec::new();
    for r in 0..h {
        for c in 0..w {
            px.extend([(7 * c + r) as u8, (3 * r + 11 * c) as u8, (c * r) as u8]);
        }
    }
    px
}

fn png_bytes(
    w: u32,
    h: u32,
    color: png::ColorType,
    depth: png::BitDepth,
    data: &[u8],
    palette: Option<&[u8]>,
) -> Vec<u8> {
    let mut out = Vec::new();
    let mut e = png::Encoder::new(&mut out, w, h);
    e.set_color(color);
    e.set_depth(depth);
    if let Some(p) = palette {
        e.set_palette(p.to_vec());
    }
    let mut wr = e.write_header().unwrap();
    wr.write_image_data(data).unwrap();
    wr.finish().unwrap();
    out
}

/// Refusal of `bytes` under `name`, whose message names it.
fn refusal(name: &str, bytes: &[u8], extent: Option<Extent>) -> ImageryError {
    let e = Imagery::import_bytes(name, bytes, extent).unwrap_err();
    assert_eq!(e.file(), name);
    assert!(e.to_string().contains(name), "{e}");
    e
}

#[test]
fn png_rgb_round_trips_exactly_over_the_globe_by_default() {
    let (w, h) = (40, 20);
    let px = pattern(w, h);
    let bytes = png_bytes(w, h, png::ColorType::Rgb, png::BitDepth::Eight, &px, None);
    let img = Imagery::import_bytes("p.png", &bytes, None).unwrap();
    assert_eq!((img.width(), img.height()), (w, h));
    assert_eq!(img.extent(), Extent::GLOBAL);
    assert_eq!(img.pixels(), &px[..]);
    let ext = Extent::new(-10.0, 35.0, 5.0, 44.0).unwrap();
    let img = Imagery::import_bytes("p.png", &bytes, Some(ext)).unwrap();
    assert_eq!(img.extent(), ext);
    assert_eq!(img.pixels(), &px[..]);
}

#[test]
fn png_grey_alpha_palette_and_16_bit_become_rgb() {
    let (w, h) = (5u32, 3u32);
    let n = (w * h) as usize;
    let grey: Vec<u8> = (0..n as u8).map(|i| i * 17).collect();
    let img = Imagery::import_bytes(
        "g.png",
        &png_bytes(w, h, png::ColorType::Grayscale, png::BitDepth::Eight, &grey, None),
        None,
    )
    .unwrap();
    assert_eq!(img.pixels(), grey.iter().flat_map(|&g| [g; 3]).collect::<Vec<_>>());

    let rgb = pattern(w, h);
    let rgba: Vec<u8> = rgb.chunks(3).flat_map(|p| [p[0], p[1], p[2], 9]).collect();
    let img = Imagery::import_bytes(
        "a.png",
        &png_bytes(w, h, png::ColorType::Rgba, png::BitDepth::Eight, &rgba, None),
        None,
    )
    .unwrap();
    assert_eq!(img.pixels(), &rgb[..], "alpha dropped");

    let palette = [10, 20, 30, 200, 100, 50];
    let idx: Vec<u8> = (0..n).map(|i| (i % 2) as u8).collect();
    let img = Imagery::import_bytes(
        "i.png",
        &png_bytes(
            w,
            h,
            png::ColorType::Indexed,
            png::BitDepth::Eight,
            &idx,
            Some(&palette),
        ),
        None,
    )
    .unwrap();
    let want: Vec<u8> = idx
        .iter()
        .flat_map(|&i| palette[3 * i as usize..3 * i as usize + 3].to_vec())
        .collect();
    assert_eq!(img.pixels(), &want[..]);

    let wide: Vec<u16> = rgb.iter().map(|&v| u16::from(v) * 257 + 100).collect();
    let be: Vec<u8> = wide.iter().flat_map(|v| v.to_be_bytes()).collect();
    let img = Imagery::import_bytes(
        "w.png",
        &png_bytes(w, h, png::ColorType::Rgb, png::BitDepth::Sixteen, &be, None),
        None,
    )
    .unwrap();
    assert_eq!(
        img.pixels(),
        &rgb[..],
        "16-bit values rounded to the nearest 8-bit value"
    );
}

#[test]
fn jpeg_matches_an_independent_decoder() {
    let img = Imagery::import(fixture("earth64.jpg"), None).unwrap();
    assert_eq!((img.width(), img.height()), (64, 32));
    assert_eq!(img.extent(), Extent::GLOBAL);
    let reference = Imagery::import(fixture("earth64-libjpeg.png"), None).unwrap();
    // Decoders may round their inverse transforms differently by a few units, no more.
    let diffs: Vec<u8> = img
        .pixels()
        .iter()
        .zip(reference.pixels())
        .map(|(a, b)| a.abs_diff(*b))
        .collect();
    let worst = *diffs.iter().max().unwrap();
    let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len() as f64;
    assert!(
        worst <= 4 && mean < 0.5,
        "jpeg decoders differ by {worst} on a channel, {mean} on average"
    );
    // The north-west corner is polar ice, the Pacific near (0, -150) is dark blue.
    let ice = img.pixel(0, 0);
    assert!(ice.iter().all(|&v| v > 150), "{ice:?}");
    let pacific = img.color_at(0.0, -150.0).unwrap();
    assert!(pacific[2] > pacific[0] + 20, "{pacific:?}");

    let grey = Imagery::import(fixture("earth64-gray.jpg"), None).unwrap();
    assert_eq!((grey.width(), grey.height()), (64, 32));
    assert!(grey.pixels().chunks(3).all(|p| p[0] == p[1] && p[1] == p[2]));
}

/// Georeferencing tags of a TIFF.
struct Geo {
    scale: Option<Vec<f64>>,
    tiepoint: Option<Vec<f64>>,
    transform: Option<Vec<f64>>,
    keys: Option<Vec<u16>>,
}

/// GeoKeys of WGS 84 longitudes and latitudes; pixels are points or areas.
fn geographic_keys(pixel_is_point: bool) -> Vec<u16> {
    let raster = if pixel_is_point { 2 } else { 1 };
    vec![1, 1, 0, 3, 1024, 0, 1, 2, 1025, 0, 1, raster, 2048, 0, 1, 4326]
}

impl Geo {
    /// Pixel-is-area grid with its north-west corner at (`west`, `north`), square pixels of
    /// `step` degrees.
    fn area(west: f64, north: f64, step: f64) -> Geo {
        Geo {
            scale: Some(vec![step, step, 0.0]),
            tiepoint: Some(vec![0.0, 0.0, 0.0, west, north, 0.0]),
            transform: None,
            keys: Some(geographic_keys(false)),
        }
    }

    fn none() -> Geo {
        Geo {
            scale: None,
            tiepoint: None,
            transform: None,
            keys: None,
        }
    }
}

fn tiff_bytes<C: ColorType>(w: u32, h: u32, data: &[C::Inner], geo: &Geo) -> Vec<u8>
where
    [C::Inner]: tiff::encoder::TiffValue,
{
    let mut out = Cursor::new(Vec::new());
    let mut enc = TiffEncoder::new(&mut out).unwrap();
    let mut img = enc.new_image::<C>(w, h).unwrap();
    img.rows_per_strip(3).unwrap();
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
    img.write_data(data).unwrap();
    out.into_inner()
}

#[test]
fn geotiff_extent_comes_from_its_georeferencing() {
    let (w, h) = (8, 6);
    let px = pattern(w, h);
    let bytes = tiff_bytes::<RGB8>(w, h, &px, &Geo::area(10.0, 40.0, 0.5));
    let img = Imagery::import_bytes("g.tif", &bytes, None).unwrap();
    assert_eq!(img.extent(), Extent::new(10.0, 37.0, 14.0, 40.0).unwrap());
    assert_eq!(img.pixels(), &px[..]);
    // An extent given replaces the georeferencing.
    let given = Extent::new(0.0, 0.0, 8.0, 6.0).unwrap();
    assert_eq!(
        Imagery::import_bytes("g.tif", &bytes, Some(given)).unwrap().extent(),
        given
    );

    // The whole globe, one degree a pixel, read as wrapping.
    let (w, h) = (360, 180);
    let px = pattern(w, h);
    let img = Imagery::import_bytes(
        "globe.tif",
        &tiff_bytes::<RGB8>(w, h, &px, &Geo::area(-180.0, 90.0, 1.0)),
        None,
    )
    .unwrap();
    assert!(img.extent().wraps());
    assert_eq!(img.pixels(), &px[..]);
}

#[test]
fn geotiff_points_south_up_and_16_bit() {
    let (w, h) = (4u32, 3u32);
    let px = pattern(w, h);
    // Pixels as points: the tie point is the centre of the north-west pixel.
    let mut geo = Geo::area(10.0, 40.0, 1.0);
    geo.keys = Some(geographic_keys(true));
    let img = Imagery::import_bytes("p.tif", &tiff_bytes::<RGB8>(w, h, &px, &geo), None).unwrap();
    assert_eq!(img.extent(), Extent::new(9.5, 37.5, 13.5, 40.5).unwrap());

    // Rows from the south (a positive y scale in the transformation): flipped to run north.
    let mut geo = Geo::none();
    geo.transform = Some(vec![
        1.0, 0.0, 0.0, 10.0, //
        0.0, 1.0, 0.0, 37.0, //
        0.0, 0.0, 0.0, 0.0, //
        0.0, 0.0, 0.0, 1.0,
    ]);
    geo.keys = Some(geographic_keys(false));
    let img = Imagery::import_bytes("s.tif", &tiff_bytes::<RGB8>(w, h, &px, &geo), None).unwrap();
    assert_eq!(img.extent(), Extent::new(10.0, 37.0, 14.0, 40.0).unwrap());
    let row = (w * 3) as usize;
    for r in 0..h as usize {
        assert_eq!(
            &img.pixels()[r * row..(r + 1) * row],
            &px[(h as usize - 1 - r) * row..(h as usize - r) * row]
        );
    }

    let wide: Vec<u16> = px.iter().map(|&v| u16::from(v) * 257).collect();
    let img = Imagery::import_bytes(
        "w.tif",
        &tiff_bytes::<RGB16>(w, h, &wide, &Geo::area(0.0, 10.0, 1.0)),
        None,
    )
    .unwrap();
    assert_eq!(img.pixels(), &px[..]);
}

#[test]
fn tiff_without_georeferencing_needs_an_extent() {
    let (w, h) = (4u32, 2u32);
    let px = pattern(w, h);
    let bytes = tiff_bytes::<RGB8>(w, h, &px, &Geo::none());
    let e = refusal("plain.tif", &bytes, None);
    assert!(matches!(e, ImageryError::Georeference { .. }), "{e}");
    assert!(e.to_string().contains("give the image's extent"), "{e}");
    let img = Imagery::import_bytes("plain.tif", &bytes, Some(Extent::GLOBAL)).unwrap();
    assert_eq!(img.pixels(), &px[..]);

    let mut geo = Geo::area(0.0, 10.0, 1.0);
    geo.keys = Some(vec![1, 1, 0, 2, 1024, 0, 1, 1, 3072, 0, 1, 32632]);
    let e = refusal("utm.tif", &tiff_bytes::<RGB8>(w, h, &px, &geo), None);
    assert!(e.to_string().contains("projected"), "{e}");

    // Georeferencing that runs off the globe.
    let e = refusal(
        "off.tif",
        &tiff_bytes::<RGB8>(w, h, &px, &Geo::area(0.0, 91.0, 1.0)),
        None,
    );
    assert!(matches!(e, ImageryError::InvalidExtent { .. }), "{e}");
}

#[test]
fn pmcimg_round_trips_exactly() {
    let dir = temp_dir("roundtrip");
    let ext = Extent::new(170.0, -20.0, 200.0, 10.0).unwrap();
    let img = Imagery::new(30, 12, ext, pattern(30, 12)).unwrap();
    let path = dir.join("a.pmcimg");
    img.write(&path).unwrap();
    let back = Imagery::open(&path).unwrap();
    assert_eq!(back, img);
    assert_eq!(back.digest(), img.digest());
    assert_eq!(back.extent().to_array(), [170.0, 200.0, -20.0, 10.0]);
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(bytes, img.to_pmcimg_bytes());
    assert_eq!(bytes.len(), 160 + 30 * 12 * 3);
    assert_eq!(Imagery::from_pmcimg_bytes("a", &bytes).unwrap(), img);
    // Nothing else left in the directory (no temporary file).
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_damaged_byte_of_a_pmcimg_is_refused() {
    let img = Imagery::new(5, 3, Extent::GLOBAL, pattern(5, 3)).unwrap();
    let good = img.to_pmcimg_bytes();
    for at in 0..good.len() {
        for flip in [0x01u8, 0x80] {
            let mut bad = good.clone();
            bad[at] ^= flip;
            let e = Imagery::from_pmcimg_bytes("bad.pmcimg", &bad).unwrap_err();
            assert_eq!(e.file(), "bad.pmcimg");
            assert!(e.to_string().starts_with("bad.pmcimg: "), "{e}");
            if at >= 8 {
                assert!(
                    matches!(
                        e,
                        ImageryError::Damaged { .. } | ImageryError::UnsupportedVersion { .. }
                    ),
                    "byte {at}: {e}"
                );
            }
        }
    }
}

#[test]
fn truncated_or_extended_pmcimg_is_refused() {
    let img = Imagery::new(5, 3, Extent::GLOBAL, pattern(5, 3)).unwrap();
    let good = img.to_pmcimg_bytes();
    for len in 0..good.len() {
        let e = Imagery::from_pmcimg_bytes("cut.pmcimg", &good[..len]).unwrap_err();
        match len {
            0 => assert!(matches!(e, ImageryError::NotImagery { .. }), "{e}"),
            _ => assert!(matches!(e, ImageryError::Damaged { .. }), "{len}: {e}"),
        }
    }
    let mut longer = good.clone();
    longer.push(0);
    let e = Imagery::from_pmcimg_bytes("long.pmcimg", &longer).unwrap_err();
    assert!(e.to_string().contains("bytes appended"), "{e}");

    // The same through files.
    let dir = temp_dir("truncated");
    let path = dir.join("cut.pmcimg");
    std::fs::write(&path, &good[..good.len() - 1]).unwrap();
    assert!(matches!(Imagery::open(&path), Err(ImageryError::Damaged { .. })));
    assert!(matches!(
        Imagery::open(dir.join("missing.pmcimg")),
        Err(ImageryError::Io { .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn foreign_files_are_named_for_what_they_are() {
    let img = Imagery::new(2, 1, Extent::GLOBAL, vec![0; 6]).unwrap();
    let mut v2 = img.to_pmcimg_bytes();
    v2[8] = 2;
    assert!(matches!(
        Imagery::from_pmcimg_bytes("v2", &v2),
        Err(ImageryError::UnsupportedVersion { version: 2, .. })
    ));
    let jpeg = std::fs::read(fixture("earth64.jpg")).unwrap();
    let e = Imagery::from_pmcimg_bytes("earth.jpg", &jpeg).unwrap_err();
    assert!(matches!(e, ImageryError::NotImagery { .. }));
    assert!(e.to_string().contains("JPEG"), "{e}");
    let e = Imagery::from_pmcimg_bytes("d.pmcdem", b"\x89PMCDEM\n and more").unwrap_err();
    assert!(e.to_string().contains(".pmcdem elevation file"), "{e}");

    let e = refusal("n.cdf", b"CDF\x01\0\0\0\0", None);
    assert!(matches!(e, ImageryError::UnknownFormat { .. }));
    assert!(e.to_string().contains("netCDF"), "{e}");
    let e = refusal("empty.png", b"", None);
    assert!(e.to_string().contains("empty"), "{e}");
    let e = refusal("x.pmcimg", &img.to_pmcimg_bytes(), None);
    assert!(e.to_string().contains(".pmcimg"), "{e}");
}

/// A deterministic sequence of pseudo-random numbers (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
}

/// Truncations and random byte changes of `good` decode to imagery or to an error naming the
/// file, never a panic; every truncation before the last bytes is an error.
fn fuzz(name: &str, good: &[u8], extent: Option<Extent>) {
    Imagery::import_bytes(name, good, extent).unwrap();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ good.len() as u64);
    let step = (good.len() / 150).max(1);
    for len in (0..good.len().saturating_sub(16)).step_by(step) {
        let e = Imagery::import_bytes(name, &good[..len], extent).unwrap_err();
        assert_eq!(e.file(), name, "{e}");
    }
    for _ in 0..400 {
        let mut bad = good.to_vec();
        for _ in 0..1 + rng.next() % 4 {
            let at = (rng.next() % bad.len() as u64) as usize;
            bad[at] = rng.next() as u8;
        }
        if let Err(e) = Imagery::import_bytes(name, &bad, extent) {
            assert_eq!(e.file(), name, "{e}");
        }
    }
}

#[test]
fn truncated_and_garbled_images_are_errors_never_panics() {
    fuzz("f.jpg", &std::fs::read(fixture("earth64.jpg")).unwrap(), None);
    fuzz("f.png", &std::fs::read(fixture("earth64-libjpeg.png")).unwrap(), None);
    let (w, h) = (16, 8);
    let geo_tiff = tiff_bytes::<RGB8>(w, h, &pattern(w, h), &Geo::area(-180.0, 90.0, 22.5));
    fuzz("f.tif", &geo_tiff, None);
    fuzz("f.tif", &geo_tiff, Some(Extent::GLOBAL));
}

#[test]
fn nasa_visible_earth_imports_north_up_from_the_antimeridian() {
    let path = std::path::Path::new("/usr/share/xplanet/images/earth.jpg");
    assert!(
        path.exists(),
        "{} is missing: install Debian's xplanet-images (scripts/test.sh does)",
        path.display()
    );
    let img = Imagery::import(path, None).unwrap();
    assert_eq!((img.width(), img.height()), (2048, 1024));
    assert_eq!(img.extent(), Extent::GLOBAL);
    // Where things are: the Sahara is sand, the Pacific deep blue, Antarctica white, and the
    // Amazon forest green.
    let sahara = img.color_at(23.0, 12.0).unwrap();
    assert!(sahara[0] > 150 && sahara[0] > sahara[2] + 40, "Sahara {sahara:?}");
    let pacific = img.color_at(0.0, -150.0).unwrap();
    assert!(pacific[2] > pacific[0] + 20 && pacific[0] < 60, "Pacific {pacific:?}");
    let antarctica = img.color_at(-85.0, 0.0).unwrap();
    assert!(antarctica.iter().all(|&v| v > 180), "Antarctica {antarctica:?}");
    let amazon = img.color_at(-4.0, -62.0).unwrap();
    assert!(amazon[1] > amazon[0] && amazon[1] > amazon[2], "Amazon {amazon:?}");
    // At pixel centres, the lookup is the pixel.
    for (c, r) in [(0, 0), (2047, 1023), (1024, 300), (7, 1000), (1500, 512)] {
        let lon = -180.0 + (f64::from(c) + 0.5) * 360.0 / 2048.0;
        let lat = 90.0 - (f64::from(r) + 0.5) * 180.0 / 1024.0;
        assert_eq!(img.color_at(lat, lon), Some(img.pixel(c, r)), "({c}, {r})");
    }
    // A level for the viewer: 1024 x 512, each pixel the mean of a 2 x 2 block.
    let level = img.downsampled(1024);
    assert_eq!((level.width(), level.height()), (1024, 512));
    let block: Vec<u32> = [(600, 200), (601, 200), (600, 201), (601, 201)]
        .iter()
        .map(|&(c, r)| u32::from(img.pixel(c, r)[1]))
        .collect();
    assert_eq!(u32::from(level.pixel(300, 100)[1]), (block.iter().sum::<u32>() + 2) / 4);
}
