//! Closed seams between levels of detail: chunks of two levels, each fine chunk closing the
//! seam toward its coarser neighbours with transition patches, weld into one closed 2-manifold
//! by edge key, and every place the meshes hold more than once (one edge in several chunks, or a
//! fine and a coarse vertex in one place, in one chunk or two) carries one normal.

use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkKey, ChunkSide, EdgeKey, Face, Layout, SideMask};
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

/// Whether two unit normals are the same (to `f32` rounding of the same gradient).
fn same_normal(a: [f32; 3], b: [f32; 3]) -> bool {
    (0..3).map(|i| a[i] * b[i]).sum::<f32>() > 1.0 - 1e-6
}

/// Two vertices closer than this (metres) are in the same place.
const SAME_PLACE: f64 = 1e-3;

/// The copies of every place among `meshes`: vertices with the same edge key (in several
/// chunks), and vertices in the same place (within [`SAME_PLACE`], in one chunk or in several)
/// whatever their keys.
#[derive(Debug, Default)]
struct Copies {
    /// Copies compared by key.
    keyed: usize,
    /// Copies with different keys compared by place.
    placed: usize,
    /// Where copies with one key have different normals.
    key_differs: Vec<DVec3>,
    /// Where copies with different keys in one place have different normals.
    place_differs: Vec<DVec3>,
}

/// A vertex: its place, normal and edge key.
type Vertex = (DVec3, [f32; 3], EdgeKey);

fn copies(meshes: &[ChunkMesh]) -> Copies {
    let mut by_key: HashMap<EdgeKey, [f32; 3]> = HashMap::new();
    let mut cells: HashMap<[i64; 3], Vec<Vertex>> = HashMap::new();
    let mut out = Copies::default();
    for m in meshes {
        for i in 0..m.vertex_count() {
            let (p, n, k) = (m.world_position(i), m.normals[i], m.edge_keys[i]);
            if let Some(prev) = by_key.insert(k, n) {
                out.keyed += 1;
                if !same_normal(prev, n) {
                    out.key_differs.push(p);
                }
            }
            let cell = p.to_array().map(|x| (x / SAME_PLACE).floor() as i64);
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let near = [cell[0] + dx, cell[1] + dy, cell[2] + dz];
                        for (q, nq, kq) in cells.get(&near).into_iter().flatten() {
                            if *kq != k && p.distance(*q) < SAME_PLACE {
                                out.placed += 1;
                                if !same_normal(*nq, n) {
                                    out.place_differs.push(p);
                                }
                            }
                        }
                    }
                }
            }
            cells.entry(cell).or_default().push((p, n, k));
        }
    }
    out
}

/// Every place held by several vertices (by edge key in several chunks, or by position in one
/// chunk or several) has one normal, but that vertices of different keys in one place may
/// differ on the radial `lines` given (unit directions). Returns the number of copies compared
/// by key and by place.
fn assert_normals_agree_off(meshes: &[ChunkMesh], lines: &[DVec3], what: &str) -> (usize, usize) {
    let c = copies(meshes);
    assert!(
        c.key_differs.is_empty(),
        "{what}: {} vertices of one edge with different normals, the first at {:?}",
        c.key_differs.len(),
        c.key_differs[0]
    );
    let off: Vec<&DVec3> = c
        .place_differs
        .iter()
        .filter(|p| !lines.iter().any(|d| p.normalize().distance(*d) < 1e-6))
        .collect();
    assert!(
        off.is_empty(),
        "{what}: {} vertices in one place with different normals, the first at {:?}",
        off.len(),
        off[0]
    );
    (c.keyed, c.placed)
}

/// Every place held by several vertices has one normal (see [`assert_normals_agree_off`]).
fn assert_normals_agree(meshes: &[ChunkMesh], what: &str) -> (usize, usize) {
    assert_normals_agree_off(meshes, &[], what)
}

