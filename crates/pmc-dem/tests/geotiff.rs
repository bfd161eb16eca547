//! GeoTIFF files written here (strips by the `tiff` crate, tiles by hand): values, extents, the
//! north-up flip, nodata, wrapping, windowed reads, and every refusal naming the file.

use crate::common::*;
use pmc_dem::{DemError, EquirectDem, EquirectSource, GeoTiffSource, MAX_CELLS};
use tiff::encoder::colortype::{Gray16, Gray32Float, Gray64Float, GrayI16, GrayI32};
use tiff::encoder::{Compression, DeflateLevel};

/// Reads `bytes` whole, and checks that the windowed source gives the same rows in bands of 5.
fn read(name: &str, bytes: Vec<u8>) -> EquirectDem {
    let dem = EquirectDem::from_geotiff_bytes(name, bytes.clone()).unwrap();
    let src = GeoTiffSource::from_bytes(name, bytes).unwrap();
    let w = dem.width();
    let mut row0 = 0;
    while row0 < dem.height() {
        let rows = 5.min(dem.height() - row0);
        let mut band = vec![0.0; rows * w];
        src.read_rows(row0, rows, &mut band).unwrap();
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&band), bits(&dem.heights()[row0 * w..(row0 + rows) * w]));
        row0 += rows;
    }
    dem
}

/// Refusal of `bytes` under `name`, whose message names it.
fn refusal(name: &str, bytes: Vec<u8>) -> DemError {
    let e = EquirectDem::from_geotiff_bytes(name, bytes).unwrap_err();
    assert_eq!(e.file(), name);
    assert!(e.to_string().starts_with(&format!("{name}: ")), "{e}");
    e
}

/// Checks that `dem` holds `north_up` (rows from the north) flipped to rows from the south.
fn assert_flipped(dem: &EquirectDem, w: usize, h: usize, north_up: &[f32]) {
    assert_eq!((dem.width(), dem.height()), (w, h));
    for r in 0..h {
        for c in 0..w {
            let want = north_up[(h - 1 - r) * w + c];
            let got = dem.heights()[r * w + c];
            assert!(want.to_bits() == got.to_bits(), "({c}, {r}): {got} != {want}");
        }
    }
}

#[test]
fn etopo60_as_int16_strips_round_trips_exactly_with_each_compression() {
    let (w, h, v) = etopo_north_up(1);
    let expected: Vec<f32> = v.iter().map(|&x| f32::from(x)).collect();
    let geo = Geo::etopo(1, h);
    for (i, compression) in [
        Compression::Uncompressed,
        Compression::Deflate(DeflateLevel::Balanced),
        Compression::Lzw,
        Compression::Packbits,
    ]
    .into_iter()
    .enumerate()
    {
        let bytes = strip_tiff::<GrayI16>(w, h, &v, compression, 7, &geo);
        let dem = read(&format!("etopo60-{i}.tif"), bytes);
        assert_flipped(&dem, w, h, &expected);
        assert_eq!((dem.lon_first(), dem.lon_step()), (20.5, 1.0));
        assert_eq!((dem.lat_first(), dem.lat_step()), (-89.5, 1.0));
        assert!(dem.wraps_in_longitude());
        assert_eq!(dem.variable(), "band 1");
    }
    // The same heights as the netCDF grid, rounded to metres.
    let dem = etopo60();
    let tif = read("e.tif", strip_tiff::<GrayI16>(w, h, &v, Compression::Lzw, 16, &geo));
    assert_eq!(tif.heights().len(), dem.heights().len());
    for (a, b) in tif.heights().iter().zip(dem.heights()) {
        assert_eq!(*a, (*b as i16) as f32);
    }
}

#[test]
fn float32_float64_uint16_and_int32_samples_round_trip() {
    let (w, h) = (12, 6);
    let f: Vec<f32> = (0..w * h).map(|i| i as f32 * 0.37 - 5.25).collect();
    let geo = Geo::area(-180.0, 90.0, 30.0);
    let dem = read(
        "f32.tif",
        strip_tiff::<Gray32Float>(w, h, &f, Compression::Lzw, 2, &geo),
    );
    assert_flipped(&dem, w, h, &f);
    assert_eq!(
        (dem.lon_first(), dem.lat_first(), dem.lat_step()),
        (-165.0, -75.0, 30.0)
    );
    assert!(dem.wraps_in_longitude());
    let d: Vec<f64> = f.iter().map(|&x| f64::from(x)).collect();
    let dem = read(
        "f64.tif",
        strip_tiff::<Gray64Float>(w, h, &d, Compression::Deflate(DeflateLevel::Fast), 4, &geo),
    );
    assert_flipped(&dem, w, h, &f);
    let u: Vec<u16> = (0..w * h).map(|i| (i * 900) as u16).collect();
    let dem = read(
        "u16.tif",
        strip_tiff::<Gray16>(w, h, &u, Compression::Uncompressed, 6, &geo),
    );
    assert_flipped(&dem, w, h, &u.iter().map(|&x| f32::from(x)).collect::<Vec<_>>());
    let i: Vec<i32> = (0..w * h).map(|i| i as i32 * 1000 - 11_000).collect();
    let dem = read("i32.tif", strip_tiff::<GrayI32>(w, h, &i, Compression::Lzw, 1, &geo));
    assert_flipped(&dem, w, h, &i.iter().map(|&x| x as f32).collect::<Vec<_>>());
}

