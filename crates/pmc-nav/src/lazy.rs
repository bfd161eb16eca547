//! The lazy navigation grid: the same nodes and steps as [`crate::NavGrid`], built tile by tile
//! on first use around a query and kept in a bounded cache, for planets far too large for a
//! whole-planet grid (the Earth at 1 m voxels has about 4e14 columns).
//!
//! # Tiles
//!
//! A tile is a square of `tile_side` columns a side on one face ([`LazyOptions::tile_side`]), the
//! last tile of a face side also holding the face's last column, as [`crate::NavGrid`] cuts its
//! tiles (with `tile_side = n_t` the tiles are exactly its tiles, the chunk footprints). A column
//! on a face edge or a cube corner belongs to the tile of its canonical place
//! ([`crate::ColumnPlace`]). A tile is built from the density alone, so it is the same whenever
//! it is built, in whatever order.
//!
//! By default a tile is 4 columns a side, a sixty-fourth of a chunk footprint at `n_t = 32`: a
//! search reads the columns next to the nodes it expands, so the smaller the tile the less ground
//! it builds beside a path. On the Earth's layout a 10 km walk builds about 80 000 columns in
//! 4-column tiles, 130 000 in 8-column tiles and 440 000 in chunk footprints, for the same path
//! (the `nav_lazy` benchmark).
//!
//! # What is sampled
//!
//! **The window.** The density's [`Density::radial_bounds`] `(lo, hi)` say that everything
//! below `lo` is solid and everything above `hi` air. The window is the layers from one below
//! the last layer under `lo` to one above the first layer over `hi`, within the shell
//! (`0..=D`, at least two layers); without bounds, the whole shell. No layer outside the window
//! can be a floor or change a step, so nothing outside it is sampled.
//!
//! **Whole window** (when it has at most [`LazyOptions::full_window`] layers: every small
//! planet): every layer of the window of every column of the tile, a batch call per row. The tile
//! is then exactly the whole-planet grid's (a test compares nodes, steps and paths).
//!
//! **Band** (larger windows: at the Earth's 1 m layers the window is about 25 000 layers): each
//! column keeps only the layers `t - below ..= t + above` (clipped to the window), where `t` is
//! the column's *top*, its highest solid layer, `below` is [`LazyOptions::below`], and
//! `above = max(climb, drop) + clearance + 1` in layers for the agent. The top is found by
//! sampling a band around a guess and moving it until it holds a solid layer with `above`
//! layers of air over it and `below` layers under it (or the window's end):
//!
//! - the guess is the top of the previous column of the tile (rows in order; the first column
//!   of a row takes the first column of the row before);
//! - the first column of a tile, a column whose band comes out all air, and a column whose
//!   top climbs out of its band twice (a cliff) *probe*: they sample every
//!   [`LazyOptions::probe`]-th layer from the top of the window down and take the highest solid
//!   one as the guess, and their next band reaches four probe strides higher than a guessed one
//!   (the roof over a cave the probe fell through);
//! - every band sample also looks at a few layers above the band, `probe * 2^m` layers over its
//!   top for `m = 0, 1, ...` within the window: a solid one there means solid above the band
//!   (the roof over a cave the guess fell into), and the column probes from the window's top;
//! - after eight attempts the last band sampled is kept.
//!
//! Within the band the occupancy is exact, and every check of Fig. 11 that involves a floor of
//! the band reads only layers of the band: a floor's clearance, and the passage of a step up or
//! down to a neighbouring floor, reach at most `above` layers over the column's top. So every
//! floor in the band, and every step between floors in bands, is exactly as in the whole-planet
//! grid. Not seen: floors more than `below` layers under the top (deep cave floors), and solid
//! that lies more than `above` layers above the top with air between that neither a probe nor
//! the look above the band hits (a floating rock, or ground whose thickness fits between two
//! probes above a cave the guess fell into).
//!
//! # The cache
//!
//! Built tiles are kept in a cache bounded in bytes ([`LazyOptions::cache_bytes`]): each tile
//! counts its buffers (directions, bands, occupancy words and nodes; at the Earth's layout with
//! the default agent and options about 90 bytes a column, 1.4 KiB a tile), and when the total
//! passes the bound the least recently used tiles are dropped, down to 7/8 of the bound (the
//! last one built always stays). The default 256 MiB hold some 190 000 such tiles, 3 million
//! columns. A dropped tile is built again when it is needed, with the same result. A search holds
//! the tiles it is reading at the moment, never the whole region it has seen.
//!
//! # Searches
//!
//! There is no planet-wide component table. A* runs over the tiles as it reaches them
//! ([`LazyGrid::find_path`]) within [`SearchOptions`]: at most so many nodes expanded and tiles
//! built. Meanwhile a search backward from the goal (over the steps into each node) visits the
//! nodes that can reach the goal, one for every four nodes A* expands, up to 1/64 of the node
//! bound (at least 1024). The answer is a path, or [`NoPath::Enclosed`] when either search
//! exhausts a closed region without meeting the other end (no path exists: a sealed cave, an
//! island), or [`NoPath::SearchBound`] when a bound stops the search first (a path may exist).
//! Besides the cache, a search keeps a record (16 bytes) for each node of every tile it reads,
//! so its bounds also bound its memory.

use crate::agent::Agent;
use crate::columns::{ColumnPlace, Columns};
use crate::grid::{NavError, Node, TileKey};
use crate::report::{End, PathAnswer};
use crate::rules::{ColumnView, Rules};
use crate::search::{astar, Halt, Heuristic, NoPath, Outcome, Path, SearchGraph, SearchOptions, SearchStats};
use pmc_density::Density;
use pmc_edit::{affected_chunks, BrushOp};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{Face, Layout};
use std::collections::{HashMap, HashSet, VecDeque};
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::Arc;

