//! Edited planets: brushes keep the planet one closed surface, chunks keep agreeing on shared
//! voxels, undo gives back the exact meshes, and remeshing the affected chunks is enough.

use pmc_density::Density;
use pmc_edit::{affected_chunks, affected_chunks_lod, BrushKind, BrushOp, EditLog, EditSnapshot};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{face_uv_to_sphere, ChunkGrid, ChunkKey, Face, Layout, SideMask, VoxelKey};
use pmc_mesh::{ChunkMesh, WeldedMesh};
use pmc_planet::{ChunkScratch, Planet, PresetKind};
use proptest::prelude::*;
use std::collections::{BTreeMap, HashMap};

/// The small layout of the property tests: `n_c = 2`, `n_t = 8`, a 16 m shell at radius 60-76 m.
fn small_layout() -> Layout {
    Layout::new(2, 8, 60.0, 1.0, 2).unwrap()
}

/// Every chunk's mesh (empty ones included), by key.
fn all_meshes(planet: &Planet) -> BTreeMap<ChunkKey, ChunkMesh> {
    planet
        .layout()
        .chunks(0)
        .into_iter()
        .map(|k| (k, planet.chunk_mesh(k)))
        .collect()
}

/// Every byte of a mesh that anything downstream reads.
fn bytes(m: &ChunkMesh) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend(format!("{:?}", m.key).bytes());
    for x in m.origin.to_array() {
        b.extend(x.to_bits().to_le_bytes());
    }
    for v in m.positions.iter().chain(&m.normals) {
        for x in v {
            b.extend(x.to_bits().to_le_bytes());
        }
    }
    for i in &m.indices {
        b.extend(i.to_le_bytes());
    }
    for k in &m.edge_keys {
        b.extend(k.0.to_le_bytes());
        b.extend(k.1.to_le_bytes());
    }
    for x in m.heights.iter().chain(&m.water_depths) {
        b.extend(x.to_bits().to_le_bytes());
    }
    for c in &m.colors {
        b.extend(c);
    }
    b.extend(&m.materials);
    b
}

fn same(a: &BTreeMap<ChunkKey, ChunkMesh>, b: &BTreeMap<ChunkKey, ChunkMesh>) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|((ka, ma), (kb, mb))| ka == kb && bytes(ma) == bytes(mb))
}

fn report(meshes: &BTreeMap<ChunkKey, ChunkMesh>) -> pmc_mesh::ManifoldReport {
    let list: Vec<ChunkMesh> = meshes.values().filter(|m| !m.is_empty()).cloned().collect();
    WeldedMesh::weld(&list).report()
}

fn assert_closed(meshes: &BTreeMap<ChunkKey, ChunkMesh>) {
    let r = report(meshes);
    assert!(r.triangles > 0);
    assert!(r.is_closed_manifold(), "not a closed manifold: {r:?}");
}

/// Samples every chunk's padded grid through the planet's (edited) density and checks that every
/// voxel held by several chunks (borders, face edges, cube corners, valid padding) got the same
/// bits from each. Returns the number of repeated readings compared.
fn shared_voxels_agree(planet: &Planet) -> usize {
    let mut seen: HashMap<VoxelKey, (u32, ChunkKey)> = HashMap::new();
    let mut compared = 0;
    for key in planet.layout().chunks(0) {
        let g = ChunkGrid::new(planet.layout(), key);
        let mut d = vec![0.0f32; g.sample_count()];
        planet.density().sample_shell(&g.dirs, &g.radii, &mut d);
        for c in 0..g.padded {
            for b in 0..g.padded {
                for a in 0..g.padded {
                    if !g.valid[b * g.padded + a] {
                        continue;
                    }
                    let bits = d[g.index(a, b, c)].to_bits();
                    let vk = g.voxel_key(a, b, c);
                    if let Some((prev, owner)) = seen.insert(vk, (bits, key)) {
                        compared += 1;
                        assert_eq!(
                            prev,
                            bits,
                            "voxel {vk:?}: {} in {owner}, {} in {key}",
                            f32::from_bits(prev),
                            f32::from_bits(bits)
                        );
                    }
                }
            }
        }
    }
    compared
}

/// The radius of the surface along `dir` (the outermost zero crossing, by bisection).
fn surface_radius(density: &dyn Density, dir: DVec3, lo: f64, hi: f64) -> f64 {
    let step = 0.25;
    let mut r = hi;
    while r > lo && density.density(dir * r) <= 0.0 {
        r -= step;
    }
    let (mut a, mut b) = (r, r + step);
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        if density.density(dir * m) > 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    a
}