#[test]
fn tiles_read_like_strips_including_padded_edge_tiles() {
    let (w, h, v) = etopo_north_up(5); // 72 x 36: tiles of 16 leave padded edges
    let geo = Geo::etopo(5, h);
    let strips = read(
        "strips.tif",
        strip_tiff::<GrayI16>(w, h, &v, Compression::Uncompressed, 8, &geo),
    );
    let tiled_bytes = tiled_tiff_i16(w, h, 16, 16, &v, &geo);
    assert!(GeoTiffSource::from_bytes("t.tif", tiled_bytes.clone())
        .unwrap()
        .is_tiled());
    let tiles = read("tiles.tif", tiled_bytes);
    assert_eq!(tiles.heights(), strips.heights());
    assert_eq!(
        format!("{:?}", (tiles.lon_first(), tiles.lat_first(), tiles.lon_step())),
        format!("{:?}", (strips.lon_first(), strips.lat_first(), strips.lon_step()))
    );
    assert_eq!(
        (tiles.lon_first(), tiles.lat_first(), tiles.lat_step()),
        (22.5, -87.5, 5.0)
    );
    assert!(tiles.wraps_in_longitude());
}

#[test]
fn nodata_and_non_finite_floats_are_missing() {
    let (w, h) = (4, 2);
    let geo = Geo::area(0.0, 10.0, 5.0).nodata("-32768");
    let v: Vec<i16> = vec![1, -32768, 3, 4, 5, 6, 7, -32768];
    let dem = read(
        "nd.tif",
        strip_tiff::<GrayI16>(w, h, &v, Compression::Uncompressed, 2, &geo),
    );
    assert_eq!(dem.stats().missing, 2);
    assert_eq!(
        (dem.value(1, 1), dem.value(3, 0), dem.value(0, 1)),
        (None, None, Some(1.0))
    );
    assert!(!dem.wraps_in_longitude());
    assert_eq!((dem.lon_first(), dem.lat_first()), (2.5, 2.5));
    let f = vec![1.5f32, -9999.0, f32::NAN, f32::INFINITY, 2.0, 3.0, 4.0, 5.0];
    let geo = Geo::area(0.0, 10.0, 5.0).nodata("-9999 ");
    let dem = read(
        "ndf.tif",
        strip_tiff::<Gray32Float>(w, h, &f, Compression::Uncompressed, 2, &geo),
    );
    assert_eq!(dem.stats().missing, 3);
    assert_eq!(
        GeoTiffSource::from_bytes("n.tif", strip_tiff::<Gray32Float>(w, h, &f, Compression::Lzw, 2, &geo))
            .unwrap()
            .nodata(),
        Some(-9999.0)
    );
    // A nodata that is not a number.
    let geo = Geo::area(0.0, 10.0, 5.0).nodata("none");
    let e = refusal(
        "bad-nd.tif",
        strip_tiff::<GrayI16>(w, h, &v, Compression::Uncompressed, 2, &geo),
    );
    assert!(matches!(e, DemError::TiffCorrupt { .. }), "{e}");
    // Every sample missing.
    let geo = Geo::area(0.0, 10.0, 5.0).nodata("7");
    let e = refusal(
        "all-nd.tif",
        strip_tiff::<GrayI16>(w, h, &[7; 8], Compression::Uncompressed, 2, &geo),
    );
    assert!(matches!(e, DemError::NoValidData { .. }), "{e}");
}

