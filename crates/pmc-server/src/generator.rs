//! Chunk generation off the async runtime: a worker pool, a bounded priority queue, in-flight
//! de-duplication, cancellation of jobs nobody waits for any more, and a cache of encoded chunks
//! bounded by bytes.
//!
//! Every job counts the requests waiting for it. Each waiting request holds a [`Waiter`]; when
//! the last one goes away (the client hung up, the request future was dropped) while the job
//! still waits for a worker, the job leaves the queue at once and is never meshed. A job that a
//! worker has started runs to the end and is cached.
//!
//! For the planet being edited, the meshes behind the cached chunks are kept too (in a cache of
//! their own, bounded by bytes): when an edit changes a chunk, its mesh before the edit goes with
//! the edit to the job that meshes the chunk again, which copies the shading of every vertex the
//! edit did not touch instead of shading it anew ([`Planet::chunk_mesh_lod_reusing_into`]; same
//! bytes).

use crate::chunk_cache::ByteCache;
use axum::body::Bytes;
use pmc_edit::BrushOp;
use pmc_formats::chunk_encoding::encode_chunk;
use pmc_geometry::{ChunkKey, SideMask};
use pmc_mesh::ChunkMesh;
use pmc_planet::{ChunkScratch, Planet, TerrainSpec};
use std::cell::RefCell;
use std::cmp::Ordering;
use std::collections::{BTreeMap, HashMap};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use tokio::sync::watch;

/// A planet's identity: preset and seed (the layout is the server's).
/// A planet's identity: its terrain (every planet a server holds shares its layout).
pub(crate) type PlanetId = std::sync::Arc<TerrainSpec>;

/// A chunk of a planet. The key carries the level of detail, so the chunks of every level are
/// distinct entries of the cache and distinct jobs.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) struct ChunkId {
    pub planet: PlanetId,
    pub key: ChunkKey,
    /// The sides whose seams toward a coarser neighbour the mesh closes, normalised to
    /// [`pmc_geometry::Layout::seam_sides`] (so one chunk has at most 8 variants).
    pub seams: SideMask,
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

/// A snapshot of the generator's counters (for `/api/v1/stats`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct JobCounts {
    /// Jobs waiting for a worker.
    pub queued: usize,
    /// Jobs a worker is generating.
    pub running: usize,
    /// Requests waiting for a queued or running job.
    pub waiting: usize,
    /// Jobs a worker ran to the end (whether they succeeded or not).
    pub done: u64,
    /// Jobs that ran to the end and produced a chunk.
    pub generated: u64,
    /// Jobs dropped from the queue, never meshed, because every request waiting for them went
    /// away.
    pub dropped: u64,
    /// Requests refused because the queue was full.
    pub rejected_busy: u64,
    /// Jobs that meshed a chunk again after an edit copying the shading of its mesh before.
    pub reused: u64,
}

/// A job's place in the queue: higher priority first, then older first.
#[derive(Clone, Copy, Debug)]
struct Rank {
    /// Finite, never -0 (so that equal priorities compare equal under `total_cmp`).
    priority: f64,
    /// The job's token: tokens grow with each job, so a lower one is an older job.
    seq: u64,
}

impl Ord for Rank {
    fn cmp(&self, other: &Self) -> Ordering {
        other.priority.total_cmp(&self.priority).then(self.seq.cmp(&other.seq))
    }
}

