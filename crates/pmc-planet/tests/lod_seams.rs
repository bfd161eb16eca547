//! Closed seams between levels of detail: chunks of two levels, each fine chunk closing the
//! seam toward its coarser neighbours with transition patches, weld into one closed 2-manifold
//! by edge key, and vertices shared across a level seam carry the same normal.

use pmc_geometry::{ChunkKey, ChunkSide, Face, Layout, SideMask};
use pmc_mesh::{ChunkMesh, WeldedMesh};
use pmc_planet::{Planet, PresetKind};
use std::collections::{BTreeSet, HashMap};

/// The side mask of every leaf: the sides across which the leaf region is one level coarser.
fn masks(layout: &Layout, leaves: &BTreeSet<ChunkKey>) -> Vec<(ChunkKey, SideMask)> {
    leaves
        .iter()
        .map(|key| {
            let mut mask = SideMask::NONE;
            for side in ChunkSide::ALL {
                let Some(coarse) = layout.neighbour(key, side, key.level + 1) else {
                    continue;
                };
                if leaves.contains(&coarse)
                    && layout.neighbour(key, side, key.level).map(|n| n.parent()) == Some(coarse)
                {
                    mask = mask.with(side);
                }
            }
            (*key, mask)
        })
        .collect()
}

/// Meshes every leaf with its mask.
fn mesh_all(planet: &Planet, leaves: &BTreeSet<ChunkKey>) -> Vec<ChunkMesh> {
    masks(planet.layout(), leaves)
        .into_iter()
        .map(|(key, mask)| planet.chunk_mesh_lod(key, mask))
        .filter(|m| !m.is_empty())
        .collect()
}

/// Replaces `key` in `leaves` by its children.
fn split(layout: &Layout, leaves: &mut BTreeSet<ChunkKey>, key: ChunkKey) {
    assert!(leaves.remove(&key), "{key} is not a leaf");
    for c in key.children().unwrap() {
        if layout.contains_chunk(&c) {
            leaves.insert(c);
        }
    }
}

fn assert_closed(meshes: &[ChunkMesh], what: &str) {
    let report = WeldedMesh::weld(meshes).report();
    assert!(report.is_closed_manifold(), "{what}: {report:?}");
    assert!(report.triangles > 0, "{what}: empty");
}

/// Every vertex key shared by several chunks has the same normal in each (bit for bit in f32).
fn assert_normals_agree(meshes: &[ChunkMesh], what: &str) -> usize {
    let mut seen: HashMap<pmc_geometry::EdgeKey, [f32; 3]> = HashMap::new();
    let mut shared = 0;
    for m in meshes {
        for (k, n) in m.edge_keys.iter().zip(&m.normals) {
            if let Some(prev) = seen.insert(*k, *n) {
                shared += 1;
                let dot: f32 = (0..3).map(|i| prev[i] * n[i]).sum();
                assert!(
                    dot > 1.0 - 1e-6,
                    "{what}: normals {prev:?} and {n:?} differ at a shared vertex"
                );
            }
        }
    }
    shared
}

fn small_planet(preset: PresetKind, seed: u64) -> Planet {
    Planet::new(preset, seed, Layout::new(4, 8, 100.0, 2.0, 4).unwrap())
}

#[test]
fn one_split_chunk_in_a_coarser_planet_is_closed() {
    let planet = small_planet(PresetKind::Earthlike, 7);
    let layout = *planet.layout();
    let base: BTreeSet<ChunkKey> = layout.chunks(1).into_iter().collect();
    assert_closed(&mesh_all(&planet, &base), "level 1 alone");
    for key in base.iter().copied().filter(|k| planet.may_hold_surface(k)).take(12) {
        let mut leaves = base.clone();
        split(&layout, &mut leaves, key);
        let meshes = mesh_all(&planet, &leaves);
        assert_closed(&meshes, &format!("{key} split"));
        assert_normals_agree(&meshes, &format!("{key} split"));
    }
}

#[test]
fn splits_at_cube_corners_and_face_edges_are_closed() {
    for (preset, seed) in [
        (PresetKind::Earthlike, 3),
        (PresetKind::Moon, 5),
        (PresetKind::Mars, 9),
        (PresetKind::Sphere, 0),
    ] {
        let planet = small_planet(preset, seed);
        let layout = *planet.layout();
        // One face at level 1, the others at level 2: seams across the four face edges and at
        // the cube corners around it.
        let mut leaves: BTreeSet<ChunkKey> = layout.chunks(2).into_iter().collect();
        for k in layout.chunks(2).into_iter().filter(|k| k.face == Face::Top) {
            split(&layout, &mut leaves, k);
        }
        let meshes = mesh_all(&planet, &leaves);
        assert_closed(&meshes, &format!("{preset:?} face at level 1"));
        assert_normals_agree(&meshes, &format!("{preset:?} face at level 1"));
        // Everything at level 1, and the chunks at one cube corner of the top face at level 0.
        let mut leaves: BTreeSet<ChunkKey> = layout.chunks(1).into_iter().collect();
        for k in 0..layout.depth_chunks(1) {
            split(
                &layout,
                &mut leaves,
                ChunkKey {
                    face: Face::Top,
                    level: 1,
                    i: 0,
                    j: 0,
                    k,
                },
            );
        }
        let meshes = mesh_all(&planet, &leaves);
        assert_closed(&meshes, &format!("{preset:?} corner at level 0"));
        assert_normals_agree(&meshes, &format!("{preset:?} corner at level 0"));
    }
}