/// Options of a [`LazyGrid`]: its tiles, what it samples, and its cache.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LazyOptions {
    /// Columns along a tile's side (at most a face's); 0 takes the chunk footprint (`n_t`).
    /// Smaller tiles build less ground beside a path, larger ones fewer tiles.
    pub tile_side: u32,
    /// Windows of at most this many layers are sampled whole (see the module docs).
    pub full_window: u32,
    /// Layers kept under a column's top in band sampling: floors deeper than this under the
    /// top (cave floors) are not seen.
    pub below: u32,
    /// Stride in layers of the probe that finds a column's top without a guess (at least 1).
    pub probe: u32,
    /// Most bytes of tiles the cache holds (at least one tile is always held).
    pub cache_bytes: usize,
}

impl Default for LazyOptions {
    /// Tiles of 4 columns a side, whole windows up to 512 layers, 32 layers under the top,
    /// probes every 16 layers, a 256 MiB cache.
    fn default() -> Self {
        LazyOptions {
            tile_side: 4,
            full_window: 512,
            below: 32,
            probe: 16,
            cache_bytes: 256 << 20,
        }
    }
}

/// A node of the lazy grid: a floor of a column, named by the column's canonical place and the
/// floor's layer. Unlike [`crate::NodeId`] it does not depend on which tiles are built.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeKey {
    /// The column.
    pub column: ColumnPlace,
    /// The floor's layer.
    pub layer: u32,
}

/// What the tile cache holds and has done.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CacheStats {
    /// Tiles held.
    pub tiles: usize,
    /// Bytes held (the sum of the tiles' sizes).
    pub bytes: usize,
    /// The bound on bytes held.
    pub max_bytes: usize,
    /// Tiles built since the grid was made (rebuilds included).
    pub built: u64,
    /// Tiles dropped to keep within the bound.
    pub evicted: u64,
}

/// What a query of the lazy grid found, and what the search did.
#[derive(Clone, Debug, PartialEq)]
pub struct LazyAnswer {
    /// The answer: a path, no path (with why), or no ground near an end.
    pub answer: PathAnswer<NodeKey>,
    /// The search's counts (tiles built to find the ends included).
    pub stats: SearchStats,
}

/// A small, fast hasher for tile keys and node references (keys are not chosen by an
/// adversary).
#[derive(Clone, Copy, Default)]
struct FxHasher(u64);

impl FxHasher {
    #[inline]
    fn add(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl Hasher for FxHasher {
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.add(u64::from(*b));
        }
    }
    fn write_u8(&mut self, x: u8) {
        self.add(u64::from(x));
    }
    fn write_u32(&mut self, x: u32) {
        self.add(u64::from(x));
    }
    fn write_u64(&mut self, x: u64) {
        self.add(x);
    }
    fn write_i64(&mut self, x: i64) {
        self.add(x as u64);
    }
    fn write_usize(&mut self, x: usize) {
        self.add(x as u64);
    }
    fn write_isize(&mut self, x: isize) {
        self.add(x as u64);
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

type Fx = BuildHasherDefault<FxHasher>;

/// One built tile: its columns (a rectangle of the face, unowned slots empty), their bands and
/// floors.
#[derive(Debug)]
struct Tile {
    face: Face,
    /// Face grid indices of slot 0, and the rectangle's width.
    i0: i64,
    j0: i64,
    w: i64,
    /// Unit direction of each slot's column.
    dirs: Vec<DVec3>,
    /// First layer of each slot's band and its length (0 for slots of columns the tile does
    /// not own).
    base: Vec<i32>,
    len: Vec<u32>,
    /// Start of each slot's words in `words` (one more entry than slots).
    word_start: Vec<u32>,
    words: Vec<u64>,
    /// Start of each slot's floors in `nodes` (one more entry than slots).
    node_start: Vec<u32>,
    nodes: Vec<Node>,
    /// The slot of each node.
    node_slot: Vec<u32>,
}

impl Tile {
    fn slot(&self, place: ColumnPlace) -> usize {
        ((place.j - self.j0) * self.w + (place.i - self.i0)) as usize
    }

    fn place(&self, slot: usize) -> ColumnPlace {
        ColumnPlace {
            face: self.face,
            i: self.i0 + slot as i64 % self.w,
            j: self.j0 + slot as i64 / self.w,
        }
    }

    fn view(&self, slot: usize) -> ColumnView<'_> {
        let (a, b) = (self.word_start[slot] as usize, self.word_start[slot + 1] as usize);
        ColumnView {
            base: i64::from(self.base[slot]),
            len: i64::from(self.len[slot]),
            words: &self.words[a..b],
        }
    }

    fn floors(&self, slot: usize) -> std::ops::Range<usize> {
        self.node_start[slot] as usize..self.node_start[slot + 1] as usize
    }

    /// Bytes held by the tile's buffers.
    fn bytes(&self) -> usize {
        use std::mem::size_of;
        size_of::<Tile>()
            + self.dirs.capacity() * size_of::<DVec3>()
            + self.base.capacity() * size_of::<i32>()
            + self.len.capacity() * size_of::<u32>()
            + self.word_start.capacity() * size_of::<u32>()
            + self.words.capacity() * size_of::<u64>()
            + self.node_start.capacity() * size_of::<u32>()
            + self.nodes.capacity() * size_of::<Node>()
            + self.node_slot.capacity() * size_of::<u32>()
    }
}

/// The tiles held, least recently used first out.
#[derive(Debug)]
struct Cache {
    map: HashMap<TileKey, (Arc<Tile>, u64), Fx>,
    clock: u64,
    bytes: usize,
    max_bytes: usize,
    built: u64,
    evicted: u64,
}

impl Cache {
    fn get(&mut self, key: TileKey) -> Option<Arc<Tile>> {
        self.clock += 1;
        let clock = self.clock;
        self.map.get_mut(&key).map(|(t, stamp)| {
            *stamp = clock;
            t.clone()
        })
    }

