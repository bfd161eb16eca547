//! Fractal 3D gradient noise in `f64`.
//!
//! - [`gradient3`] / [`GradientNoise`] (and [`gradient3_pair`], two seeds at one point): one octave of Perlin-style gradient noise with a quintic
//!   fade, the lattice hashed from `i64` cell coordinates (no permutation table, so no repeat
//!   every 256 cells), exact at coordinates beyond `1e7`. Output in `[-1, 1]`.
//! - [`Fbm`]: fractional Brownian motion, output in `[-1, 1]`.
//! - [`Ridged`]: ridged multifractal, output in `[0, 1]`.
//! - [`mix64`], [`derive_seed`]: the integer mixing behind seeds.
//!
//! Height fields are sampled as 3D noise at the unit direction times a frequency, so they wrap
//! the sphere without seams or pole pinching (seed 000 Sec. 4.6); caves and overhangs sample the
//! world position divided by a length.
//!
//! Everything is deterministic: the same inputs give the same bits on every call and thread.

mod fbm;
mod gradient;
mod hash;
mod lanes;
mod octave;
mod ridged;

pub use fbm::{Fbm, FbmParams, DEFAULT_FREQUENCY, DEFAULT_GAIN, DEFAULT_LACUNARITY, DEFAULT_OCTAVES};
pub use gradient::{gradient3, gradient3_pair, GradientNoise, GRADIENT_RAW_MAX};
pub use hash::{derive_seed, mix64, unit_f64};
pub(crate) use lanes::wide;
pub use lanes::{gradient3_accumulate, gradient3_accumulate_offset, gradient3_x8, Lanes8, LANES};
pub use octave::{octaves_for, MAX_OCTAVES};
pub use ridged::{Ridged, RidgedParams, DEFAULT_RIDGE_FEEDBACK, DEFAULT_RIDGE_OFFSET};
