//! 16-bit grayscale PNG files written here with the `png` encoder: values, extents, the
//! north-up flip, nodata, wrapping, and every refusal naming the file.

use crate::common::*;
use pmc_dem::{DemError, EquirectDem, PngExtent};

fn refusal(name: &str, bytes: &[u8], extent: &PngExtent) -> DemError {
    let e = EquirectDem::from_png16_bytes(name, bytes, extent).unwrap_err();
    assert_eq!(e.file(), name);
    assert!(e.to_string().starts_with(&format!("{name}: ")), "{e}");
    e
}

/// ETOPO60 every 5 degrees as `value = height + 11000`, rows from the north.
fn etopo_png() -> (usize, usize, Vec<u16>, Vec<u8>) {
    let (w, h, v) = etopo_north_up(5);
    let u: Vec<u16> = v.iter().map(|&x| (i32::from(x) + 11_000) as u16).collect();
    let bytes = png16(w, h, &u);
    (w, h, u, bytes)
}

#[test]
fn heights_are_value_times_scale_plus_offset_rows_from_the_south() {
    let (w, h, u, bytes) = etopo_png();
    let extent = PngExtent {
        west: 20.0,
        south: -90.0,
        east: 380.0,
        north: 90.0,
        scale: 1.0,
        offset: -11_000.0,
        nodata: None,
        cell_centres: true,
    };
    let dem = EquirectDem::from_png16_bytes("etopo.png", &bytes, &extent).unwrap();
    assert_eq!(
        (dem.width(), dem.height(), dem.variable(), dem.source()),
        (w, h, "gray", "etopo.png")
    );
    assert_eq!(
        (dem.lon_first(), dem.lon_step(), dem.lat_first(), dem.lat_step()),
        (22.5, 5.0, -87.5, 5.0)
    );
    assert!(dem.wraps_in_longitude());
    for r in 0..h {
        for c in 0..w {
            assert_eq!(dem.heights()[r * w + c], f32::from(u[(h - 1 - r) * w + c]) - 11_000.0);
        }
    }
    // Against the netCDF grid at the same points, to the metre.
    let nc = etopo60();
    assert_eq!(
        dem.value(3, 4).unwrap(),
        nc.value(3 * 5 + 2, 4 * 5 + 2).unwrap().trunc()
    );
    // Read from a file.
    let path = dir("png").join("etopo.png");
    std::fs::write(&path, &bytes).unwrap();
    let from_file = EquirectDem::read_png16(&path, &extent).unwrap();
    assert_eq!((from_file.heights(), from_file.source()), (dem.heights(), "etopo.png"));
}

#[test]
fn nodes_nodata_scale_and_regional_extents() {
    // Nodes at 0, 90, ..., 360 (the last repeating the first) and -90, 0, 90.
    let u: Vec<u16> = (0..15).collect();
    let mut extent = PngExtent {
        west: 0.0,
        south: -90.0,
        east: 360.0,
        north: 90.0,
        scale: 0.5,
        offset: -1.0,
        nodata: Some(7),
        cell_centres: false,
    };
    let dem = EquirectDem::from_png16_bytes("nodes.png", &png16(5, 3, &u), &extent).unwrap();
    assert_eq!((dem.width(), dem.height(), dem.wraps_in_longitude()), (4, 3, true));
    assert_eq!((dem.lon_first(), dem.lat_first(), dem.lat_step()), (0.0, -90.0, 90.0));
    assert_eq!(dem.value(0, 0), Some(4.0)); // value 10 from the bottom-left
    assert_eq!(dem.value(2, 1), None); // value 7
    assert_eq!(dem.stats().missing, 1);
    // 200 .. 240: east of the antimeridian.
    extent.west = 200.0;
    extent.east = 240.0;
    let dem = EquirectDem::from_png16_bytes("east.png", &png16(5, 3, &u), &extent).unwrap();
    assert_eq!(
        (dem.width(), dem.lon_first(), dem.lon_step(), dem.wraps_in_longitude()),
        (5, -160.0, 10.0, false)
    );
    extent.nodata = Some(3);
    let e = refusal(
        "all-nd.png",
        &png16(1, 2, &[3, 3]),
        &PngExtent {
            cell_centres: true,
            ..extent
        },
    );
    assert!(matches!(e, DemError::NoValidData { .. }), "{e}");
    let e = refusal("one-col.png", &png16(1, 2, &[3, 4]), &extent);
    assert!(matches!(e, DemError::AxisInvalid { .. }), "{e}");
    assert_eq!(PngExtent::global(1.0, 0.0).east, 180.0);
}