    fn insert(&mut self, key: TileKey, tile: Arc<Tile>) {
        self.clock += 1;
        self.built += 1;
        self.bytes += tile.bytes();
        if let Some((old, _)) = self.map.insert(key, (tile, self.clock)) {
            self.bytes -= old.bytes();
        }
        if self.bytes <= self.max_bytes {
            return;
        }
        // Least recently used first, down to 7/8 of the bound: one sort for many inserts.
        let mut order: Vec<(u64, TileKey)> = self
            .map
            .iter()
            .filter(|(k, _)| **k != key)
            .map(|(k, (_, stamp))| (*stamp, *k))
            .collect();
        order.sort_unstable();
        let target = self.max_bytes - self.max_bytes / 8;
        for (_, k) in order {
            if self.bytes <= target {
                break;
            }
            if let Some((t, _)) = self.map.remove(&k) {
                self.bytes -= t.bytes();
                self.evicted += 1;
            }
        }
    }

    fn remove(&mut self, key: &TileKey) -> bool {
        match self.map.remove(key) {
            Some((t, _)) => {
                self.bytes -= t.bytes();
                true
            }
            None => false,
        }
    }

    fn clear(&mut self) {
        self.map.clear();
        self.bytes = 0;
    }
}

/// Layers of slack on either side of a guessed band.
const SLACK: i64 = 4;
/// Band attempts per column before the last band sampled is kept.
const ATTEMPTS: usize = 8;

/// The lazy navigation grid of a planet for one agent (see the module docs).
///
/// ```
/// use pmc_density::Sphere;
/// use pmc_geometry::{glam::DVec3, Layout};
/// use pmc_nav::{Agent, End, LazyGrid, LazyOptions, PathAnswer, SearchOptions};
/// use std::sync::Arc;
/// // A sphere of radius 100 km with 1 m layers: far too many columns for a whole-planet grid.
/// let layout = Layout::new(1 << 12, 32, 99_000.0, 1.0, 64).unwrap();
/// let sphere = Arc::new(Sphere { radius: 100_000.0 });
/// let mut grid = LazyGrid::new(sphere, &layout, Agent::default(), LazyOptions::default()).unwrap();
/// let a = DVec3::new(0.001, 1.0, 0.0);
/// let b = DVec3::new(0.0, 1.0, 0.001); // about 140 m away
/// let found = grid.query(End { dir: a, radius: None }, End { dir: b, radius: None }, 8, &SearchOptions::default());
/// let PathAnswer::Found(path) = found.answer else { panic!() };
/// assert!(path.length > 140.0 && path.length < 210.0);
/// // A few dozen tiles of 4 x 4 columns, of the planet's 6 x 32 768^2.
/// assert!(found.stats.tiles_built < 100);
/// ```
pub struct LazyGrid {
    density: Arc<dyn Density>,
    columns: Columns,
    rules: Rules,
    options: LazyOptions,
    /// Columns along a tile side, and tiles along a face side.
    side: i64,
    per_side: i64,
    /// The window: first and last layer sampled at most.
    window: (i64, i64),
    /// Whether tiles sample the whole window.
    whole: bool,
    /// A lower bound on every node's surface radius.
    r_min: f64,
    cache: Cache,
}

impl std::fmt::Debug for LazyGrid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LazyGrid")
            .field("layout", self.columns.layout())
            .field("agent", &self.rules.agent)
            .field("options", &self.options)
            .field("window", &self.window)
            .field("whole", &self.whole)
            .field("cache", &self.cache_stats())
            .finish()
    }
}

/// The window of layers the radial bounds leave (see the module docs).
fn window(layout: &Layout, bounds: Option<(f64, f64)>) -> (i64, i64) {
    let depth = layout.depth_tiles();
    let (lo, hi) = match bounds {
        Some((lo, hi)) if lo.is_finite() && hi.is_finite() && lo <= hi => (lo, hi),
        _ => return (0, depth),
    };
    let layer = |r: f64| ((r - layout.d_b()) / layout.l_d()).clamp(-1.0, depth as f64 + 1.0);
    let w0 = (layer(lo).floor() as i64 - 1).clamp(0, depth - 1);
    let w1 = (layer(hi).ceil() as i64 + 1).clamp(w0 + 1, depth);
    (w0, w1)
}

impl LazyGrid {
    /// The lazy grid of `density` on `layout` for `agent`. Builds nothing yet.
    pub fn new(
        density: Arc<dyn Density>,
        layout: &Layout,
        agent: Agent,
        options: LazyOptions,
    ) -> Result<LazyGrid, NavError> {
        agent.validate()?;
        if options.probe == 0 {
            return Err(NavError::Options("the probe stride must be at least 1 layer".into()));
        }
        let columns = Columns::new(layout);
        let n = columns.face_tiles();
        let side = if options.tile_side == 0 {
            i64::from(layout.n_t())
        } else {
            i64::from(options.tile_side).min(n)
        };
        let per_side = ((n + side - 1) / side).max(1);
        let mut grid = LazyGrid {
            density,
            columns,
            rules: Rules::new(agent, layout.l_d()),
            options,
            side,
            per_side,
            window: (0, 0),
            whole: true,
            r_min: 0.0,
            cache: Cache {
                map: HashMap::default(),
                clock: 0,
                bytes: 0,
                max_bytes: options.cache_bytes,
                built: 0,
                evicted: 0,
            },
        };
        grid.set_window();
        Ok(grid)
    }

