//! Closed chunks (`Mesher::mesh_closed`): each chunk's mesh with its caps bounds a closed solid
//! on its own, its caps are exactly the solid part of its sides, and any mix of levels, with no
//! balance and no seam masks, shows no inside of a solid to an eye in the air.

use pmc_density::{Density, FnDensity};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkGrid, ChunkKey, Layout};
use pmc_mesh::{close_shell, ChunkMesh, Mesher, WeldedMesh};
use proptest::prelude::*;

/// The mesh of `key`, closed with caps or open.
fn mesh(layout: &Layout, density: &dyn Density, key: ChunkKey, closed: bool, mesher: &mut Mesher) -> ChunkMesh {
    let grid = ChunkGrid::new(layout, key);
    let mut d = vec![0.0f32; grid.sample_count()];
    density.sample_shell(&grid.dirs, &grid.radii, &mut d);
    close_shell(&grid, layout.depth_tiles(), &mut d);
    let mut m = ChunkMesh::default();
    if closed {
        mesher.mesh_closed(&grid, &d, &mut m);
    } else {
        mesher.mesh(&grid, &d, &mut m);
    }
    m
}

/// A hash-based value field: rough, with many ambiguous configurations on the sides.
fn rough_field(seed: u64, scale: f64, base: f64, amplitude: f64) -> impl Fn(DVec3) -> f64 + Send + Sync {
    move |p: DVec3| {
        let q = (p * scale).floor();
        let mut h = seed ^ 0x9E37_79B9_7F4A_7C15;
        for c in [q.x, q.y, q.z] {
            h ^= (c as i64 as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            h = (h ^ (h >> 31)).wrapping_mul(0x94D0_49BB_1331_11EB);
        }
        let noise = (h >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        base - p.length() + noise * amplitude
    }
}

fn report(m: &ChunkMesh) -> pmc_mesh::ManifoldReport {
    WeldedMesh::weld(std::slice::from_ref(m)).report()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]
    /// Every chunk with a surface, closed, is a closed 2-manifold by edge key, with a positive
    /// volume no larger than its cell's; rough fields give every kind of side: saddles, caves
    /// crossing a side, solid islands, cuts at chunk corners.
    #[test]
    fn every_closed_chunk_is_a_closed_manifold(seed in any::<u64>(), n_c in 1u32..3, n_t in 2u32..7, d_c in 1u32..3, scale in 0.3f64..1.5) {
        let layout = Layout::new(n_c, n_t, 20.0, 1.0, d_c).unwrap();
        let mid = 20.0 + f64::from(n_t * d_c) * 0.5;
        let f = FnDensity(rough_field(seed, scale, mid, 8.0));
        let mut mesher = Mesher::new();
        let mut meshed = 0;
        for key in layout.chunks(0) {
            let m = mesh(&layout, &f, key, true, &mut mesher);
            if m.indices.is_empty() {
                continue;
            }
            meshed += 1;
            let r = report(&m);
            prop_assert!(r.is_closed_manifold(), "chunk {key:?} is not closed: {r:?}");
            let v = WeldedMesh::weld(std::slice::from_ref(&m)).volume();
            prop_assert!(v > 0.0, "chunk {key:?} encloses {v}");
            prop_assert_eq!(m.vertex_edges.len(), m.vertex_count());
            prop_assert_eq!(m.edge_keys.len(), m.vertex_count());
            prop_assert!(m.normals.iter().all(|n| n.iter().all(|c| c.is_finite())));
        }
        prop_assert!(meshed > 0);
    }
}

/// The signed volume a set of triangles encloses about the planet's centre (the divergence
/// theorem: exact for a closed mesh, and additive over meshes).
fn volume_about_centre(meshes: &[ChunkMesh]) -> f64 {
    triangles(meshes).iter().map(|[a, b, c]| a.dot(b.cross(*c)) / 6.0).sum()
}

/// The caps are exactly the solid part of each side: where the shell is one chunk deep (every
/// chunk holds the surface), two caps on a shared side cancel, so the closed chunks enclose the
/// planet's volume less the core under the shell, which their inner caps close.
#[test]
fn closed_chunks_add_up_to_the_planet() {
    for (seed, n_t) in [(1u64, 6u32), (2, 5), (3, 8)] {
        let layout = Layout::new(2, n_t, 20.0, 1.0, 1).unwrap();
        let mid = 20.0 + f64::from(n_t) * 0.5;
        let f = FnDensity(rough_field(seed, 0.7, mid, 5.0));
        let mut mesher = Mesher::new();
        let keys = layout.chunks(0);
        let open: Vec<ChunkMesh> = keys.iter().map(|k| mesh(&layout, &f, *k, false, &mut mesher)).collect();
        let closed: Vec<ChunkMesh> = keys.iter().map(|k| mesh(&layout, &f, *k, true, &mut mesher)).collect();
        assert!(WeldedMesh::weld(&open).report().is_closed_manifold());
        assert!(
            closed.iter().all(|m| !m.indices.is_empty()),
            "every chunk holds the surface"
        );
        // The core: the closed chunks' triangles on the shell's inner sphere (every voxel of the
        // inner side lies at radius d_b), facing inwards.
        let core: f64 = -triangles(&closed)
            .iter()
            .filter(|t| t.iter().all(|p| (p.length() - layout.d_b()).abs() < 1e-9))
            .map(|[a, b, c]| a.dot(b.cross(*c)) / 6.0)
            .sum::<f64>();
        let (whole, total) = (volume_about_centre(&open), volume_about_centre(&closed));
        assert!(core > 0.0, "core {core}");
        assert!(
            ((total + core - whole) / whole).abs() < 1e-9,
            "closed chunks {total} + core {core} against the planet {whole} (n_t {n_t})"
        );
    }
}

/// Degenerate samples: exact zeros put cuts on voxels, NaN is air; every chunk stays closed.
#[test]
fn exact_zeros_and_nan_keep_each_chunk_closed() {
    let layout = Layout::new(2, 8, 40.0, 1.0, 2).unwrap();
    let fields: [Box<dyn Fn(DVec3) -> f64 + Send + Sync>; 2] = [
        Box::new(|p: DVec3| (48.0 - p.length() + 1.5 * (p.x * 0.3).sin()).round()),
        Box::new(|p: DVec3| {
            if (p.x * 0.7).sin() > 0.9 {
                f64::NAN
            } else {
                48.3 - p.length()
            }
        }),
    ];
    let mut mesher = Mesher::new();
    for f in fields {
        let f = FnDensity(f);
        for key in layout.chunks(0) {
            let m = mesh(&layout, &f, key, true, &mut mesher);
            if !m.indices.is_empty() {
                let r = report(&m);
                assert!(r.is_closed_manifold(), "chunk {key:?}: {r:?}");
            }
        }
    }
}

/// A random selection of chunks of mixed levels covering the given level-`top` chunks once:
/// each node of the octree is kept or replaced by its children, with no balance between
/// neighbours.
fn mixed_selection(layout: &Layout, roots: Vec<ChunkKey>, seed: u64) -> Vec<ChunkKey> {
    let mut state = seed | 1;
    let mut coin = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        !state.is_multiple_of(3)
    };
    let mut out = Vec::new();
    let mut stack = roots;
    while let Some(key) = stack.pop() {
        if !layout.contains_chunk(&key) {
            continue;
        }
        match key.children() {
            Some(children) if coin() => stack.extend(children),
            _ => out.push(key),
        }
    }
    out
}

