//! An elevation model as a planet's terrain: the cube-face file as a [`HeightField`] under the
//! volumetric terrain of `pmc_density` (caves and rock under its land, meshed by marching cubes).

use crate::cube::{CubeDem, DetailNoise};
use crate::error::DemError;
use pmc_density::presets::{layout_for_radius, Terrain};
use pmc_density::terrain::{heightfield_terrain, DemSpec, HeightField, Interpolation, ReliefError, TerrainSpec};
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use std::sync::Arc;

/// Why an elevation-model terrain could not be built.
#[derive(Debug, thiserror::Error)]
pub enum DemTerrainError {
    /// The file could not be opened or read.
    #[error(transparent)]
    Dem(#[from] DemError),
    /// The file's digest is not the one the terrain records.
    #[error("the file's digest is {found}, not {expected}")]
    DigestMismatch {
        /// The digest the terrain records.
        expected: String,
        /// The file's digest.
        found: String,
    },
    /// The relief does not fit the layout.
    #[error(transparent)]
    Relief(#[from] ReliefError),
}

/// The heights of a cube-face elevation model along any direction: interpolated data plus detail
/// noise down to `finest` metres (zero at every data sample).
pub struct DemHeights {
    dem: Arc<CubeDem>,
    interpolation: Interpolation,
    detail: DetailNoise,
    finest: f64,
    bounds: (f64, f64),
}

impl DemHeights {
    /// The heights of `dem` interpolated by `interpolation`, with `detail` down to wavelengths of
    /// `finest` metres.
    pub fn new(dem: Arc<CubeDem>, interpolation: Interpolation, detail: DetailNoise, finest: f64) -> DemHeights {
        let bounds = dem.height_bounds_with(&detail);
        DemHeights {
            dem,
            interpolation,
            detail,
            finest,
            bounds,
        }
    }

    /// The elevation model.
    pub fn dem(&self) -> &Arc<CubeDem> {
        &self.dem
    }

    /// The height at the canonical lattice point `lattice` of resolution `m` (see
    /// [`CubeDem::height_at_lattice`]): exact at the data's samples, with the detail octaves coarser
    /// than the point's spacing. A pure, scale-invariant function of the point: what a
    /// height-field mesher needs of its heights.
    pub fn height_at_lattice(&self, lattice: pmc_geometry::glam::IVec3, m: i32) -> f64 {
        self.dem.height_at_lattice(lattice, m, self.interpolation, &self.detail)
    }

    /// [`DemHeights::height_at_lattice`] of many points of one resolution, with the same bits
    /// (see [`CubeDem::heights_at_lattice`]).
    pub fn heights_at_lattice(&self, points: &[pmc_geometry::glam::IVec3], m: i32, out: &mut [f64]) {
        self.dem
            .heights_at_lattice(points, m, self.interpolation, &self.detail, out)
    }

    /// [`DemHeights::heights_at_lattice`] of the entries of a face grid, with the same bits (see
    /// [`CubeDem::heights_on_grid`]).
    pub fn heights_on_grid(
        &self,
        grid: &pmc_geometry::FaceGrid,
        points: &[pmc_geometry::glam::IVec3],
        m: i32,
        out: &mut [f64],
    ) {
        self.dem
            .heights_on_grid(grid, points, m, self.interpolation, &self.detail, out)
    }
}

impl HeightField for DemHeights {
    fn height(&self, dir: DVec3) -> f64 {
        self.dem.height(dir, self.interpolation, &self.detail, self.finest)
    }
    fn bounds(&self) -> (f64, f64) {
        self.bounds
    }
}

/// The sample of an elevation file nearest to a direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NearestSample {
    /// Latitude of the sample, degrees.
    pub lat: f64,
    /// Longitude of the sample, degrees.
    pub lon: f64,
    /// Its value, metres above the datum.
    pub value: f32,
    /// Distance along the body's surface from the direction asked to the sample, metres.
    pub distance: f64,
}

/// The data sample of `dem` nearest to the unit direction `dir`: in a version 2 file the source
/// sample nearest in column and row; in a version 1 file the finest-level face sample nearest on
/// the face `dir` projects onto.
pub fn nearest_sample(dem: &CubeDem, dir: DVec3) -> Result<NearestSample, DemError> {
    let bad = || DemError::OutOfGrid {
        file: dem.path().to_string(),
        detail: format!("no sample near the direction {dir}"),
    };
    if dem.keeps_source() {
        let (c, r, lat, lon) = dem.nearest_source_sample(dir).ok_or_else(bad)?;
        let value = dem.source_sample(c, r)?;
        let at = pmc_geometry::LatLon::new(lat.clamp(-90.0, 90.0), lon).map_err(|_| bad())?;
        return Ok(NearestSample {
            lat: at.lat,
            lon: at.lon,
            value,
            distance: at.to_unit().angle_between(dir.normalize()) * dem.radius(),
        });
    }
    let (face, u, v) = pmc_geometry::sphere_to_face_uv(dir).ok_or_else(bad)?;
    let n = f64::from(1u32 << dem.data_level());
    let index = |x: f64| ((x + 1.0) * 0.5 * n).round().clamp(0.0, n) as u32;
    let (i, j) = (index(u), index(v));
    let value = dem.sample(0, face, i, j)?;
    let at = pmc_geometry::face_uv_to_sphere(face, 2.0 * f64::from(i) / n - 1.0, 2.0 * f64::from(j) / n - 1.0);
    let ll = pmc_geometry::LatLon::from_point(at).ok_or_else(bad)?;
    Ok(NearestSample {
        lat: ll.lat,
        lon: ll.lon,
        value,
        distance: at.angle_between(dir.normalize()) * dem.radius(),
    })
}

/// The layout a planet of the elevation file `spec` names is made for: the one chosen for its
/// body's radius ([`layout_for_radius`]; for the Earth, 1 m voxels and the sea in the middle of a
/// 32 km shell).
pub fn dem_layout(spec: &DemSpec) -> Result<Layout, DemError> {
    let dem = CubeDem::open(&spec.path)?;
    layout_for_radius(dem.radius()).map_err(|e| DemError::OutOfGrid {
        file: spec.path.clone(),
        detail: format!("the body radius {} m has no layout: {e}", dem.radius()),
    })
}

/// The volumetric terrain of the elevation file `spec` names, on `layout`: the file is opened,
/// its digest checked against the spec's, heights scaled by the layout's sea radius over the
/// body's (1 on the layout of [`dem_layout`]), detail noise below the data's resolution down to
/// two voxels across, caves and rock bumps under the land.
pub fn dem_terrain(spec: &DemSpec, layout: &Layout) -> Result<Terrain, DemTerrainError> {
    let dem = Arc::new(CubeDem::open(&spec.path)?);
    if dem.digest() != spec.digest {
        return Err(DemTerrainError::DigestMismatch {
            expected: spec.digest.clone(),
            found: dem.digest().to_string(),
        });
    }
    let (heights, vertical) = dem_heights(dem, spec, layout);
    Ok(heightfield_terrain(
        Arc::new(heights),
        TerrainSpec::Dem(spec.clone()),
        layout,
        vertical,
    )?)
}

/// The heights a planet of `spec` on `layout` uses (in the body's metres) and the vertical scale
/// from them to the layout's metres (its sea radius over the body's radius): detail noise from
/// the spec's seed, down to wavelengths of two voxels across (finer would alias).
pub fn dem_heights(dem: Arc<CubeDem>, spec: &DemSpec, layout: &Layout) -> (DemHeights, f64) {
    let sea = 0.5 * (layout.d_b() + layout.radius());
    let vertical = sea / dem.radius();
    let tile = std::f64::consts::FRAC_PI_2 * layout.radius() / layout.face_tiles() as f64;
    let finest = 2.0 * tile / vertical;
    let detail = DetailNoise {
        seed: spec.seed,
        ..DetailNoise::default()
    };
    (DemHeights::new(dem, spec.interpolation, detail, finest), vertical)
}
