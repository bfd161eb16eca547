//! The navigation grid: surface voxels of the whole planet, the steps between them, and their
//! connected components (seed 000 Sec. 4.5, Fig. 10 and 11).
//!
//! - **Occupancy.** Every voxel of level 0 is filled or not, from exactly the samples the mesher
//!   uses (the same canonical directions and layer radii, through [`Density::sample_shell`], with
//!   the shell contract: the innermost layer is solid, the outermost air).
//! - **Surface voxels** are filled voxels whose voxel above (along the depth axis) is unfilled,
//!   every one of them in a column, so cave floors are surfaces too. A surface voxel is a
//!   **node** when the agent fits above it (its clearance in air). A node's surface point is where
//!   the density crosses zero between it and the voxel above (as the mesher places the vertex).
//! - **Steps** (Fig. 11) go from a node to the floors of a neighbouring column (four neighbours;
//!   three at a cube corner; across chunk borders and face edges alike, see [`Columns`]) that lie
//!   within the agent's step limits. The passage is checked voxel by voxel: each column must be
//!   unfilled from just above its own floor up to the higher floor plus the clearance, so a voxel
//!   that is suddenly filled above the agent, an overhang or a cave ceiling, closes the way. The
//!   rise or drop must be within the agent's step limits and the slope within its steepest slope.
//!   The conditions read the same from either end, so a step exists both ways when the agent's
//!   step up and down are equal. Its cost is the distance walked: the horizontal distance between
//!   the columns at the mean radius combined with the rise.
//! - **Tiles.** The grid is built and rebuilt per tile: the columns under one chunk footprint
//!   (face, i, j) through the whole depth. After an edit only the tiles under the chunks the edit
//!   touches are sampled again ([`NavGrid::rebuild_for`]).
//! - **Components** label the nodes joined by steps (either way), so detached grids (Fig. 10) are
//!   known without a search: nodes in different components have no path between them.
//!
//! The grid holds every column of the planet, up to [`MAX_COLUMNS`]. [`crate::LazyGrid`] has the
//! same floors and steps (the rules are one implementation) for planets of any size, built tile
//! by tile around a query, without components.

use crate::agent::{Agent, AgentError};
use crate::columns::{ColumnPlace, Columns};
use crate::rules::{ColumnView, Rules};
use pmc_density::Density;
use pmc_edit::{affected_chunks, BrushOp};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{Face, Layout};
use rayon::prelude::*;

/// Most columns a grid may have (a guard against layouts too large to hold in memory).
pub const MAX_COLUMNS: usize = 30_000_000;

/// A node of the grid: a surface voxel the agent can stand on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    /// Its layer (depth index, 0 innermost).
    pub layer: u32,
    /// Radius of its surface point, metres.
    pub radius: f64,
}

/// A node's id: stable until the grid is rebuilt.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(pub u32);

/// A tile of the grid: the columns under one chunk footprint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TileKey {
    /// The face.
    pub face: Face,
    /// Chunk index along `u`.
    pub i: u32,
    /// Chunk index along `v`.
    pub j: u32,
}

/// One tile's columns and nodes.
#[derive(Clone, Debug, Default)]
struct Tile {
    /// The canonical columns it owns, ascending.
    columns: Vec<u32>,
    /// Start of each column's nodes in `nodes` (one more entry than columns).
    starts: Vec<u32>,
    /// The nodes, column by column, ascending layer within a column.
    nodes: Vec<Node>,
    /// Each node's component among the steps inside the tile, numbered in order of first node.
    local: Vec<u32>,
    /// Node count of each of those components.
    local_sizes: Vec<u32>,
    /// Steps that leave the tile.
    border: Vec<BorderStep>,
    /// Smallest radius of its nodes' surface points (infinite without nodes).
    min_radius: f64,
}

/// A step out of a tile: (local node, tile index, local node there).
type BorderStep = (u32, u32, u32);