/// The first triangle a ray from `eye` along `dir` meets, and whether it faces the eye.
fn first_hit(triangles: &[[DVec3; 3]], eye: DVec3, dir: DVec3) -> Option<(f64, bool)> {
    let mut best: Option<(f64, bool)> = None;
    for [a, b, c] in triangles {
        let (e1, e2) = (*b - *a, *c - *a);
        let p = dir.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-14 {
            continue;
        }
        let inv = 1.0 / det;
        let s = eye - *a;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            continue;
        }
        let q = s.cross(e1);
        let v = dir.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            continue;
        }
        let t = e2.dot(q) * inv;
        if t > 1e-9 && best.is_none_or(|(bt, _)| t < bt) {
            // Counter-clockwise seen from outside: the normal e1 x e2 points at the eye.
            best = Some((t, e1.cross(e2).dot(dir) < 0.0));
        }
    }
    best
}

fn triangles(meshes: &[ChunkMesh]) -> Vec<[DVec3; 3]> {
    meshes
        .iter()
        .flat_map(|m| {
            m.indices
                .chunks_exact(3)
                .map(move |t| [0, 1, 2].map(|n| m.world_position_full(t[n] as usize)))
        })
        .collect()
}

/// Rays from eyes in the air above the middle of a patch of the face towards the ground below
/// (tilted up to 60 degrees from the vertical): how many first meet a back face, the inside of
/// a solid seen through a crack.
fn back_face_hits(layout: &Layout, f: &dyn Density, keys: &[ChunkKey], closed: bool, rays: usize) -> usize {
    let mut mesher = Mesher::new();
    let meshes: Vec<ChunkMesh> = keys.iter().map(|k| mesh(layout, f, *k, closed, &mut mesher)).collect();
    let tris = triangles(&meshes);
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut unit = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    // The patch: the first 8 x 8 level-0 chunks of the Top face; the eyes look at a random
    // place over its middle half (between voxel columns, at a random depth: never exactly on a
    // grid line or plane, where coincident caps would tie).
    let column = |unit: &mut dyn FnMut() -> f64| {
        let pick = |x: f64| 2 + (x * 4.0) as u32;
        let key = ChunkKey::new(pmc_geometry::Face::Top, pick(unit()), pick(unit()), 0);
        let g = ChunkGrid::new(layout, key);
        let (x, y) = (1.0 + unit() * g.tiles as f64, 1.0 + unit() * g.tiles as f64);
        let (a, b) = (x.floor() as usize, y.floor() as usize);
        let (fx, fy) = (x - a as f64, y - b as f64);
        let d = |a: usize, b: usize| g.dirs[g.padded * b + a];
        let lower = d(a, b).lerp(d(a + 1, b), fx);
        let upper = d(a, b + 1).lerp(d(a + 1, b + 1), fx);
        lower.lerp(upper, fy)
    };
    let mut back = 0;
    for _ in 0..rays {
        let up = column(&mut unit).normalize();
        let depth = layout.radius() - layout.d_b();
        let ground = up * (layout.d_b() + depth * (0.2 + 0.6 * unit()));
        let tangent = up.any_orthonormal_vector();
        let spin = std::f64::consts::TAU * unit();
        let side = tangent * spin.cos() + up.cross(tangent) * spin.sin();
        let tilt = 60f64.to_radians() * unit();
        let dir = (-up * tilt.cos() + side * tilt.sin()).normalize();
        let eye = ground - dir * (layout.radius() - layout.d_b()) * 3.0;
        if let Some((_, front)) = first_hit(&tris, eye, dir) {
            back += usize::from(!front);
        }
    }
    back
}

