//! A small software rasteriser that draws a planet's chunk meshes to a picture, for docs,
//! thumbnails and tests.
//!
//! [`render`] takes [`ChunkMesh`](pmc_mesh::ChunkMesh)es in the planet-centred world frame, a
//! [`Camera`] placed by latitude, longitude and distance, and [`RenderOptions`] (size, sun,
//! optional sea sphere, background), and returns an sRGB [`Image`] that can be written with
//! [`Image::write_png`]. Vertex transforms are `f64` (`origin + position`), triangles are
//! rasterised with perspective, back-face culling and a depth buffer at 2x2 samples per pixel,
//! shaded by vertex colour and a sun, under an optional translucent sea and a thin atmosphere.
//! Work is split over image bands with rayon.
//!
//! ```
//! use pmc_geometry::glam::DVec3;
//! use pmc_mesh::ChunkMesh;
//! use pmc_render::{render, Camera, RenderOptions};
//!
//! // One triangle facing +Z (counter-clockwise seen from +Z), 1000 m out.
//! let mut mesh = ChunkMesh { origin: DVec3::new(0.0, 0.0, 1000.0), ..ChunkMesh::default() };
//! mesh.positions = vec![[-300.0, -300.0, 0.0], [300.0, -300.0, 0.0], [0.0, 300.0, 0.0]];
//! mesh.normals = vec![[0.0, 0.0, 1.0]; 3];
//! mesh.colors = vec![[200, 120, 60, 255]; 3];
//! mesh.indices = vec![0, 1, 2];
//!
//! let opts = RenderOptions { width: 160, height: 100, ..RenderOptions::default() };
//! let image = render(&[mesh], &Camera::orbit(0.0, 0.0, 3000.0), &opts).unwrap();
//! assert_eq!(image.rgba.len(), 160 * 100 * 4);
//! assert!(image.foreground_fraction(opts.background) > 0.05);
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod camera;
mod coverage;
mod error;
mod image;
mod raster;

pub use camera::{Camera, DEFAULT_FOV_DEG};
pub use error::RenderError;
pub use image::Image;
pub use raster::render;

use pmc_geometry::glam::DVec3;

/// Largest accepted image width or height, pixels.
pub const MAX_DIMENSION: u32 = 16384;

/// What to draw besides the meshes, and at what size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels, 1..=[`MAX_DIMENSION`].
    pub width: u32,
    /// Image height in pixels, 1..=[`MAX_DIMENSION`].
    pub height: u32,
    /// Direction towards the sun in world coordinates (normalised by [`render`]; must be finite
    /// and non-zero).
    pub sun_dir: DVec3,
    /// Radius of the sea sphere in metres (planet-centred), or `None` for no sea.
    pub sea_radius: Option<f64>,
    /// sRGB colour of pixels where nothing is drawn.
    pub background: [u8; 3],
    /// Whether to draw a thin atmosphere around the limb (for planets with air).
    pub atmosphere: bool,
}

impl Default for RenderOptions {
    /// 1280x800, no sea, near-black space, and a sun at the upper left of a camera on longitude 0
    /// (`Camera::orbit(0.0, 0.0, d)` looks along -Z with +X to the right and +Y up), somewhat
    /// behind the viewer so most of the visible side is lit.
    fn default() -> Self {
        RenderOptions {
            width: 1280,
            height: 800,
            sun_dir: DVec3::new(-1.0, 0.8, 1.2).normalize(),
            sea_radius: None,
            background: [5, 6, 12],
            atmosphere: true,
        }
    }
}
