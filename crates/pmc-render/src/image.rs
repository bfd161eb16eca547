//! The rendered picture and its PNG output.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::RenderError;

/// An 8-bit sRGB RGBA picture, rows top to bottom, pixels left to right.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` bytes: red, green, blue, alpha (alpha is 255 for rendered pictures).
    pub rgba: Vec<u8>,
}

impl Image {
    /// The RGBA value of pixel (`x`, `y`), `x` from the left, `y` from the top.
    ///
    /// # Panics
    /// If the pixel is outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 4] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {}x{}",
            self.width,
            self.height
        );
        let i = 4 * (y as usize * self.width as usize + x as usize);
        [self.rgba[i], self.rgba[i + 1], self.rgba[i + 2], self.rgba[i + 3]]
    }

    /// Share of pixels (0 to 1) whose colour differs from `background` (alpha ignored). 0 for an
    /// empty image.
    pub fn foreground_fraction(&self, background: [u8; 3]) -> f64 {
        let total = self.rgba.len() / 4;
        if total == 0 {
            return 0.0;
        }
        let differ = self.rgba.chunks_exact(4).filter(|p| p[..3] != background).count();
        differ as f64 / total as f64
    }

    /// Writes the picture as an 8-bit RGBA PNG (tagged sRGB) to `path`.
    ///
    /// The data goes to a temporary file in the same folder that is then renamed over `path`, so
    /// a reader never sees a half-written file. Errors name the path.
    pub fn write_png(&self, path: impl AsRef<Path>) -> Result<(), RenderError> {
        let path = path.as_ref();
        let file_name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "image".into());
        let temp = path.with_file_name(format!(".{file_name}.{}.tmp", std::process::id()));
        let result = self.write_png_to(path, &temp).and_then(|()| {
            std::fs::rename(&temp, path).map_err(|source| RenderError::Io {
                path: path.to_path_buf(),
                source,
            })
        });
        if result.is_err() {
            let _ = std::fs::remove_file(&temp);
        }
        result
    }

    fn write_png_to(&self, path: &Path, temp: &Path) -> Result<(), RenderError> {
        let io = |source| RenderError::Io {
            path: path.to_path_buf(),
            source,
        };
        let png_err = |source| RenderError::Png {
            path: PathBuf::from(path),
            source,
        };
        let mut out = BufWriter::new(File::create(temp).map_err(io)?);
        {
            let mut encoder = png::Encoder::new(&mut out, self.width, self.height);
            encoder.set_color(png::ColorType::Rgba);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            let mut writer = encoder.write_header().map_err(png_err)?;
            writer.write_image_data(&self.rgba).map_err(png_err)?;
            writer.finish().map_err(png_err)?;
        }
        out.flush().map_err(io)?;
        let file = out.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        Ok(())
    }
}
