//! Chunk generation off the async runtime: a worker pool, a bounded queue, in-flight
//! de-duplication and a cache of encoded chunks bounded by bytes.

use crate::lru::ByteLru;
use axum::body::Bytes;
use pmc_formats::chunk_encoding::encode_chunk;
use pmc_geometry::ChunkKey;
use pmc_mesh::ChunkMesh;
use pmc_planet::{ChunkScratch, Planet, PresetKind};
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use tokio::sync::watch;

/// A planet's identity: preset and seed (the layout is the server's).
pub(crate) type PlanetId = (PresetKind, u64);

/// A chunk of a planet.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct ChunkId {
    pub planet: PlanetId,
    pub key: ChunkKey,
}

/// The outcome of one job, shared by every request that waited for it.
type JobResult = Result<Bytes, Arc<str>>;

/// Why a chunk could not be served.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ChunkError {
    /// The queue is full: try again shortly.
    Busy,
    /// The planet given is older than the chunk's last edit: take the current planet and ask again.
    Stale,
    /// Generation failed (a bug); the message says how.
    Failed(Arc<str>),
}

/// Counters for `/api/v1/stats`.
#[derive(Debug, Default)]
pub(crate) struct Counters {
    /// Chunks generated (each generation counted once, however many requests waited for it).
    pub generated: AtomicU64,
    /// Jobs waiting for a worker.
    pub queued: AtomicUsize,
    /// Jobs being generated.
    pub in_flight: AtomicUsize,
    /// Requests answered 503 because the queue was full.
    pub rejected_busy: AtomicU64,
}

/// A job registered for a chunk: its token (to tell it from a later job for the same chunk) and
/// the receiver its waiters share.
struct Pending {
    token: u64,
    rx: watch::Receiver<Option<JobResult>>,
}

struct Store {
    cache: ByteLru<ChunkId, Bytes>,
    pending: HashMap<ChunkId, Pending>,
    /// For each chunk an edit changed: the planet revision of that edit. A planet of a lower
    /// revision must not start a job for the chunk (its mesh would be stale).
    changed_at: HashMap<ChunkId, u64>,
    /// For each planet a change may have touched everywhere: the planet revision of that change.
    min_revision: HashMap<PlanetId, u64>,
    next_token: u64,
}

/// Generates, de-duplicates and caches encoded chunks.
pub(crate) struct Generator {
    store: Mutex<Store>,
    pool: rayon::ThreadPool,
    queue_limit: usize,
    /// The counters.
    pub counters: Counters,
}

thread_local! {
    static SCRATCH: RefCell<ChunkScratch> = RefCell::new(ChunkScratch::default());
}

/// Meshes and encodes one chunk (on a worker thread).
fn generate(planet: &Planet, key: ChunkKey) -> Result<Bytes, String> {
    let mut mesh = ChunkMesh::default();
    SCRATCH.with(|s| planet.chunk_mesh_into(key, &mut s.borrow_mut(), &mut mesh));
    let mut out = Vec::new();
    encode_chunk(&mesh, &mut out).map_err(|e| e.to_string())?;
    Ok(Bytes::from(out))
}