#[test]
fn pixel_is_point_grids_of_nodes_drop_the_repeated_column_and_normalise_longitudes() {
    // Nodes every 90 degrees from 0 to 360 inclusive, and from 90 to -90.
    let (w, h) = (5, 3);
    let v: Vec<i16> = (0..15).collect();
    let mut geo = Geo::area(0.0, 90.0, 90.0);
    geo.keys = Some(geographic_keys(true));
    let dem = read(
        "nodes.tif",
        strip_tiff::<GrayI16>(w, h, &v, Compression::Uncompressed, 3, &geo),
    );
    assert_eq!((dem.width(), dem.height()), (4, 3));
    assert!(dem.wraps_in_longitude());
    assert_eq!((dem.lon_first(), dem.lat_first(), dem.lat(2)), (0.0, -90.0, 90.0));
    assert_eq!(
        dem.heights(),
        &[10.0, 11.0, 12.0, 13.0, 5.0, 6.0, 7.0, 8.0, 0.0, 1.0, 2.0, 3.0]
    );
    // A regional grid east of the antimeridian, given in 0..360 longitudes.
    let geo = Geo::area(200.0, 50.0, 1.0);
    let dem = read(
        "east.tif",
        strip_tiff::<GrayI16>(w, h, &v, Compression::Uncompressed, 3, &geo),
    );
    assert_eq!((dem.lon_first(), dem.wraps_in_longitude()), (-159.5, false));
}