impl PartialOrd for Rank {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Rank {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Rank {}

/// What a queued job does.
enum Work {
    /// Mesh and encode the job's chunk of `planet`, whose edits are those of `revision`, and
    /// send the outcome on `tx`.
    Chunk {
        planet: Arc<Planet>,
        revision: u64,
        tx: watch::Sender<Option<JobResult>>,
    },
    /// Run a task ([`Generator::task`]); it hands on its outcome itself.
    Task(Box<dyn FnOnce() + Send>),
}

/// Where a job stands.
enum JobState {
    /// Waiting in the queue at `rank`, with what the worker needs.
    Queued { rank: Rank, work: Work },
    /// A worker is running it.
    Running,
}

/// A job: queued or running (a job leaves [`Store::jobs`] when it ends or is dropped).
struct Job {
    /// The chunk it makes (`None` for a task).
    id: Option<ChunkId>,
    /// The receiver its waiters share (a task's waiter waits on its own channel).
    rx: watch::Receiver<Option<JobResult>>,
    /// Requests waiting for it (each holds a [`Waiter`]).
    waiters: usize,
    state: JobState,
}

struct Store {
    cache: ByteCache<ChunkId, Bytes>,
    /// Jobs queued or running, by token.
    jobs: HashMap<u64, Job>,
    /// For each chunk, the token of the job new requests for it join. A job an edit invalidated
    /// is not here any more: it still answers its waiters, but its result is not cached.
    pending: HashMap<ChunkId, u64>,
    /// The queued jobs' tokens, best first.
    queue: BTreeMap<Rank, u64>,
    /// For each chunk an edit changed: the planet revision of that edit. A planet of a lower
    /// revision must not start a job for the chunk (its mesh would be stale).
    changed_at: HashMap<ChunkId, u64>,
    /// For each planet a change may have touched everywhere: the planet revision of that change.
    min_revision: HashMap<PlanetId, u64>,
    /// The meshes of the edited planet's cached chunks (see [`Reuse`]).
    meshes: Option<Reuse>,
    next_token: u64,
    /// The counters (`queued` and `waiting` are counted when a snapshot is taken).
    counts: JobCounts,
}

impl Store {
    /// Removes job `token` from the chunk's pending entry when it is the one registered there.
    fn unregister(&mut self, id: ChunkId, token: u64) {
        if self.pending.get(&id) == Some(&token) {
            self.pending.remove(&id);
        }
    }

    /// Adds a waiter to job `token` (registered in `pending`), raising its priority to
    /// `priority` when it is still queued at a lower one; returns the receiver of its result.
    fn join(&mut self, token: u64, priority: f64) -> watch::Receiver<Option<JobResult>> {
        let Store { jobs, queue, .. } = self;
        let Some(job) = jobs.get_mut(&token) else {
            // `pending` only names jobs that exist; a receiver that never gets a value makes the
            // request fail instead of hanging, should that ever not hold.
            return watch::channel(None).1;
        };
        job.waiters += 1;
        if let JobState::Queued { rank, .. } = &mut job.state {
            if priority > rank.priority {
                queue.remove(&*rank);
                rank.priority = priority;
                queue.insert(*rank, token);
            }
        }
        job.rx.clone()
    }
}

/// What the generator keeps so that meshing a chunk again after an edit can copy the shading of
/// the vertices the edit did not touch.
struct Reuse {
    /// The planet being edited (meshes of other planets are not kept).
    planet: PlanetId,
    /// The meshes behind its cached chunks, of the revision the cache is of.
    meshes: ByteCache<ChunkId, Arc<ChunkMesh>>,
    /// For each chunk an edit changed and no job has meshed since: its mesh before the edit,
    /// the edit, and the revision the edit made (a job of that revision may reuse the mesh).
    /// Bounded like `meshes`: chunks edited and never asked for again do not pile up.
    previous: ByteCache<ChunkId, (Arc<ChunkMesh>, BrushOp, u64)>,
}

/// Bytes a mesh holds (its buffers), for the mesh caches' bound.
fn mesh_bytes(m: &ChunkMesh) -> u64 {
    use std::mem::size_of_val;
    let buffers = size_of_val(m.positions.as_slice())
        + size_of_val(m.positions_low.as_slice())
        + size_of_val(m.normals.as_slice())
        + size_of_val(m.indices.as_slice())
        + size_of_val(m.edge_keys.as_slice())
        + size_of_val(m.heights.as_slice())
        + size_of_val(m.water_depths.as_slice())
        + size_of_val(m.colors.as_slice())
        + size_of_val(m.materials.as_slice())
        + size_of_val(m.vertex_edges.as_slice())
        + size_of_val(m.cube_runs.as_slice());
    (buffers + std::mem::size_of::<ChunkMesh>()) as u64
}

/// Generates, de-duplicates and caches encoded chunks.
pub(crate) struct Generator {
    store: Mutex<Store>,
    pool: rayon::ThreadPool,
    queue_limit: usize,
}

/// A request's hold on a job: dropping it (when the request ends, answered or abandoned) tells
/// the generator that one waiter fewer wants the job.
struct Waiter<'a> {
    generator: &'a Generator,
    token: u64,
}

impl Drop for Waiter<'_> {
    fn drop(&mut self) {
        self.generator.leave(self.token);
    }
}