#[test]
fn wrong_extents_are_refused_before_the_file_is_read() {
    let (_, _, _, bytes) = etopo_png();
    let good = PngExtent::global(1.0, -11_000.0);
    let cases: [(&str, PngExtent); 11] = [
        (
            "nan-scale",
            PngExtent {
                scale: f64::NAN,
                ..good
            },
        ),
        (
            "inf-scale",
            PngExtent {
                scale: f64::INFINITY,
                ..good
            },
        ),
        ("zero-scale", PngExtent { scale: 0.0, ..good }),
        (
            "inf-offset",
            PngExtent {
                offset: f64::NEG_INFINITY,
                ..good
            },
        ),
        ("nan-west", PngExtent { west: f64::NAN, ..good }),
        (
            "west-east",
            PngExtent {
                west: 10.0,
                east: 10.0,
                ..good
            },
        ),
        (
            "reversed",
            PngExtent {
                west: 10.0,
                east: -10.0,
                ..good
            },
        ),
        (
            "too-wide",
            PngExtent {
                west: -180.0,
                east: 181.0,
                ..good
            },
        ),
        (
            "south-north",
            PngExtent {
                south: 10.0,
                north: 0.0,
                ..good
            },
        ),
        ("past-pole", PngExtent { north: 91.0, ..good }),
        ("below-pole", PngExtent { south: -90.5, ..good }),
    ];
    for (name, extent) in cases {
        let e = refusal(name, &bytes, &extent);
        assert!(matches!(e, DemError::InvalidExtent { .. }), "{name}: {e}");
    }
    // Checked before the file is opened.
    let e = EquirectDem::read_png16(
        "/nonexistent.png",
        &PngExtent {
            scale: f64::NAN,
            ..good
        },
    )
    .unwrap_err();
    assert!(matches!(e, DemError::InvalidExtent { .. }));
    let e = EquirectDem::read_png16("/nonexistent.png", &good).unwrap_err();
    assert!(matches!(e, DemError::Io { .. }));
}

#[test]
fn eight_bit_colour_foreign_and_truncated_files_are_refused() {
    let extent = PngExtent::global(1.0, 0.0);
    let gray8 = png(2, 2, png::ColorType::Grayscale, png::BitDepth::Eight, &[1, 2, 3, 4]);
    let e = refusal("gray8.png", &gray8, &extent);
    assert!(
        matches!(e, DemError::PngUnsupported { ref found, .. } if found.contains("8-bit Grayscale")),
        "{e}"
    );
    let rgb16 = png(1, 1, png::ColorType::Rgb, png::BitDepth::Sixteen, &[0; 6]);
    let e = refusal("rgb16.png", &rgb16, &extent);
    assert!(
        matches!(e, DemError::PngUnsupported { ref found, .. } if found.contains("16-bit Rgb")),
        "{e}"
    );
    let rgb8 = png(1, 1, png::ColorType::Rgb, png::BitDepth::Eight, &[0; 3]);
    assert!(matches!(
        refusal("rgb8.png", &rgb8, &extent),
        DemError::PngUnsupported { .. }
    ));
    let cdf = std::fs::read(fixture_dir().join("etopo60.cdf")).unwrap();
    let e = refusal("etopo60.cdf", &cdf, &extent);
    assert!(
        matches!(e, DemError::NotPng { ref detail, .. } if detail.contains("netCDF")),
        "{e}"
    );
    assert!(matches!(refusal("empty.png", &[], &extent), DemError::NotPng { .. }));
    assert!(matches!(
        refusal("sig.png", b"\x89PN", &extent),
        DemError::Truncated { .. }
    ));
    let (_, _, _, bytes) = etopo_png();
    for keep in [8, 20, 40, 100, bytes.len() / 2, bytes.len() - 40] {
        let e = refusal("cut.png", &bytes[..keep], &extent);
        assert!(
            matches!(e, DemError::Truncated { .. } | DemError::PngCorrupt { .. }),
            "{keep}: {e}"
        );
    }
    // Only the closing IEND chunk cut: every pixel is there, and read.
    let whole = EquirectDem::from_png16_bytes("whole.png", &bytes, &extent).unwrap();
    let cut = EquirectDem::from_png16_bytes("cut.png", &bytes[..bytes.len() - 1], &extent).unwrap();
    assert_eq!(cut.heights(), whole.heights());
    // A damaged checksum.
    let mut bad = bytes.clone();
    bad[30] ^= 0xFF;
    assert!(matches!(refusal("crc.png", &bad, &extent), DemError::PngCorrupt { .. }));
}

