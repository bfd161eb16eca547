//! Where the mesh of one level of detail puts the surface along a ray: the accuracy check of
//! seed 003 Sec. 8.1, made on the triangles a viewer would draw.

use pmc_geometry::glam::DVec3;
use pmc_geometry::{sphere_to_face_uv, ChunkKey, Layout, SideMask};
use pmc_mesh::ChunkMesh;
use pmc_planet::Planet;

/// The level-`level` chunk holding the point `dir * radius` (a unit `dir`), or `None` outside
/// the shell, past the layout's levels or for a non-finite input.
pub fn chunk_at(layout: &Layout, dir: DVec3, radius: f64, level: u8) -> Option<ChunkKey> {
    if level > layout.max_level() || !radius.is_finite() {
        return None;
    }
    let (face, u, v) = sphere_to_face_uv(dir)?;
    let n = layout.face_tiles() as f64;
    let span = layout.chunk_span(level) as f64;
    let per_side = layout.chunks_per_side(level);
    let index = |x: f64| (((x + 1.0) * 0.5 * n / span).floor().max(0.0) as u32).min(per_side - 1);
    let layer = (radius - layout.d_b()) / layout.l_d();
    if !(0.0..=layout.depth_tiles() as f64).contains(&layer) {
        return None;
    }
    let k = ((layer / span).floor() as u32).min(layout.depth_chunks(level) - 1);
    Some(ChunkKey {
        face,
        level,
        i: index(u),
        j: index(v),
        k,
    })
}

/// The radius at which the ray from the planet's centre along `dir` meets `mesh` (the hit
/// farthest out), or `None` when it misses every triangle.
pub fn ray_hit(mesh: &ChunkMesh, dir: DVec3) -> Option<f64> {
    let mut best: Option<f64> = None;
    let o = -mesh.origin; // the ray's origin (the planet's centre) relative to the mesh
    for tri in mesh.indices.chunks_exact(3) {
        let p = |i: u32| DVec3::from(mesh.positions[i as usize].map(f64::from));
        let (a, b, c) = (p(tri[0]), p(tri[1]), p(tri[2]));
        // Moller-Trumbore in f64, relative to the chunk origin; barycentric slack for the f32
        // rounding of the vertices, so a ray through a vertex or an edge is not lost.
        let (e1, e2) = (b - a, c - a);
        let h = dir.cross(e2);
        let det = e1.dot(h);
        if det.abs() < 1e-18 {
            continue;
        }
        let f = 1.0 / det;
        let s = o - a;
        let u = f * s.dot(h);
        if !(-1e-5..=1.0 + 1e-5).contains(&u) {
            continue;
        }
        let q = s.cross(e1);
        let v = f * dir.dot(q);
        if v < -1e-5 || u + v > 1.0 + 1e-5 {
            continue;
        }
        let t = f * e2.dot(q);
        if t > 0.0 && best.is_none_or(|b| t > b) {
            best = Some(t);
        }
    }
    best
}

/// The radius of the surface the level-`level` mesh draws along the unit direction `dir`: the
/// chunk holding the true surface there (from [`Planet::surface_radius`]) and the chunks above
/// and below it are meshed at that level (no seams), and the outermost triangle the ray meets is
/// taken. `None` when no mesh is met (the level's surface lies in another chunk).
pub fn meshed_surface_radius(planet: &Planet, dir: DVec3, level: u8) -> Option<f64> {
    let layout = planet.layout();
    let r = planet.surface_radius(dir);
    let key = chunk_at(layout, dir, r, level)?;
    let mut best: Option<f64> = None;
    for dk in [1i64, 0, -1] {
        let k = i64::from(key.k) + dk;
        if k < 0 || k >= i64::from(layout.depth_chunks(level)) {
            continue;
        }
        let key = ChunkKey { k: k as u32, ..key };
        let mesh = planet.chunk_mesh_lod(key, SideMask::NONE);
        if let Some(t) = ray_hit(&mesh, dir) {
            best = Some(best.map_or(t, |b: f64| b.max(t)));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_planet::PresetKind;

    #[test]
    fn the_sphere_preset_is_met_at_its_radius_at_every_level() {
        let layout = Layout::new(8, 8, 60.0, 1.0, 2).unwrap();
        let planet = Planet::new(PresetKind::Sphere, 1, layout);
        for (i, dir) in [
            DVec3::Y,
            DVec3::new(0.3, -0.5, 0.8).normalize(),
            DVec3::new(-1.0, 1.0, 1.0).normalize(),
        ]
        .into_iter()
        .enumerate()
        {
            let truth = planet.surface_radius(dir);
            for level in 0..=layout.max_level() {
                let r = meshed_surface_radius(&planet, dir, level)
                    .unwrap_or_else(|| panic!("{i}: no mesh at level {level}"));
                // Chords of a sphere lie inside it, by at most a voxel's sagitta.
                assert!(
                    r <= truth + 1e-6 && truth - r < 0.05 * f64::from(1u32 << level),
                    "{i} level {level}: {r} vs {truth}"
                );
            }
        }
    }

    #[test]
    fn bad_points_have_no_chunk() {
        let layout = Layout::new(8, 8, 60.0, 1.0, 2).unwrap();
        assert_eq!(chunk_at(&layout, DVec3::NAN, 70.0, 0), None);
        assert_eq!(chunk_at(&layout, DVec3::Y, 10.0, 0), None);
        assert_eq!(chunk_at(&layout, DVec3::Y, 70.0, 9), None);
        assert_eq!(chunk_at(&layout, DVec3::Y, f64::NAN, 0), None);
        let k = chunk_at(&layout, DVec3::Y, 70.0, 0).unwrap();
        assert!(layout.contains_chunk(&k));
    }
}
