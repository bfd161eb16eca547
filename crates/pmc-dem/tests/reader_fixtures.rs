//! The GeoTIFF and PNG fixtures that seed the fuzzer (`src/fuzz.rs`) are built here from the
//! ETOPO60 fixture: every 5 degrees (72 x 36 pixels), as whole metres.
//!
//! Rebuild them with `PMC_WRITE_FIXTURES=1 cargo test -p pmc-dem --test dem reader_fixtures::`;
//! otherwise this test checks that the committed files are what the builders write.

use crate::common::*;
use pmc_dem::fuzz::{PNG_EXTENT, SEED_FILES};
use pmc_dem::{EquirectDem, EquirectSource, GeoTiffSource};
use tiff::encoder::colortype::{Gray32Float, GrayI16};
use tiff::encoder::{Compression, DeflateLevel};

fn built() -> Vec<(&'static str, Vec<u8>)> {
    let (w, h, v) = etopo_north_up(5);
    let geo = Geo::etopo(5, h).nodata("-32768");
    let f: Vec<f32> = v.iter().map(|&x| f32::from(x)).collect();
    let u: Vec<u16> = v.iter().map(|&x| (i32::from(x) + 11_000) as u16).collect();
    vec![
        (
            SEED_FILES[1],
            strip_tiff::<GrayI16>(w, h, &v, Compression::Deflate(DeflateLevel::Best), 8, &geo),
        ),
        (
            SEED_FILES[2],
            strip_tiff::<Gray32Float>(w, h, &f, Compression::Lzw, 8, &geo),
        ),
        (SEED_FILES[3], tiled_tiff_i16(w, h, 16, 16, &v, &geo)),
        (SEED_FILES[4], png16(w, h, &u)),
    ]
}

#[test]
fn committed_seed_files_are_what_the_builders_write() {
    for (name, bytes) in built() {
        let path = fixture_dir().join(name);
        if std::env::var_os("PMC_WRITE_FIXTURES").is_some() {
            std::fs::write(&path, &bytes).unwrap();
        }
        assert_eq!(std::fs::read(&path).unwrap(), bytes, "{name} differs from its builder");
    }
}

#[test]
fn the_seed_files_read_as_the_same_grid() {
    let dir = fixture_dir();
    let tif = EquirectDem::read_geotiff(dir.join(SEED_FILES[1])).unwrap();
    assert_eq!(
        (tif.width(), tif.height(), tif.lon_first(), tif.lat_first()),
        (72, 36, 22.5, -87.5)
    );
    for name in &SEED_FILES[2..4] {
        assert_eq!(
            EquirectDem::read_geotiff(dir.join(name)).unwrap().heights(),
            tif.heights(),
            "{name}"
        );
    }
    let src = GeoTiffSource::open(dir.join(SEED_FILES[3])).unwrap();
    assert!(src.is_tiled() && src.wraps_in_longitude());
    let png = EquirectDem::read_png16(dir.join(SEED_FILES[4]), &PNG_EXTENT).unwrap();
    assert_eq!(png.heights(), tif.heights());
    assert_eq!((png.lon_first(), png.lat_first()), (tif.lon_first(), tif.lat_first()));
}