/// A union-find over `0..n`.
struct UnionFind(Vec<u32>);

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind((0..n as u32).collect())
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let up = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = up;
            x = up;
        }
        x
    }

    /// Joins two sets; the smaller root stays root.
    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb) as usize] = ra.min(rb);
        }
    }

    /// Dense labels in order of each set's first member, and the sets' sizes.
    fn labels(&mut self) -> (Vec<u32>, Vec<u32>) {
        let n = self.0.len();
        let mut root_label = vec![u32::MAX; n];
        let mut labels = Vec::with_capacity(n);
        let mut sizes = Vec::new();
        for x in 0..n as u32 {
            let r = self.find(x) as usize;
            if root_label[r] == u32::MAX {
                root_label[r] = sizes.len() as u32;
                sizes.push(0);
            }
            labels.push(root_label[r]);
        }
        for l in &labels {
            sizes[*l as usize] += 1;
        }
        (labels, sizes)
    }
}

/// Why a grid could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NavError {
    /// Invalid agent limits.
    #[error(transparent)]
    Agent(#[from] AgentError),
    /// Invalid options.
    #[error("{0}")]
    Options(String),
    /// The layout has too many columns.
    #[error("a navigation grid of this layout would have {columns} columns, more than {MAX_COLUMNS}; use a smaller n_c or n_t, or the lazy grid")]
    TooLarge {
        /// The columns it would have.
        columns: usize,
    },
}

/// The navigation grid of a planet for one agent.
#[derive(Clone, Debug)]
pub struct NavGrid {
    columns: Columns,
    agent: Agent,
    radii: Vec<f64>,
    /// `u64` words per column.
    words: usize,
    /// Occupancy bits of every column slot, `words` per slot.
    occupancy: Vec<u64>,
    tiles: Vec<Tile>,
    /// First global node id of each tile (one more entry than tiles).
    tile_base: Vec<u32>,
    /// First (tile, local component) pair index of each tile (one more entry than tiles).
    pair_base: Vec<u32>,
    /// Component label of each (tile, local component) pair.
    pair_label: Vec<u32>,
    /// Node count of each component.
    component_sizes: Vec<u32>,
    /// The agent's limits in layers.
    rules: Rules,
    min_radius: f64,
}

/// A step from a node to a neighbouring node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// The node reached.
    pub to: NodeId,
    /// Metres walked.
    pub cost: f64,
}

impl NavGrid {
    /// Builds the grid of `density` on `layout` for `agent`, tiles in parallel on the current
    /// rayon pool.
    pub fn build(density: &dyn Density, layout: &Layout, agent: Agent) -> Result<NavGrid, NavError> {
        agent.validate()?;
        let columns = Columns::new(layout);
        if columns.index_count() > MAX_COLUMNS {
            return Err(NavError::TooLarge {
                columns: columns.index_count(),
            });
        }
        let depth = layout.depth_tiles();
        let radii: Vec<f64> = (0..=depth).map(|k| layout.layer_radius(k)).collect();
        let words = radii.len().div_ceil(64);
        let mut grid = NavGrid {
            columns,
            agent,
            words,
            occupancy: vec![0; columns.index_count() * words],
            tiles: Vec::new(),
            tile_base: Vec::new(),
            pair_base: Vec::new(),
            pair_label: Vec::new(),
            component_sizes: Vec::new(),
            rules: Rules::new(agent, layout.l_d()),
            min_radius: f64::INFINITY,
            radii,
        };
        let keys = grid.tile_keys();
        grid.tiles = vec![Tile::default(); keys.len()];
        grid.rebuild_tiles(density, &keys);
        Ok(grid)
    }

    /// Every tile, in index order.
    pub fn tile_keys(&self) -> Vec<TileKey> {
        let n_c = self.columns.layout().n_c();
        let mut out = Vec::with_capacity(6 * (n_c * n_c) as usize);
        for face in Face::ALL {
            for j in 0..n_c {
                for i in 0..n_c {
                    out.push(TileKey { face, i, j });
                }
            }
        }
        out
    }

