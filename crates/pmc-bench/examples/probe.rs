use pmc_bench::{default_planet, surface_chunk};
use pmc_mesh::ChunkMesh;
use pmc_planet::ChunkScratch;
use std::time::Instant;
fn stats(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[0], v[v.len() / 2])
}
fn main() {
    let planet = default_planet();
    let key = surface_chunk(&planet);
    let mut scratch = ChunkScratch::default();
    let mut out = ChunkMesh::default();
    let grid = pmc_geometry::ChunkGrid::new(planet.layout(), key);
    let mut d = vec![0.0f32; grid.sample_count()];
    let mut mesher = pmc_mesh::Mesher::new();
    let (mut full, mut dm) = (Vec::new(), Vec::new());
    for _ in 0..3000 {
        let t = Instant::now();
        planet.chunk_mesh_into(key, &mut scratch, &mut out);
        full.push(t.elapsed().as_secs_f64() * 1e6);
        let t = Instant::now();
        planet.terrain().density.sample_shell(&grid.dirs, &grid.radii, &mut d);
        pmc_mesh::close_shell(&grid, planet.layout().depth_tiles(), &mut d);
        mesher.mesh(&grid, &d, &mut out);
        dm.push(t.elapsed().as_secs_f64() * 1e6);
    }
    println!("full min/med {:.0?}  d+m min/med {:.0?}", stats(full), stats(dm));
}
