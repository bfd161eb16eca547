//! Shared fixtures for the benchmarks: the default planet and a chunk of it that holds surface.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

use pmc_density::Density;
use pmc_geometry::glam::DVec3;
use pmc_geometry::{sphere_to_face_uv, ChunkGrid, ChunkKey, Face, LatLon, Layout};
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
    let mut best = (0, ChunkKey::new(Face::Top, 0, 0, k));
    for i in 0..l.n_c() {
        for j in 0..l.n_c() {
            let key = ChunkKey::new(Face::Top, i, j, k);
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

/// The terrain surface of `planet` above latitude `lat`, longitude `lon` (degrees); see
/// [`surface_along`].
pub fn surface_point(planet: &Planet, lat: f64, lon: f64) -> DVec3 {
    let dir = LatLon::new(lat, lon).expect("a valid latitude and longitude").to_unit();
    surface_along(planet, dir)
}

/// The terrain surface of `planet` along the unit direction `dir`: the outermost zero crossing of
/// the density on the radial line, searched down from the top of the shell in quarter-voxel steps
/// and refined by bisection. The point returned is on the solid side, within 1e-9 m.
pub fn surface_along(planet: &Planet, dir: DVec3) -> DVec3 {
    let density = planet.density();
    let l = planet.layout();
    let step = 0.25 * l.l_d();
    let mut r = l.radius();
    while r > l.d_b() && density.density(dir * r) <= 0.0 {
        r -= step;
    }
    let (mut a, mut b) = (r, r + step);
    while b - a > 1e-9 {
        let m = 0.5 * (a + b);
        if density.density(dir * m) > 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    dir * a
}

/// The direction of the level-0 voxel column nearest to the direction of `p`.
pub fn nearest_column(layout: &Layout, p: DVec3) -> DVec3 {
    let (face, u, v) = sphere_to_face_uv(p).expect("a point away from the centre");
    let n = layout.face_tiles();
    let index = |x: f64| (((x + 1.0) * 0.5 * n as f64).round() as i64).clamp(0, n);
    let l = layout.lattice(face, index(u), index(v)).expect("an index on the face");
    layout.lattice_direction(l)
}

/// The direction of the voxel column where the level-0 chunks `(i - 1, j - 1)`, `(i, j - 1)`,
/// `(i - 1, j)` and `(i, j)` of `face` meet (chunk corner indices `0..=n_c`).
pub fn chunk_corner(layout: &Layout, face: Face, i: u32, j: u32) -> DVec3 {
    let n_t = i64::from(layout.n_t());
    let l = layout
        .lattice(face, i64::from(i) * n_t, i64::from(j) * n_t)
        .expect("a chunk corner on the face");
    layout.lattice_direction(l)
}