    fn tile_index(&self, t: TileKey) -> usize {
        let n_c = self.columns.layout().n_c() as usize;
        (t.face.index() * n_c + t.j as usize) * n_c + t.i as usize
    }

    /// The tile that owns a canonical column place.
    fn tile_of(&self, place: ColumnPlace) -> TileKey {
        let l = self.columns.layout();
        let (n_t, last) = (i64::from(l.n_t()), l.n_c() - 1);
        let chunk = |x: i64| ((x / n_t) as u32).min(last);
        TileKey {
            face: place.face,
            i: chunk(place.i),
            j: chunk(place.j),
        }
    }

    /// The tiles under the chunks an edit can change: rebuild these after applying `op` (or
    /// undoing it).
    pub fn tiles_for(&self, op: &BrushOp) -> Vec<TileKey> {
        let mut keys: Vec<TileKey> = affected_chunks(self.columns.layout(), op)
            .into_iter()
            .map(|c| TileKey {
                face: c.face,
                i: c.i,
                j: c.j,
            })
            .collect();
        keys.sort();
        keys.dedup();
        keys
    }

    /// Samples `density` again under the tiles an edit changed ([`NavGrid::tiles_for`]) and
    /// relabels the components. Returns the tiles rebuilt.
    pub fn rebuild_for(&mut self, density: &dyn Density, op: &BrushOp) -> Vec<TileKey> {
        let keys = self.tiles_for(op);
        self.rebuild_tiles(density, &keys);
        keys
    }

    /// Samples `density` again under `keys`, then relabels the components: the steps inside the
    /// rebuilt tiles and the steps across the borders of them and of their neighbours are found
    /// again; the other tiles keep theirs.
    pub fn rebuild_tiles(&mut self, density: &dyn Density, keys: &[TileKey]) {
        if keys.is_empty() && !self.tile_base.is_empty() {
            return;
        }
        let built: Vec<(usize, Tile, Vec<u64>)> = keys
            .par_iter()
            .map(|t| {
                let (tile, bits) = self.sample_tile(density, *t);
                (self.tile_index(*t), tile, bits)
            })
            .collect();
        let mut rebuilt: Vec<usize> = Vec::with_capacity(built.len());
        for (index, tile, bits) in built {
            for (n, c) in tile.columns.iter().enumerate() {
                let at = *c as usize * self.words;
                self.occupancy[at..at + self.words].copy_from_slice(&bits[n * self.words..(n + 1) * self.words]);
            }
            self.tiles[index] = tile;
            rebuilt.push(index);
        }
        let mut base = Vec::with_capacity(self.tiles.len() + 1);
        let mut total = 0u32;
        for t in &self.tiles {
            base.push(total);
            total += t.nodes.len() as u32;
        }
        base.push(total);
        self.tile_base = base;
        self.min_radius = self.tiles.iter().map(|t| t.min_radius).fold(f64::INFINITY, f64::min);
        // Steps inside the rebuilt tiles.
        let inside: Vec<(usize, Vec<u32>, Vec<u32>)> = rebuilt
            .par_iter()
            .map(|t| {
                let (local, sizes) = self.inner_components(*t);
                (*t, local, sizes)
            })
            .collect();
        for (t, local, sizes) in inside {
            self.tiles[t].local = local;
            self.tiles[t].local_sizes = sizes;
        }
        // Steps across borders: of the rebuilt tiles and of every tile next to one.
        let mut touched: Vec<usize> = rebuilt.clone();
        for t in &rebuilt {
            touched.extend(self.neighbour_tiles(*t));
        }
        touched.sort_unstable();
        touched.dedup();
        let borders: Vec<(usize, Vec<BorderStep>)> = touched.par_iter().map(|t| (*t, self.border_steps(*t))).collect();
        for (t, border) in borders {
            self.tiles[t].border = border;
        }
        self.merge_components();
    }

    /// The tiles that own a neighbour of one of tile `t`'s columns (`t` excluded).
    fn neighbour_tiles(&self, t: usize) -> Vec<usize> {
        let mut out = Vec::new();
        for c in &self.tiles[t].columns {
            for q in self.columns.neighbours(*c).iter() {
                let u = self.tile_index(self.tile_of(self.columns.place_of(*q)));
                if u != t && !out.contains(&u) {
                    out.push(u);
                }
            }
        }
        out
    }

