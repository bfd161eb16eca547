//! The per-octave table shared by the fractal sums: frequency, amplitude, seed and offset.

use super::gradient::gradient3;
use super::hash::{derive_seed, mix64, unit_f64};
use super::lanes::{gradient3_x8, Lanes8, BATCH_FROM, LANES};
use pmc_geometry::glam::DVec3;

/// The most octaves a fractal sum takes (more are clamped; 16 octaves at lacunarity 2 span a
/// factor of 32768 in scale, from continents to boulders).
pub const MAX_OCTAVES: u32 = 16;

/// One octave of a fractal sum, precomputed so that sampling does no seed or offset work.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Octave {
    /// Input scale of this octave.
    pub frequency: f64,
    /// Weight of this octave in the sum.
    pub amplitude: f64,
    /// Lattice seed of this octave (derived from the fractal's seed).
    pub seed: u64,
    /// Offset added after scaling (lattice units): moves each octave's lattice zeros away from the
    /// others', so the sum has no regular grid of zeros.
    pub offset: DVec3,
}

/// Builds the octave table; returns it with the number of octaves used and the sum of the
/// amplitudes.
pub(crate) fn table(
    seed: u64,
    octaves: u32,
    frequency: f64,
    lacunarity: f64,
    gain: f64,
) -> ([Octave; MAX_OCTAVES as usize], usize, f64) {
    let n = octaves.clamp(1, MAX_OCTAVES) as usize;
    let mut out = [Octave::default(); MAX_OCTAVES as usize];
    let (mut f, mut a, mut total) = (frequency, 1.0, 0.0);
    for (i, o) in out.iter_mut().take(n).enumerate() {
        let s = derive_seed(seed, i as u64);
        let offset = DVec3::new(
            unit_f64(mix64(s ^ 1)) * 1024.0,
            unit_f64(mix64(s ^ 2)) * 1024.0,
            unit_f64(mix64(s ^ 3)) * 1024.0,
        );
        *o = Octave {
            frequency: f,
            amplitude: a,
            seed: s,
            offset,
        };
        total += a;
        f *= lacunarity;
        a *= gain;
    }
    (out, n, total)
}

/// The noise of each octave of `octaves` at `p` (`gradient3(p f + offset, seed)`, the same
/// bits), in `out[..octaves.len()]`: eight at a time from [`BATCH_FROM`] octaves on, else one by
/// one. The fractal sums then combine them in order.
#[inline]
pub(crate) fn octave_noise(octaves: &[Octave], p: DVec3, out: &mut [f64; MAX_OCTAVES as usize]) {
    if octaves.len() >= BATCH_FROM {
        for (group, out) in octaves.chunks(LANES).zip(out.chunks_mut(LANES)) {
            let mut q = Lanes8::default();
            for (l, o) in group.iter().enumerate() {
                q.set(l, p * o.frequency + o.offset, o.seed);
            }
            let n = gradient3_x8(&q);
            out.copy_from_slice(&n[..out.len()]);
        }
    } else {
        for (o, n) in octaves.iter().zip(out.iter_mut()) {
            *n = gradient3(p * o.frequency + o.offset, o.seed);
        }
    }
}

/// The number of octaves needed to go from wavelength `coarsest` down to no finer than `finest`
/// at `lacunarity` (at least 1, at most [`MAX_OCTAVES`]).
///
/// Presets use it to fit the detail to the voxel size of a layout: octaves finer than about two
/// voxels only alias.
pub fn octaves_for(coarsest: f64, finest: f64, lacunarity: f64) -> u32 {
    if !(coarsest > finest && finest > 0.0 && lacunarity > 1.0) {
        return 1;
    }
    let n = ((coarsest / finest).ln() / lacunarity.ln()).floor() as i64 + 1;
    n.clamp(1, i64::from(MAX_OCTAVES)) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octave_counts() {
        assert_eq!(octaves_for(100.0, 200.0, 2.0), 1);
        assert_eq!(octaves_for(100.0, 100.0, 2.0), 1);
        assert_eq!(octaves_for(100.0, 50.0, 2.0), 2);
        assert_eq!(octaves_for(100.0, 12.0, 2.0), 4);
        assert_eq!(octaves_for(1e9, 1.0, 2.0), MAX_OCTAVES);
        assert_eq!(octaves_for(100.0, 1.0, 1.0), 1);
    }

    #[test]
    fn table_has_distinct_seeds_and_decaying_amplitudes() {
        let (t, n, total) = table(5, 6, 2.0, 2.0, 0.5);
        assert_eq!(n, 6);
        assert!((total - (2.0 - 1.0 / 32.0)).abs() < 1e-12);
        for i in 1..n {
            assert_ne!(t[i].seed, t[i - 1].seed);
            assert_eq!(t[i].frequency, t[i - 1].frequency * 2.0);
            assert_eq!(t[i].amplitude, t[i - 1].amplitude * 0.5);
        }
        assert_eq!(table(5, 0, 1.0, 2.0, 0.5).1, 1);
        assert_eq!(table(5, 99, 1.0, 2.0, 0.5).1, MAX_OCTAVES as usize);
    }
}