    fn set_window(&mut self) {
        let layout = *self.columns.layout();
        self.window = window(&layout, self.density.radial_bounds());
        self.whole = self.window.1 - self.window.0 < i64::from(self.options.full_window);
        self.r_min = layout.layer_radius(self.window.0);
    }

    /// The agent.
    pub fn agent(&self) -> &Agent {
        &self.rules.agent
    }

    /// The columns.
    pub fn columns(&self) -> &Columns {
        &self.columns
    }

    /// The options.
    pub fn options(&self) -> &LazyOptions {
        &self.options
    }

    /// The window: the first and last layer any column samples (see the module docs).
    pub fn window(&self) -> (i64, i64) {
        self.window
    }

    /// Whether tiles sample their columns' whole window (else a band around each top).
    pub fn samples_whole_window(&self) -> bool {
        self.whole
    }

    /// Layers a band keeps above a column's top: the agent's larger step plus its clearance,
    /// and one.
    pub fn band_above(&self) -> i64 {
        self.rules.reach_above() + 1
    }

    /// Columns along a tile's side.
    pub fn tile_side(&self) -> i64 {
        self.side
    }

    /// The tile that holds the column at canonical place `place`.
    pub fn tile_of(&self, place: ColumnPlace) -> TileKey {
        let t = |x: i64| (x / self.side).min(self.per_side - 1) as u32;
        TileKey {
            face: place.face,
            i: t(place.i),
            j: t(place.j),
        }
    }

    /// The face grid indices a tile spans along one axis.
    fn span(&self, t: u32) -> (i64, i64) {
        let lo = i64::from(t) * self.side;
        let hi = if i64::from(t) == self.per_side - 1 {
            self.columns.face_tiles()
        } else {
            lo + self.side - 1
        };
        (lo, hi)
    }

    /// The cache's counts.
    pub fn cache_stats(&self) -> CacheStats {
        CacheStats {
            tiles: self.cache.map.len(),
            bytes: self.cache.bytes,
            max_bytes: self.cache.max_bytes,
            built: self.cache.built,
            evicted: self.cache.evicted,
        }
    }

    /// The tiles held by the cache, in key order.
    pub fn cached_tiles(&self) -> Vec<TileKey> {
        let mut keys: Vec<TileKey> = self.cache.map.keys().copied().collect();
        keys.sort_unstable();
        keys
    }

    /// Nodes held by the cached tiles.
    pub fn cached_nodes(&self) -> usize {
        self.cache.map.values().map(|(t, _)| t.nodes.len()).sum()
    }

    /// Drops every cached tile.
    pub fn clear_cache(&mut self) {
        self.cache.clear();
    }

    /// The tiles whose columns an edit can change: the tiles over the columns of every chunk
    /// [`affected_chunks`] lists.
    pub fn tiles_for(&self, op: &BrushOp) -> Vec<TileKey> {
        let n_t = i64::from(self.columns.layout().n_t());
        let mut keys = Vec::new();
        for c in affected_chunks(self.columns.layout(), op) {
            let (i0, j0) = (i64::from(c.i) * n_t, i64::from(c.j) * n_t);
            let lo = self.tile_of(ColumnPlace {
                face: c.face,
                i: i0,
                j: j0,
            });
            let hi = self.tile_of(ColumnPlace {
                face: c.face,
                i: i0 + n_t,
                j: j0 + n_t,
            });
            for j in lo.j..=hi.j {
                for i in lo.i..=hi.i {
                    keys.push(TileKey { face: c.face, i, j });
                }
            }
        }
        keys.sort_unstable();
        keys.dedup();
        keys
    }

    /// Replaces the density by `density`, the old one with the edit `op` applied (or undone),
    /// and drops the tiles it can change ([`LazyGrid::tiles_for`]; every tile when the edit
    /// moves the radial bounds' window). They are built again from the new density when next
    /// needed. Returns the tiles whose columns may have changed.
    pub fn apply_edit(&mut self, density: Arc<dyn Density>, op: &BrushOp) -> Vec<TileKey> {
        let keys = self.tiles_for(op);
        let before = (self.window, self.whole);
        self.density = density;
        self.set_window();
        if (self.window, self.whole) != before {
            self.cache.clear();
        } else {
            for k in &keys {
                self.cache.remove(k);
            }
        }
        keys
    }

    /// The tile `key`, from the cache or built (and cached).
    fn tile(&mut self, key: TileKey) -> Arc<Tile> {
        if let Some(t) = self.cache.get(key) {
            return t;
        }
        let t = Arc::new(self.build(key));
        self.cache.insert(key, t.clone());
        t
    }

    /// Whether tile `key` is held, without touching the cache's order.
    fn is_cached(&self, key: &TileKey) -> bool {
        self.cache.map.contains_key(key)
    }

