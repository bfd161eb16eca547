//! Occupancy: every voxel of a tile's columns filled or not, from the mesher's samples, and the
//! floors (nodes) found in them.

use super::{NavGrid, Tile, TileKey};
use crate::columns::ColumnPlace;
use crate::rules::{ColumnView, Rules};
use pmc_density::Density;
use pmc_geometry::glam::DVec3;

impl NavGrid {
    /// Samples one tile: its columns' occupancy bits and nodes.
    pub(super) fn sample_tile(&self, density: &dyn Density, key: TileKey) -> (Tile, Vec<u64>) {
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
