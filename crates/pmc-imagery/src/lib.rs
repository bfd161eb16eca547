//! Imagery draped on a planet: an equirectangular colour image (NASA's Visible Earth, say) over
//! an extent of longitudes and latitudes, imported once from JPEG, PNG or GeoTIFF into a small
//! checksummed `.pmcimg` file (`docs/specs/pmcimg-v1.md`), sampled by latitude and longitude
//! ([`Imagery::color_at`], bilinear on the sRGB-encoded values as a GPU filters a plain 8-bit
//! texture), reduced to smaller levels ([`Imagery::downsampled`]) and encoded as PNG for the
//! viewer ([`Imagery::to_png`]).
//!
//! Input from outside is checked before it is trusted: every problem is an [`ImageryError`]
//! naming the file, never a panic, and sizes are checked against [`MAX_PIXELS`] before pixels
//! are decoded.
//!
//! ```
//! use pmc_imagery::{Extent, Imagery};
//!
//! // A 4 x 2 image of the whole globe: one colour per quarter of each hemisphere.
//! let pixels: Vec<u8> = (0..8u8).flat_map(|i| [i * 30, 255 - i * 30, 100]).collect();
//! let img = Imagery::new(4, 2, Extent::GLOBAL, pixels)?;
//! let out = std::env::temp_dir().join(format!("pmc-imagery-doc-{}.pmcimg", std::process::id()));
//! img.write(&out)?;
//! let back = Imagery::open(&out)?; // header, length, checksum and digest checked
//! assert_eq!(back, img);
//! // Pixel (1, 0) covers longitudes -90 to 0 and latitudes 0 to 90; its centre is (45, -45).
//! assert_eq!(back.color_at(45.0, -45.0), Some(img.pixel(1, 0)));
//! # std::fs::remove_file(&out).unwrap();
//! # Ok::<(), pmc_imagery::ImageryError>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod decode;
mod error;
mod extent;
mod imagery;
pub mod pmcimg;

pub use decode::ImageFormat;
pub use error::ImageryError;
pub use extent::Extent;
pub use imagery::{Imagery, MAX_PIXELS, MAX_SIDE};