    /// Samples tile `key` (see the module docs).
    fn build(&self, key: TileKey) -> Tile {
        let (i0, i1) = self.span(key.i);
        let (j0, j1) = self.span(key.j);
        let w = i1 - i0 + 1;
        let slots = (w * (j1 - j0 + 1)) as usize;
        let mut tile = Tile {
            face: key.face,
            i0,
            j0,
            w,
            dirs: Vec::with_capacity(slots),
            base: vec![0; slots],
            len: vec![0; slots],
            word_start: Vec::with_capacity(slots + 1),
            words: Vec::new(),
            node_start: Vec::with_capacity(slots + 1),
            nodes: Vec::new(),
            node_slot: Vec::new(),
        };
        let mut owned = Vec::with_capacity(slots);
        for s in 0..slots {
            let place = tile.place(s);
            owned.push(self.columns.is_canonical(place));
            tile.dirs.push(self.columns.place_direction(place));
        }
        let layout = *self.columns.layout();
        let depth = layout.depth_tiles();
        let radius = |k: i64| layout.layer_radius(k);
        if self.whole {
            // One batch call per row of the tile, which bounds the buffer however large the
            // tile and the window.
            let (w0, w1) = self.window;
            let radii: Vec<f64> = (w0..=w1).map(radius).collect();
            let mut d = vec![0.0f32; radii.len()];
            let mut samples = Vec::new();
            for row in 0..slots / w as usize {
                let row_slots = row * w as usize..(row + 1) * w as usize;
                let mine: Vec<usize> = row_slots.clone().filter(|s| owned[*s]).collect();
                let dirs: Vec<DVec3> = mine.iter().map(|s| tile.dirs[*s]).collect();
                samples.clear();
                samples.resize(dirs.len() * radii.len(), 0.0f32);
                self.density.sample_shell(&dirs, &radii, &mut samples);
                for s in row_slots {
                    tile.word_start.push(tile.words.len() as u32);
                    tile.node_start.push(tile.nodes.len() as u32);
                    let Ok(col) = mine.binary_search(&s) else {
                        continue;
                    };
                    for (b, v) in d.iter_mut().enumerate() {
                        *v = Rules::contract(w0 + b as i64, depth, samples[b * dirs.len() + col]);
                    }
                    tile.base[s] = w0 as i32;
                    tile.len[s] = d.len() as u32;
                    let first = tile.nodes.len();
                    self.rules.column(w0, &d, radius, &mut tile.words, &mut tile.nodes);
                    tile.node_slot
                        .resize(tile.node_slot.len() + tile.nodes.len() - first, s as u32);
                }
            }
        } else {
            // The guess: the previous column's top in the row, or the first column's of the row
            // before.
            let mut prev: Option<i64> = None;
            let mut row_first: Option<i64> = None;
            let mut first_in_row = true;
            for (s, mine) in owned.iter().enumerate() {
                tile.word_start.push(tile.words.len() as u32);
                tile.node_start.push(tile.nodes.len() as u32);
                if s as i64 % w == 0 {
                    prev = None;
                    first_in_row = true;
                }
                if !mine {
                    continue;
                }
                let (base, d, top) = self.band(tile.dirs[s], prev.or(row_first));
                if top.is_some() {
                    prev = top;
                }
                if first_in_row {
                    if top.is_some() {
                        row_first = top;
                    }
                    first_in_row = false;
                }
                tile.base[s] = base as i32;
                tile.len[s] = d.len() as u32;
                let first = tile.nodes.len();
                self.rules.column(base, &d, radius, &mut tile.words, &mut tile.nodes);
                tile.node_slot
                    .resize(tile.node_slot.len() + tile.nodes.len() - first, s as u32);
            }
        }
        tile.word_start.push(tile.words.len() as u32);
        tile.node_start.push(tile.nodes.len() as u32);
        tile.words.shrink_to_fit();
        tile.nodes.shrink_to_fit();
        tile.node_slot.shrink_to_fit();
        tile
    }

    /// Samples layers `layers` of the column along `dir`, shell contract applied.
    fn sample(&self, dir: DVec3, layers: &[i64]) -> Vec<f32> {
        let layout = self.columns.layout();
        let radii: Vec<f64> = layers.iter().map(|k| layout.layer_radius(*k)).collect();
        let mut out = vec![0.0f32; radii.len()];
        self.density.sample_shell(std::slice::from_ref(&dir), &radii, &mut out);
        let depth = layout.depth_tiles();
        for (v, k) in out.iter_mut().zip(layers) {
            *v = Rules::contract(*k, depth, *v);
        }
        out
    }

    /// The highest solid layer among `from, from - probe, from - 2 probe, ...` down to `to`,
    /// sampled from the top in batches.
    fn probe(&self, dir: DVec3, from: i64, to: i64) -> Option<i64> {
        let stride = i64::from(self.options.probe);
        let mut k = from;
        while k >= to {
            let layers: Vec<i64> = (0..64).map(|m| k - m * stride).take_while(|x| *x >= to).collect();
            let d = self.sample(dir, &layers);
            if let Some(m) = d.iter().position(|v| *v > 0.0) {
                return Some(layers[m]);
            }
            k -= 64 * stride;
        }
        None
    }

    /// The band of the column along `dir` (see the module docs): its first layer, its samples,
    /// and the column's top when the band holds solid.
    fn band(&self, dir: DVec3, guess: Option<i64>) -> (i64, Vec<f32>, Option<i64>) {
        let (w0, w1) = self.window;
        let above = self.band_above();
        let below = i64::from(self.options.below);
        let stride = i64::from(self.options.probe);
        let mut probed = false;
        let mut climbs = 0;
        let probe_from = |grid: &Self, from: i64, to: i64, probed: &mut bool| -> i64 {
            *probed = true;
            grid.probe(dir, from, to).unwrap_or(to)
        };
        // After a probe the top lies at least at the probe's solid layer, and thin solid
        // between the probes above it (the roof of a cave the probe fell into) is looked for
        // layer by layer up to four strides over it.
        let after_probe = 4 * stride;
        let (mut g, mut extra) = match guess {
            Some(g) => (g.clamp(w0, w1), 0),
            None => (probe_from(self, w1, w0, &mut probed), after_probe),
        };
        let mut last = (w0, Vec::new(), None);
        for _ in 0..ATTEMPTS {
            let lo = (g - below - SLACK).max(w0);
            let hi = (g + above + SLACK + extra).min(w1);
            let mut layers: Vec<i64> = (lo..=hi).collect();
            let mut up = stride;
            while hi + up <= w1 {
                layers.push(hi + up);
                up *= 2;
            }
            let mut d = self.sample(dir, &layers);
            let over = layers[(hi - lo + 1) as usize..]
                .iter()
                .zip(&d[(hi - lo + 1) as usize..])
                .filter(|(_, v)| **v > 0.0)
                .map(|(k, _)| *k)
                .max();
            d.truncate((hi - lo + 1) as usize);
            let top = d.iter().rposition(|v| *v > 0.0).map(|b| lo + b as i64);
            last = (lo, d, top);
            if let Some(q) = over {
                // Solid above the band: the top is higher.
                g = if probed {
                    q
                } else {
                    probe_from(self, w1, q, &mut probed)
                };
                extra = after_probe;
                continue;
            }
            match top {
                None if lo == w0 => break,
                None => {
                    g = if probed {
                        lo - 1
                    } else {
                        probe_from(self, lo - 1, w0, &mut probed)
                    };
                    extra = after_probe;
                }
                Some(t) => {
                    let room_up = t + above <= hi || hi == w1;
                    let room_down = t - below >= lo || lo == w0;
                    if room_up && room_down {
                        let (a, b) = ((t - below).max(lo), (t + above).min(hi));
                        let (lo, d, top) = last;
                        let kept = d[(a - lo) as usize..=(b - lo) as usize].to_vec();
                        return (a, kept, top);
                    }
                    if !room_up {
                        climbs += 1;
                    }
                    if climbs >= 2 && !probed {
                        g = probe_from(self, w1, t, &mut probed);
                        extra = after_probe;
                    } else {
                        g = t;
                        extra = 0;
                    }
                }
            }
        }
        last
    }

