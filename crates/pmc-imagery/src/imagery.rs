//! An equirectangular RGB image over an extent: its pixels, colour lookup, smaller levels and
//! PNG encoding.

use crate::{Extent, ImageryError};
use sha2::{Digest, Sha256};

/// Most pixels imagery may hold (2^27: 16384 x 8192, 384 MiB of RGB).
pub const MAX_PIXELS: u64 = 1 << 27;

/// Longest side, in pixels, imagery may have.
pub const MAX_SIDE: u32 = 1 << 16;

/// The pixel format code of 8-bit sRGB-encoded RGB (the only one of `.pmcimg` version 1).
pub(crate) const FORMAT_RGB8: u8 = 1;

/// An equirectangular colour image over an [`Extent`]: `width x height` pixels of 8-bit RGB,
/// sRGB-encoded, row 0 the northernmost, column 0 the westernmost. Pixel `(col, row)` covers
/// longitudes `west + col dx .. west + (col + 1) dx` and latitudes `north - (row + 1) dy ..
/// north - row dy`, `dx = (east - west) / width`, `dy = (north - south) / height`; its colour
/// lies at the cell's centre.
///
/// Its content digest (SHA-256, 64 lower-case hex digits) identifies the pixels and the extent,
/// whatever file they came from (see `docs/specs/pmcimg-v1.md`).
///
/// ```
/// use pmc_imagery::{Extent, Imagery};
///
/// // Two pixels round the globe: the west half red, the east half blue.
/// let img = Imagery::new(2, 1, Extent::GLOBAL, vec![255, 0, 0, 0, 0, 255])?;
/// assert_eq!(img.color_at(0.0, -90.0), Some([255, 0, 0])); // the centre of the red pixel
/// assert_eq!(img.color_at(45.0, 0.0), Some([128, 0, 128])); // halfway between the centres
/// assert_eq!(img.color_at(0.0, 180.0), Some([128, 0, 128])); // wraps across the antimeridian
/// # Ok::<(), pmc_imagery::ImageryError>(())
/// ```
#[derive(Clone, PartialEq)]
pub struct Imagery {
    width: u32,
    height: u32,
    extent: Extent,
    pixels: Vec<u8>,
    digest: String,
}

impl std::fmt::Debug for Imagery {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Imagery")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("extent", &self.extent)
            .field("digest", &self.digest)
            .finish_non_exhaustive()
    }
}

/// Checks a size against [`MAX_PIXELS`] and [`MAX_SIDE`] (and refuses an empty image).
pub(crate) fn check_size(file: &str, width: u64, height: u64) -> Result<(), ImageryError> {
    if width == 0 || height == 0 {
        return Err(ImageryError::Corrupt {
            file: file.to_owned(),
            detail: format!("the image is {width} x {height} pixels"),
        });
    }
    if width.saturating_mul(height) > MAX_PIXELS || width > u64::from(MAX_SIDE) || height > u64::from(MAX_SIDE) {
        return Err(ImageryError::TooLarge {
            file: file.to_owned(),
            width,
            height,
            max_pixels: MAX_PIXELS,
            max_side: u64::from(MAX_SIDE),
        });
    }
    Ok(())
}

