//! A least-recently-used map bounded by the total size of its values.

use std::collections::{BTreeMap, HashMap};
use std::hash::Hash;

/// A map that keeps its values' total size (as given on insert) at most `limit`, dropping the
/// least recently used entries first. Values larger than `limit` are not kept at all.
#[derive(Debug)]
pub(crate) struct ByteLru<K, V> {
    map: HashMap<K, Entry<V>>,
    /// Use tick -> key, oldest first.
    order: BTreeMap<u64, K>,
    tick: u64,
    bytes: u64,
    limit: u64,
}

#[derive(Debug)]
struct Entry<V> {
    value: V,
    size: u64,
    tick: u64,
}

impl<K: Hash + Eq + Clone, V> ByteLru<K, V> {
    /// An empty map holding at most `limit` bytes.
    pub fn new(limit: u64) -> Self {
        ByteLru {
            map: HashMap::new(),
            order: BTreeMap::new(),
            tick: 0,
            bytes: 0,
            limit,
        }
    }

    fn next_tick(&mut self) -> u64 {
        self.tick += 1;
        self.tick
    }

    /// The value of `key`, marking it as just used.
    pub fn get(&mut self, key: &K) -> Option<&V> {
        let tick = self.next_tick();
        let e = self.map.get_mut(key)?;
        self.order.remove(&e.tick);
        e.tick = tick;
        self.order.insert(tick, key.clone());
        Some(&e.value)
    }

    /// Inserts (or replaces) `key`, then drops the oldest entries until the total fits.
    pub fn insert(&mut self, key: K, value: V, size: u64) {
        self.remove(&key);
        if size > self.limit {
            return;
        }
        let tick = self.next_tick();
        self.order.insert(tick, key.clone());
        self.map.insert(key, Entry { value, size, tick });
        self.bytes += size;
        while self.bytes > self.limit {
            let Some((_, oldest)) = self.order.pop_first() else {
                break;
            };
            if let Some(e) = self.map.remove(&oldest) {
                self.bytes -= e.size;
            }
        }
    }

    /// Removes `key`.
    pub fn remove(&mut self, key: &K) -> Option<V> {
        let e = self.map.remove(key)?;
        self.order.remove(&e.tick);
        self.bytes -= e.size;
        Some(e.value)
    }

    /// Keeps only the entries whose key satisfies `keep`.
    pub fn retain(&mut self, mut keep: impl FnMut(&K) -> bool) {
        let gone: Vec<K> = self.map.keys().filter(|k| !keep(k)).cloned().collect();
        for k in gone {
            self.remove(&k);
        }
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.map.len()
    }

    /// Total size of the entries.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn evicts_least_recently_used_by_size() {
        let mut c = ByteLru::new(10);
        c.insert("a", 1, 4);
        c.insert("b", 2, 4);
        assert_eq!(c.get(&"a"), Some(&1)); // a is now newer than b
        c.insert("c", 3, 4); // 12 > 10: b goes
        assert_eq!((c.len(), c.bytes()), (2, 8));
        assert!(c.get(&"b").is_none());
        c.insert("big", 9, 11); // larger than the limit: not kept
        assert!(c.get(&"big").is_none());
        assert_eq!(c.bytes(), 8);
        c.insert("a", 5, 2); // replace
        assert_eq!(c.bytes(), 6);
        assert_eq!(c.get(&"a"), Some(&5));
        c.retain(|k| *k != "c");
        assert_eq!((c.len(), c.bytes()), (1, 2));
        c.insert("d", 0, 10);
        assert_eq!((c.len(), c.bytes()), (1, 10));
    }
}