/// The radial lines along which a fine chunk cannot give its vertex the coarse normal of the
/// coarse vertex in the same place: the edges of a coarser leaf `coarse` that lie on a face edge
/// (where, in the whole-face selections here, two coarser and two finer chunks meet, each fine
/// chunk beside a chunk of its own level: its side mask cannot tell that chunk from one facing
/// nothing coarser), but not on a cube corner.
fn coarse_edges_on_face_edges(layout: &Layout, coarse: impl IntoIterator<Item = ChunkKey>) -> Vec<DVec3> {
    let n = layout.face_tiles();
    let mut out = Vec::new();
    for key in coarse {
        let span = i64::from(layout.n_t()) * key.stride();
        let (i, j) = (i64::from(key.i) * span, i64::from(key.j) * span);
        for (ci, cj) in [(i, j), (i + span, j), (i, j + span), (i + span, j + span)] {
            let l = layout.lattice(key.face, ci, cj).expect("a chunk corner is on its face");
            let on_edges = l.abs().to_array().iter().filter(|c| i64::from(**c) == n).count();
            if on_edges == 2 {
                out.push(layout.lattice_direction(l));
            }
        }
    }
    out
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

/// One face a level finer or coarser than the other five, on every preset: the level changes
/// along the face's four edges and at its four cube corners. Every place the meshes hold more
/// than once (one edge in several chunks, or a fine and a coarse vertex in one place, in one
/// chunk or in two) has one normal, but where two coarser chunks meet on a face edge (see
/// [`coarse_edges_on_face_edges`]; with one coarse chunk per face there is none).
#[test]
fn whole_face_level_changes_give_every_place_one_normal_on_every_preset() {
    let (mut keyed, mut placed) = (0, 0);
    for (n, preset) in PresetKind::ALL.into_iter().enumerate() {
        let planet = small_planet(preset, 3 + n as u64);
        let layout = *planet.layout();
        for (face, level, rest) in [
            (Face::Top, 1, 2),
            (Face::West, 2, 1),
            (Face::Bottom, 0, 1),
            (Face::North, 1, 0),
        ] {
            let mut leaves: BTreeSet<ChunkKey> = layout.chunks(rest).into_iter().filter(|k| k.face != face).collect();
            leaves.extend(layout.chunks(level).into_iter().filter(|k| k.face == face));
            let meshes = mesh_all(&planet, &leaves);
            let what = format!("{preset:?}, {face:?} at level {level}, the other faces at {rest}");
            assert_closed(&meshes, &what);
            let coarse = leaves.iter().filter(|k| k.level == level.max(rest)).copied();
            let lines = coarse_edges_on_face_edges(&layout, coarse);
            let (k, p) = assert_normals_agree_off(&meshes, &lines, &what);
            keyed += k;
            placed += p;
        }
    }
    assert!(keyed > 0 && placed > 0, "{keyed} copies by key, {placed} by place");
}

/// A chunk's key from its name, `face/level/i/j/k`.
fn chunk(face: Face, level: u8, i: u32, j: u32, k: u32) -> ChunkKey {
    ChunkKey { face, level, i, j, k }
}

/// Where a face met coarser faces, a fine chunk held a fine vertex and its patch's coarse vertex
/// in one place with different normals (the fine chunk's gradient, and the coarse neighbour's):
/// on the default planet with `west` at level 1 and the rest at level 2, `west/1/0/3/0`
/// (seams 9) held two vertices at (-1225.41, 790.41, -1225.41) with normals (-0.50, 0.39, -0.78)
/// and (-0.01, 0.22, -0.98); on Mars (`n_c = 16`, seed 5, `bottom` at level 0, the rest at
/// level 1) the copies differed by up to 1.2 in a component, in `bottom/0/11/0/0` and between it
/// and `south/1/5/7/0`.
#[test]
fn fine_and_coarse_copies_of_a_place_at_a_face_edge_share_one_normal() {
    let default = Layout::default();
    let mars = Layout::new(16, default.n_t(), default.d_b(), default.l_d(), default.d_c()).unwrap();
    let cases = [
        (
            Planet::new(PresetKind::Earthlike, 7, default),
            (Face::West, 1, 2),
            chunk(Face::West, 1, 0, 3, 0),
            9,
            None,
            DVec3::new(-1225.41, 790.41, -1225.41),
        ),
        (
            Planet::new(PresetKind::Mars, 5, mars),
            (Face::Bottom, 0, 1),
            chunk(Face::Bottom, 0, 11, 0, 0),
            4,
            Some(chunk(Face::South, 1, 5, 7, 0)),
            DVec3::new(-438.17, -1258.47, 1258.47),
        ),
    ];
    for (planet, (face, level, rest), fine, seams, coarse, place) in cases {
        let layout = *planet.layout();
        let mut leaves: BTreeSet<ChunkKey> = layout.chunks(rest).into_iter().filter(|k| k.face != face).collect();
        leaves.extend(layout.chunks(level).into_iter().filter(|k| k.face == face));
        let masks = masks(&layout, &leaves);
        let meshes: Vec<ChunkMesh> = masks
            .iter()
            .map(|(key, mask)| planet.chunk_mesh_lod(*key, *mask))
            .collect();
        let lines = coarse_edges_on_face_edges(&layout, leaves.iter().filter(|k| k.level == rest).copied());
        let (_, placed) = assert_normals_agree_off(&meshes, &lines, &format!("{fine} and its neighbours"));
        assert!(placed > 0, "{fine}: no fine and coarse copies of a place");
        // The copies the issue names.
        let at = |key: ChunkKey| -> Vec<[f32; 3]> {
            let m = &meshes[masks.iter().position(|(k, _)| *k == key).expect("a selected chunk")];
            (0..m.vertex_count())
                .filter(|&i| m.world_position(i).distance(place) < 0.01)
                .map(|i| m.normals[i])
                .collect()
        };
        assert_eq!(masks.iter().find(|(k, _)| *k == fine).map(|(_, m)| m.0), Some(seams));
        let mut copies = at(fine);
        assert!(copies.len() >= 2, "{fine}: {copies:?}");
        copies.extend(coarse.map(at).unwrap_or_default());
        assert!(copies.len() >= 2 + usize::from(coarse.is_some()), "{copies:?}");
        assert!(copies.iter().all(|n| same_normal(*n, copies[0])), "{fine}: {copies:?}");
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
        // Along an edge of an unsplit chunk a split chunk beside a split one cannot tell whether
        // that one faces the unsplit chunk too: there a fine and a coarse vertex in one place
        // may keep their own normals (never two vertices of one edge).
        let lines = unsplit_edges(&layout, all.iter().filter(|k| !chosen.contains(*k)).copied());
        assert_normals_agree_off(&meshes, &lines, &format!("round {round}"));
    }
    assert!(refined > 0, "the rounds should meet some checkerboards");
}

/// The radial edges of the chunks `unsplit` (unit directions), but those on cube corners.
fn unsplit_edges(layout: &Layout, unsplit: impl IntoIterator<Item = ChunkKey>) -> Vec<DVec3> {
    let n = layout.face_tiles();
    let mut out = Vec::new();
    for key in unsplit {
        let span = i64::from(layout.n_t()) * key.stride();
        let (i, j) = (i64::from(key.i) * span, i64::from(key.j) * span);
        for (ci, cj) in [(i, j), (i + span, j), (i, j + span), (i + span, j + span)] {
            let l = layout.lattice(key.face, ci, cj).expect("a chunk corner is on its face");
            if !l.abs().to_array().iter().all(|c| i64::from(*c) == n) {
                out.push(layout.lattice_direction(l));
            }
        }
    }
    out
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

/// Thin dark lines along chunk borders (`docs/images/earth-10km.png`): the copies of a border
/// vertex in two chunks were stored as `f32` offsets from two origins, so they came back up to
/// half an `f32` step of the larger chunk apart (centimetres for chunks hundreds of kilometres
/// wide) and the viewer rasterised them a hair apart, the sky showing through. With the
/// positions' low-order parts every copy comes back to the same place far below a micrometre
/// (what the viewer's eye-relative high/low positions need to rasterise them the same), at
/// planetary scale as on a small planet, between chunks of one level and of two.
#[test]
fn copies_of_a_border_vertex_rasterised_a_hair_apart_drew_dark_lines() {
    let earth = Planet::new(PresetKind::Earth, 7, PresetKind::Earth.default_layout(None).unwrap());
    let small = small_planet(PresetKind::Earthlike, 7);
    for planet in [&small, &earth] {
        let layout = *planet.layout();
        let top = layout.max_level();
        // one face two levels finer than the rest, around the face's corner at the top
        let (face, level, rest) = (Face::Top, top.saturating_sub(2), top.saturating_sub(1));
        let mut leaves: BTreeSet<ChunkKey> = layout.chunks(rest).into_iter().filter(|k| k.face != face).collect();
        leaves.extend(layout.chunks(level).into_iter().filter(|k| k.face == face));
        let meshes = mesh_all(planet, &leaves);
        let mut first: HashMap<EdgeKey, (DVec3, DVec3)> = HashMap::new();
        let (mut shared, mut plain, mut full, mut radius) = (0usize, 0f64, 0f64, 0f64);
        for m in &meshes {
            assert_eq!(
                m.positions_low.len(),
                m.vertex_count(),
                "{:?}: low parts for every vertex",
                m.key
            );
            for i in 0..m.vertex_count() {
                let (p, q) = (m.world_position(i), m.world_position_full(i));
                radius = radius.max(q.length());
                if let Some((p0, q0)) = first.insert(m.edge_keys[i], (p, q)) {
                    shared += 1;
                    plain = plain.max(p.distance(p0));
                    full = full.max(q.distance(q0));
                }
            }
        }
        let what = format!("radius {radius:.0} m, {} chunks", meshes.len());
        assert!(shared > 100, "{what}: only {shared} shared vertices");
        // a few f64 steps at the radius: the sums' own rounding
        let bound = 8.0 * radius * f64::EPSILON;
        assert!(
            full <= bound,
            "{what}: copies {full:e} m apart with the low parts (bound {bound:e})"
        );
        assert!(
            plain > 100.0 * full.max(bound / 8.0),
            "{what}: without the low parts {plain:e} m apart, with {full:e}"
        );
    }
}
