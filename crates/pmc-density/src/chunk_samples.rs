//! Whole-chunk batches from a source that may keep them: the density at the lattice points of a
//! chunk's sample grid, for readers of a planet's voxels other than the mesher (the navigation
//! grid), so that a planet which caches its terrain's batches per chunk can answer them without
//! sampling the terrain again.

use crate::Density;
use pmc_geometry::ChunkGrid;

/// The density at the samples of a chunk's grid: `out[c * dirs.len() + d]` is the density at
/// `grid.dirs[d] * grid.radii[c]`, exactly the bits [`Density::sample_shell`] gives for them
/// (a source that caches batches must answer with those bits).
///
/// Every [`Density`] is one (it samples); a planet with a cache of its terrain's batches answers
/// from the cache and applies its edits on top (`pmc_planet::Planet`).
pub trait ChunkSamples: Sync {
    /// Writes the samples of `grid` (a level-0 or coarser chunk's grid, as
    /// [`ChunkGrid::new`] builds it) into `out`.
    ///
    /// # Panics
    /// If `out.len() != grid.dirs.len() * grid.radii.len()`.
    fn chunk_samples(&self, grid: &ChunkGrid, out: &mut [f32]);
}

impl<D: Density + ?Sized> ChunkSamples for D {
    fn chunk_samples(&self, grid: &ChunkGrid, out: &mut [f32]) {
        self.sample_shell(&grid.dirs, &grid.radii, out);
    }
}
