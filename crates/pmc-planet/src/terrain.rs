//! Building a planet's terrain from its [`TerrainSpec`]: a preset, or an elevation model.

use pmc_density::presets::{self, Terrain};
use pmc_density::terrain::{ReliefError, TerrainSpec};
use pmc_geometry::Layout;

/// Why a terrain could not be built.
#[derive(Debug, thiserror::Error)]
pub enum TerrainError {
    /// The elevation model could not be opened or read (the message names the file).
    #[error(transparent)]
    Dem(#[from] pmc_dem::DemError),
    /// The elevation file is not the one the terrain was made from: its content digest differs.
    /// Fix: give the file the planet (or world) was made with, or make a new world for this one.
    #[error(
        "{path}: this elevation file's digest is {found}, but the planet was made from the file with digest {expected}; give that file, or start a new world for this one"
    )]
    DigestMismatch {
        /// The file opened.
        path: String,
        /// The digest the terrain records.
        expected: String,
        /// The digest of the file.
        found: String,
    },
    /// A height-field planet was asked of a terrain that is no elevation model (presets have
    /// caves and overhangs no height field can hold). Fix: give an elevation file, or mesh the
    /// preset volumetrically.
    #[error("only an elevation model can be meshed as a height field, not the preset {0}")]
    NotHeightfield(String),
    /// The patch layout of a height-field planet could not be made.
    #[error("the height-field layout: {0}")]
    Layout(#[from] pmc_geometry::LayoutError),
    /// The relief does not fit the layout's shell.
    #[error("{path}: {source}")]
    Relief {
        /// The elevation file.
        path: String,
        /// What does not fit.
        #[source]
        source: ReliefError,
    },
    /// A planet radius out of range.
    #[error(transparent)]
    Radius(#[from] pmc_density::presets::RadiusError),
    /// A radius was given with layout parameters: the radius picks the whole layout.
    #[error("a planet radius picks the whole layout: give either the radius or the layout parameters (n_c, n_t, d_b, l_d, d_c), not both")]
    RadiusWithLayout,
    /// A radius was given for an elevation model, whose file gives the body's radius.
    #[error("a radius does not apply to an elevation model: the elevation file gives the body's radius")]
    RadiusWithDem,
    /// A file path that is not valid UTF-8 (a planet records its elevation file's path as text).
    #[error("{0}: the path is not valid UTF-8; rename the file")]
    PathNotUtf8(String),
}

/// The terrain `spec` describes, built for `layout`. Presets never fail; an elevation model is
/// opened (its path as given, relative to the working directory), its digest checked against
/// the spec's, and its relief fitted into the layout's shell.
pub fn build_terrain(spec: &TerrainSpec, layout: &Layout) -> Result<Terrain, TerrainError> {
    match spec {
        TerrainSpec::Preset { kind, seed } => Ok(presets::build(*kind, *seed, layout)),
        TerrainSpec::Dem(dem) => pmc_dem::dem_terrain(dem, layout).map_err(|e| match e {
            pmc_dem::DemTerrainError::Dem(e) => TerrainError::Dem(e),
            pmc_dem::DemTerrainError::DigestMismatch { expected, found } => TerrainError::DigestMismatch {
                path: dem.path.clone(),
                expected,
                found,
            },
            pmc_dem::DemTerrainError::Relief(source) => TerrainError::Relief {
                path: dem.path.clone(),
                source,
            },
        }),
    }
}

/// The layout a terrain is made for when none is given: the preset's own
/// ([`PresetKind::default_layout`](presets::PresetKind::default_layout)), or for an elevation
/// model the layout chosen for its body's radius ([`presets::layout_for_radius`]).
pub fn default_layout(spec: &TerrainSpec) -> Result<Layout, TerrainError> {
    match spec {
        TerrainSpec::Preset { kind, .. } => Ok(kind.default_layout(None).expect("every preset has a default layout")),
        TerrainSpec::Dem(dem) => Ok(pmc_dem::dem_layout(dem)?),
    }
}

/// An elevation model's heights at lattice points, for the height-field mesher.
struct DemLattice(pmc_dem::DemHeights);

impl pmc_heightfield::LatticeHeights for DemLattice {
    fn height(&self, lattice: pmc_geometry::glam::IVec3, m: i32) -> f64 {
        self.0.height_at_lattice(lattice, m)
    }

    fn heights(&self, points: &[pmc_geometry::glam::IVec3], m: i32, out: &mut [f64]) {
        self.0.heights_at_lattice(points, m, out)
    }

    fn heights_on_grid(
        &self,
        grid: &pmc_geometry::FaceGrid,
        points: &[pmc_geometry::glam::IVec3],
        m: i32,
        out: &mut [f64],
    ) {
        self.0.heights_on_grid(grid, points, m, out)
    }
}

/// The terrain of the elevation model `spec` (on its own layout) and its height-field meshing
/// (with the patch layout).
pub(crate) fn heightfield_parts(
    spec: &TerrainSpec,
) -> Result<(Terrain, crate::heightfield::HeightfieldMode, Layout), TerrainError> {
    let TerrainSpec::Dem(dem) = spec else {
        return Err(TerrainError::NotHeightfield(spec.name()));
    };
    let layout = default_layout(spec)?;
    let terrain = build_terrain(spec, &layout)?;
    let cube = std::sync::Arc::new(pmc_dem::CubeDem::open(&dem.path)?);
    let (heights, vertical) = pmc_dem::dem_heights(cube, dem, &layout);
    let datum = terrain
        .sea_radius
        .unwrap_or_else(|| 0.5 * (layout.d_b() + layout.radius()));
    let (lo, hi) = pmc_dem::HeightField::bounds(&heights);
    let (mode, patch_layout) = crate::heightfield::HeightfieldMode::new(
        std::sync::Arc::new(DemLattice(heights)),
        datum,
        (lo * vertical, hi * vertical),
    )?;
    Ok((terrain, mode, patch_layout))
}
