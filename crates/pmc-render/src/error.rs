//! Errors of rendering and of writing pictures.

use std::path::PathBuf;

use crate::MAX_DIMENSION;

/// Why a picture could not be made or written.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The image width or height is zero or above [`MAX_DIMENSION`].
    #[error("image size {width}x{height} is not valid: each side must be 1..={MAX_DIMENSION} pixels")]
    Size {
        /// The requested width in pixels.
        width: u32,
        /// The requested height in pixels.
        height: u32,
    },
    /// A camera value is not a finite number, the field of view is outside (0, 180) degrees, or
    /// the camera sits on the point it looks at.
    #[error("camera is not valid: {0}")]
    Camera(String),
    /// A render option is not usable (sun direction zero or not finite, sea radius not a
    /// positive finite number).
    #[error("render options are not valid: {0}")]
    Options(String),
    /// A mesh's index buffer is not a triangle list over its vertices.
    #[error("mesh {mesh} is not valid: {reason}")]
    Mesh {
        /// Position of the mesh in the slice given to [`render`](crate::render).
        mesh: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// Creating, writing or renaming the PNG file failed.
    #[error("cannot write PNG {}: {source}", path.display())]
    Io {
        /// The file that was to be written.
        path: PathBuf,
        /// The I/O failure.
        #[source]
        source: std::io::Error,
    },
    /// The PNG encoder refused the image (for example a pixel buffer of the wrong length).
    #[error("cannot encode PNG {}: {source}", path.display())]
    Png {
        /// The file that was to be written.
        path: PathBuf,
        /// The encoder's failure.
        #[source]
        source: png::EncodingError,
    },
}
