//! Which tiles of a subtree are there: one bit per tile, in level order and Morton order within
//! a level.

/// A set of tiles of a subtree, one bit each.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Bits {
    bytes: Vec<u8>,
    len: usize,
}

impl Bits {
    /// `len` zero bits.
    pub fn zeros(len: usize) -> Bits {
        Bits {
            bytes: vec![0; len.div_ceil(8)],
            len,
        }
    }

    /// Sets bit `n`.
    pub fn set(&mut self, n: usize) {
        self.bytes[n / 8] |= 1 << (n % 8);
    }

    /// Bit `n`.
    pub fn get(&self, n: usize) -> bool {
        n < self.len && self.bytes[n / 8] >> (n % 8) & 1 == 1
    }

    /// How many bits are set.
    pub fn count(&self) -> usize {
        self.bytes.iter().map(|b| b.count_ones() as usize).sum()
    }

    /// The number of bits.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the stream has no bit.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}
