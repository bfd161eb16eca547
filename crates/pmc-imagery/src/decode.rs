//! Importing imagery from JPEG, PNG and TIFF (GeoTIFF) images.

use crate::imagery::{check_size, MAX_PIXELS};
use crate::pmcimg::looks_like;
use crate::{Extent, Imagery, ImageryError};
use std::io::Cursor;
use std::path::Path;

/// The image formats [`Imagery::import`] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// JPEG (baseline or progressive; greyscale or colour).
    Jpeg,
    /// PNG (any colour type and bit depth; alpha is dropped).
    Png,
    /// TIFF, georeferenced (GeoTIFF) or not: grey, RGB or RGBA of 8 or 16 bits.
    Tiff,
}

impl ImageFormat {
    /// The format of a file from its first bytes, if it is one of these.
    pub fn sniff(head: &[u8]) -> Option<ImageFormat> {
        if head.starts_with(b"\xff\xd8\xff") {
            Some(ImageFormat::Jpeg)
        } else if head.starts_with(b"\x89PNG\r\n\x1a\n") {
            Some(ImageFormat::Png)
        } else if [b"II*\0", b"MM\0*", b"II+\0", b"MM\0+"]
            .iter()
            .any(|s| head.starts_with(*s))
        {
            Some(ImageFormat::Tiff)
        } else {
            None
        }
    }
}

impl Imagery {
    /// Imports the image at `path` (JPEG, PNG or TIFF, told by its first bytes) as imagery over
    /// `extent`. Without an extent, a GeoTIFF's georeferencing gives it (see
    /// [`pmc_dem::Georeference`]: longitudes and latitudes in degrees, north up or down, pixels
    /// as areas or points), and any other image covers the whole globe ([`Extent::GLOBAL`]).
    /// Greyscale becomes RGB, alpha is dropped, 16-bit samples are rounded to 8 bits
    /// (`v * 255 / 65535`).
    ///
    /// Errors, each naming `path` as displayed: [`ImageryError::Io`],
    /// [`ImageryError::UnknownFormat`], [`ImageryError::Unsupported`],
    /// [`ImageryError::Corrupt`] (damaged or cut short), [`ImageryError::TooLarge`] (refused
    /// before decoding), [`ImageryError::Georeference`] (a TIFF without an extent that is not
    /// georeferenced in longitudes and latitudes), [`ImageryError::InvalidExtent`] (from a
    /// GeoTIFF's georeferencing).
    pub fn import(path: impl AsRef<Path>, extent: Option<Extent>) -> Result<Imagery, ImageryError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| ImageryError::Io {
            file: file.clone(),
            source,
        })?;
        Imagery::import_bytes(&file, &bytes, extent)
    }

    /// As [`import`](Self::import), for an image held in memory; `name` stands for the file in
    /// errors.
    pub fn import_bytes(name: &str, bytes: &[u8], extent: Option<Extent>) -> Result<Imagery, ImageryError> {
        match ImageFormat::sniff(bytes) {
            Some(ImageFormat::Jpeg) => {
                let (w, h, px) = jpeg(name, bytes)?;
                Imagery::named(name, w, h, extent.unwrap_or_default(), px)
            }
            Some(ImageFormat::Png) => {
                let (w, h, px) = png(name, bytes)?;
                Imagery::named(name, w, h, extent.unwrap_or_default(), px)
            }
            Some(ImageFormat::Tiff) => tiff(name, bytes, extent),
            None => Err(ImageryError::UnknownFormat {
                file: name.to_owned(),
                detail: format!(
                    "{}; a JPEG starts with FF D8 FF, a PNG with \"\\x89PNG\", a TIFF with \"II*\\0\" or \"MM\\0*\"",
                    looks_like(bytes)
                ),
            }),
        }
    }
}

/// Interleaved samples of `channels` per pixel (1 grey, 2 grey and alpha, 3 RGB, 4 RGBA) as RGB.
fn to_rgb(samples: &[u8], channels: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(samples.len() / channels * 3);
    for px in samples.chunks_exact(channels) {
        match channels {
            1 | 2 => out.extend([px[0]; 3]),
            _ => out.extend_from_slice(&px[..3]),
        }
    }
    out
}

/// A 16-bit sample rounded to 8 bits.
fn to_8bit(v: u16) -> u8 {
    ((u32::from(v) * 255 + 32767) / 65535) as u8
}

