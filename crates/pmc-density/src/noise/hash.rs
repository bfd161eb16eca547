//! Integer hashing: the mixer that replaces a permutation table, and seed derivation.
//!
//! A 256-entry permutation table repeats every 256 lattice cells, which shows at planetary scale.
//! Hashing the full 64-bit lattice coordinates instead never repeats within the range of `i64`.

/// Multiplier applied to the `x` lattice coordinate (odd, from the golden ratio).
pub(crate) const LATTICE_X: u64 = 0x9E37_79B9_7F4A_7C15;
/// Multiplier applied to the `y` lattice coordinate (odd).
pub(crate) const LATTICE_Y: u64 = 0xC2B2_AE3D_27D4_EB4F;
/// Multiplier applied to the `z` lattice coordinate (odd).
pub(crate) const LATTICE_Z: u64 = 0x1656_67B1_9E37_79F9;
/// Multiplier of the one-round finaliser used per lattice corner.
pub(crate) const FINAL_MUL: u64 = 0xD6E8_FEB8_6659_FD93;

/// A strong 64-bit mixer (the SplitMix64 finaliser): every input bit affects every output bit.
///
/// Used for seeds and other per-call work; the per-corner lattice hash uses a cheaper single round
/// (`corner_hash`).
#[inline]
pub fn mix64(mut x: u64) -> u64 {
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// A seed derived from `seed` for the independent stream `stream` (an octave, a feature, ...).
///
/// Different streams of one seed, and the same stream of different seeds, give unrelated values.
#[inline]
pub fn derive_seed(seed: u64, stream: u64) -> u64 {
    mix64(seed ^ mix64(stream.wrapping_add(0x632B_E59B_D9B4_E019)))
}

/// A uniform value in `[0, 1)` from the top 53 bits of `h`.
#[inline]
pub fn unit_f64(h: u64) -> f64 {
    (h >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The hash of one lattice corner from the pre-multiplied coordinates and a pre-mixed seed.
///
/// `key` is `ix * LATTICE_X ^ iy * LATTICE_Y ^ iz * LATTICE_Z ^ seed`; one xor-shift-multiply
/// round makes its top bits depend on every input bit.
#[inline(always)]
pub(crate) fn corner_hash(key: u64) -> u64 {
    (key ^ (key >> 32)).wrapping_mul(FINAL_MUL)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_seeds_differ() {
        let mut seen = std::collections::HashSet::new();
        for seed in 0..32u64 {
            for stream in 0..32u64 {
                assert!(seen.insert(derive_seed(seed, stream)), "collision at {seed}/{stream}");
            }
        }
    }

    #[test]
    fn unit_values_are_in_range() {
        for i in 0..10_000u64 {
            let u = unit_f64(mix64(i));
            assert!((0.0..1.0).contains(&u));
        }
        assert_eq!(unit_f64(0), 0.0);
        assert!(unit_f64(u64::MAX) < 1.0);
    }

    #[test]
    fn corner_hash_top_bits_are_balanced() {
        // The gradient index is the top 4 bits: every value should appear about equally often over
        // a block of lattice cells.
        let mut counts = [0u32; 16];
        for x in -20i64..20 {
            for y in -20i64..20 {
                for z in -20i64..20 {
                    let key = (x as u64).wrapping_mul(LATTICE_X)
                        ^ (y as u64).wrapping_mul(LATTICE_Y)
                        ^ (z as u64).wrapping_mul(LATTICE_Z)
                        ^ 12345;
                    counts[(corner_hash(key) >> 60) as usize] += 1;
                }
            }
        }
        let mean = 64_000.0 / 16.0;
        for c in counts {
            assert!(
                (f64::from(c) - mean).abs() < 0.1 * mean,
                "unbalanced gradient choice: {counts:?}"
            );
        }
    }
}
