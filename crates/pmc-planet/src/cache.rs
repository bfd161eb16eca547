//! A bounded, shared LRU cache of the terrain's base density batches, by chunk.
//!
//! The base terrain never changes (edits apply on top of it), so a chunk's base batch stays valid
//! for the planet's whole life, across every edit, undo and redo. Meshing a chunk again after an
//! edit then pays only for the edits over a copy of the cached batch, not for the terrain noise.

use pmc_geometry::ChunkKey;
use std::collections::{BTreeMap, HashMap};
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

/// The cache: least recently used batches go first once `max_chunks` are held.
#[derive(Debug)]
pub(crate) struct BaseCache {
    max_chunks: usize,
    inner: Mutex<Lru>,
}

#[derive(Debug, Default)]
struct Lru {
    /// Each batch and the tick of its last use.
    map: HashMap<ChunkKey, (Arc<[f32]>, u64)>,
    /// Keys by the tick of their last use: the first is the least recently used.
    order: BTreeMap<u64, ChunkKey>,
    tick: u64,
    bytes: usize,
    hits: u64,
    misses: u64,
}

impl BaseCache {
    /// A cache that holds at most `max_chunks` batches (`max_chunks > 0`).
    pub(crate) fn new(max_chunks: usize) -> BaseCache {
        debug_assert!(max_chunks > 0);
        BaseCache {
            max_chunks,
            inner: Mutex::new(Lru::default()),
        }
    }

    /// The lock; a panic while it was held cannot leave the maps inconsistent (every update
    /// completes before anything that could panic), so a poisoned lock is taken as is.
    fn lock(&self) -> MutexGuard<'_, Lru> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The batch of `key`, if held, marked as just used. The caller copies it outside the lock.
    pub(crate) fn get(&self, key: &ChunkKey) -> Option<Arc<[f32]>> {
        let mut lru = self.lock();
        lru.tick += 1;
        let tick = lru.tick;
        let Some((batch, used)) = lru.map.get_mut(key) else {
            lru.misses += 1;
            return None;
        };
        let (batch, old) = (batch.clone(), std::mem::replace(used, tick));
        lru.order.remove(&old);
        lru.order.insert(tick, *key);
        lru.hits += 1;
        Some(batch)
    }

    /// Stores the batch of `key` (built by the caller outside the lock), dropping the least
    /// recently used batches beyond `max_chunks`.
    pub(crate) fn insert(&self, key: ChunkKey, batch: Arc<[f32]>) {
        let mut lru = self.lock();
        lru.tick += 1;
        let tick = lru.tick;
        let bytes = std::mem::size_of_val(&*batch);
        if let Some((_, old)) = lru.map.insert(key, (batch, tick)) {
            // Another thread stored the same batch meanwhile (same bits: the base is a pure
            // function of the key).
            lru.order.remove(&old);
            lru.bytes -= bytes;
        }
        lru.order.insert(tick, key);
        lru.bytes += bytes;
        while lru.map.len() > self.max_chunks {
            let Some((_, victim)) = lru.order.pop_first() else {
                break;
            };
            if let Some((gone, _)) = lru.map.remove(&victim) {
                lru.bytes -= std::mem::size_of_val(&*gone);
            }
        }
    }

    /// Counts and sizes.
    pub(crate) fn stats(&self) -> BaseCacheStats {
        let lru = self.lock();
        BaseCacheStats {
            chunks: lru.map.len(),
            max_chunks: self.max_chunks,
            bytes: lru.bytes,
            hits: lru.hits,
            misses: lru.misses,
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
    fn keeps_the_most_recently_used_within_its_bound() {
        let c = BaseCache::new(2);
        c.insert(key(0), batch(0.0));
        c.insert(key(1), batch(1.0));
        assert_eq!(c.get(&key(0)).as_deref(), Some(&[0.0f32; 4][..]));
        // Key 1 is now the least recently used: it goes.
        c.insert(key(2), batch(2.0));
        assert!(c.get(&key(1)).is_none());
        assert!(c.get(&key(0)).is_some() && c.get(&key(2)).is_some());
        // Storing a held key again replaces it without growing.
        c.insert(key(2), batch(2.0));
        let s = c.stats();
        assert_eq!((s.chunks, s.max_chunks, s.bytes), (2, 2, 2 * 16));
        assert_eq!((s.hits, s.misses), (3, 1));
        for i in 3..50 {
            c.insert(key(i), batch(i as f32));
            let s = c.stats();
            assert!(s.chunks <= 2 && s.bytes == s.chunks * 16, "{s:?}");
            let lru = c.lock();
            assert_eq!(lru.map.len(), lru.order.len());
        }
    }
}
