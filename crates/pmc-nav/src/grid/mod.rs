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
//! - **The abstract graph** of the hierarchical search ([`crate::find_path_hierarchical`]): a
//!   node per (tile, local component) pair, a link per pair of pairs that a border step joins;
//!   kept up to date by every rebuild, like the components.
//!
//! The grid holds every column of the planet, up to [`MAX_COLUMNS`]. [`crate::LazyGrid`] has the
//! same floors and steps (the rules are one implementation) for planets of any size, built tile
//! by tile around a query, without components.
//!
//! This module holds the types and the build and rebuild by tile; `occupancy` samples a tile's
//! voxels and floors, `components` labels the components, `hierarchy` keeps the abstract graph, and `queries` answers for nodes,
//! steps and the nodes near a place.

mod components;
mod hierarchy;
mod occupancy;
mod queries;

use crate::agent::{Agent, AgentError};
use crate::columns::{ColumnPlace, Columns};
use crate::rules::Rules;
use occupancy::Source;
use pmc_density::{ChunkSamples, Density};
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
    /// Mean surface point of each local component (the abstract graph's nodes).
    local_points: Vec<DVec3>,
    /// Links of the abstract graph out of the tile: (local component, tile, local component
    /// there), sorted, each once.
    links: Vec<Link>,
    /// Smallest radius of its nodes' surface points (infinite without nodes).
    min_radius: f64,
}

/// A step out of a tile: (local node, tile index, local node there).
type BorderStep = (u32, u32, u32);

/// A link of the abstract graph out of a tile: (local component, tile index, local component
/// there).
type Link = (u32, u32, u32);

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
        grid.rebuild(Source::Density(density), &keys);
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

    /// Whether canonical column `c` of tile `t` lies on the tile's edge: the columns inside it
    /// have their four neighbours on the same face, one grid step away, in the same tile.
    ///
    /// A column strictly inside the tile's span but one step from a border line of its face
    /// that another face owns (the line's columns are canonical there, so in that face's tiles)
    /// is on the edge too: its step onto the line leaves the tile. Counting it as inside hid
    /// that step from the tile's border steps, and the tile from the neighbours of the tile
    /// across the face edge ([`NavGrid::neighbour_tiles`]), so a rebuild kept that tile's stale
    /// links.
    fn on_tile_edge(&self, t: usize, c: u32) -> bool {
        let n_c = i64::from(self.columns.layout().n_c());
        let (n, n_t) = (self.columns.face_tiles(), i64::from(self.columns.layout().n_t()));
        let (ti, tj) = (t as i64 % n_c, t as i64 / n_c % n_c);
        let span = |x: i64| (x * n_t, if x == n_c - 1 { n } else { x * n_t + n_t - 1 });
        let place = self.columns.place_of(c);
        let ((ilo, ihi), (jlo, jhi)) = (span(ti), span(tj));
        if !(place.i > ilo && place.i < ihi && place.j > jlo && place.j < jhi) {
            return true;
        }
        let off_face = |i: i64, j: i64| !self.columns.is_canonical(ColumnPlace { face: place.face, i, j });
        (place.i == 1 && off_face(0, place.j))
            || (place.i == n - 1 && off_face(n, place.j))
            || (place.j == 1 && off_face(place.i, 0))
            || (place.j == n - 1 && off_face(place.i, n))
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

    /// [`NavGrid::rebuild_for`] reading the tiles' voxels from whole-chunk batches of the edited
    /// planet: `source` answers for the level-0 chunks under each tile (a `pmc_planet::Planet`
    /// with a base cache answers from it, applying only its edits, instead of sampling the
    /// terrain again). The grid is the same, node for node, as a fresh build of the edited
    /// density: the batches hold the same bits at the same points.
    pub fn rebuild_for_from(&mut self, source: &dyn ChunkSamples, op: &BrushOp) -> Vec<TileKey> {
        let keys = self.tiles_for(op);
        self.rebuild_tiles_from(source, &keys);
        keys
    }

    /// Samples `density` again under `keys`, then relabels the components: the steps inside the
    /// rebuilt tiles and the steps across the borders of them and of their neighbours are found
    /// again; the other tiles keep theirs. The abstract graph of the hierarchical search follows.
    pub fn rebuild_tiles(&mut self, density: &dyn Density, keys: &[TileKey]) {
        self.rebuild(Source::Density(density), keys);
    }

    /// [`NavGrid::rebuild_tiles`] from whole-chunk batches (see [`NavGrid::rebuild_for_from`]).
    pub fn rebuild_tiles_from(&mut self, source: &dyn ChunkSamples, keys: &[TileKey]) {
        self.rebuild(Source::Chunks(source), keys);
    }

    fn rebuild(&mut self, source: Source, keys: &[TileKey]) {
        if keys.is_empty() && !self.tile_base.is_empty() {
            return;
        }
        let built: Vec<(usize, Tile, Vec<u64>)> = keys
            .par_iter()
            .map(|t| {
                let (tile, bits) = self.sample_tile(source, *t);
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
        type Inside = (usize, Vec<u32>, Vec<u32>, Vec<DVec3>);
        let inside: Vec<Inside> = rebuilt
            .par_iter()
            .map(|t| {
                let (local, sizes, points) = self.inner_components(*t);
                (*t, local, sizes, points)
            })
            .collect();
        for (t, local, sizes, points) in inside {
            self.tiles[t].local = local;
            self.tiles[t].local_sizes = sizes;
            self.tiles[t].local_points = points;
        }
        // Steps across borders: of the rebuilt tiles and of every tile next to one, kept as the
        // abstract graph's links (the border steps between (tile, local component) pairs, each
        // pair of pairs once).
        rebuilt.sort_unstable();
        rebuilt.dedup();
        let mut touched: Vec<usize> = rebuilt.clone();
        for t in &rebuilt {
            touched.extend(self.neighbour_tiles(*t));
        }
        touched.sort_unstable();
        touched.dedup();
        // A tile next to a rebuilt one keeps its links into the tiles not rebuilt (neither end
        // changed) and finds those into the rebuilt ones again.
        let links: Vec<(usize, Vec<Link>)> = touched
            .par_iter()
            .map(|t| {
                if rebuilt.binary_search(t).is_ok() {
                    return (*t, self.links(*t, &self.border_steps(*t, |_| true)));
                }
                let into = |u: usize| rebuilt.binary_search(&u).is_ok();
                let mut l = self.links(*t, &self.border_steps(*t, into));
                l.extend(self.tiles[*t].links.iter().filter(|(_, u, _)| !into(*u as usize)));
                l.sort_unstable();
                (*t, l)
            })
            .collect();
        for (t, l) in links {
            self.tiles[t].links = l;
        }
        self.merge_components();
    }
}