fn jpeg(file: &str, bytes: &[u8]) -> Result<(u32, u32, Vec<u8>), ImageryError> {
    let err = |e: jpeg_decoder::Error| match e {
        jpeg_decoder::Error::Unsupported(f) => ImageryError::Unsupported {
            file: file.to_owned(),
            detail: format!("the JPEG uses {f:?}, which this reader does not decode"),
        },
        e => ImageryError::Corrupt {
            file: file.to_owned(),
            detail: e.to_string(),
        },
    };
    let mut decoder = jpeg_decoder::Decoder::new(Cursor::new(bytes));
    decoder.set_max_decoding_buffer_size((MAX_PIXELS * 4) as usize);
    decoder.read_info().map_err(err)?;
    let info = decoder.info().ok_or_else(|| ImageryError::Corrupt {
        file: file.to_owned(),
        detail: "the JPEG has no frame header".to_owned(),
    })?;
    let (w, h) = (u32::from(info.width), u32::from(info.height));
    check_size(file, u64::from(w), u64::from(h))?;
    let channels = match info.pixel_format {
        jpeg_decoder::PixelFormat::L8 => 1,
        jpeg_decoder::PixelFormat::RGB24 => 3,
        other => {
            return Err(ImageryError::Unsupported {
                file: file.to_owned(),
                detail: format!("the JPEG's pixels are {other:?}, not 8-bit greyscale or RGB"),
            })
        }
    };
    let samples = decoder.decode().map_err(err)?;
    if samples.len() != w as usize * h as usize * channels {
        return Err(ImageryError::Corrupt {
            file: file.to_owned(),
            detail: format!(
                "the JPEG decodes to {} bytes where {w} x {h} pixels need {}",
                samples.len(),
                w as usize * h as usize * channels
            ),
        });
    }
    Ok((w, h, if channels == 3 { samples } else { to_rgb(&samples, 1) }))
}

fn png(file: &str, bytes: &[u8]) -> Result<(u32, u32, Vec<u8>), ImageryError> {
    let err = |e: png::DecodingError| match e {
        png::DecodingError::LimitsExceeded => ImageryError::TooLarge {
            file: file.to_owned(),
            width: 0,
            height: 0,
            max_pixels: MAX_PIXELS,
            max_side: u64::from(crate::MAX_SIDE),
        },
        e => ImageryError::Corrupt {
            file: file.to_owned(),
            detail: e.to_string(),
        },
    };
    let limits = png::Limits {
        bytes: (MAX_PIXELS * 8) as usize,
    };
    let mut decoder = png::Decoder::new_with_limits(Cursor::new(bytes), limits);
    // Palettes and low bit depths expanded to 8 bits; 16-bit samples kept, rounded below.
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(err)?;
    let (w, h) = (reader.info().width, reader.info().height);
    check_size(file, u64::from(w), u64::from(h))?;
    let (color, depth) = reader.output_color_type();
    let channels = color.samples();
    let mut buf = vec![0u8; reader.output_buffer_size()];
    let frame = reader.next_frame(&mut buf).map_err(err)?;
    buf.truncate(frame.buffer_size());
    let samples = match depth {
        png::BitDepth::Eight => buf,
        png::BitDepth::Sixteen => buf
            .chunks_exact(2)
            .map(|b| to_8bit(u16::from_be_bytes([b[0], b[1]])))
            .collect(),
        other => {
            return Err(ImageryError::Unsupported {
                file: file.to_owned(),
                detail: format!("the PNG decodes to {other:?}-bit samples"),
            })
        }
    };
    if samples.len() != w as usize * h as usize * channels {
        return Err(ImageryError::Corrupt {
            file: file.to_owned(),
            detail: format!("the PNG decodes to {} samples for {w} x {h} pixels", samples.len()),
        });
    }
    Ok((
        w,
        h,
        if channels == 3 {
            samples
        } else {
            to_rgb(&samples, channels)
        },
    ))
}