/// Where a random brush goes: anywhere on a face, on a face edge, or on a cube corner.
#[derive(Clone, Copy, Debug)]
enum Place {
    Face(usize, f64, f64),
    Edge(usize, bool, bool, f64),
    Corner(usize, bool, bool),
}

impl Place {
    fn dir(self) -> DVec3 {
        let pm = |b: bool| if b { 1.0 } else { -1.0 };
        match self {
            Place::Face(f, u, v) => face_uv_to_sphere(Face::ALL[f], u, v),
            Place::Edge(f, along_u, side, t) => {
                let (u, v) = if along_u { (t, pm(side)) } else { (pm(side), t) };
                face_uv_to_sphere(Face::ALL[f], u, v)
            }
            Place::Corner(f, a, b) => face_uv_to_sphere(Face::ALL[f], pm(a), pm(b)),
        }
        .normalize()
    }
}

fn place() -> impl Strategy<Value = Place> {
    prop_oneof![
        (0usize..6, -1.0f64..1.0, -1.0f64..1.0).prop_map(|(f, u, v)| Place::Face(f, u, v)),
        (0usize..6, any::<bool>(), any::<bool>(), -1.0f64..1.0).prop_map(|(f, a, s, t)| Place::Edge(f, a, s, t)),
        (0usize..6, any::<bool>(), any::<bool>()).prop_map(|(f, a, b)| Place::Corner(f, a, b)),
    ]
}

/// A random brush: kind, place, height offset from the surface, radius, strength.
#[derive(Clone, Copy, Debug)]
struct RandomOp {
    kind: usize,
    place: Place,
    offset: f64,
    radius: f64,
    strength: f64,
}

fn random_op() -> impl Strategy<Value = RandomOp> {
    (0usize..5, place(), -3.0f64..3.0, 1.0f64..30.0, 0.2f64..1.0).prop_map(|(kind, place, offset, radius, strength)| {
        RandomOp {
            kind,
            place,
            offset,
            radius,
            strength,
        }
    })
}

impl RandomOp {
    /// The brush, centred `offset` metres off the current surface. Smoothing reads the density
    /// six times per sample (recursively under earlier smoothing), so its radius stays small.
    fn resolve(self, planet: &Planet) -> BrushOp {
        let kind = [
            BrushKind::Add,
            BrushKind::Remove,
            BrushKind::Smooth,
            BrushKind::Flatten,
            BrushKind::Paint { material: 2 },
        ][self.kind];
        let radius = if kind == BrushKind::Smooth {
            1.0 + (self.radius - 1.0) * 7.0 / 29.0
        } else {
            self.radius
        };
        let l = planet.layout();
        let dir = self.place.dir();
        let r = surface_radius(planet.density().as_ref(), dir, l.d_b(), l.radius());
        BrushOp::new(kind, dir * (r + self.offset), radius, self.strength).unwrap()
    }
}