thread_local! {
    static SCRATCH: RefCell<ChunkScratch> = RefCell::new(ChunkScratch::default());
}

/// Meshes and encodes one chunk (on a worker thread), reusing the shading of `previous` (the
/// chunk's mesh before the edit given with it) where the edit did not reach.
fn generate(
    planet: &Planet,
    key: ChunkKey,
    seams: SideMask,
    previous: Option<&(Arc<ChunkMesh>, BrushOp)>,
) -> Result<(Bytes, ChunkMesh), String> {
    let mut mesh = ChunkMesh::default();
    SCRATCH.with(|s| {
        let scratch = &mut s.borrow_mut();
        match previous {
            Some((previous, op)) => planet.chunk_mesh_lod_reusing_into(key, seams, previous, op, scratch, &mut mesh),
            None => planet.chunk_mesh_lod_into(key, seams, scratch, &mut mesh),
        }
    });
    let mut out = Vec::new();
    encode_chunk(&mesh, &mut out).map_err(|e| e.to_string())?;
    Ok((Bytes::from(out), mesh))
}

impl Generator {
    /// A generator with `threads` workers (0: one per core), at most `queue_limit` waiting jobs
    /// and `cache_bytes` of cache; with `edited`, the planet being edited and the bytes of its
    /// meshes kept for reusing their shading after an edit (half for the current meshes, half for
    /// those before an edit that no job has meshed again yet).
    pub fn new(
        threads: usize,
        queue_limit: usize,
        cache_bytes: u64,
        edited: Option<(PlanetId, u64)>,
    ) -> Result<Generator, String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("pmc-chunk-{i}"))
            .build()
            .map_err(|e| e.to_string())?;
        Ok(Generator {
            store: Mutex::new(Store {
                cache: ByteCache::new(cache_bytes),
                jobs: HashMap::new(),
                pending: HashMap::new(),
                queue: BTreeMap::new(),
                changed_at: HashMap::new(),
                min_revision: HashMap::new(),
                meshes: edited.map(|(planet, bytes)| Reuse {
                    planet,
                    meshes: ByteCache::new(bytes / 2),
                    previous: ByteCache::new(bytes / 2),
                }),
                next_token: 0,
                counts: JobCounts::default(),
            }),
            pool,
            queue_limit,
        })
    }

    fn store(&self) -> MutexGuard<'_, Store> {
        self.store.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The encoded chunk `id` of `planet`, whose edits are those of `revision` (0 for a planet
    /// that is never edited): from the cache, from a job already queued or running for it, or
    /// from a new job (refused with [`ChunkError::Busy`] when the queue is full, and with
    /// [`ChunkError::Stale`] when an edit of a later revision changed the chunk: the caller
    /// takes the current planet and asks again). `id.key` must be a chunk of the planet's layout.
    ///
    /// Queued jobs are served highest `priority` first (a finite number; a request joining a
    /// queued job raises the job to its priority), equal priorities oldest first. Dropping the
    /// returned future before it completes withdraws the request: a queued job that no request
    /// waits for any more is dropped without being meshed.
    pub async fn chunk(
        self: &Arc<Self>,
        planet: Arc<Planet>,
        revision: u64,
        id: ChunkId,
        priority: f64,
    ) -> Result<Bytes, ChunkError> {
        // -0 and +0 are one priority.
        let priority = priority + 0.0;
        let (rx, token) = {
            let mut store = self.store();
            if let Some(bytes) = store.cache.get(&id) {
                return Ok(bytes.clone());
            }
            match store.pending.get(&id).copied() {
                Some(token) => {
                    let rx = store.join(token, priority);
                    (rx, token)
                }
                None => {
                    let changed = store.changed_at.get(&id).copied().unwrap_or(0);
                    let everywhere = store.min_revision.get(&id.planet).copied().unwrap_or(0);
                    if changed.max(everywhere) > revision {
                        return Err(ChunkError::Stale);
                    }
                    if store.queue.len() >= self.queue_limit {
                        store.counts.rejected_busy += 1;
                        return Err(ChunkError::Busy);
                    }
                    let (tx, rx) = watch::channel(None);
                    let work = Work::Chunk { planet, revision, tx };
                    let token = self.enqueue(&mut store, priority, Some(id.clone()), rx.clone(), work);
                    store.pending.insert(id, token);
                    (rx, token)
                }
            }
        };
        self.outcome(rx, token, "the generation job was dropped").await
    }

    /// Queues job `work` (of chunk `id`, `None` for a task) at `priority`, its waiters sharing
    /// `rx`, and starts a worker task for it; returns its token. One worker task per queued job:
    /// each takes the best job queued when it starts, or nothing when dropped jobs left the
    /// queue shorter.
    fn enqueue(
        self: &Arc<Self>,
        store: &mut Store,
        priority: f64,
        id: Option<ChunkId>,
        rx: watch::Receiver<Option<JobResult>>,
        work: Work,
    ) -> u64 {
        let token = store.next_token;
        store.next_token += 1;
        let rank = Rank { priority, seq: token };
        store.queue.insert(rank, token);
        let state = JobState::Queued { rank, work };
        store.jobs.insert(
            token,
            Job {
                id,
                rx,
                waiters: 1,
                state,
            },
        );
        let this = Arc::clone(self);
        self.pool.spawn(move || this.work());
        token
    }

    /// The outcome of job `token`, waited for on `rx` (`dropped` when the job ended without
    /// one). Dropping this future (the request went away) lets go of the job.
    async fn outcome(
        &self,
        mut rx: watch::Receiver<Option<JobResult>>,
        token: u64,
        dropped: &str,
    ) -> Result<Bytes, ChunkError> {
        let _waiter = Waiter { generator: self, token };
        let result = match rx.wait_for(Option::is_some).await {
            Ok(r) => r.clone(),
            Err(_) => None,
        };
        match result {
            Some(Ok(bytes)) => Ok(bytes),
            Some(Err(e)) => Err(ChunkError::Failed(e)),
            None => Err(ChunkError::Failed(dropped.into())),
        }
    }

    /// One waiter of job `token` went away (answered or not): when it was the last and the job
    /// is still queued, the job is dropped.
    fn leave(&self, token: u64) {
        let mut store = self.store();
        let Some(job) = store.jobs.get_mut(&token) else {
            // The job ended: nothing to do.
            return;
        };
        job.waiters = job.waiters.saturating_sub(1);
        if job.waiters > 0 {
            return;
        }
        let rank = match &job.state {
            JobState::Queued { rank, .. } => *rank,
            JobState::Running => return,
        };
        let id = job.id.clone();
        store.queue.remove(&rank);
        store.jobs.remove(&token);
        if let Some(id) = id {
            store.unregister(id, token);
        }
        store.counts.dropped += 1;
    }

    /// Forgets what an edit of `revision` changed: the cached meshes of `ids` and the jobs
    /// queued or running for them (their waiters still get their answer, but it is not cached),
    /// and makes planets older than `revision` unable to start jobs for them. Call it after the
    /// edited planet replaced the old one, before telling clients.
    ///
    /// With the edit `op` that made `revision` (applied, undone or redone), the meshes of `ids`
    /// kept for the edited planet go to the jobs of `revision` that mesh them again, for their
    /// shading.
    pub fn invalidate(&self, ids: impl IntoIterator<Item = ChunkId>, revision: u64, op: Option<&BrushOp>) {
        let mut guard = self.store();
        let store = &mut *guard;
        for id in ids {
            store.cache.remove(&id);
            store.pending.remove(&id);
            if let Some(reuse) = &mut store.meshes {
                // A mesh from before an earlier edit that no job has replaced is no longer the
                // mesh before this one.
                let before = reuse.meshes.remove(&id);
                match (before, op) {
                    (Some(mesh), Some(op)) => {
                        let size = mesh_bytes(&mesh);
                        reuse.previous.insert(id.clone(), (mesh, *op, revision), size);
                    }
                    _ => {
                        reuse.previous.remove(&id);
                    }
                }
            }
            let at = store.changed_at.entry(id).or_insert(revision);
            *at = (*at).max(revision);
        }
    }

    /// One worker task: takes the best queued job, if any is left, and runs it: generate, cache,
    /// wake the waiters.
    fn work(&self) {
        let (token, id, planet, previous, tx) = {
            let mut guard = self.store();
            let store = &mut *guard;
            let Some((_, token)) = store.queue.pop_first() else {
                return;
            };
            let Some(job) = store.jobs.get_mut(&token) else {
                return;
            };
            let (planet, revision, tx) = match std::mem::replace(&mut job.state, JobState::Running) {
                JobState::Queued {
                    work: Work::Chunk { planet, revision, tx },
                    ..
                } => (planet, revision, tx),
                JobState::Queued {
                    work: Work::Task(task), ..
                } => {
                    store.counts.running += 1;
                    drop(guard);
                    self.run_task(token, task);
                    return;
                }
                JobState::Running => return,
            };
            let Some(id) = job.id.clone() else {
                return;
            };
            // The mesh before the edit of this job's revision, when it is kept.
            let previous = store.meshes.as_ref().and_then(|r| {
                r.previous
                    .get(&id)
                    .filter(|(_, _, at)| *at == revision)
                    .map(|(mesh, op, _)| (Arc::clone(mesh), *op))
            });
            store.counts.running += 1;
            store.counts.reused += u64::from(previous.is_some());
            (token, id, planet, previous, tx)
        };
        let generated = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            generate(&planet, id.key, id.seams, previous.as_ref())
        }));
        let (result, mesh): (JobResult, Option<ChunkMesh>) = match generated {
            Ok(Ok((bytes, mesh))) => (Ok(bytes), Some(mesh)),
            Ok(Err(e)) => (Err(format!("chunk {} could not be encoded: {e}", id.key).into()), None),
            Err(_) => (
                Err(format!("generating chunk {} panicked; this is a bug in pmc", id.key).into()),
                None,
            ),
        };
        {
            // Cache and un-register under one lock, so a new request sees one or the other; a
            // job that an edit invalidated meanwhile (it is no longer the registered one) is not
            // cached.
            let mut guard = self.store();
            let store = &mut *guard;
            store.counts.running = store.counts.running.saturating_sub(1);
            store.counts.done += 1;
            if let Ok(bytes) = &result {
                store.counts.generated += 1;
                if store.pending.get(&id) == Some(&token) {
                    store.cache.insert(id.clone(), bytes.clone(), bytes.len() as u64);
                    if let (Some(reuse), Some(mesh)) = (&mut store.meshes, mesh) {
                        if reuse.planet == id.planet {
                            // The chunk is current again: this mesh is the one before its next edit.
                            reuse.previous.remove(&id);
                            let size = mesh_bytes(&mesh);
                            reuse.meshes.insert(id.clone(), Arc::new(mesh), size);
                        }
                    }
                }
            }
            store.unregister(id, token);
            store.jobs.remove(&token);
        }
        tx.send_replace(Some(result));
    }

    /// Queues `task` among the chunk jobs, at `priority` (as [`Generator::chunk`]'s): it runs on
    /// one of the same workers, in the same order, and counts in the same counters. Dropping the
    /// returned future before a worker starts the task withdraws it (the task is dropped, never
    /// run); once started it runs to its end. The task hands on what it makes itself (a channel,
    /// a cache). Unlike a chunk it is never refused for a full queue: the clients of tasks (3D
    /// Tiles viewers) do not ask again after a 503, they show a hole.
    pub async fn task(self: &Arc<Self>, priority: f64, task: impl FnOnce() + Send + 'static) -> Result<(), ChunkError> {
        let (tx, rx) = watch::channel(None);
        let done = move || {
            let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(task));
            let outcome = match ran {
                Ok(()) => Ok(Bytes::new()),
                Err(_) => Err(Arc::from("a task panicked; this is a bug in pmc")),
            };
            tx.send_replace(Some(outcome));
        };
        let work = Work::Task(Box::new(done));
        let token = self.enqueue(&mut self.store(), priority + 0.0, None, rx.clone(), work);
        self.outcome(rx, token, "the task was dropped").await.map(drop)
    }

    /// Runs task `token` (a worker took it from the queue; it catches its own panic and hands
    /// on its outcome), then ends the job.
    fn run_task(&self, token: u64, task: Box<dyn FnOnce() + Send>) {
        task();
        let mut store = self.store();
        store.counts.running = store.counts.running.saturating_sub(1);
        store.counts.done += 1;
        store.jobs.remove(&token);
    }

    /// The revision of the latest edit that changed chunk `key` of `planet` (its mesh at any
    /// revision from this one on is the same), 0 when none did since the server started.
    pub fn changed_revision(&self, planet: &PlanetId, key: ChunkKey) -> u64 {
        let store = self.store();
        let id = ChunkId {
            planet: planet.clone(),
            key,
            seams: SideMask(0),
        };
        let changed = store.changed_at.get(&id).copied().unwrap_or(0);
        changed.max(store.min_revision.get(planet).copied().unwrap_or(0))
    }

    /// Drops the cached chunks of `planet`.
    pub fn forget_planet(&self, planet: PlanetId) {
        let mut store = self.store();
        store.cache.retain(|id| id.planet != planet);
        if let Some(reuse) = &mut store.meshes {
            reuse.meshes.retain(|id| id.planet != planet);
            reuse.previous.retain(|id| id.planet != planet);
        }
    }

    /// Forgets every cached chunk and queued or running job of `planet` and makes planets older
    /// than `revision` unable to start jobs for it (after a change that may touch any chunk).
    pub fn invalidate_planet(&self, planet: PlanetId, revision: u64) {
        let mut store = self.store();
        store.cache.retain(|id| id.planet != planet);
        if let Some(reuse) = &mut store.meshes {
            reuse.meshes.retain(|id| id.planet != planet);
            reuse.previous.retain(|id| id.planet != planet);
        }
        store.pending.retain(|id, _| id.planet != planet);
        store.changed_at.retain(|id, _| id.planet != planet);
        store.min_revision.insert(planet, revision);
    }

    /// Cached chunks and their bytes.
    pub fn cache_usage(&self) -> (usize, u64) {
        let store = self.store();
        (store.cache.len(), store.cache.bytes())
    }

    /// The job counters now.
    pub fn job_counts(&self) -> JobCounts {
        let store = self.store();
        JobCounts {
            queued: store.queue.len(),
            waiting: store.jobs.values().map(|j| j.waiters).sum(),
            ..store.counts
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn higher_priority_ranks_first_then_older() {
        let r = |priority: f64, seq: u64| Rank { priority, seq };
        let mut q = BTreeMap::new();
        for (i, rank) in [r(0.0, 0), r(5.0, 1), r(-1.0, 2), r(5.0, 3), r(0.0, 4), r(1e300, 5)]
            .into_iter()
            .enumerate()
        {
            q.insert(rank, i);
        }
        let order: Vec<usize> = q.into_values().collect();
        assert_eq!(order, [5, 1, 3, 0, 4, 2]);
        assert_eq!(r(0.0, 7), r(-0.0 + 0.0, 7));
    }
}