impl Generator {
    /// A generator with `threads` workers (0: one per core), at most `queue_limit` waiting jobs
    /// and `cache_bytes` of cache.
    pub fn new(threads: usize, queue_limit: usize, cache_bytes: u64) -> Result<Generator, String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("pmc-chunk-{i}"))
            .build()
            .map_err(|e| e.to_string())?;
        Ok(Generator {
            store: Mutex::new(Store {
                cache: ByteLru::new(cache_bytes),
                pending: HashMap::new(),
                changed_at: HashMap::new(),
                min_revision: HashMap::new(),
                next_token: 0,
            }),
            pool,
            queue_limit,
            counters: Counters::default(),
        })
    }

    fn store(&self) -> MutexGuard<'_, Store> {
        self.store.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The encoded chunk `id` of `planet`, whose edits are those of `revision` (0 for a planet
    /// that is never edited): from the cache, from a job already running for it, or from a new
    /// job (refused with [`ChunkError::Busy`] when the queue is full, and with
    /// [`ChunkError::Stale`] when an edit of a later revision changed the chunk: the caller
    /// takes the current planet and asks again). `id.key` must be a chunk of the planet's layout.
    pub async fn chunk(self: &Arc<Self>, planet: Arc<Planet>, revision: u64, id: ChunkId) -> Result<Bytes, ChunkError> {
        let mut rx = {
            let mut store = self.store();
            if let Some(bytes) = store.cache.get(&id) {
                return Ok(bytes.clone());
            }
            match store.pending.get(&id) {
                Some(p) => p.rx.clone(),
                None => {
                    let changed = store.changed_at.get(&id).copied().unwrap_or(0);
                    let everywhere = store.min_revision.get(&id.planet).copied().unwrap_or(0);
                    if changed.max(everywhere) > revision {
                        return Err(ChunkError::Stale);
                    }
                    if self.counters.queued.load(Ordering::SeqCst) >= self.queue_limit {
                        self.counters.rejected_busy.fetch_add(1, Ordering::Relaxed);
                        return Err(ChunkError::Busy);
                    }
                    let (tx, rx) = watch::channel(None);
                    let token = store.next_token;
                    store.next_token += 1;
                    store.pending.insert(id, Pending { token, rx: rx.clone() });
                    self.counters.queued.fetch_add(1, Ordering::SeqCst);
                    let this = Arc::clone(self);
                    self.pool.spawn(move || this.run_job(&planet, id, token, tx));
                    rx
                }
            }
        };
        let result = match rx.wait_for(Option::is_some).await {
            Ok(r) => r.clone(),
            Err(_) => None,
        };
        match result {
            Some(Ok(bytes)) => Ok(bytes),
            Some(Err(e)) => Err(ChunkError::Failed(e)),
            None => Err(ChunkError::Failed("the generation job was dropped".into())),
        }
    }

    /// Forgets what an edit of `revision` changed: the cached meshes of `ids` and the jobs
    /// running for them (their waiters still get their answer, but it is not cached), and makes
    /// planets older than `revision` unable to start jobs for them. Call it after the edited
    /// planet replaced the old one, before telling clients.
    pub fn invalidate(&self, ids: impl IntoIterator<Item = ChunkId>, revision: u64) {
        let mut store = self.store();
        for id in ids {
            store.cache.remove(&id);
            store.pending.remove(&id);
            let at = store.changed_at.entry(id).or_insert(revision);
            *at = (*at).max(revision);
        }
    }

    /// Runs one job on a worker: generate, cache, wake the waiters.
    fn run_job(&self, planet: &Planet, id: ChunkId, token: u64, tx: watch::Sender<Option<JobResult>>) {
        self.counters.queued.fetch_sub(1, Ordering::SeqCst);
        self.counters.in_flight.fetch_add(1, Ordering::SeqCst);
        let result: JobResult =
            match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| generate(planet, id.key))) {
                Ok(Ok(bytes)) => Ok(bytes),
                Ok(Err(e)) => Err(format!("chunk {} could not be encoded: {e}", id.key).into()),
                Err(_) => Err(format!("generating chunk {} panicked; this is a bug in pmc", id.key).into()),
            };
        self.counters.in_flight.fetch_sub(1, Ordering::SeqCst);
        if result.is_ok() {
            self.counters.generated.fetch_add(1, Ordering::Relaxed);
        }
        {
            // Cache and un-register under one lock, so a new request sees one or the other; a
            // job that an edit invalidated meanwhile (it is no longer the registered one) is not
            // cached.
            let mut store = self.store();
            if store.pending.get(&id).is_some_and(|p| p.token == token) {
                if let Ok(bytes) = &result {
                    store.cache.insert(id, bytes.clone(), bytes.len() as u64);
                }
                store.pending.remove(&id);
            }
        }
        tx.send_replace(Some(result));
    }

    /// Drops the cached chunks of `planet`.
    pub fn forget_planet(&self, planet: PlanetId) {
        self.store().cache.retain(|id| id.planet != planet);
    }

    /// Forgets every cached chunk and running job of `planet` and makes planets older than
    /// `revision` unable to start jobs for it (after a change that may touch any chunk).
    pub fn invalidate_planet(&self, planet: PlanetId, revision: u64) {
        let mut store = self.store();
        store.cache.retain(|id| id.planet != planet);
        store.pending.retain(|id, _| id.planet != planet);
        store.changed_at.retain(|id, _| id.planet != planet);
        store.min_revision.insert(planet, revision);
    }

    /// Cached chunks and their bytes.
    pub fn cache_usage(&self) -> (usize, u64) {
        let store = self.store();
        (store.cache.len(), store.cache.bytes())
    }
}