#[test]
fn without_transition_patches_the_seams_are_open() {
    let planet = small_planet(PresetKind::Earthlike, 7);
    let layout = *planet.layout();
    let mut leaves: BTreeSet<ChunkKey> = layout.chunks(1).into_iter().collect();
    let key = *leaves.iter().find(|k| planet.may_hold_surface(k)).unwrap();
    split(&layout, &mut leaves, key);
    let plain: Vec<ChunkMesh> = leaves
        .iter()
        .map(|k| planet.chunk_mesh_lod(*k, SideMask::NONE))
        .collect();
    let report = WeldedMesh::weld(&plain).report();
    assert!(report.boundary_edges > 0, "{report:?}");
}

/// The level-1 chunks around each level-1 chunk edge whose four chunks alternate split and
/// unsplit: (the two unsplit ones).
fn checkerboards(layout: &Layout, split: &BTreeSet<ChunkKey>) -> BTreeSet<ChunkKey> {
    let mut out = BTreeSet::new();
    let near = |k: &ChunkKey| -> BTreeSet<ChunkKey> {
        ChunkSide::ALL
            .into_iter()
            .filter_map(|s| layout.neighbour(k, s, 1))
            .collect()
    };
    for x in layout.chunks(1) {
        for (a, b) in [
            (0, 2),
            (0, 3),
            (1, 2),
            (1, 3),
            (0, 4),
            (0, 5),
            (1, 4),
            (1, 5),
            (2, 4),
            (2, 5),
            (3, 4),
            (3, 5),
        ] {
            let (Some(n1), Some(n2)) = (
                layout.neighbour(&x, ChunkSide::ALL[a], 1),
                layout.neighbour(&x, ChunkSide::ALL[b], 1),
            ) else {
                continue;
            };
            let (m1, m2) = (near(&n1), near(&n2));
            if m1.contains(&n2) {
                continue; // three chunks around a cube-corner line
            }
            let Some(d) = m1.intersection(&m2).copied().find(|d| *d != x) else {
                continue;
            };
            let (sx, sd, s1, s2) = (
                split.contains(&x),
                split.contains(&d),
                split.contains(&n1),
                split.contains(&n2),
            );
            if sx == sd && s1 == s2 && sx != s1 {
                out.extend(if sx { [n1, n2] } else { [x, d] });
            }
        }
    }
    out
}

/// Random sets of level-1 chunks split to level 0 (the 2:1 rule always holds) close exactly
/// when no chunk edge has its four chunks alternating split and unsplit; splitting the unsplit
/// ones of such an edge (what the level-of-detail selection does) closes them all.
#[test]
fn random_splits_close_once_edge_checkerboards_are_refined() {
    let planet = small_planet(PresetKind::Earthlike, 11);
    let layout = *planet.layout();
    let all: Vec<ChunkKey> = layout.chunks(1);
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut rand = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let mut refined = 0;
    for round in 0..12 {
        let mut chosen: BTreeSet<ChunkKey> = all.iter().copied().filter(|_| rand() % 3 == 0).collect();
        let leaves_of = |chosen: &BTreeSet<ChunkKey>| {
            let mut leaves: BTreeSet<ChunkKey> = all.iter().copied().collect();
            for k in chosen {
                split(&layout, &mut leaves, *k);
            }
            leaves
        };
        let report = WeldedMesh::weld(&mesh_all(&planet, &leaves_of(&chosen))).report();
        let boards = checkerboards(&layout, &chosen);
        assert_eq!(report.boundary_edges, 0, "round {round}: {report:?}");
        assert_eq!(
            report.is_closed_manifold(),
            boards.is_empty() || report.bad_edges == 0,
            "round {round}: {report:?}"
        );
        loop {
            let boards = checkerboards(&layout, &chosen);
            if boards.is_empty() {
                break;
            }
            refined += 1;
            chosen.extend(boards);
        }
        let meshes = mesh_all(&planet, &leaves_of(&chosen));
        assert_closed(&meshes, &format!("round {round}"));
        assert_normals_agree(&meshes, &format!("round {round}"));
    }
    assert!(refined > 0, "the rounds should meet some checkerboards");
}