    /// The tile of `place` and its slot there.
    fn locate(&mut self, place: ColumnPlace) -> (TileKey, Arc<Tile>, usize) {
        let key = self.tile_of(place);
        let tile = self.tile(key);
        let slot = tile.slot(place);
        (key, tile, slot)
    }

    /// The floors of the column at canonical place `place`, lowest first (builds its tile if
    /// needed).
    pub fn column_nodes(&mut self, place: ColumnPlace) -> Vec<(NodeKey, Node)> {
        if !self.valid(place) {
            return Vec::new();
        }
        let (_, tile, slot) = self.locate(place);
        tile.floors(slot)
            .map(|n| {
                (
                    NodeKey {
                        column: place,
                        layer: tile.nodes[n].layer,
                    },
                    tile.nodes[n],
                )
            })
            .collect()
    }

    /// The layers a column keeps: its first layer and how many (builds its tile if needed).
    pub fn column_band(&mut self, place: ColumnPlace) -> Option<(i64, u32)> {
        if !self.valid(place) {
            return None;
        }
        let (_, tile, slot) = self.locate(place);
        Some((i64::from(tile.base[slot]), tile.len[slot]))
    }

    /// Whether voxel `layer` of the column at `place` is filled as the grid keeps it: sampled
    /// within the column's band, filled below it and air above it.
    pub fn is_filled(&mut self, place: ColumnPlace, layer: i64) -> Option<bool> {
        if !self.valid(place) {
            return None;
        }
        let (_, tile, slot) = self.locate(place);
        Some(tile.view(slot).filled(layer))
    }

    /// Whether `place` is a canonical place of this layout.
    fn valid(&self, place: ColumnPlace) -> bool {
        let n = self.columns.face_tiles();
        (0..=n).contains(&place.i) && (0..=n).contains(&place.j) && self.columns.is_canonical(place)
    }

    /// The tile, slot and node index of `key`, if it is a node.
    fn resolve(&mut self, key: NodeKey) -> Option<NodeRef> {
        if !self.valid(key.column) {
            return None;
        }
        let (tk, tile, slot) = self.locate(key.column);
        let n = tile.floors(slot).find(|n| tile.nodes[*n].layer == key.layer)?;
        Some(NodeRef {
            tile: tk,
            node: n as u32,
        })
    }

    /// The node `key`, if the grid has it.
    pub fn node(&mut self, key: NodeKey) -> Option<Node> {
        let r = self.resolve(key)?;
        Some(self.tile(r.tile).nodes[r.node as usize])
    }

    /// The surface point of node `key`, metres, planet-centred.
    pub fn position(&mut self, key: NodeKey) -> Option<DVec3> {
        let node = self.node(key)?;
        Some(self.columns.place_direction(key.column) * node.radius)
    }

    /// The steps the agent can take from node `key`: (node reached, metres).
    pub fn steps(&mut self, key: NodeKey) -> Vec<(NodeKey, f64)> {
        let Some(from) = self.resolve(key) else {
            return Vec::new();
        };
        let tile = self.tile(from.tile);
        let n = from.node as usize;
        let (slot, node) = (tile.node_slot[n] as usize, tile.nodes[n]);
        let mut out = Vec::new();
        for q in self.columns.neighbour_places(key.column).iter() {
            let qk = self.tile_of(*q);
            let qt = if qk == from.tile { tile.clone() } else { self.tile(qk) };
            let qs = qt.slot(*q);
            for m in qt.floors(qs) {
                let step = self.rules.step(
                    tile.view(slot),
                    tile.dirs[slot],
                    node,
                    qt.view(qs),
                    qt.dirs[qs],
                    qt.nodes[m],
                );
                if let Some(cost) = step {
                    let to = NodeKey {
                        column: *q,
                        layer: qt.nodes[m].layer,
                    };
                    out.push((to, cost));
                }
            }
        }
        out
    }