    /// The components of tile `t` among the steps that stay inside it.
    fn inner_components(&self, t: usize) -> (Vec<u32>, Vec<u32>) {
        let tile = &self.tiles[t];
        let mut uf = UnionFind::new(tile.nodes.len());
        let base = self.tile_base[t];
        for (lc, column) in tile.columns.iter().enumerate() {
            for q in self.columns.neighbours(*column).iter() {
                if tile.columns.binary_search(q).is_err() {
                    continue;
                }
                for i in tile.starts[lc]..tile.starts[lc + 1] {
                    for s in self.steps_into(*column, tile.nodes[i as usize], *q) {
                        uf.union(i, s.to.0 - base);
                    }
                }
            }
        }
        uf.labels()
    }

    /// The steps from tile `t`'s nodes into other tiles: (local node, tile, local node there).
    fn border_steps(&self, t: usize) -> Vec<BorderStep> {
        let tile = &self.tiles[t];
        let mut out = Vec::new();
        for (lc, column) in tile.columns.iter().enumerate() {
            for q in self.columns.neighbours(*column).iter() {
                let u = self.tile_index(self.tile_of(self.columns.place_of(*q)));
                if u == t {
                    continue;
                }
                for i in tile.starts[lc]..tile.starts[lc + 1] {
                    for s in self.steps_into(*column, tile.nodes[i as usize], *q) {
                        out.push((i, u as u32, s.to.0 - self.tile_base[u]));
                    }
                }
            }
        }
        out
    }

    /// Joins the tiles' local components along the border steps into the grid's components,
    /// labelled in order of their first node.
    fn merge_components(&mut self) {
        let mut pair_base = Vec::with_capacity(self.tiles.len() + 1);
        let mut pairs = 0u32;
        for t in &self.tiles {
            pair_base.push(pairs);
            pairs += t.local_sizes.len() as u32;
        }
        pair_base.push(pairs);
        let mut uf = UnionFind::new(pairs as usize);
        for (t, tile) in self.tiles.iter().enumerate() {
            for (from, u, to) in &tile.border {
                let a = pair_base[t] + tile.local[*from as usize];
                let b = pair_base[*u as usize] + self.tiles[*u as usize].local[*to as usize];
                uf.union(a, b);
            }
        }
        // Pairs are numbered in node order (tiles in order, local components by first node), so
        // labelling pairs in order labels components by their first node.
        let (labels, _) = uf.labels();
        let mut sizes = vec![0u32; labels.iter().max().map_or(0, |m| *m as usize + 1)];
        for (t, tile) in self.tiles.iter().enumerate() {
            for (lc, size) in tile.local_sizes.iter().enumerate() {
                sizes[labels[pair_base[t] as usize + lc] as usize] += size;
            }
        }
        self.pair_base = pair_base;
        self.pair_label = labels;
        self.component_sizes = sizes;
    }