fn preset(sphere: bool) -> PresetKind {
    if sphere {
        PresetKind::Sphere
    } else {
        PresetKind::Earthlike
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random sequences of all five brushes, anywhere near the surface (face edges and cube
    /// corners included): after every edit, replacing the affected chunks' meshes gives exactly
    /// a fresh planet's meshes, and the union is a closed 2-manifold; after the sequence, chunks
    /// agree bit for bit on every shared voxel.
    #[test]
    fn random_edit_sequences_keep_the_planet_closed_and_paired(
        sphere in any::<bool>(),
        seed in 0u64..1000,
        ops in proptest::collection::vec(random_op(), 1..6),
    ) {
        let mut planet = Planet::new(preset(sphere), seed, small_layout());
        let mut log = EditLog::new();
        let mut meshes = all_meshes(&planet);
        for r in ops {
            let op = r.resolve(&planet);
            log.push(op);
            planet.set_edits(log.snapshot());
            let remeshed = planet.remesh(&op);
            let reused = planet.remesh_reusing(&op, |k| meshes.get(k));
            prop_assert_eq!(remeshed.len(), reused.len());
            for (a, b) in remeshed.iter().zip(&reused) {
                prop_assert!(bytes(a) == bytes(b), "reusing the shading changed {:?}", a.key);
            }
            for m in remeshed {
                meshes.insert(m.key.unwrap(), m);
            }
            let fresh = all_meshes(&planet);
            prop_assert!(same(&meshes, &fresh), "remeshing the affected chunks missed a change after {op:?}");
            let rep = report(&meshes);
            prop_assert!(rep.is_closed_manifold(), "after {op:?}: {rep:?}");
        }
        prop_assert!(shared_voxels_agree(&planet) > 1000);
        // The parallel generator agrees with the chunk-by-chunk meshes.
        let generated = planet.generate(|_| {});
        let nonempty: Vec<&ChunkMesh> = meshes.values().filter(|m| !m.is_empty()).collect();
        prop_assert_eq!(generated.len(), nonempty.len());
        for (g, m) in generated.iter().zip(nonempty) {
            prop_assert!(bytes(g) == bytes(m));
        }
    }

    /// Soundness of `affected_chunks`: on a planet already carrying edits, every chunk whose mesh
    /// changes when one more random brush is applied is listed.
    #[test]
    fn every_chunk_whose_mesh_changes_is_affected(
        sphere in any::<bool>(),
        before in proptest::collection::vec(random_op(), 0..3),
        op in random_op(),
    ) {
        let mut planet = Planet::new(preset(sphere), 7, small_layout());
        let mut log = EditLog::new();
        for r in before {
            log.push(r.resolve(&planet));
            planet.set_edits(log.snapshot());
        }
        let old = all_meshes(&planet);
        let op = op.resolve(&planet);
        log.push(op);
        planet.set_edits(log.snapshot());
        let new = all_meshes(&planet);
        let listed = affected_chunks(planet.layout(), &op);
        let mut changed = 0;
        for (key, m) in &new {
            if bytes(m) != bytes(&old[key]) {
                changed += 1;
                prop_assert!(listed.contains(key), "{key} changed but is not listed for {op:?}");
            }
        }
        // Paint is widened by one grid edge (up to 10 m here) and may change nothing (a material the
        // sphere lacks), so the slack is a few columns of chunks.
        prop_assert!(listed.len() <= changed + 24 || listed.len() <= 2 * changed + 4, "{} listed, {changed} changed", listed.len());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// What the server does after an edit: every chunk of every level the edit reaches, in every
    /// seam variant, meshed reusing the shading of the same variant before the edit, gives the
    /// bytes of meshing it anew; after a paint brush too (whose colours the reuse must not copy
    /// inside its reach), and undoing the edit the same way.
    #[test]
    fn lod_chunks_reusing_the_shading_before_an_edit_are_byte_identical(
        sphere in any::<bool>(),
        seed in 0u64..1000,
        first in random_op(),
        second in random_op(),
    ) {
        let layout = Layout::new(4, 8, 60.0, 1.0, 2).unwrap();
        let mut planet = Planet::new(preset(sphere), seed, layout);
        let mut log = EditLog::new();
        log.push(first.resolve(&planet));
        planet.set_edits(log.snapshot());
        let before = planet.clone();
        let op = second.resolve(&planet);
        log.push(op);
        planet.set_edits(log.snapshot());
        let mut scratch = ChunkScratch::default();
        let mut reused = ChunkMesh::default();
        let mut checked = 0;
        let keys = affected_chunks_lod(&layout, &op);
        // A brush that reaches no chunk (a small one in the air) has nothing to check.
        prop_assume!(!keys.is_empty());
        for key in keys {
            let sides = layout.seam_sides(&key).0;
            for mask in (0..=sides).filter(|m| m & !sides == 0).map(SideMask) {
                for (from, to) in [(&before, &planet), (&planet, &before)] {
                    let previous = from.chunk_mesh_lod(key, mask);
                    let fresh = to.chunk_mesh_lod(key, mask);
                    to.chunk_mesh_lod_reusing_into(key, mask, &previous, &op, &mut scratch, &mut reused);
                    prop_assert!(bytes(&fresh) == bytes(&reused), "{key} seams {mask:?} after {op:?}");
                    checked += 1;
                }
            }
        }
        prop_assert!(checked > 0);
    }
}

/// A surface point of `planet` above `dir`, and the planet with one brush there.
fn brush_at(planet: &Planet, kind: BrushKind, dir: DVec3, radius: f64) -> BrushOp {
    let l = planet.layout();
    let r = surface_radius(planet.density().as_ref(), dir.normalize(), l.d_b(), l.radius());
    BrushOp::new(kind, dir.normalize() * r, radius, 1.0).unwrap()
}

#[test]
fn undo_gives_back_the_exact_meshes_and_redo_the_edited_ones() {
    let mut planet = Planet::new(PresetKind::Earthlike, 3, small_layout());
    let original = all_meshes(&planet);
    let mut log = EditLog::new();
    let dig = brush_at(&planet, BrushKind::Remove, DVec3::new(0.3, 1.0, 0.2), 9.0);
    log.push(dig);
    planet.set_edits(log.snapshot());
    let edited = all_meshes(&planet);
    assert!(!same(&original, &edited), "the edit changes the planet");

    assert_eq!(log.undo(), Some(dig));
    planet.set_edits(log.snapshot());
    assert!(
        same(&all_meshes(&planet), &original),
        "undo restores the meshes byte for byte"
    );
    // Remeshing after the undo, with or without the edited meshes' shading, gives them too.
    let undone = planet.remesh(&dig);
    assert!(!undone.is_empty());
    for (m, r) in undone.iter().zip(planet.remesh_reusing(&dig, |k| edited.get(k))) {
        assert_eq!(bytes(m), bytes(&original[&m.key.unwrap()]));
        assert_eq!(bytes(m), bytes(&r));
    }

    assert_eq!(log.redo(), Some(dig));
    planet.set_edits(log.snapshot());
    assert!(same(&all_meshes(&planet), &edited), "redo restores the edited meshes");

    // Pushing after an undo drops the redo tail.
    log.undo();
    let fill = brush_at(&planet, BrushKind::Add, DVec3::new(-0.5, 0.2, 1.0), 6.0);
    log.push(fill);
    assert_eq!(log.redo(), None);
    assert_eq!(log.active(), &[fill]);
    planet.set_edits(log.snapshot());
    let filled = all_meshes(&planet);
    assert!(!same(&filled, &original) && !same(&filled, &edited));
    // And undoing that one gives the original planet back again.
    log.undo();
    planet.set_edits(log.snapshot());
    assert!(same(&all_meshes(&planet), &original));
    assert_eq!(
        planet.density().radial_bounds(),
        planet.terrain().density.radial_bounds()
    );
}

#[test]
fn dig_then_look_a_remove_at_the_surface_opens_a_pit() {
    // A sphere with 1 m layers and about 5 m columns: a 10 m ball carved at its surface.
    let layout = Layout::new(2, 16, 100.0, 1.0, 1).unwrap();
    let mut planet = Planet::new(PresetKind::Sphere, 1, layout);
    let (r, _) = planet.terrain().density.radial_bounds().unwrap();
    let before = all_meshes(&planet);
    assert_closed(&before);
    let dir = DVec3::new(0.2, 0.3, 1.0).normalize();
    let op = BrushOp::new(BrushKind::Remove, dir * r, 10.0, 1.0).unwrap();
    planet.set_edits(vec![op].into());
    assert!(
        (planet.density().density(op.center) + 10.0).abs() < 1e-9,
        "air at the centre"
    );
    let after = all_meshes(&planet);
    assert_closed(&after);
    let deepest = |m: &BTreeMap<ChunkKey, ChunkMesh>| {
        m.values()
            .flat_map(|c| (0..c.vertex_count()).map(move |i| c.world_position(i)))
            .filter(|p| (*p - op.center).length() < 12.0)
            .map(|p| p.length())
            .fold(f64::INFINITY, f64::min)
    };
    assert!(deepest(&before) > r - 0.5, "no pit before: {}", deepest(&before));
    assert!(deepest(&after) < r - 8.0, "a pit about 10 m deep: {}", deepest(&after));
    // The volume lost is about half the ball (the surface curves away a little).
    let volume = |m: &BTreeMap<ChunkKey, ChunkMesh>| {
        WeldedMesh::weld(&m.values().filter(|c| !c.is_empty()).cloned().collect::<Vec<_>>()).volume()
    };
    let lost = volume(&before) - volume(&after);
    let half_ball = 2.0 / 3.0 * std::f64::consts::PI * 1000.0;
    assert!(
        lost > 0.7 * half_ball && lost < 1.2 * half_ball,
        "lost {lost} m^3, half ball {half_ball}"
    );
    // Everything changed lies in the affected chunks, and only a few chunks are.
    let listed = affected_chunks(&layout, &op);
    for (k, m) in &after {
        if bytes(m) != bytes(&before[k]) {
            assert!(listed.contains(k), "{k}");
        }
    }
    assert!(listed.len() <= 8, "{listed:?}");
}

/// The eight cube corners, each named once (three faces meet at each).
fn cube_corners() -> Vec<DVec3> {
    let mut out: Vec<DVec3> = Vec::new();
    for face in Face::ALL {
        for (u, v) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
            let d = face_uv_to_sphere(face, u, v);
            if !out.iter().any(|o| (*o - d).length() < 1e-9) {
                out.push(d);
            }
        }
    }
    assert_eq!(out.len(), 8);
    out
}

#[test]
fn remove_at_a_cube_corner_keeps_the_planet_closed() {
    for (i, corner) in cube_corners().into_iter().enumerate() {
        for preset in [PresetKind::Earthlike, PresetKind::Sphere] {
            let mut planet = Planet::new(preset, 11 + i as u64, small_layout());
            let before = all_meshes(&planet);
            let op = brush_at(&planet, BrushKind::Remove, corner, 6.0);
            planet.set_edits(vec![op].into());
            let after = all_meshes(&planet);
            assert_closed(&after);
            assert!(shared_voxels_agree(&planet) > 1000);
            // The pit reaches the three faces that meet there.
            let mut faces: Vec<Face> = after
                .iter()
                .filter(|(k, m)| bytes(m) != bytes(&before[k]))
                .map(|(k, _)| k.face)
                .collect();
            faces.dedup();
            faces.sort_by_key(|f| f.index());
            faces.dedup();
            assert_eq!(faces.len(), 3, "{preset} corner {i}: changed faces {faces:?}");
        }
    }
}

#[test]
fn remove_across_a_face_edge_keeps_the_planet_closed() {
    for face in Face::ALL {
        for (u, v) in [(1.0, 0.3), (-0.4, -1.0)] {
            let mut planet = Planet::new(PresetKind::Earthlike, 5, small_layout());
            let before = all_meshes(&planet);
            let op = brush_at(&planet, BrushKind::Remove, face_uv_to_sphere(face, u, v), 12.0);
            planet.set_edits(vec![op].into());
            let after = all_meshes(&planet);
            assert_closed(&after);
            assert!(shared_voxels_agree(&planet) > 1000);
            let faces: std::collections::BTreeSet<usize> = after
                .iter()
                .filter(|(k, m)| bytes(m) != bytes(&before[k]))
                .map(|(k, _)| k.face.index())
                .collect();
            assert!(
                faces.len() >= 2,
                "{face} ({u}, {v}): the edit crosses the edge, changed {faces:?}"
            );
            assert!(faces.contains(&face.index()));
        }
    }
}

#[test]
fn add_above_the_terrain_and_remove_below_it_widen_the_bounds() {
    // A sphere with room above and below its surface, columns about 5 m apart.
    let layout = Layout::new(2, 16, 60.0, 1.0, 4).unwrap();
    let mut planet = Planet::new(PresetKind::Sphere, 2, layout);
    let (lo, hi) = planet.terrain().density.radial_bounds().unwrap();
    let dir = DVec3::new(0.1, 0.2, -1.0).normalize();
    // A ball floating 8 m above the surface and a cavern 6 m under it.
    let tower = BrushOp::new(BrushKind::Add, dir * (hi + 14.0), 6.0, 1.0).unwrap();
    let cavern = BrushOp::new(BrushKind::Remove, -dir * (lo - 12.0), 6.0, 1.0).unwrap();
    planet.set_edits(vec![tower, cavern].into());
    let (lo2, hi2) = planet.density().radial_bounds().unwrap();
    assert!(hi2 >= hi + 20.0 && lo2 <= lo - 18.0, "({lo2}, {hi2}) vs ({lo}, {hi})");
    let meshes = all_meshes(&planet);
    assert_closed(&meshes);
    let r = report(&meshes);
    // The sphere, a floating ball and the inner wall of an enclosed cavern: three spheres.
    assert_eq!(r.euler_characteristic(), 6, "{r:?}");
    // Meshed through the skip logic and without it, the same.
    let tops = meshes
        .values()
        .filter(|m| !m.is_empty())
        .map(|m| m.key.unwrap().k)
        .max();
    assert!(
        tops.unwrap() > 2,
        "the floating ball lies in a chunk the terrain alone would skip"
    );
}

#[test]
fn paint_changes_materials_and_colours_inside_its_ball_only() {
    let mut planet = Planet::new(PresetKind::Earthlike, 9, small_layout());
    let before = all_meshes(&planet);
    let snow = 4u8;
    assert_eq!(planet.terrain().materials[usize::from(snow)], "snow");
    let op = brush_at(
        &planet,
        BrushKind::Paint { material: snow },
        DVec3::new(0.7, 0.1, 0.6),
        8.0,
    );
    planet.set_edits(vec![op].into());
    assert!(planet.density().radial_bounds() == planet.terrain().density.radial_bounds());
    let after = all_meshes(&planet);
    let listed = affected_chunks(planet.layout(), &op);
    let mut painted = 0;
    for (k, m) in &after {
        let b = &before[k];
        assert_eq!(
            (&m.positions, &m.normals, &m.indices),
            (&b.positions, &b.normals, &b.indices)
        );
        for i in 0..m.vertex_count() {
            let p = m.world_position(i);
            if (p - op.center).length() < op.radius {
                painted += 1;
                assert!(listed.contains(k));
                assert_eq!(m.materials[i], snow);
                assert_eq!(m.colors[i], planet.terrain().shader.shade_material(snow, p).color);
            } else {
                assert_eq!((m.materials[i], m.colors[i]), (b.materials[i], b.colors[i]));
            }
        }
    }
    assert!(painted > 3, "{painted} vertices painted");
    // Paint past the terrain's material list is ignored.
    let bogus = BrushOp::new(BrushKind::Paint { material: 200 }, op.center, 8.0, 1.0).unwrap();
    planet.set_edits(EditSnapshot::from(vec![bogus]));
    assert!(same(&all_meshes(&planet), &before));
}

#[test]
fn a_brush_that_touches_no_sample_changes_nothing() {
    let mut planet = Planet::new(PresetKind::Sphere, 1, small_layout());
    let before = all_meshes(&planet);
    // Far outside the shell.
    let op = BrushOp::new(BrushKind::Add, DVec3::X * 500.0, 10.0, 1.0).unwrap();
    assert!(affected_chunks(planet.layout(), &op).is_empty());
    planet.set_edits(vec![op].into());
    assert!(planet.remesh(&op).is_empty());
    let after = all_meshes(&planet);
    assert!(same(&before, &after));
}

/// A random step of an editing session: push a brush, or undo the last one.
#[derive(Clone, Copy, Debug)]
enum Step {
    Push(RandomOp),
    Undo,
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        4 => random_op().prop_map(Step::Push),
        1 => Just(Step::Undo),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// The base density cache changes no byte: random sessions of all five brushes (face edges
    /// and cube corners included) and undos give the same meshes on a cached planet as on an
    /// uncached one, chunk by chunk, with the cache cold, warm, and evicting (a bound smaller
    /// than the planet), through `chunk_mesh`, `remesh`, `remesh_reusing` and `generate`.
    #[test]
    fn the_base_cache_changes_no_byte(
        sphere in any::<bool>(),
        seed in 0u64..1000,
        small_bound in any::<bool>(),
        steps in proptest::collection::vec(step(), 1..6),
    ) {
        let max_chunks = if small_bound { 5 } else { 1000 };
        let mut plain = Planet::new(preset(sphere), seed, small_layout());
        let mut cached = plain.clone().with_base_cache(max_chunks);
        // Cold: every chunk misses (or is skipped without sampling).
        let mut meshes = all_meshes(&cached);
        prop_assert!(same(&meshes, &all_meshes(&plain)), "cold cache");
        let mut log = EditLog::new();
        for s in steps {
            let op = match s {
                Step::Push(r) => {
                    let op = r.resolve(&plain);
                    log.push(op);
                    op
                }
                Step::Undo => match log.undo() {
                    Some(op) => op,
                    None => continue,
                },
            };
            plain.set_edits(log.snapshot());
            cached.set_edits(log.snapshot());
            let expected = plain.remesh(&op);
            let warm = cached.remesh(&op);
            let reused = cached.remesh_reusing(&op, |k| meshes.get(k));
            prop_assert_eq!(expected.len(), warm.len());
            prop_assert_eq!(expected.len(), reused.len());
            for ((e, w), r) in expected.iter().zip(&warm).zip(&reused) {
                prop_assert!(bytes(e) == bytes(w), "remesh {:?} after {op:?}", e.key);
                prop_assert!(bytes(e) == bytes(r), "remesh_reusing {:?} after {op:?}", e.key);
            }
            for m in warm {
                meshes.insert(m.key.unwrap(), m);
            }
            let fresh = all_meshes(&cached);
            prop_assert!(same(&fresh, &all_meshes(&plain)), "all chunks after {op:?}");
            prop_assert!(same(&fresh, &meshes));
            let stats = cached.base_cache_stats().unwrap();
            // A bound smaller than the planet thrashes under whole-planet sweeps (all misses).
            prop_assert!(stats.chunks <= max_chunks && (small_bound || stats.hits > 0), "{stats:?}");
        }
        // A cold cache on the edited planet, and the parallel generator on the warm one.
        let cold = plain.clone().with_base_cache(max_chunks);
        prop_assert!(same(&all_meshes(&cold), &meshes), "cold cache with edits");
        let generated = cached.generate(|_| {});
        let nonempty: Vec<&ChunkMesh> = meshes.values().filter(|m| !m.is_empty()).collect();
        prop_assert_eq!(generated.len(), nonempty.len());
        for (g, m) in generated.iter().zip(nonempty) {
            prop_assert!(bytes(g) == bytes(m));
        }
    }
}

#[test]
fn the_base_cache_is_bounded_and_shared_by_clones() {
    let plain = Planet::new(PresetKind::Earthlike, 4, small_layout());
    assert!(plain.base_cache_stats().is_none(), "off by default");
    assert!(
        plain.clone().with_base_cache(0).base_cache_stats().is_none(),
        "0 is off"
    );
    let planet = plain.with_base_cache(5);
    let mut clone = planet.clone();
    let mut sampled = Vec::new();
    for key in planet.layout().chunks(0) {
        let _ = clone.chunk_mesh(key);
        let s = planet.base_cache_stats().unwrap();
        assert!(s.chunks <= 5, "{s:?}");
        assert_eq!(s.chunks, (s.misses as usize).min(5), "{s:?}");
        if s.misses as usize > sampled.len() {
            sampled.push(key);
        }
    }
    assert!(
        sampled.len() > 5,
        "the planet has more chunks with surface than the bound"
    );
    let s = planet.base_cache_stats().unwrap();
    assert_eq!((s.hits, s.max_chunks, s.chunks), (0, 5, 5));
    let grid = ChunkGrid::new(planet.layout(), sampled[0]);
    assert_eq!(s.bytes, 5 * grid.sample_count() * 4);
    assert_eq!(grid.sample_count(), 11 * 11 * 11, "(n_t + 3)^3 samples");
    // The clone filled the original's cache: the chunk sampled last is there for both (edits do
    // not invalidate it).
    clone.set_edits(vec![BrushOp::new(BrushKind::Remove, DVec3::Y * 68.0, 5.0, 1.0).unwrap()].into());
    let last = sampled[sampled.len() - 1];
    let _ = planet.chunk_mesh(last);
    let _ = clone.chunk_mesh(last);
    let s2 = planet.base_cache_stats().unwrap();
    assert_eq!((s2.hits, s2.misses), (2, s.misses));
    // The others beyond the bound were dropped: a second sweep misses some, and five stay held.
    for key in &sampled {
        let _ = planet.chunk_mesh(*key);
    }
    let s3 = planet.base_cache_stats().unwrap();
    assert!(s3.misses > s.misses, "{s3:?}");
    assert_eq!(
        (s3.hits + s3.misses, s3.chunks),
        (2 + s.misses + sampled.len() as u64, 5)
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// Remeshing around an edit samples only a box of a chunk's samples, and relies on a batch
    /// giving each sample the bits the whole chunk's batch gives it: a batch over any box of a
    /// chunk's columns and layers, on every preset, with edits, agrees with the chunk's batch
    /// bit for bit.
    #[test]
    fn a_batch_over_part_of_a_chunk_gives_the_whole_batchs_bits(
        kind in 0usize..PresetKind::ALL.len(),
        seed in 0u64..1000,
        chunk in 0usize..1000,
        lo in prop::array::uniform3(0usize..11),
        size in prop::array::uniform3(0usize..6),
        brush in 0.0f64..1.0,
    ) {
        let layout = small_layout();
        let mut planet = Planet::new(PresetKind::ALL[kind], seed, layout);
        let keys = layout.chunks(0);
        let key = keys[chunk % keys.len()];
        let grid = ChunkGrid::new(&layout, key);
        // A remove brush at a sample of the chunk, so some samples carry an edit.
        let p = grid.padded;
        let at = grid.position(p / 2, p / 2, (brush * (p - 1) as f64) as usize);
        planet.set_edits(EditSnapshot::from(vec![BrushOp::new(BrushKind::Remove, at, 9.0, 1.0).unwrap()]));
        let mut whole = vec![0.0f32; grid.sample_count()];
        planet.density().sample_shell(&grid.dirs, &grid.radii, &mut whole);
        let lo = lo.map(|x| x.min(p - 1));
        let hi: [usize; 3] = std::array::from_fn(|a| (lo[a] + size[a]).min(p - 1));
        let all = &grid.dirs;
        let dirs: Vec<DVec3> = (lo[1]..=hi[1]).flat_map(|b| (lo[0]..=hi[0]).map(move |a| all[b * p + a])).collect();
        let radii = &grid.radii[lo[2]..=hi[2]];
        let mut part = vec![0.0f32; dirs.len() * radii.len()];
        planet.density().sample_shell(&dirs, radii, &mut part);
        let mut values = part.iter();
        for c in lo[2]..=hi[2] {
            for b in lo[1]..=hi[1] {
                for a in lo[0]..=hi[0] {
                    let v = values.next().unwrap();
                    prop_assert_eq!(v.to_bits(), whole[grid.index(a, b, c)].to_bits(), "{} sample {:?}", key, (a, b, c));
                }
            }
        }
    }
}

/// The earth preset on a small layout: a 128 m shell, eight chunks of 16 m deep, the surface
/// within 40 m of its middle.
fn small_earth() -> Planet {
    Planet::new(PresetKind::Earth, 7, Layout::new(4, 8, 500.0, 2.0, 8).unwrap())
}

/// The marching-cubes mesh of `key` by hand: the density's batch, the shell's closure, the
/// mesher (no shading: only whether it holds a triangle is compared).
fn triangles_by_hand(planet: &Planet, key: ChunkKey) -> usize {
    let grid = ChunkGrid::new(planet.layout(), key);
    let mut d = vec![0.0f32; grid.sample_count()];
    planet.density().sample_shell(&grid.dirs, &grid.radii, &mut d);
    pmc_mesh::close_shell(&grid, planet.layout().depth_tiles(), &mut d);
    let mut out = ChunkMesh::default();
    pmc_mesh::Mesher::default().mesh(&grid, &d, &mut out);
    out.triangle_count()
}

#[test]
fn chunks_of_one_sign_are_empty_without_meshing_and_the_planet_stays_closed() {
    // The earth density tells chunks whose samples all have one sign from the ends of their
    // columns, and the planet gives them an empty mesh without sampling them: every such chunk
    // would have meshed to nothing, every other chunk meshes as by hand, and the planet is closed.
    let planet = small_earth();
    let meshes = all_meshes(&planet);
    assert_closed(&meshes);
    let mut told = 0;
    for (key, mesh) in &meshes {
        let grid = ChunkGrid::new(planet.layout(), *key);
        if planet.density().uniform_sign(&grid.dirs, &grid.radii).is_some() {
            told += 1;
            assert!(mesh.is_empty(), "{key:?} told of one sign");
        }
        assert_eq!(mesh.triangle_count(), triangles_by_hand(&planet, *key), "{key:?}");
    }
    assert!(
        told >= meshes.len() / 4,
        "{told} of {} chunks told of one sign",
        meshes.len()
    );
    // and the chunks of level 1, closing every side against a coarser neighbour
    let mut scratch = ChunkScratch::default();
    let mut out = ChunkMesh::default();
    let mut coarse = 0;
    for key in planet.layout().chunks(1) {
        let grid = ChunkGrid::new(planet.layout(), key);
        if planet.density().uniform_sign(&grid.dirs, &grid.radii).is_some() {
            coarse += 1;
            planet.chunk_mesh_lod_into(key, SideMask::ALL, &mut scratch, &mut out);
            assert!(out.is_empty() && out.key == Some(key), "{key:?} at level 1");
        }
    }
    assert!(coarse > 0, "chunks of level 1 told of one sign");
}

#[test]
fn a_bubble_carved_in_a_chunk_of_solid_rock_is_meshed() {
    // A chunk of one sign stops being one once an edit reaches it: the edited density declines
    // to tell (regression guard for the shortcut that skips chunks of one sign), the bubble is
    // meshed, and the planet stays closed.
    let mut planet = small_earth();
    let key = planet
        .layout()
        .chunks(0)
        .into_iter()
        .find(|k| {
            let grid = ChunkGrid::new(planet.layout(), *k);
            k.k == 0 && planet.density().uniform_sign(&grid.dirs, &grid.radii) == Some(true)
        })
        .expect("a chunk of solid rock at the bottom of the shell");
    let grid = ChunkGrid::new(planet.layout(), key);
    let middle = grid.dirs[grid.dirs.len() / 2] * grid.radii[grid.radii.len() / 2];
    let op = BrushOp::new(BrushKind::Remove, middle, 5.0, 1.0).unwrap();
    planet.set_edits(vec![op].into());
    assert_eq!(planet.density().uniform_sign(&grid.dirs, &grid.radii), None);
    let meshes = all_meshes(&planet);
    assert!(!meshes[&key].is_empty(), "the bubble is meshed");
    assert_eq!(meshes[&key].triangle_count(), triangles_by_hand(&planet, key));
    assert_closed(&meshes);
}
