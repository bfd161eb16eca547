//! A bounded cache of the terrain's base density batches, by chunk, shared by a planet's clones.
//!
//! The base terrain never changes (edits apply on top of it), so a chunk's base batch stays valid
//! for the planet's whole life, across every edit, undo and redo. Meshing a chunk again after an
//! edit then pays only for the edits over a copy of the cached batch, not for the terrain noise.

use pmc_geometry::ChunkKey;
use quick_cache::unsync::Cache;
use std::sync::{Arc, Mutex, MutexGuard};

/// How a planet's base density cache is doing: see [`crate::Planet::base_cache_stats`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BaseCacheStats {
    /// Chunks whose base batch is held now (never more than `max_chunks`).
    pub chunks: usize,
    /// The most chunks held at once.
    pub max_chunks: usize,
    /// Bytes held by the batches: `chunks × (n_t + 3)³ × 4`.
    pub bytes: usize,
    /// Lookups that found the chunk's batch, since the cache was made.
    pub hits: u64,
    /// Lookups that did not (the batch was then sampled and stored), since the cache was made.
    pub misses: u64,
}

/// The cache: at most `max_chunks` batches (`quick_cache`, one unit of weight a batch); when
/// full, batches used again are kept over batches used once.
#[derive(Debug)]
pub(crate) struct BaseCache {
    max_chunks: usize,
    inner: Mutex<Inner>,
}

#[derive(Debug)]
struct Inner {
    batches: Cache<ChunkKey, Arc<[f32]>>,
    hits: u64,
    misses: u64,
}

impl BaseCache {
    /// A cache that holds at most `max_chunks` batches (`max_chunks > 0`).
    pub(crate) fn new(max_chunks: usize) -> BaseCache {
        debug_assert!(max_chunks > 0);
        BaseCache {
            max_chunks,
            inner: Mutex::new(Inner {
                batches: Cache::new(max_chunks),
                hits: 0,
                misses: 0,
            }),
        }
    }

    /// The lock; a panic while it was held cannot leave the cache inconsistent (its updates do
    /// not call back into code that could panic), so a poisoned lock is taken as is.
    fn lock(&self) -> MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The batch of `key`, if held, marked as used. The caller copies it outside the lock.
    pub(crate) fn get(&self, key: &ChunkKey) -> Option<Arc<[f32]>> {
        let mut inner = self.lock();
        let found = inner.batches.get(key).cloned();
        match found {
            Some(_) => inner.hits += 1,
            None => inner.misses += 1,
        }
        found
    }

    /// Stores the batch of `key` (built by the caller outside the lock), dropping others beyond
    /// `max_chunks`. Another thread may have stored the same batch meanwhile (same bits: the
    /// base is a pure function of the key); it is replaced.
    pub(crate) fn insert(&self, key: ChunkKey, batch: Arc<[f32]>) {
        self.lock().batches.insert(key, batch);
    }

    /// Counts and sizes.
    pub(crate) fn stats(&self) -> BaseCacheStats {
        let inner = self.lock();
        BaseCacheStats {
            chunks: inner.batches.len(),
            max_chunks: self.max_chunks,
            bytes: inner.batches.iter().map(|(_, b)| std::mem::size_of_val(&**b)).sum(),
            hits: inner.hits,
            misses: inner.misses,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_geometry::Face;

    fn key(i: u32) -> ChunkKey {
        ChunkKey::new(Face::Top, i, 0, 0)
    }

    fn batch(x: f32) -> Arc<[f32]> {
        Arc::from(vec![x; 4])
    }

    #[test]
    fn keeps_at_most_max_chunks_and_counts_lookups() {
        let c = BaseCache::new(2);
        c.insert(key(0), batch(0.0));
        c.insert(key(1), batch(1.0));
        assert_eq!(c.get(&key(0)).as_deref(), Some(&[0.0f32; 4][..]));
        c.insert(key(2), batch(2.0));
        assert_eq!(
            c.get(&key(2)).as_deref(),
            Some(&[2.0f32; 4][..]),
            "the batch just stored"
        );
        let s = c.stats();
        assert_eq!((s.chunks, s.max_chunks, s.bytes), (2, 2, 2 * 16));
        // Storing a held key again replaces it without growing.
        c.insert(key(2), batch(2.0));
        assert_eq!(c.stats(), s);
        assert!(c.get(&key(7)).is_none());
        let s = c.stats();
        assert_eq!((s.hits, s.misses), (2, 1));
        for i in 3..50 {
            c.insert(key(i), batch(i as f32));
            assert!(c.get(&key(i)).is_some(), "the batch just stored is held");
            let s = c.stats();
            assert!(s.chunks <= 2 && s.bytes == s.chunks * 16, "{s:?}");
        }
    }
}