    /// Samples one tile: its columns' occupancy bits and nodes.
    fn sample_tile(&self, density: &dyn Density, key: TileKey) -> (Tile, Vec<u64>) {
        let l = self.columns.layout();
        let (n, n_t) = (self.columns.face_tiles(), i64::from(l.n_t()));
        let last = i64::from(l.n_c()) - 1;
        let span = |c: u32| {
            let c = i64::from(c);
            let lo = c * n_t;
            let hi = if c == last { n } else { lo + n_t - 1 };
            lo..=hi
        };
        let mut columns = Vec::new();
        for j in span(key.j) {
            for i in span(key.i) {
                let place = ColumnPlace { face: key.face, i, j };
                if self.columns.is_canonical(place) {
                    columns.push(self.columns.index_of(place));
                }
            }
        }
        let dirs: Vec<DVec3> = columns.iter().map(|c| self.columns.direction(*c)).collect();
        let layers = self.radii.len();
        let mut samples = vec![0.0f32; dirs.len() * layers];
        density.sample_shell(&dirs, &self.radii, &mut samples);
        let top = layers as i64 - 1;
        let mut bits = Vec::with_capacity(columns.len() * self.words);
        let mut starts = Vec::with_capacity(columns.len() + 1);
        let mut nodes = Vec::new();
        let mut d = vec![0.0f32; layers];
        for col in 0..columns.len() {
            for (k, dk) in d.iter_mut().enumerate() {
                *dk = Rules::contract(k as i64, top, samples[k * dirs.len() + col]);
            }
            starts.push(nodes.len() as u32);
            self.rules
                .column(0, &d, |k| self.radii[k as usize], &mut bits, &mut nodes);
        }
        starts.push(nodes.len() as u32);
        let min_radius = nodes.iter().map(|n| n.radius).fold(f64::INFINITY, f64::min);
        let tile = Tile {
            columns,
            starts,
            nodes,
            min_radius,
            ..Tile::default()
        };
        (tile, bits)
    }

