//! Shared fixtures for the benchmarks: the default planet and a chunk of it that holds surface.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

use pmc_geometry::{ChunkGrid, ChunkKey, Layout};
use pmc_mesh::{close_shell, ChunkMesh, Mesher};
use pmc_planet::{Planet, PresetKind};

/// The default planet (`earthlike`, seed 7, default layout).
pub fn default_planet() -> Planet {
    Planet::new(PresetKind::Earthlike, 7, Layout::default())
}

/// A fixed chunk of the default planet with land surface, mountains and caves: among the chunks
/// of the Top face's outer depth layer, the one with the most triangles.
pub fn surface_chunk(planet: &Planet) -> ChunkKey {
    let l = planet.layout();
    let k = l.d_c() - 1;
    let mut best = (0, ChunkKey::new(pmc_geometry::Face::Top, 0, 0, k));
    for i in 0..l.n_c() {
        for j in 0..l.n_c() {
            let key = ChunkKey::new(pmc_geometry::Face::Top, i, j, k);
            let tris = planet.chunk_mesh(key).triangle_count();
            if tris > best.0 {
                best = (tris, key);
            }
        }
    }
    best.1
}

/// The padded, shell-closed densities of a chunk, ready for the mesher.
pub fn chunk_densities(planet: &Planet, key: ChunkKey) -> (ChunkGrid, Vec<f32>) {
    let grid = ChunkGrid::new(planet.layout(), key);
    let mut d = vec![0.0; grid.sample_count()];
    planet.terrain().density.sample_shell(&grid.dirs, &grid.radii, &mut d);
    close_shell(&grid, planet.layout().depth_tiles(), &mut d);
    (grid, d)
}

/// Meshes given densities once (for labelling benchmarks by output size).
pub fn triangle_count(grid: &ChunkGrid, d: &[f32]) -> usize {
    let mut m = ChunkMesh::default();
    Mesher::new().mesh(grid, d, &mut m);
    m.triangle_count()
}
