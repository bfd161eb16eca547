//! Damaged copies of the ETOPO60 fixture never make the reader panic: every header word set to
//! extreme values, every header byte flipped, and random flips, overwrites and truncations.
//! Whatever is read instead (a grid or an error) must be self-consistent.

use pmc_dem::EquirectDem;
use proptest::prelude::*;
use std::sync::OnceLock;

/// Bytes of the fixture's header (the axes' data begin there).
const HEADER: usize = 568;
/// Where the heights (variable ROSE) begin.
const ROSE: usize = 4888;

fn fixture() -> &'static [u8] {
    static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
    BYTES.get_or_init(|| std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/etopo60.cdf")).unwrap())
}

/// Reads `bytes`; checks that a grid read is consistent and that an error names the file.
fn read_and_check(bytes: Vec<u8>) {
    match EquirectDem::from_netcdf_bytes("mutant.cdf", bytes, None) {
        Ok(dem) => {
            let (w, h) = (dem.width(), dem.height());
            assert!(w >= 1 && h >= 2);
            assert_eq!(dem.heights().len(), w * h);
            assert!(dem.lon_step() > 0.0 && dem.lat_step() > 0.0);
            assert!((-180.0..180.0).contains(&dem.lon_first()));
            let stats = dem.stats();
            assert!(stats.valid > 0);
            assert_eq!(stats.valid + stats.missing, w * h);
            for (lat, lon) in [(0.0, 0.0), (45.0, -170.0), (-89.0, 359.0), (91.0, 1e6)] {
                if let Some(v) = dem.sample_bilinear(lat, lon) {
                    assert!(v.is_finite());
                }
            }
        }
        Err(e) => {
            assert_eq!(e.file(), "mutant.cdf");
            assert!(e.to_string().starts_with("mutant.cdf: "), "{e}");
        }
    }
}

#[test]
fn every_header_word_set_to_extreme_values() {
    for at in (0..HEADER).step_by(4) {
        for value in [0u32, 1, 2, 0x7F, 0x7FFF_FFFF, 0x8000_0000, 0xFFFF_FFFF, 0x0001_0000] {
            let mut b = fixture().to_vec();
            b[at..at + 4].copy_from_slice(&value.to_be_bytes());
            read_and_check(b);
        }
    }
}

#[test]
fn every_header_byte_flipped() {
    for at in 0..HEADER {
        for mask in [0x01u8, 0x80, 0xFF] {
            let mut b = fixture().to_vec();
            b[at] ^= mask;
            read_and_check(b);
        }
    }
}

#[test]
fn flipping_height_bytes_changes_heights_not_the_grid() {
    let mut b = fixture().to_vec();
    for at in (ROSE..b.len()).step_by(997) {
        b[at] ^= 0xFF;
    }
    let dem = EquirectDem::from_netcdf_bytes("flipped.cdf", b, None).unwrap();
    assert_eq!((dem.width(), dem.height()), (360, 180));
}

/// One change to the file's bytes.
#[derive(Debug, Clone)]
enum Mutation {
    /// XOR the byte at this position (taken modulo the length) with a mask.
    Flip(usize, u8),
    /// Overwrite the big-endian word at this header position.
    Word(usize, u32),
    /// Keep only this many bytes (taken modulo the length).
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        3 => (0..HEADER, 1..=255u8).prop_map(|(at, mask)| Mutation::Flip(at, mask)),
        1 => (any::<usize>(), 1..=255u8).prop_map(|(at, mask)| Mutation::Flip(at, mask)),
        3 => (0..HEADER / 4, prop_oneof![any::<u32>(), 0..64u32, Just(u32::MAX), Just(0x8000_0000)])
            .prop_map(|(word, v)| Mutation::Word(word * 4, v)),
        1 => any::<usize>().prop_map(Mutation::Truncate),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn mutated_fixtures_never_panic(mutations in prop::collection::vec(mutation(), 1..5)) {
        let mut b = fixture().to_vec();
        for m in mutations {
            if b.is_empty() {
                break;
            }
            match m {
                Mutation::Flip(at, mask) => {
                    let at = at % b.len();
                    b[at] ^= mask;
                }
                Mutation::Word(at, v) => {
                    if at + 4 <= b.len() {
                        b[at..at + 4].copy_from_slice(&v.to_be_bytes());
                    }
                }
                Mutation::Truncate(len) => b.truncate(len % (b.len() + 1)),
            }
        }
        read_and_check(b);
    }
}