    /// The occupancy of a column: every layer sampled, below layer 0 filled, above the top air.
    fn view(&self, column: u32) -> ColumnView<'_> {
        let at = column as usize * self.words;
        ColumnView {
            base: 0,
            len: self.radii.len() as i64,
            words: &self.occupancy[at..at + self.words],
        }
    }

    /// The agent.
    pub fn agent(&self) -> &Agent {
        &self.agent
    }

    /// The columns.
    pub fn columns(&self) -> &Columns {
        &self.columns
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.tile_base.last().copied().unwrap_or(0) as usize
    }

    /// Smallest radius of any node's surface point (for the A* heuristic).
    pub fn min_radius(&self) -> f64 {
        self.min_radius
    }

    /// Whether voxel `layer` of `column` is filled.
    pub fn is_filled(&self, column: u32, layer: i64) -> bool {
        self.view(column).filled(layer)
    }

    /// The tile index and the local index of a canonical column in it.
    fn locate(&self, column: u32) -> Option<(usize, usize)> {
        let place = self.columns.place_of(column);
        let t = self.tile_index(self.tile_of(place));
        let local = self.tiles.get(t)?.columns.binary_search(&column).ok()?;
        Some((t, local))
    }

    /// The nodes of `column` with their ids, lowest first.
    pub fn column_nodes(&self, column: u32) -> impl Iterator<Item = (NodeId, Node)> + '_ {
        let found = self.locate(column);
        let (t, range) = match found {
            Some((t, local)) => {
                let tile = &self.tiles[t];
                (t, tile.starts[local] as usize..tile.starts[local + 1] as usize)
            }
            None => (0, 0..0),
        };
        range.map(move |i| (NodeId(self.tile_base[t] + i as u32), self.tiles[t].nodes[i]))
    }

    /// The node `id`: its column and the node.
    pub fn node(&self, id: NodeId) -> Option<(u32, Node)> {
        if id.0 as usize >= self.node_count() {
            return None;
        }
        let t = self.tile_base.partition_point(|b| *b <= id.0) - 1;
        let tile = &self.tiles[t];
        let local = (id.0 - self.tile_base[t]) as usize;
        let col = tile.starts.partition_point(|s| *s as usize <= local) - 1;
        Some((tile.columns[col], tile.nodes[local]))
    }

    /// The surface point of node `id`, metres, planet-centred.
    pub fn position(&self, id: NodeId) -> Option<DVec3> {
        self.node(id).map(|(c, n)| self.columns.direction(c) * n.radius)
    }

    /// The steps from node (`column`, `node`) into the neighbouring column `to` (Fig. 11): one
    /// to each floor of `to` within the agent's step limits whose passage is open.
    pub fn steps_into(&self, column: u32, node: Node, to: u32) -> impl Iterator<Item = Step> + '_ {
        let (a, b) = (self.view(column), self.view(to));
        let from_dir = self.columns.direction(column);
        let to_dir = self.columns.direction(to);
        self.column_nodes(to).filter_map(move |(id, reached)| {
            self.rules
                .step(a, from_dir, node, b, to_dir, reached)
                .map(|cost| Step { to: id, cost })
        })
    }

    /// The steps the agent can take from node `id`.
    pub fn steps(&self, id: NodeId) -> Vec<Step> {
        let Some((column, node)) = self.node(id) else {
            return Vec::new();
        };
        self.columns
            .neighbours(column)
            .iter()
            .flat_map(|to| self.steps_into(column, node, *to))
            .collect()
    }

    /// The component of node `id`.
    pub fn component(&self, id: NodeId) -> Option<u32> {
        if id.0 as usize >= self.node_count() {
            return None;
        }
        let t = self.tile_base.partition_point(|b| *b <= id.0) - 1;
        let local = self.tiles[t].local[(id.0 - self.tile_base[t]) as usize];
        self.pair_label.get((self.pair_base[t] + local) as usize).copied()
    }

    /// Node count of each component, by label.
    pub fn component_sizes(&self) -> &[u32] {
        &self.component_sizes
    }

    /// The node nearest to direction `dir` (any non-zero vector): in the nearest column that has
    /// nodes (searching outward column by column, at most `max_rings` steps), the node whose
    /// surface radius is nearest to `radius`, or the highest node when `radius` is `None`.
    pub fn node_near(&self, dir: DVec3, radius: Option<f64>, max_rings: usize) -> Option<NodeId> {
        let start = self.columns.nearest(dir)?;
        let mut ring = vec![start];
        let mut seen = std::collections::HashSet::from([start]);
        for _ in 0..=max_rings {
            let mut best: Option<(f64, NodeId)> = None;
            for c in &ring {
                for (id, n) in self.column_nodes(*c) {
                    let score = match radius {
                        Some(r) => (n.radius - r).abs(),
                        None => -n.radius,
                    };
                    if best.is_none_or(|(s, _)| score < s) {
                        best = Some((score, id));
                    }
                }
            }
            if let Some((_, id)) = best {
                return Some(id);
            }
            let mut next = Vec::new();
            for c in &ring {
                for q in self.columns.neighbours(*c).iter() {
                    if seen.insert(*q) {
                        next.push(*q);
                    }
                }
            }
            ring = next;
        }
        None
    }

    /// The nodes whose surface points lie within `range` metres of `p` (planet frame), nearest
    /// column first, at most `limit`; and whether more were left out. Found by walking the
    /// columns outward from the one under `p`, so the cost follows the area asked for, not the
    /// planet's size.
    pub fn nodes_near(&self, p: DVec3, range: f64, limit: usize) -> (Vec<NodeId>, bool) {
        let mut out = Vec::new();
        let Some(start) = self.columns.nearest(p) else {
            return (out, false);
        };
        // A column can hold a node within range only if its direction is within this angle of
        // p's (nodes lie at radius at least min_radius); columns are walked while they are.
        let r = p.length();
        let reach = |c: u32| -> bool {
            let d = self.columns.direction(c);
            let angle = d.cross(p).length().atan2(d.dot(p));
            // Distance from p to the ray of the column, at its nearest: r sin(angle) when the
            // angle is below 90 degrees.
            angle <= std::f64::consts::FRAC_PI_2 && r * angle.sin() <= range * 1.5 + 1e-9
        };
        let mut seen = std::collections::HashSet::from([start]);
        let mut queue = std::collections::VecDeque::from([start]);
        let mut truncated = false;
        while let Some(c) = queue.pop_front() {
            let dir = self.columns.direction(c);
            for (id, n) in self.column_nodes(c) {
                if (dir * n.radius - p).length() <= range {
                    if out.len() == limit {
                        truncated = true;
                        return (out, truncated);
                    }
                    out.push(id);
                }
            }
            for q in self.columns.neighbours(c).iter() {
                if seen.insert(*q) && reach(*q) {
                    queue.push_back(*q);
                }
            }
        }
        (out, truncated)
    }
}