    /// The node nearest to direction `dir` (any non-zero vector): in the nearest column that has
    /// nodes (searching outward column by column, at most `max_rings` steps), the node whose
    /// surface radius is nearest to `radius`, or the highest node when `radius` is `None`.
    pub fn node_near(&mut self, dir: DVec3, radius: Option<f64>, max_rings: usize) -> Option<NodeKey> {
        let start = self.columns.nearest_place(dir)?;
        let mut ring = vec![start];
        let mut seen = HashSet::from([start]);
        for _ in 0..=max_rings {
            let mut best: Option<(f64, NodeKey)> = None;
            for c in &ring {
                for (key, n) in self.column_nodes(*c) {
                    let score = match radius {
                        Some(r) => (n.radius - r).abs(),
                        None => -n.radius,
                    };
                    if best.is_none_or(|(s, _)| score < s) {
                        best = Some((score, key));
                    }
                }
            }
            if let Some((_, key)) = best {
                return Some(key);
            }
            let mut next = Vec::new();
            for c in &ring {
                for q in self.columns.neighbour_places(*c).iter() {
                    if seen.insert(*q) {
                        next.push(*q);
                    }
                }
            }
            ring = next;
        }
        None
    }

    /// A path from `from` to `to` (nodes of this grid), or why there is none, within the bounds
    /// of `options` (see the module docs); and what the search did. With weight 1 the path is a
    /// shortest one. Nodes that are not floors of the grid answer [`NoPath::Enclosed`] with no
    /// nodes. Options [`SearchOptions::validate`] refuses are taken at their nearest valid value
    /// (bounds of 0 as 1, a weight below 1 or not finite as 1).
    pub fn find_path(
        &mut self,
        from: NodeKey,
        to: NodeKey,
        options: &SearchOptions,
    ) -> (Result<Path<NodeKey>, NoPath>, SearchStats) {
        let built = self.cache.built;
        let ends = (self.resolve(from), self.resolve(to));
        let (Some(a), Some(b)) = ends else {
            let stats = SearchStats {
                tiles_built: (self.cache.built - built) as usize,
                ..SearchStats::default()
            };
            let none = NoPath::Enclosed {
                nodes: 0,
                start_side: ends.0.is_none(),
            };
            return (Err(none), stats);
        };
        let heuristic = Heuristic::new(
            &self.columns,
            self.r_min,
            self.columns.lattice(from.column),
            self.columns.place_direction(to.column),
            self.columns.lattice(to.column),
        );
        let weight = if options.weight.is_finite() {
            options.weight.max(1.0)
        } else {
            1.0
        };
        let mut search = Search {
            grid: self,
            slots: HashMap::default(),
            blocks: Vec::new(),
            next_slot: 0,
            heuristic,
            built_at_start: built,
            max_tiles: options.max_tiles_built.max(1) as u64,
            start: a,
            back: Backward {
                seen: HashSet::default(),
                queue: VecDeque::from([b]),
                cap: (options.max_expanded / 64).max(1024),
                active: a != b,
                wait: 0,
            },
        };
        search.back.seen.insert(b);
        let (outcome, expanded) = astar(&mut search, a, b, weight, options.max_expanded.max(1), |s| {
            s.backward_step()
        });
        let backward = search.back.seen.len();
        let result = match outcome {
            Outcome::Found { nodes, length } => {
                let mut keys = Vec::with_capacity(nodes.len());
                let mut points = Vec::with_capacity(nodes.len());
                for r in nodes {
                    let tile = search.grid.tile(r.tile);
                    let n = r.node as usize;
                    let place = tile.place(tile.node_slot[n] as usize);
                    keys.push(NodeKey {
                        column: place,
                        layer: tile.nodes[n].layer,
                    });
                    points.push(tile.dirs[tile.node_slot[n] as usize] * tile.nodes[n].radius);
                }
                Ok(Path {
                    nodes: keys,
                    points,
                    length,
                    expanded,
                })
            }
            Outcome::Exhausted => Err(NoPath::Enclosed {
                nodes: expanded,
                start_side: true,
            }),
            Outcome::Halted(Halt::GoalEnclosed(nodes)) => Err(NoPath::Enclosed {
                nodes,
                start_side: false,
            }),
            Outcome::Halted(Halt::Bound) => Err(NoPath::SearchBound {
                expanded,
                tiles_built: (self.cache.built - built) as usize,
            }),
        };
        let stats = SearchStats {
            expanded,
            backward,
            tiles_built: (self.cache.built - built) as usize,
        };
        (result, stats)
    }

    /// Finds the path between the walkable ground nearest to `from` and `to`, as
    /// [`crate::query`] does on the whole-planet grid: each end is, in the nearest column with
    /// nodes within `max_rings` columns, the node nearest to the radius asked for, or the
    /// highest one. The stats count the tiles built to find the ends too.
    pub fn query(&mut self, from: End, to: End, max_rings: usize, options: &SearchOptions) -> LazyAnswer {
        let built = self.cache.built;
        let tiles = |g: &Self| (g.cache.built - built) as usize;
        let Some(a) = self.node_near(from.dir, from.radius, max_rings) else {
            return LazyAnswer {
                answer: PathAnswer::NoGround { start: true },
                stats: SearchStats {
                    tiles_built: tiles(self),
                    ..SearchStats::default()
                },
            };
        };
        let Some(b) = self.node_near(to.dir, to.radius, max_rings) else {
            return LazyAnswer {
                answer: PathAnswer::NoGround { start: false },
                stats: SearchStats {
                    tiles_built: tiles(self),
                    ..SearchStats::default()
                },
            };
        };
        let (result, mut stats) = self.find_path(a, b, options);
        stats.tiles_built = tiles(self);
        let answer = match result {
            Ok(p) => PathAnswer::Found(p),
            Err(NoPath::SearchBound { expanded, .. }) => PathAnswer::NoPath(NoPath::SearchBound {
                expanded,
                tiles_built: stats.tiles_built,
            }),
            Err(e) => PathAnswer::NoPath(e),
        };
        LazyAnswer { answer, stats }
    }
}

/// A node during a search: its tile and its index among the tile's nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct NodeRef {
    tile: TileKey,
    node: u32,
}

