//! A cache bounded by the total size of its values, in bytes: `quick_cache`'s weighted cache,
//! each entry weighing the size given when it was stored.

use quick_cache::unsync::Cache;
use quick_cache::Weighter;
use std::hash::Hash;

/// Weighs an entry by the size stored with it.
#[derive(Clone, Copy, Debug, Default)]
struct BySize;

impl<K, V> Weighter<K, (V, u64)> for BySize {
    fn weight(&self, _key: &K, value: &(V, u64)) -> u64 {
        value.1
    }
}

/// A map that keeps its values' total size (as given on insert) at most `limit`. When it is
/// full, entries used again since they were stored are kept over entries used once
/// (`quick_cache`'s CLOCK-PRO policy). A value larger than 97 % of `limit` is not kept at all.
#[derive(Debug)]
pub(crate) struct ByteCache<K, V> {
    cache: Cache<K, (V, u64), BySize>,
}

/// Entries expected per byte of the limit when sizing the index (chunks are tens of kilobytes).
const BYTES_PER_ENTRY: u64 = 16 * 1024;

impl<K: Hash + Eq, V> ByteCache<K, V> {
    /// An empty map holding at most `limit` bytes.
    pub fn new(limit: u64) -> Self {
        let entries = (limit / BYTES_PER_ENTRY).clamp(16, 1 << 20) as usize;
        ByteCache {
            cache: Cache::with_weighter(entries, limit, BySize),
        }
    }

    /// The value of `key`, marking it as used.
    pub fn get(&self, key: &K) -> Option<&V> {
        self.cache.get(key).map(|(value, _)| value)
    }

    /// Inserts (or replaces) `key`, dropping other entries until the total fits.
    pub fn insert(&mut self, key: K, value: V, size: u64) {
        self.cache.insert(key, (value, size));
    }

    /// Removes `key`.
    pub fn remove(&mut self, key: &K) -> Option<V> {
        self.cache.remove(key).map(|(_, (value, _))| value)
    }

    /// Keeps only the entries whose key satisfies `keep`.
    pub fn retain(&mut self, keep: impl Fn(&K) -> bool) {
        self.cache.retain(|key, _| keep(key));
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.cache.len()
    }

    /// Total size of the entries.
    pub fn bytes(&self) -> u64 {
        self.cache.weight()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stays_within_its_byte_bound() {
        let mut c = ByteCache::new(10);
        c.insert("a", 1, 4);
        assert_eq!(c.get(&"a"), Some(&1));
        c.insert("b", 2, 4);
        c.insert("c", 3, 4); // 12 > 10: one goes
        assert_eq!((c.len(), c.bytes()), (2, 8));
        assert_eq!(c.get(&"c"), Some(&3), "the entry just stored is kept");
        c.insert("big", 9, 11); // larger than the limit: not kept
        assert!(c.get(&"big").is_none());
        assert_eq!(c.bytes(), 8);
        c.insert("c", 5, 2); // replace
        assert_eq!(c.bytes(), 6);
        assert_eq!(c.get(&"c"), Some(&5));
        c.retain(|k| *k == "c");
        assert_eq!((c.len(), c.bytes()), (1, 2));
        assert_eq!(c.remove(&"c"), Some(5));
        assert_eq!((c.len(), c.bytes()), (0, 0));
        for n in 0..100 {
            c.insert(if n % 2 == 0 { "x" } else { "y" }, n, 3 + n % 4);
            assert!(c.bytes() <= 10, "{}", c.bytes());
        }
    }

    #[test]
    fn a_limit_of_zero_keeps_nothing() {
        let mut c = ByteCache::new(0);
        c.insert(1, 1, 1);
        assert_eq!((c.len(), c.bytes()), (0, 0));
    }
}