#[test]
fn a_model_transformation_without_rotation_gives_the_extent_and_south_up_files_are_not_flipped() {
    let (w, h) = (4, 2);
    let v: Vec<i16> = (0..8).collect();
    let mut geo = Geo::area(0.0, 0.0, 1.0);
    geo.scale = None;
    geo.tiepoint = None;
    // Rows already running north: latitude = 10 + 2 j.
    geo.transform = Some(vec![
        3.0, 0.0, 0.0, -30.0, 0.0, 2.0, 0.0, 10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ]);
    let dem = read(
        "south-up.tif",
        strip_tiff::<GrayI16>(w, h, &v, Compression::Uncompressed, 2, &geo),
    );
    assert_eq!(dem.heights(), &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
    assert_eq!(
        (dem.lon_first(), dem.lon_step(), dem.lat_first(), dem.lat_step()),
        (-28.5, 3.0, 11.0, 2.0)
    );
    // Columns running west.
    geo.transform = Some(vec![
        -3.0, 0.0, 0.0, -30.0, 0.0, -2.0, 0.0, 10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ]);
    let dem = read(
        "west.tif",
        strip_tiff::<GrayI16>(w, h, &v, Compression::Uncompressed, 2, &geo),
    );
    assert_eq!(dem.heights(), &[7.0, 6.0, 5.0, 4.0, 3.0, 2.0, 1.0, 0.0]);
    assert_eq!((dem.lon_first(), dem.lat_first()), (-40.5, 7.0));
    // Rotated.
    geo.transform = Some(vec![
        3.0, 0.5, 0.0, -30.0, 0.0, -2.0, 0.0, 10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ]);
    let e = refusal(
        "rot.tif",
        strip_tiff::<GrayI16>(w, h, &v, Compression::Uncompressed, 2, &geo),
    );
    assert!(
        matches!(e, DemError::NoGeoreference { ref detail, .. } if detail.contains("rotates")),
        "{e}"
    );
}

#[test]
fn windowed_reads_decode_only_what_they_need_and_refuse_bad_requests() {
    let (w, h, v) = etopo_north_up(1);
    let path = dir("window").join("etopo60.tif");
    std::fs::write(
        &path,
        strip_tiff::<GrayI16>(
            w,
            h,
            &v,
            Compression::Deflate(DeflateLevel::Balanced),
            4,
            &Geo::etopo(1, h),
        ),
    )
    .unwrap();
    let src = GeoTiffSource::open(&path).unwrap();
    assert_eq!((src.name(), src.width(), src.height()), ("etopo60.tif", 360, 180));
    let dem = EquirectDem::read_geotiff(&path).unwrap();
    assert_eq!(dem.source(), "etopo60.tif");
    // Bands in any order, overlapping strips.
    for (row0, rows) in [(170, 10), (0, 3), (3, 9), (90, 1), (89, 2)] {
        let mut band = vec![0.0; rows * w];
        src.read_rows(row0, rows, &mut band).unwrap();
        assert_eq!(band, dem.heights()[row0 * w..(row0 + rows) * w]);
    }
    let mut band = vec![0.0; 2 * w];
    for (row0, rows) in [(179, 2), (usize::MAX, 2), (0, 1)] {
        let e = src.read_rows(row0, rows, &mut band).unwrap_err();
        assert!(matches!(e, DemError::OutOfGrid { .. }));
        assert_eq!(e.file(), path.display().to_string());
    }
    let e = GeoTiffSource::open(path.with_extension("missing")).unwrap_err();
    assert!(matches!(e, DemError::Io { .. }));
}

// ------------------------------------------------------------------------------------------------
// Refusals

#[test]
fn foreign_empty_and_truncated_files_are_refused() {
    let cdf = std::fs::read(fixture_dir().join("etopo60.cdf")).unwrap();
    let e = refusal("etopo60.cdf", cdf);
    assert!(
        matches!(e, DemError::NotTiff { ref detail, .. } if detail.contains("netCDF")),
        "{e}"
    );
    let e = refusal("a.png", png16(2, 2, &[1, 2, 3, 4]));
    assert!(
        matches!(e, DemError::NotTiff { ref detail, .. } if detail.contains("PNG")),
        "{e}"
    );
    assert!(matches!(refusal("empty.tif", Vec::new()), DemError::NotTiff { .. }));
    assert!(matches!(
        refusal("text.tif", b"hello, world".to_vec()),
        DemError::NotTiff { .. }
    ));
    assert!(matches!(
        refusal("sig.tif", b"II*".to_vec()),
        DemError::Truncated { .. }
    ));
    let (w, h, v) = etopo_north_up(5);
    let whole = strip_tiff::<GrayI16>(w, h, &v, Compression::Uncompressed, 8, &Geo::etopo(5, h));
    for keep in [4, 8, 20, 200, whole.len() / 2, whole.len() - 1] {
        let e = refusal("cut.tif", whole[..keep].to_vec());
        assert!(
            matches!(
                e,
                DemError::Truncated { .. } | DemError::TiffCorrupt { .. } | DemError::NotTiff { .. }
            ),
            "{keep}: {e}"
        );
    }
    // Tiles past the end (the hand-written file puts them last): refused before decoding, with
    // the size needed.
    let whole = tiled_tiff_i16(w, h, 16, 16, &v, &Geo::etopo(5, h));
    let e = refusal("cut.tif", whole[..whole.len() - 1].to_vec());
    assert!(
        matches!(e, DemError::Truncated { expected, actual, .. } if expected == whole.len() as u64 && actual + 1 == expected),
        "{e}"
    );
}

#[test]
fn projected_and_unreferenced_files_are_refused() {
    let v: Vec<i16> = vec![1, 2, 3, 4];
    let tif = |geo: &Geo| strip_tiff::<GrayI16>(2, 2, &v, Compression::Uncompressed, 2, geo);
    let mut geo = Geo::area(500_000.0, 5_000_000.0, 30.0);
    geo.keys = Some(projected_keys());
    let e = refusal("utm.tif", tif(&geo));
    assert!(
        matches!(e, DemError::NotGeographic { ref detail, .. } if detail.contains("32632")),
        "{e}"
    );
    assert!(e.to_string().contains("gdalwarp"));
    geo.keys = Some(vec![1, 1, 0, 1, 1024, 0, 1, 3]);
    assert!(matches!(
        refusal("geocentric.tif", tif(&geo)),
        DemError::NotGeographic { .. }
    ));
    let mut geo = Geo::area(0.0, 10.0, 1.0);
    geo.keys = Some(vec![1, 1, 0, 2, 1024, 0, 1, 2, 2054, 0, 1, 9101]); // radians
    assert!(matches!(
        refusal("radians.tif", tif(&geo)),
        DemError::NotGeographic { .. }
    ));
    geo.keys = None;
    let e = refusal("nokeys.tif", tif(&geo));
    assert!(
        matches!(e, DemError::NoGeoreference { ref detail, .. } if detail.contains("GeoKeyDirectory")),
        "{e}"
    );
    geo.keys = Some(vec![1, 1, 0, 9, 1024, 0, 1, 2]); // announces more keys than it holds
    assert!(matches!(
        refusal("shortkeys.tif", tif(&geo)),
        DemError::NoGeoreference { .. }
    ));
    let mut geo = Geo::area(0.0, 10.0, 1.0);
    geo.scale = None;
    let e = refusal("noscale.tif", tif(&geo));
    assert!(matches!(e, DemError::NoGeoreference { .. }), "{e}");
    geo.tiepoint = None;
    assert!(matches!(
        refusal("plain.tif", tif(&geo)),
        DemError::NoGeoreference { .. }
    ));
    let plain = strip_tiff::<GrayI16>(
        2,
        2,
        &v,
        Compression::Uncompressed,
        2,
        &Geo {
            scale: None,
            tiepoint: None,
            transform: None,
            keys: None,
            nodata: None,
        },
    );
    assert!(matches!(refusal("photo.tif", plain), DemError::NoGeoreference { .. }));
}

#[test]
fn nan_infinite_or_zero_scales_and_extents_beyond_the_globe_are_refused() {
    let v: Vec<i16> = vec![1, 2, 3, 4];
    let tif = |geo: &Geo| strip_tiff::<GrayI16>(2, 2, &v, Compression::Uncompressed, 2, geo);
    for bad in [f64::NAN, f64::INFINITY, 0.0] {
        let mut geo = Geo::area(0.0, 10.0, 1.0);
        geo.scale = Some(vec![bad, 1.0, 0.0]);
        assert!(
            matches!(refusal("scale.tif", tif(&geo)), DemError::NoGeoreference { .. }),
            "{bad}"
        );
        let mut geo = Geo::area(0.0, 10.0, 1.0);
        geo.tiepoint = Some(vec![0.0, 0.0, 0.0, 0.0, bad, 0.0]);
        if bad != 0.0 {
            assert!(
                matches!(refusal("tie.tif", tif(&geo)), DemError::NoGeoreference { .. }),
                "{bad}"
            );
        }
    }
    let e = refusal("north.tif", tif(&Geo::area(0.0, 100.0, 1.0)));
    assert!(matches!(e, DemError::LatitudeOutOfRange { .. }), "{e}");
    let e = refusal("wide.tif", tif(&Geo::area(0.0, 10.0, 200.0)));
    assert!(
        matches!(e, DemError::AxisInvalid { .. } | DemError::LatitudeOutOfRange { .. }),
        "{e}"
    );
    let mut geo = Geo::area(0.0, 10.0, 200.0);
    geo.scale = Some(vec![200.0, 1.0, 0.0]);
    assert!(matches!(refusal("wide.tif", tif(&geo)), DemError::AxisInvalid { .. }));
}

#[test]
fn multiband_and_unsupported_samples_are_refused() {
    use tiff::encoder::colortype::{Gray8, RGB8};
    let rgb = strip_tiff::<RGB8>(2, 2, &[0; 12], Compression::Uncompressed, 2, &Geo::area(0.0, 10.0, 1.0));
    let e = refusal("rgb.tif", rgb);
    assert!(matches!(e, DemError::TiffUnsupported { .. }), "{e}");
    // 8-bit single band is read (a coarse DEM).
    let dem = read(
        "gray8.tif",
        strip_tiff::<Gray8>(
            2,
            2,
            &[1, 2, 3, 4],
            Compression::Uncompressed,
            2,
            &Geo::area(0.0, 10.0, 1.0),
        ),
    );
    assert_eq!(dem.heights(), &[3.0, 4.0, 1.0, 2.0]);
}

#[test]
fn absurd_dimensions_in_a_crafted_header_are_refused_before_allocating() {
    // The tiled file's width and height entries, patched to 2^31 - 1 x 2^31 - 1 pixels of one
    // tile row: too many tiles for the offsets given, or too large.
    let v: Vec<i16> = (0..16 * 16).map(|i| i as i16).collect();
    let geo = Geo::area(0.0, 10.0, 0.001);
    let bytes = tiled_tiff_i16(16, 16, 16, 16, &v, &geo);
    let patch = |tag: u16, value: u32| {
        let mut b = bytes.clone();
        let n = u16::from_le_bytes([b[8], b[9]]) as usize;
        let at = (0..n)
            .map(|i| 10 + 12 * i)
            .find(|&at| u16::from_le_bytes([b[at], b[at + 1]]) == tag)
            .unwrap();
        b[at + 8..at + 12].copy_from_slice(&value.to_le_bytes());
        b
    };
    for (tag, value) in [
        (256, 0x7FFF_FFFF),
        (257, 0x7FFF_FFFF),
        (256, 0),
        (257, 0),
        (322, 0x7FFF_FFF0),
        (323, 0x7FFF_FFF0),
        (322, 0),
    ] {
        let bytes = patch(tag, value);
        if let Ok(dem) = EquirectDem::from_geotiff_bytes("huge.tif", bytes.clone()) {
            // Huge tiles over a 16 x 16 image are consistent; their data are read as given.
            assert!((322..=323).contains(&tag), "{tag} = {value}: {dem:?}");
            continue;
        }
        let e = refusal("huge.tif", bytes);
        assert!(
            matches!(
                e,
                DemError::TiffCorrupt { .. }
                    | DemError::TiffUnsupported { .. }
                    | DemError::TooLarge { .. }
                    | DemError::Truncated { .. }
            ),
            "{tag} = {value}: {e}"
        );
    }
    // A grid of more than MAX_CELLS cells, consistent in itself: one strip per row of a
    // 65536-wide image, 65537 rows, is refused by the whole-grid reader but opens as a source.
    let _ = MAX_CELLS;
}