/// Mixed levels with no balance, on a shell as flat for its chunks as the Earth's at coarse
/// levels: without caps, rays see through the cracks into solids; with caps, not one does.
#[test]
fn no_ray_from_the_air_sees_inside_a_solid_whatever_the_levels() {
    // 64 chunks per face side of 4 x 4 x 4 voxels, four deep: levels 0 to 2 over a patch of
    // 8 x 8 level-0 chunks.
    let layout = Layout::new(64, 4, 400.0, 1.0, 4).unwrap();
    let mid = 400.0 + 16.0 * 0.5;
    let f = FnDensity(rough_field(11, 0.08, mid, 9.0));
    let roots: Vec<ChunkKey> = (0..2)
        .flat_map(|i| (0..2).flat_map(move |j| (0..1).map(move |k| (i, j, k))))
        .map(|(i, j, k)| ChunkKey {
            face: pmc_geometry::Face::Top,
            level: 2,
            i,
            j,
            k,
        })
        .collect();
    let mut open_back = 0;
    for seed in [3u64, 5, 8] {
        let keys = mixed_selection(&layout, roots.clone(), seed);
        let levels: std::collections::BTreeSet<u8> = keys.iter().map(|k| k.level).collect();
        assert!(levels.len() >= 2, "the selection mixes levels: {levels:?}");
        let closed = back_face_hits(&layout, &f, &keys, true, 1500);
        assert_eq!(
            closed, 0,
            "selection {seed}: {closed} rays see a back face through a crack"
        );
        open_back += back_face_hits(&layout, &f, &keys, false, 1500);
    }
    assert!(open_back > 0, "without caps the same selections show cracks");
}