/// An edit changes the level-of-detail mesh (any level, any side mask) of no chunk outside
/// `affected_chunks_lod`; some of those changes are seam patches of a finer chunk next to a
/// reached coarser one, which the per-level lists alone would miss; and edits show at every
/// level.
#[test]
fn edits_change_only_the_listed_chunks_of_every_level() {
    use pmc_planet::pmc_edit::{affected_chunks_at, affected_chunks_lod, BrushKind, BrushOp};
    let planet = small_planet(PresetKind::Earthlike, 5);
    let layout = *planet.layout();
    let surface = planet.datum_radius();
    let (mut seam_only, mut changed_levels) = (0, BTreeSet::new());
    for step in 0..16 {
        // Small brushes along a line across chunk borders of every level.
        let u = -0.3 + 0.6 * f64::from(step) / 15.0;
        let dir = pmc_geometry::face_uv_to_sphere(Face::Top, u, 0.013);
        let op = BrushOp::new(BrushKind::Remove, dir * surface, 3.0, 1.0).unwrap();
        let edited = planet.clone().with_edits(vec![op].into());
        let listed: BTreeSet<ChunkKey> = affected_chunks_lod(&layout, &op).into_iter().collect();
        let per_level: BTreeSet<ChunkKey> = (0..=layout.max_level())
            .flat_map(|l| affected_chunks_at(&layout, l, &op))
            .collect();
        for level in 0..=layout.max_level() {
            for key in layout.chunks(level) {
                for mask in [SideMask::NONE, SideMask::ALL] {
                    if planet.chunk_mesh_lod(key, mask) != edited.chunk_mesh_lod(key, mask) {
                        assert!(listed.contains(&key), "{key} (mask {mask:?}) changed but is not listed");
                        changed_levels.insert(level);
                        if !per_level.contains(&key) {
                            seam_only += 1;
                        }
                    }
                }
            }
        }
    }
    assert_eq!(
        changed_levels.len(),
        usize::from(layout.max_level()) + 1,
        "{changed_levels:?}"
    );
    assert!(seam_only > 0, "no brush reached a coarser chunk's seam samples only");

    // Paint changes no sample but the vertices in its ball: small balls, between the samples of
    // every level, still change only listed chunks, and some of them do change a mesh.
    let mut painted = 0;
    for step in 0..12 {
        let u = -0.3 + 0.6 * f64::from(step) / 11.0;
        let dir = pmc_geometry::face_uv_to_sphere(Face::Top, u, 0.021).normalize();
        // On the surface (bisection on the density between the shell's bounds).
        let (mut lo, mut hi) = (layout.d_b(), layout.radius());
        for _ in 0..60 {
            let m = 0.5 * (lo + hi);
            if planet.density().density(dir * m) > 0.0 {
                lo = m;
            } else {
                hi = m;
            }
        }
        let op = BrushOp::new(BrushKind::Paint { material: 1 }, dir * lo, 1.2, 1.0).unwrap();
        let edited = planet.clone().with_edits(vec![op].into());
        let listed: BTreeSet<ChunkKey> = affected_chunks_lod(&layout, &op).into_iter().collect();
        for level in 0..=layout.max_level() {
            for key in layout.chunks(level) {
                for mask in [SideMask::NONE, SideMask::ALL] {
                    if planet.chunk_mesh_lod(key, mask) != edited.chunk_mesh_lod(key, mask) {
                        assert!(listed.contains(&key), "{key} (mask {mask:?}) painted but is not listed");
                        painted += 1;
                    }
                }
            }
        }
    }
    assert!(painted > 0, "no paint brush met a vertex");
}

/// Seam patches read a coarser neighbour's samples from the base cache when it holds them: the
/// meshes are byte-identical to uncached ones, with and without edits.
#[test]
fn seams_through_the_base_cache_are_byte_identical() {
    use pmc_planet::pmc_edit::{BrushKind, BrushOp};
    let plain = small_planet(PresetKind::Earthlike, 7);
    let layout = *plain.layout();
    let mut leaves: BTreeSet<ChunkKey> = layout.chunks(1).into_iter().collect();
    let key = *leaves.iter().find(|k| plain.may_hold_surface(k)).unwrap();
    split(&layout, &mut leaves, key);
    let dir = pmc_geometry::face_uv_to_sphere(key.face, 0.0, 0.0);
    let dig = BrushOp::new(BrushKind::Remove, dir * plain.datum_radius(), 20.0, 1.0).unwrap();
    for edits in [vec![], vec![dig]] {
        let plain = plain.clone().with_edits(edits.clone().into());
        let cached = plain.clone().with_base_cache(4096);
        let expected = mesh_all(&plain, &leaves);
        // Coarse chunks first, so their batches are cached when their finer neighbours mesh.
        let mut order: Vec<ChunkKey> = leaves.iter().copied().collect();
        order.sort_by_key(|k| std::cmp::Reverse(k.level));
        for k in order {
            cached.chunk_mesh_lod(k, SideMask::NONE);
        }
        assert_eq!(mesh_all(&cached, &leaves), expected);
        assert!(cached.base_cache_stats().unwrap().hits > 0);
    }
}
