//! Occupancy: every voxel of a tile's columns filled or not, from the mesher's samples, and the
//! floors (nodes) found in them.

use super::{NavGrid, Tile, TileKey};
use crate::columns::ColumnPlace;
use crate::rules::{ColumnView, Rules};
use pmc_density::{ChunkSamples, Density};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, ChunkKey};

/// Where a tile's samples come from.
#[derive(Clone, Copy)]
pub(super) enum Source<'a> {
    /// A density, sampled at the tile's columns and layers.
    Density(&'a dyn Density),
    /// Whole-chunk batches of the level-0 chunks under the tile (the same bits).
    Chunks(&'a dyn ChunkSamples),
}

impl NavGrid {
    /// Samples one tile: its columns' occupancy bits and nodes.
    pub(super) fn sample_tile(&self, source: Source, key: TileKey) -> (Tile, Vec<u64>) {
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
        let mut places = Vec::new();
        for j in span(key.j) {
            for i in span(key.i) {
                let place = ColumnPlace { face: key.face, i, j };
                if self.columns.is_canonical(place) {
                    columns.push(self.columns.index_of(place));
                    places.push((i, j));
                }
            }
        }
        // Column by column: `samples[column * layers + layer]`.
        let layers = self.radii.len();
        let ncols = columns.len();
        let mut samples = vec![0.0f32; ncols * layers];
        match source {
            Source::Density(density) => {
                let dirs: Vec<DVec3> = columns.iter().map(|c| self.columns.direction(*c)).collect();
                let mut by_layer = vec![0.0f32; ncols * layers];
                density.sample_shell(&dirs, &self.radii, &mut by_layer);
                for (k, row) in by_layer.chunks_exact(ncols.max(1)).enumerate() {
                    for (col, v) in row.iter().enumerate() {
                        samples[col * layers + k] = *v;
                    }
                }
            }
            Source::Chunks(chunks) => self.chunk_samples(chunks, key, &places, &mut samples),
        }
        let top = layers as i64 - 1;
        let mut bits = Vec::with_capacity(ncols * self.words);
        let mut starts = Vec::with_capacity(ncols + 1);
        let mut nodes = Vec::new();
        for d in samples.chunks_exact_mut(layers) {
            for (k, dk) in d.iter_mut().enumerate() {
                *dk = Rules::contract(k as i64, top, *dk);
            }
            starts.push(nodes.len() as u32);
            self.rules
                .column(0, d, |k| self.radii[k as usize], &mut bits, &mut nodes);
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

    /// The samples of a tile's columns at `places` (grid indices on the tile's face), column by
    /// column (`out[column * layers + layer]`), from the batches of the level-0 chunks under
    /// the tile: layer `L` of a column is sample `(a, b, c)` of depth chunk `L / n_t` (the last
    /// chunk also holds the top layer), at the same lattice point and radius, so the same bits
    /// as [`Density::sample_shell`] at the column's direction.
    fn chunk_samples(&self, source: &dyn ChunkSamples, key: TileKey, places: &[(i64, i64)], out: &mut [f32]) {
        let l = self.columns.layout();
        let (n_t, d_c) = (i64::from(l.n_t()), l.d_c());
        let top = self.radii.len() as i64 - 1;
        let layers = self.radii.len();
        let mut batch = Vec::new();
        let first = ChunkGrid::new(l, ChunkKey::new(key.face, key.i, key.j, 0));
        for k in 0..d_c {
            let deeper;
            let grid = if k == 0 {
                &first
            } else {
                deeper = first.at_depth(l, k);
                &deeper
            };
            batch.resize(grid.dirs.len() * grid.radii.len(), 0.0);
            source.chunk_samples(grid, &mut batch);
            let p = grid.padded;
            let k0 = i64::from(k) * n_t;
            let last = if k + 1 == d_c { top } else { k0 + n_t - 1 };
            let (lo, hi) = (k0 as usize, last as usize);
            for ((i, j), column) in places.iter().zip(out.chunks_exact_mut(layers)) {
                let at = (j - grid.j0 + 1) as usize * p + (i - grid.i0 + 1) as usize;
                for (layer, o) in column[lo..=hi].iter_mut().enumerate() {
                    *o = batch[(layer + 1) * p * p + at];
                }
            }
        }
    }

    /// The occupancy of a column: every layer sampled, below layer 0 filled, above the top air.
    pub(super) fn view(&self, column: u32) -> ColumnView<'_> {
        let at = column as usize * self.words;
        ColumnView {
            base: 0,
            len: self.radii.len() as i64,
            words: &self.occupancy[at..at + self.words],
        }
    }

    /// Whether voxel `layer` of `column` is filled.
    pub fn is_filled(&self, column: u32, layer: i64) -> bool {
        self.view(column).filled(layer)
    }
}
