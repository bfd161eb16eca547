//! One 65 x 65 heightfield patch (`pmc_heightfield::generate_patch`: heights on the 67 x 67 grid,
//! positions, normals, stitched indices, keys and attributes into a reused `ChunkMesh`) on one
//! core, at Earth radius, level 14 (about 10 m between vertices), two sides stitched:
//!
//! - `sphere`: constant height, the cost of the mesher alone;
//! - `fbm8`: an 8-octave fBm of the direction (`pmc_density::noise::Fbm`), 4 km amplitude;
//! - `dem2049+fbm4`: a bilinear lookup into a 2049 x 2049 table addressed by the face coordinates
//!   of the cube point, plus 4 noise octaves, the cost of a DEM with noise detail (seed 003 Sec. 4.5-4.6).
//!
//! - `etopo-cube+detail`: the real thing, `pmc_dem::DemHeights::height_at_lattice` on the ETOPO60
//!   fixture imported at data level 10 (1025 x 1025 samples a face, as ETOPO5's default import):
//!   bicubic data through the tiled reader, relief weights, and the 10 detail octaves a level-14
//!   vertex gets (lattice 2^20 over data on 2^10; the finer ones are exactly zero there), through
//!   `heights_on_grid` as the height-field planet calls it.
//!
//! Seed 003 reports about 22 ms per patch for its sampling.
use criterion::{criterion_group, criterion_main, Criterion};
use pmc_density::noise::{Fbm, FbmParams};
use pmc_geometry::glam::IVec3;
use pmc_geometry::Face;
use pmc_heightfield::{generate_patch, lattice_direction, ConstantHeight, LatticeHeights, PatchKey, Side, Stitch};
use pmc_mesh::ChunkMesh;
use std::hint::black_box;

const RADIUS: f64 = 6.371e6;

struct FbmHeights(Fbm);

impl LatticeHeights for FbmHeights {
    fn height(&self, lattice: IVec3, m: i32) -> f64 {
        4000.0 * self.0.sample(lattice_direction(lattice, i64::from(m)))
    }
}

/// A 2049 x 2049 elevation table over a face's `(u, v)` square, bilinear, plus noise octaves.
struct DemHeights {
    table: Vec<f32>,
    noise: Fbm,
}

const DEM: usize = 2049;

impl DemHeights {
    fn new() -> Self {
        let table = (0..DEM * DEM)
            .map(|k| {
                let (x, y) = ((k % DEM) as f32, (k / DEM) as f32);
                3000.0 * (x * 0.013).sin() * (y * 0.021).cos() + 0.5 * ((x * y) % 97.0)
            })
            .collect();
        DemHeights {
            table,
            noise: Fbm::new(5, FbmParams::new(4000.0, 4)),
        }
    }
}

impl LatticeHeights for DemHeights {
    fn height(&self, lattice: IVec3, m: i32) -> f64 {
        // Face coordinates of the cube point: the two components that are not +-m.
        let c = lattice.as_dvec3() / f64::from(m);
        let a = c.abs();
        let (s, t) = if a.x >= a.y && a.x >= a.z {
            (c.y, c.z)
        } else if a.y >= a.z {
            (c.z, c.x)
        } else {
            (c.x, c.y)
        };
        let scale = (DEM - 1) as f64 * 0.5;
        let (x, y) = ((s + 1.0) * scale, (t + 1.0) * scale);
        let (x0, y0) = ((x.floor() as usize).min(DEM - 2), (y.floor() as usize).min(DEM - 2));
        let (fx, fy) = (x - x0 as f64, y - y0 as f64);
        let at = |i: usize, j: usize| f64::from(self.table[j * DEM + i]);
        let h0 = at(x0, y0) + (at(x0 + 1, y0) - at(x0, y0)) * fx;
        let h1 = at(x0, y0 + 1) + (at(x0 + 1, y0 + 1) - at(x0, y0 + 1)) * fx;
        h0 + (h1 - h0) * fy + 30.0 * self.noise.sample(lattice_direction(lattice, i64::from(m)))
    }
}

/// A real elevation model's heights at lattice points.
struct CubeHeights(pmc_dem::DemHeights);

impl LatticeHeights for CubeHeights {
    fn height(&self, lattice: IVec3, m: i32) -> f64 {
        self.0.height_at_lattice(lattice, m)
    }

    fn heights(&self, points: &[IVec3], m: i32, out: &mut [f64]) {
        self.0.heights_at_lattice(points, m, out)
    }

    fn heights_on_grid(&self, grid: &pmc_geometry::FaceGrid, points: &[IVec3], m: i32, out: &mut [f64]) {
        self.0.heights_on_grid(grid, points, m, out)
    }
}

fn etopo_cube() -> CubeHeights {
    use pmc_dem::{import_cube, EquirectDem, ImportOptions};
    let dir = std::env::temp_dir().join(format!("pmc-bench-heightfield-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../pmc-dem/tests/fixtures/etopo60.cdf");
    let dem = EquirectDem::read_netcdf(&src, None).unwrap();
    let out = dir.join("etopo.pmcdem");
    let options = ImportOptions {
        level: Some(10),
        ..ImportOptions::default()
    };
    let report = import_cube(&dem, &out, &options, &|_, _| {}).unwrap();
    let spec = pmc_density::terrain::DemSpec {
        path: out.to_str().unwrap().into(),
        digest: report.digest,
        interpolation: pmc_density::terrain::Interpolation::Bicubic,
        seed: 7,
    };
    let layout = pmc_density::presets::layout_for_radius(RADIUS).unwrap();
    let cube = std::sync::Arc::new(pmc_dem::CubeDem::open(&out).unwrap());
    CubeHeights(pmc_dem::dem_heights(cube, &spec, &layout).0)
}

fn heightfield(c: &mut Criterion) {
    let level = 14;
    let n = 1u32 << level;
    let key = PatchKey::new(Face::South, level, n / 2 + 37, n / 3).unwrap();
    let stitch = Stitch::NONE.with_side(Side::MinU).with_side(Side::MaxV);
    let mut g = c.benchmark_group("heightfield");
    let mut mesh = ChunkMesh::default();
    let mut bench = |name: &str, heights: &dyn LatticeHeights| {
        g.bench_function(format!("patch65/{name}"), |b| {
            b.iter(|| {
                generate_patch(heights, RADIUS, black_box(key), stitch, &mut mesh).unwrap();
                black_box(mesh.indices.len())
            })
        });
    };
    bench("sphere", &ConstantHeight(0.0));
    bench("fbm8", &FbmHeights(Fbm::new(7, FbmParams::new(900.0, 8))));
    bench("dem2049+fbm4", &DemHeights::new());
    bench("etopo-cube+detail", &etopo_cube());
    g.finish();
}

criterion_group!(benches, heightfield);
criterion_main!(benches);