/// The content digest of imagery (see `docs/specs/pmcimg-v1.md`).
pub(crate) fn content_digest(width: u32, height: u32, extent: &Extent, pixels: &[u8]) -> String {
    let mut h = Sha256::new();
    h.update(b"pmcimg-v1");
    h.update(width.to_le_bytes());
    h.update(height.to_le_bytes());
    h.update([FORMAT_RGB8]);
    for v in extent.to_array() {
        h.update(v.to_le_bytes());
    }
    h.update(pixels);
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

impl Imagery {
    /// Imagery of `width x height` pixels over `extent`; `pixels` holds `width * height * 3`
    /// bytes of RGB, row by row from the north.
    ///
    /// Errors: [`ImageryError::Corrupt`] for an empty image or a pixel buffer of the wrong
    /// length, [`ImageryError::TooLarge`] (named `memory` in the message).
    pub fn new(width: u32, height: u32, extent: Extent, pixels: Vec<u8>) -> Result<Imagery, ImageryError> {
        Imagery::named("memory", width, height, extent, pixels)
    }

    /// As [`new`](Self::new), with errors naming `file`.
    pub(crate) fn named(
        file: &str,
        width: u32,
        height: u32,
        extent: Extent,
        pixels: Vec<u8>,
    ) -> Result<Imagery, ImageryError> {
        check_size(file, u64::from(width), u64::from(height))?;
        let expected = width as usize * height as usize * 3;
        if pixels.len() != expected {
            return Err(ImageryError::Corrupt {
                file: file.to_owned(),
                detail: format!(
                    "{} bytes of pixels where {width} x {height} RGB pixels need {expected}",
                    pixels.len()
                ),
            });
        }
        let digest = content_digest(width, height, &extent, &pixels);
        Ok(Imagery {
            width,
            height,
            extent,
            pixels,
            digest,
        })
    }

    /// Imagery whose digest was read from a file and checked by the caller.
    pub(crate) fn from_parts(width: u32, height: u32, extent: Extent, pixels: Vec<u8>, digest: String) -> Imagery {
        Imagery {
            width,
            height,
            extent,
            pixels,
            digest,
        }
    }

    /// Columns.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Rows.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Where the image lies (the outer edges of its pixels).
    pub fn extent(&self) -> Extent {
        self.extent
    }

    /// The pixels: RGB, row by row from the north, `width * height * 3` bytes.
    pub fn pixels(&self) -> &[u8] {
        &self.pixels
    }

    /// The content digest: SHA-256 of the size, extent and pixels, 64 lower-case hex digits.
    pub fn digest(&self) -> &str {
        &self.digest
    }

    /// The colour of pixel `(col, row)` (row 0 the northernmost).
    ///
    /// # Panics
    /// When `col >= width` or `row >= height`.
    pub fn pixel(&self, col: u32, row: u32) -> [u8; 3] {
        assert!(
            col < self.width && row < self.height,
            "pixel ({col}, {row}) is outside the {} x {} image",
            self.width,
            self.height
        );
        let i = (row as usize * self.width as usize + col as usize) * 3;
        [self.pixels[i], self.pixels[i + 1], self.pixels[i + 2]]
    }

    /// The colour at latitude `lat` and longitude `lon` (degrees; any longitude, wrapped by
    /// whole turns), interpolated bilinearly between the four nearest pixel centres on the
    /// sRGB-encoded values, rounded to the nearest integer. This is what a GPU's linear
    /// filtering of the image as a plain 8-bit texture gives at texture coordinates
    /// `u = ((lon - west) mod 360) / (east - west)`, `v = (north - lat) / (north - south)`,
    /// wrapping (repeat) in `u` when the extent goes round the globe and clamping to the edge
    /// pixels otherwise, clamping in `v`.
    ///
    /// `None` when `lat` or `lon` is not a finite number or the place lies outside the extent
    /// (its edges included).
    pub fn color_at(&self, lat: f64, lon: f64) -> Option<[u8; 3]> {
        let e = &self.extent;
        if !lat.is_finite() || !lon.is_finite() || lat < e.south() || lat > e.north() {
            return None;
        }
        let east_of_west = e.offset_east(lon);
        if east_of_west > e.lon_span() {
            return None;
        }
        let (w, h) = (i64::from(self.width), i64::from(self.height));
        let x = east_of_west / e.lon_span() * w as f64 - 0.5;
        let y = (e.north() - lat) / e.lat_span() * h as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let col = |c: i64| -> usize {
            if e.wraps() {
                c.rem_euclid(w) as usize
            } else {
                c.clamp(0, w - 1) as usize
            }
        };
        let row = |r: i64| -> usize { r.clamp(0, h - 1) as usize };
        let (c0, c1) = (col(x0 as i64), col(x0 as i64 + 1));
        let (r0, r1) = (row(y0 as i64), row(y0 as i64 + 1));
        let at = |c: usize, r: usize, k: usize| f64::from(self.pixels[(r * self.width as usize + c) * 3 + k]);
        let mut out = [0u8; 3];
        for (k, o) in out.iter_mut().enumerate() {
            let top = at(c0, r0, k) * (1.0 - fx) + at(c1, r0, k) * fx;
            let bottom = at(c0, r1, k) * (1.0 - fx) + at(c1, r1, k) * fx;
            *o = (top * (1.0 - fy) + bottom * fy).round().clamp(0.0, 255.0) as u8;
        }
        Some(out)
    }

    /// The size of the level that [`downsampled`](Self::downsampled) gives for `max`: the
    /// image's size halved (rounding down, at least 1) as few times as needed for both sides
    /// to be at most `max` (`max` at least 1).
    pub fn level_size(&self, max: u32) -> (u32, u32) {
        let max = max.max(1);
        let (mut w, mut h) = (self.width, self.height);
        while w > max || h > max {
            w = (w / 2).max(1);
            h = (h / 2).max(1);
        }
        (w, h)
    }

    /// The image at the size of [`level_size`](Self::level_size)`(max)` over the same extent:
    /// each new pixel the mean of the pixels whose centres fall in it (a 2 x 2 box for each
    /// halving of an even side), rounded; the image itself (cloned) when it already fits.
    pub fn downsampled(&self, max: u32) -> Imagery {
        let (nw, nh) = self.level_size(max);
        if (nw, nh) == (self.width, self.height) {
            return self.clone();
        }
        let (w, h) = (self.width as usize, self.height as usize);
        let (nw_, nh_) = (nw as usize, nh as usize);
        // Source columns [cols[i], cols[i + 1]) fall in new column i.
        let bounds = |n: usize, old: usize| -> Vec<usize> { (0..=n).map(|i| i * old / n).collect() };
        let (cols, rows) = (bounds(nw_, w), bounds(nh_, h));
        let mut pixels = Vec::with_capacity(nw_ * nh_ * 3);
        for r in 0..nh_ {
            for c in 0..nw_ {
                let mut sum = [0u64; 3];
                for sr in rows[r]..rows[r + 1] {
                    let line = &self.pixels[(sr * w + cols[c]) * 3..(sr * w + cols[c + 1]) * 3];
                    for px in line.chunks_exact(3) {
                        for k in 0..3 {
                            sum[k] += u64::from(px[k]);
                        }
                    }
                }
                let n = ((rows[r + 1] - rows[r]) * (cols[c + 1] - cols[c])) as u64;
                pixels.extend(sum.map(|s| ((s + n / 2) / n) as u8));
            }
        }
        let digest = content_digest(nw, nh, &self.extent, &pixels);
        Imagery {
            width: nw,
            height: nh,
            extent: self.extent,
            pixels,
            digest,
        }
    }

    /// The image as a PNG file: 8-bit RGB, marked sRGB, row 0 at the top.
    ///
    /// Errors: [`ImageryError::Encode`] (never for valid imagery).
    pub fn to_png(&self) -> Result<Vec<u8>, ImageryError> {
        let encode = |e: png::EncodingError| ImageryError::Encode(e.to_string());
        let mut out = Vec::with_capacity(self.pixels.len() / 2 + 1024);
        let mut encoder = png::Encoder::new(&mut out, self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Fast);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        let mut writer = encoder.write_header().map_err(encode)?;
        writer.write_image_data(&self.pixels).map_err(encode)?;
        writer.finish().map_err(encode)?;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A global image whose pixel `(c, r)` is `(c, r, c ^ r)` (wrapping at 256).
    fn ramp(w: u32, h: u32) -> Imagery {
        let mut px = Vec::new();
        for r in 0..h {
            for c in 0..w {
                px.extend([c as u8, r as u8, (c ^ r) as u8]);
            }
        }
        Imagery::new(w, h, Extent::GLOBAL, px).unwrap()
    }

    /// The latitude and longitude of pixel `(c, r)`'s centre.
    fn centre(img: &Imagery, c: u32, r: u32) -> (f64, f64) {
        let e = img.extent();
        let lon = e.west() + (f64::from(c) + 0.5) * e.lon_span() / f64::from(img.width());
        let lat = e.north() - (f64::from(r) + 0.5) * e.lat_span() / f64::from(img.height());
        (lat, lon)
    }

    #[test]
    fn color_at_a_pixel_centre_is_the_pixel() {
        let img = ramp(64, 32);
        for r in 0..32 {
            for c in 0..64 {
                let (lat, lon) = centre(&img, c, r);
                assert_eq!(img.color_at(lat, lon), Some(img.pixel(c, r)), "({c}, {r})");
                assert_eq!(img.color_at(lat, lon + 720.0), Some(img.pixel(c, r)));
            }
        }
    }

    #[test]
    fn color_at_interpolates_and_wraps_in_longitude() {
        let img = ramp(8, 4);
        // Halfway between the centres of columns 2 and 3 of row 1: the mean.
        let (lat, lon2) = centre(&img, 2, 1);
        let (_, lon3) = centre(&img, 3, 1);
        let mid = img.color_at(lat, 0.5 * (lon2 + lon3)).unwrap();
        assert_eq!(mid[0], ((2.0 + 3.0) / 2.0f64).round() as u8);
        // At the antimeridian: halfway between the last and the first column.
        let v = img.color_at(lat, 180.0).unwrap();
        assert_eq!(v[0], ((7.0 + 0.0) / 2.0f64).round() as u8);
        assert_eq!(img.color_at(lat, -180.0), Some(v));
        // Past the outer row centres, the edge rows (clamped).
        assert_eq!(img.color_at(90.0, centre(&img, 5, 0).1), Some(img.pixel(5, 0)));
        assert_eq!(img.color_at(-90.0, centre(&img, 5, 3).1), Some(img.pixel(5, 3)));
    }

    #[test]
    fn color_at_outside_a_partial_extent_is_none() {
        let extent = Extent::new(10.0, 20.0, 30.0, 40.0).unwrap();
        let img = Imagery::new(2, 2, extent, vec![10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120]).unwrap();
        assert_eq!(img.color_at(30.0, 5.0), None);
        assert_eq!(img.color_at(30.0, 31.0), None);
        assert_eq!(img.color_at(41.0, 20.0), None);
        assert_eq!(img.color_at(f64::NAN, 20.0), None);
        assert_eq!(img.color_at(30.0, f64::INFINITY), None);
        // The edges are inside and clamp to the edge pixels.
        assert_eq!(img.color_at(40.0, 10.0), Some(img.pixel(0, 0)));
        assert_eq!(img.color_at(20.0, 30.0), Some(img.pixel(1, 1)));
        assert_eq!(img.color_at(35.0, 370.0 - 360.0 + 5.0), Some(img.pixel(0, 0)));
    }

    #[test]
    fn downsampling_halves_by_two_by_two_means() {
        let img = ramp(8, 4);
        assert_eq!(img.level_size(8), (8, 4));
        assert_eq!(img.level_size(4), (4, 2));
        assert_eq!(img.level_size(3), (2, 1));
        assert_eq!(img.level_size(0), (1, 1));
        let half = img.downsampled(4);
        assert_eq!((half.width(), half.height()), (4, 2));
        assert_eq!(half.extent(), img.extent());
        for r in 0..2 {
            for c in 0..4 {
                for k in 0..3 {
                    let s: u32 = [(0, 0), (1, 0), (0, 1), (1, 1)]
                        .iter()
                        .map(|(dc, dr)| u32::from(img.pixel(2 * c + dc, 2 * r + dr)[k]))
                        .sum();
                    assert_eq!(u32::from(half.pixel(c, r)[k]), (s + 2) / 4, "({c}, {r}) channel {k}");
                }
            }
        }
        assert_ne!(half.digest(), img.digest());
        assert_eq!(img.downsampled(100), img);
        // Odd sides: every source pixel falls in exactly one new pixel.
        let odd = ramp(5, 3).downsampled(2);
        assert_eq!((odd.width(), odd.height()), (2, 1));
    }

    #[test]
    fn png_round_trip_is_exact() {
        let img = ramp(33, 17);
        let bytes = img.to_png().unwrap();
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (33, 17));
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(&buf[..info.buffer_size()], img.pixels());
        assert!(reader.info().srgb.is_some());
    }

    #[test]
    fn bad_sizes_are_errors() {
        assert!(matches!(
            Imagery::new(0, 1, Extent::GLOBAL, vec![]),
            Err(ImageryError::Corrupt { .. })
        ));
        assert!(matches!(
            Imagery::new(2, 1, Extent::GLOBAL, vec![0; 5]),
            Err(ImageryError::Corrupt { .. })
        ));
        assert!(matches!(
            Imagery::new(MAX_SIDE + 1, 1, Extent::GLOBAL, vec![]),
            Err(ImageryError::TooLarge { .. })
        ));
        assert!(matches!(
            Imagery::new(1 << 14, 1 << 14, Extent::GLOBAL, vec![]),
            Err(ImageryError::TooLarge { .. })
        ));
    }

    #[test]
    fn the_digest_depends_on_pixels_and_extent() {
        let a = ramp(4, 2);
        let mut px = a.pixels().to_vec();
        px[5] ^= 1;
        let b = Imagery::new(4, 2, Extent::GLOBAL, px).unwrap();
        let c = Imagery::new(
            4,
            2,
            Extent::new(-180.0, -80.0, 180.0, 90.0).unwrap(),
            a.pixels().to_vec(),
        )
        .unwrap();
        assert_ne!(a.digest(), b.digest());
        assert_ne!(a.digest(), c.digest());
        assert_eq!(a.digest().len(), 64);
        assert_eq!(a.digest(), ramp(4, 2).digest());
    }
}