#[test]
fn absurd_dimensions_in_a_crafted_header_are_refused_before_allocating() {
    let (_, _, _, bytes) = etopo_png();
    // IHDR: width at 16..20, height at 20..24, its CRC at 29..33 (recomputed).
    for (w, h) in [(0x7FFF_FFFFu32, 0x7FFF_FFFFu32), (1 << 20, 1 << 20), (0, 5)] {
        let mut b = bytes.clone();
        b[16..20].copy_from_slice(&w.to_be_bytes());
        b[20..24].copy_from_slice(&h.to_be_bytes());
        let crc = crc32(&b[12..29]);
        b[29..33].copy_from_slice(&crc.to_be_bytes());
        let e = refusal("huge.png", &b, &PngExtent::global(1.0, 0.0));
        assert!(
            matches!(e, DemError::TooLarge { .. } | DemError::PngCorrupt { .. }),
            "{w} x {h}: {e}"
        );
    }
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A grid of heights from memory (the Python package's `pmc.dem.import_array`): the same grid as
/// the PNG's, rows given from the north or from the south, gives the same heights as the PNG.
#[test]
fn heights_from_memory_match_the_same_grid_read_from_a_png() {
    let (w, h, u, bytes) = etopo_png();
    let extent = PngExtent {
        west: 20.0,
        south: -90.0,
        east: 380.0,
        north: 90.0,
        scale: 1.0,
        offset: -11_000.0,
        nodata: None,
        cell_centres: true,
    };
    let png = EquirectDem::from_png16_bytes("etopo.png", &bytes, &extent).unwrap();
    let north_first: Vec<f32> = u.iter().map(|&v| f32::from(v) - 11_000.0).collect();
    let a = EquirectDem::from_heights("grid", w, h, true, &north_first, &extent, None).unwrap();
    let south_first: Vec<f32> = north_first.chunks(w).rev().flatten().copied().collect();
    let b = EquirectDem::from_heights("grid", w, h, false, &south_first, &extent, None).unwrap();
    for dem in [&a, &b] {
        assert_eq!((dem.width(), dem.height()), (png.width(), png.height()));
        assert_eq!(dem.heights(), png.heights());
        assert_eq!((dem.lon_first(), dem.lat_first()), (png.lon_first(), png.lat_first()));
    }
    assert_eq!(a.source(), "grid");
}

#[test]
fn heights_from_memory_mark_nodata_and_refuse_bad_grids() {
    let extent = PngExtent::global(1.0, 0.0);
    let mut v = vec![100.0f32; 8 * 4];
    v[3] = -9999.0;
    v[5] = f32::INFINITY;
    let dem = EquirectDem::from_heights("g", 8, 4, true, &v, &extent, Some(-9999.0)).unwrap();
    assert_eq!(dem.heights().iter().filter(|h| h.is_nan()).count(), 2);
    let short = EquirectDem::from_heights("g", 8, 4, true, &v[..31], &extent, None).unwrap_err();
    assert!(
        matches!(short, DemError::InvalidExtent { .. }) && short.to_string().contains("holds 31"),
        "{short}"
    );
    let none = EquirectDem::from_heights("g", 8, 4, true, &[f32::NAN; 32], &extent, None).unwrap_err();
    assert!(matches!(none, DemError::NoValidData { .. }), "{none}");
    let bad = PngExtent {
        west: 10.0,
        east: 0.0,
        ..extent
    };
    let e = EquirectDem::from_heights("g", 8, 4, true, &v, &bad, None).unwrap_err();
    assert!(
        e.to_string().starts_with("g: ") && e.to_string().contains("west"),
        "{e}"
    );
}