fn tiff(file: &str, bytes: &[u8], extent: Option<Extent>) -> Result<Imagery, ImageryError> {
    use tiff::decoder::{Decoder, DecodingResult, Limits};
    use tiff::{ColorType, TiffError};
    let len = bytes.len() as u64;
    let err = |e: TiffError| match e {
        TiffError::UnsupportedError(e) => ImageryError::Unsupported {
            file: file.to_owned(),
            detail: format!("the TIFF uses something this reader does not decode: {e}"),
        },
        TiffError::LimitsExceeded => ImageryError::Unsupported {
            file: file.to_owned(),
            detail: "a strip, tile or tag of the TIFF is larger than this reader decodes".to_owned(),
        },
        TiffError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => ImageryError::Corrupt {
            file: file.to_owned(),
            detail: format!("it ends early (it holds {len} bytes)"),
        },
        e => ImageryError::Corrupt {
            file: file.to_owned(),
            detail: e.to_string(),
        },
    };
    let mut limits = Limits::default();
    limits.decoding_buffer_size = (MAX_PIXELS * 8) as usize;
    limits.ifd_value_size = 16 << 20;
    let mut decoder = Decoder::new(Cursor::new(bytes)).map_err(err)?.with_limits(limits);
    let (w, h) = decoder.dimensions().map_err(err)?;
    check_size(file, u64::from(w), u64::from(h))?;
    let channels = match decoder.colortype().map_err(err)? {
        ColorType::Gray(8 | 16) => 1,
        ColorType::GrayA(8 | 16) => 2,
        ColorType::RGB(8 | 16) => 3,
        ColorType::RGBA(8 | 16) => 4,
        other => {
            return Err(ImageryError::Unsupported {
                file: file.to_owned(),
                detail: format!("the TIFF's pixels are {other:?}, not grey, RGB or RGBA of 8 or 16 bits"),
            })
        }
    };
    // Where the pixels lie, before any is decoded.
    let placed = match extent {
        Some(e) => Placement {
            extent: e,
            flip_cols: false,
            flip_rows: false,
        },
        None => {
            let geo = pmc_dem::Georeference::read(file, &mut decoder, len).map_err(|e| ImageryError::Georeference {
                file: file.to_owned(),
                detail: e.to_string(),
            })?;
            placement(file, &geo, w, h)?
        }
    };
    let samples = match decoder.read_image().map_err(err)? {
        DecodingResult::U8(v) => v,
        DecodingResult::U16(v) => v.into_iter().map(to_8bit).collect(),
        _ => {
            return Err(ImageryError::Unsupported {
                file: file.to_owned(),
                detail: "the TIFF's samples are not unsigned integers of 8 or 16 bits".to_owned(),
            })
        }
    };
    let (wu, hu) = (w as usize, h as usize);
    if samples.len() != wu * hu * channels {
        return Err(ImageryError::Corrupt {
            file: file.to_owned(),
            detail: format!("the TIFF decodes to {} samples for {w} x {h} pixels", samples.len()),
        });
    }
    let mut rgb = to_rgb(&samples, channels);
    if placed.flip_rows {
        let row = wu * 3;
        for r in 0..hu / 2 {
            let (top, bottom) = rgb.split_at_mut((hu - 1 - r) * row);
            top[r * row..(r + 1) * row].swap_with_slice(&mut bottom[..row]);
        }
    }
    if placed.flip_cols {
        for line in rgb.chunks_exact_mut(wu * 3) {
            for c in 0..wu / 2 {
                for k in 0..3 {
                    line.swap(c * 3 + k, (wu - 1 - c) * 3 + k);
                }
            }
        }
    }
    Imagery::named(file, w, h, placed.extent, rgb)
}

/// Where a GeoTIFF's pixels lie, and whether its columns or rows must be reversed to run from
/// the west and from the north.
struct Placement {
    extent: Extent,
    flip_cols: bool,
    flip_rows: bool,
}

/// The outer edges of the pixels of a `w x h` GeoTIFF georeferenced by `geo`.
fn placement(file: &str, geo: &pmc_dem::Georeference, w: u32, h: u32) -> Result<Placement, ImageryError> {
    // The edge of raster coordinate 0: the tie point itself for areas, half a pixel before a
    // point's centre.
    let half = if geo.pixel_is_point { 0.5 } else { 0.0 };
    let x_edge = geo.x0 - half * geo.x_scale;
    let y_edge = geo.y0 - half * geo.y_scale;
    let (x_far, y_far) = (x_edge + f64::from(w) * geo.x_scale, y_edge + f64::from(h) * geo.y_scale);
    let (west, east) = (x_edge.min(x_far), x_edge.max(x_far));
    let (south, north) = (y_edge.min(y_far), y_edge.max(y_far));
    let extent = Extent::new(west, south, east, north).map_err(|detail| ImageryError::InvalidExtent {
        file: file.to_owned(),
        detail: format!("from its GeoTIFF georeferencing: {detail}"),
    })?;
    Ok(Placement {
        extent,
        flip_cols: geo.x_scale < 0.0,
        flip_rows: geo.y_scale > 0.0,
    })
}
