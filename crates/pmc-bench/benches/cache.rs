//! The bounded caches on their own: the planet's base density cache (`pmc-planet`, chunks by
//! count) and the server's chunk cache (`pmc-server`, encoded chunks by bytes), each compiled
//! here from its crate's source so that the bench sees exactly the code the crate runs.
//!
//! - `hit`: every lookup finds its entry (1 024 held, looked up in a scrambled order).
//! - `miss_insert`: every lookup misses and the value is then stored, evicting one (4 096 keys
//!   cycled through a cache of 1 024).
//!
//! Times are per operation (one lookup, or one lookup and one insert).
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pmc_geometry::{ChunkKey, Face};
use std::hint::black_box;
use std::sync::Arc;

#[allow(dead_code, unused_imports)]
#[path = "../../pmc-planet/src/cache.rs"]
mod base_cache;

#[allow(dead_code, unused_imports)]
#[path = "../../pmc-server/src/chunk_cache.rs"]
mod chunk_cache;

/// Entries a cache holds.
const HELD: u32 = 1024;
/// Keys cycled through by the miss benchmarks.
const CYCLED: u32 = 4 * HELD;
/// Bytes of one encoded chunk in the chunk cache benchmarks.
const CHUNK_BYTES: u64 = 20_000;

/// Key `n` of a scrambled sequence of distinct keys.
fn key(n: u32) -> ChunkKey {
    let face = Face::ALL[(n % 6) as usize];
    ChunkKey::new(face, (n / 6) % 64, (n / 384) % 64, n / 24_576)
}

/// A permutation of `0..n` (multiplication by an odd number modulo a power of two).
fn scrambled(n: u32) -> Vec<u32> {
    assert!(n.is_power_of_two());
    (0..n).map(|i| i.wrapping_mul(2_654_435_761) & (n - 1)).collect()
}

fn cache(c: &mut Criterion) {
    let batch: Arc<[f32]> = Arc::from(vec![1.0f32; 16]);
    let order = scrambled(HELD);
    let mut g = c.benchmark_group("cache");
    g.throughput(Throughput::Elements(HELD as u64));

    let base = base_cache::BaseCache::new(HELD as usize);
    for n in 0..HELD {
        base.insert(key(n), batch.clone());
    }
    g.bench_function("base/hit", |b| {
        b.iter(|| {
            for n in &order {
                black_box(base.get(&key(*n)));
            }
        })
    });
    let mut next = 0u32;
    g.bench_function("base/miss_insert", |b| {
        b.iter(|| {
            for _ in 0..HELD {
                let k = key(HELD + next % CYCLED);
                next = next.wrapping_add(1);
                if base.get(&k).is_none() {
                    base.insert(k, batch.clone());
                }
            }
        })
    });

    let bytes: Arc<[u8]> = Arc::from(vec![0u8; 16]);
    let mut chunks = chunk_cache::ByteCache::new(u64::from(HELD) * CHUNK_BYTES);
    for n in 0..HELD {
        chunks.insert(key(n), bytes.clone(), CHUNK_BYTES);
    }
    g.bench_function("chunks/hit", |b| {
        b.iter(|| {
            for n in &order {
                black_box(chunks.get(&key(*n)));
            }
        })
    });
    let mut next = 0u32;
    g.bench_function("chunks/miss_insert", |b| {
        b.iter(|| {
            for _ in 0..HELD {
                let k = key(HELD + next % CYCLED);
                next = next.wrapping_add(1);
                if chunks.get(&k).is_none() {
                    chunks.insert(k, bytes.clone(), CHUNK_BYTES);
                }
            }
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).warm_up_time(std::time::Duration::from_secs(1))
        .measurement_time(std::time::Duration::from_secs(2));
    targets = cache
}
criterion_main!(benches);