/// The search backward from the goal.
struct Backward {
    seen: HashSet<NodeRef, Fx>,
    queue: VecDeque<NodeRef>,
    cap: usize,
    active: bool,
    /// Forward expansions since the last backward node.
    wait: u32,
}

/// Forward expansions per node of the backward search.
const BACKWARD_PACE: u32 = 4;

/// One search over the lazy grid.
struct Search<'a> {
    grid: &'a mut LazyGrid,
    /// First record slot of each tile seen, and the tiles in slot order.
    slots: HashMap<TileKey, usize, Fx>,
    blocks: Vec<(usize, TileKey)>,
    next_slot: usize,
    heuristic: Heuristic,
    built_at_start: u64,
    max_tiles: u64,
    start: NodeRef,
    back: Backward,
}

impl Search<'_> {
    /// The tile `key`, or the bound when building it would pass the tile bound.
    fn tile(&mut self, key: TileKey) -> Result<Arc<Tile>, Halt> {
        if !self.grid.is_cached(&key) && self.grid.cache.built - self.built_at_start >= self.max_tiles {
            return Err(Halt::Bound);
        }
        Ok(self.grid.tile(key))
    }

    /// One node of the backward search (see the module docs).
    fn backward_step(&mut self) -> Option<Halt> {
        if !self.back.active {
            return None;
        }
        self.back.wait += 1;
        if self.back.wait < BACKWARD_PACE {
            return None;
        }
        self.back.wait = 0;
        let Some(at) = self.back.queue.pop_front() else {
            self.back.active = false;
            return Some(Halt::GoalEnclosed(self.back.seen.len()));
        };
        if self.back.seen.len() >= self.back.cap {
            self.back.active = false;
            return None;
        }
        let tile = match self.tile(at.tile) {
            Ok(t) => t,
            Err(h) => return Some(h),
        };
        let n = at.node as usize;
        let (slot, node) = (tile.node_slot[n] as usize, tile.nodes[n]);
        let place = tile.place(slot);
        for q in self.grid.columns.neighbour_places(place).iter() {
            let qk = self.grid.tile_of(*q);
            let qt = if qk == at.tile {
                tile.clone()
            } else {
                match self.tile(qk) {
                    Ok(t) => t,
                    Err(h) => return Some(h),
                }
            };
            let qs = qt.slot(*q);
            for m in qt.floors(qs) {
                let step = self.grid.rules.step(
                    qt.view(qs),
                    qt.dirs[qs],
                    qt.nodes[m],
                    tile.view(slot),
                    tile.dirs[slot],
                    node,
                );
                if step.is_none() {
                    continue;
                }
                let r = NodeRef {
                    tile: qk,
                    node: m as u32,
                };
                if r == self.start {
                    // The start can reach the goal: A* will find the way.
                    self.back.active = false;
                    return None;
                }
                if self.back.seen.insert(r) {
                    self.back.queue.push_back(r);
                }
            }
        }
        None
    }

    /// Gives tile `key` (of `count` nodes) its block of record slots, once.
    fn ensure_block(&mut self, key: TileKey, count: usize) {
        if !self.slots.contains_key(&key) {
            let base = self.next_slot;
            self.slots.insert(key, base);
            self.blocks.push((base, key));
            self.next_slot += count;
        }
    }

    fn h(&self, tile: &Tile, slot: usize) -> f64 {
        self.heuristic
            .at(tile.dirs[slot], self.grid.columns.lattice(tile.place(slot)))
    }
}

impl SearchGraph for Search<'_> {
    type Key = NodeRef;

    fn slot(&mut self, key: NodeRef) -> usize {
        if let Some(base) = self.slots.get(&key.tile) {
            return base + key.node as usize;
        }
        // Every node handed to the search comes from a tile whose block was made when it was
        // read; this builds the tile again only if that did not happen.
        let count = self.grid.tile(key.tile).nodes.len();
        self.ensure_block(key.tile, count);
        self.slots[&key.tile] + key.node as usize
    }

    fn key(&self, slot: usize) -> NodeRef {
        let b = self.blocks.partition_point(|(base, _)| *base <= slot) - 1;
        let (base, tile) = self.blocks[b];
        NodeRef {
            tile,
            node: (slot - base) as u32,
        }
    }

    fn successors(&mut self, key: NodeRef, out: &mut Vec<(NodeRef, f64, f64)>) -> Result<(), Halt> {
        let tile = self.tile(key.tile)?;
        let n = key.node as usize;
        let (slot, node) = (tile.node_slot[n] as usize, tile.nodes[n]);
        let place = tile.place(slot);
        let (view, dir) = (tile.view(slot), tile.dirs[slot]);
        for q in self.grid.columns.neighbour_places(place).iter() {
            let qk = self.grid.tile_of(*q);
            let qt = if qk == key.tile { tile.clone() } else { self.tile(qk)? };
            self.ensure_block(qk, qt.nodes.len());
            let qs = qt.slot(*q);
            let mut h = None;
            for m in qt.floors(qs) {
                if let Some(cost) = self
                    .grid
                    .rules
                    .step(view, dir, node, qt.view(qs), qt.dirs[qs], qt.nodes[m])
                {
                    let h = *h.get_or_insert_with(|| self.h(&qt, qs));
                    let to = NodeRef {
                        tile: qk,
                        node: m as u32,
                    };
                    out.push((to, cost, h));
                }
            }
        }
        Ok(())
    }

    fn heuristic(&mut self, key: NodeRef) -> f64 {
        match self.tile(key.tile) {
            Ok(tile) => {
                let slot = tile.node_slot[key.node as usize] as usize;
                self.h(&tile, slot)
            }
            Err(_) => 0.0,
        }
    }
}
