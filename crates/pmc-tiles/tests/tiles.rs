//! Tiles: the frames' maps and bounds, the implicit octree's coordinates, subtree files, tile
//! contents inside their bounding spheres, deterministic bytes, and bakes that resume.

use pmc_geometry::glam::DVec3;
use pmc_geometry::{Face, Layout};
use pmc_planet::{Planet, PresetKind};
use pmc_tiles::bake::{bake, content_path, subtree_path, BakeStats};
use pmc_tiles::octree::{demorton3, morton3, octree_tiles};
use pmc_tiles::{Region, TileCoord, TileFrame, TileOptions, TileSet, TilesError, Tiling, SUBTREE_LEVELS};
use proptest::prelude::*;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

/// ECEF to geodetic latitude (degrees) and ellipsoid height by Bowring's iteration, a reference
/// independent of the crate's map.
fn geodetic(e: DVec3) -> (f64, f64, f64) {
    let a = 6_378_137.0;
    let f = 1.0 / 298.257_223_563;
    let e2 = f * (2.0 - f);
    let p = (e.x * e.x + e.y * e.y).sqrt();
    let lon = e.y.atan2(e.x);
    let mut lat = e.z.atan2(p * (1.0 - e2));
    let mut h = 0.0;
    for _ in 0..10 {
        let n = a / (1.0 - e2 * lat.sin().powi(2)).sqrt();
        h = if lat.cos().abs() > 1e-9 {
            p / lat.cos() - n
        } else {
            e.z.abs() - n * (1.0 - e2)
        };
        lat = e.z.atan2(p * (1.0 - e2 * n / (n + h)));
    }
    (lat.to_degrees(), lon.to_degrees(), h)
}

/// A planet point at geocentric latitude and longitude (degrees) and radius.
fn planet_point(lat: f64, lon: f64, r: f64) -> DVec3 {
    pmc_geometry::LatLon::new(lat, lon).unwrap().to_unit() * r
}

#[test]
fn the_sphere_frame_turns_the_planet_into_ecef_axes() {
    let f = TileFrame::Sphere;
    // longitude 0 on the planet's +Z, +90 on +X, the pole on +Y
    assert_eq!(f.to_ecef(DVec3::new(0.0, 0.0, 5.0)), DVec3::new(5.0, 0.0, 0.0));
    assert_eq!(f.to_ecef(DVec3::new(5.0, 0.0, 0.0)), DVec3::new(0.0, 5.0, 0.0));
    assert_eq!(f.to_ecef(DVec3::new(0.0, 5.0, 0.0)), DVec3::new(0.0, 0.0, 5.0));
    let p = planet_point(12.5, -70.25, 6.4e6);
    let (lat, lon, _) = geodetic(f.to_ecef(p) * (6_378_137.0 / 6.4e6));
    assert!((lon + 70.25).abs() < 1e-9, "{lon}");
    assert!(
        lat > 12.5,
        "on the sphere, geocentric {lat} lies north of geodetic 12.5"
    );
}

/// Landmarks: every place keeps its latitude, longitude and height above the datum as
/// geodetic latitude, longitude and ellipsoid height.
#[test]
fn the_wgs84_frame_keeps_latitude_longitude_and_height() {
    let datum = 6_371_000.0;
    let f = TileFrame::Wgs84 { datum };
    let landmarks = [
        ("Gulf of Guinea", 0.0, 0.0, 0.0),
        ("Everest", 27.988_1, 86.925, 8_848.86),
        ("Challenger Deep", 11.373, 142.591, -10_935.0),
        ("Greenwich", 51.477_8, -0.001_5, 45.0),
        ("Mont Blanc", 45.832_6, 6.865_1, 4_808.7),
        ("South Pole", -90.0, 0.0, 2_835.0),
        ("North Pole", 90.0, 0.0, 0.0),
        ("Antimeridian", -33.0, 180.0, 120.0),
    ];
    for (name, lat, lon, h) in landmarks {
        let e = f.to_ecef(planet_point(lat, lon, datum + h));
        let (glat, glon, gh) = geodetic(e);
        assert!((glat - lat).abs() < 1e-9, "{name}: latitude {glat}");
        if lat.abs() < 90.0 {
            let dl = (glon - lon + 540.0).rem_euclid(360.0) - 180.0;
            assert!(dl.abs() < 1e-9, "{name}: longitude {glon}");
        }
        assert!((gh - h).abs() < 1e-5, "{name}: height {gh} for {h}");
    }
    // the equator at longitude 0 at the semi-major axis, the pole at the semi-minor
    let eq = f.to_ecef(planet_point(0.0, 0.0, datum));
    assert!((eq - DVec3::new(6_378_137.0, 0.0, 0.0)).length() < 1e-6);
    let pole = f.to_ecef(planet_point(90.0, 0.0, datum));
    assert!((pole.z - 6_356_752.314_245).abs() < 1e-3, "{pole}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// A ball's image lies in the ball `TileFrame::ball` gives, at any size and place.
    #[test]
    fn balls_map_into_their_bounds(lat in -90.0f64..90.0, lon in -180.0f64..180.0, h in -40_000.0f64..40_000.0, radius in 0.5f64..3.0e6, pts in proptest::collection::vec((-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0), 24)) {
        let datum = 6_371_000.0;
        for frame in [TileFrame::Wgs84 { datum }, TileFrame::Sphere] {
            let c = planet_point(lat, lon, datum + h);
            let (bc, br) = frame.ball(c, radius);
            for &(x, y, z) in &pts {
                let d = DVec3::new(x, y, z);
                let d = if d.length() > 1.0 { d / d.length() } else { d };
                let p = c + d * radius;
                let q = frame.to_ecef(p);
                prop_assert!((q - bc).length() <= br * (1.0 + 1e-12) + 1e-6, "{} > {}", (q - bc).length(), br);
                prop_assert!((q - frame.to_ecef(p) ).length() == 0.0);
                prop_assert!((q - pmc_tiles::frame::to_ecef_axes(p)).length() <= frame.max_displacement());
            }
        }
    }

    /// Normals stay perpendicular to the surface the map carries: the image of any tangent
    /// step is perpendicular to the image of the normal.
    #[test]
    fn normals_follow_the_map(lat in -89.0f64..89.0, lon in -180.0f64..180.0, h in -10_000.0f64..9_000.0, tilt in 0.0f64..1.5, spin in 0.0f64..std::f64::consts::TAU) {
        let datum = 6_371_000.0;
        let f = TileFrame::Wgs84 { datum };
        let p = planet_point(lat, lon, datum + h);
        let up = p.normalize();
        let t0 = up.any_orthonormal_vector();
        let t1 = up.cross(t0);
        let n = (up * tilt.cos() + (t0 * spin.cos() + t1 * spin.sin()) * tilt.sin()).normalize();
        let m = f.normal_to_ecef(p, n);
        prop_assert!((m.length() - 1.0).abs() < 1e-9);
        let a = n.any_orthonormal_vector();
        for t in [a, n.cross(a)] {
            let step = (f.to_ecef(p + t * 0.5) - f.to_ecef(p - t * 0.5)).normalize();
            prop_assert!(step.dot(m).abs() < 1e-6, "tangent . normal = {}", step.dot(m));
        }
    }
}

#[test]
fn morton_codes_round_trip_and_interleave_x_first() {
    assert_eq!(morton3(1, 0, 0), 1);
    assert_eq!(morton3(0, 1, 0), 2);
    assert_eq!(morton3(0, 0, 1), 4);
    assert_eq!(morton3(3, 0, 0), 9);
    for (x, y, z) in [
        (0, 0, 0),
        (5, 9, 3),
        (1 << 20, 77, (1 << 21) - 1),
        (262_143, 262_143, 1),
    ] {
        assert_eq!(demorton3(morton3(x, y, z)), (x, y, z));
    }
    assert_eq!(octree_tiles(3), 73);
}

#[test]
fn the_earth_is_an_octree_of_chunks_from_one_root_per_face() {
    let layout = Layout::new(262_144, 32, 6_354_616.0, 1.0, 1024).unwrap();
    let t = Tiling::new(layout);
    assert_eq!(t.virtual_levels(), 0);
    assert_eq!(t.levels(), 19);
    let root = TileCoord::root(Face::East);
    assert_eq!(t.key(&root).unwrap().level, 18);
    let key = pmc_geometry::ChunkKey {
        face: Face::North,
        level: 3,
        i: 1000,
        j: 2000,
        k: 100,
    };
    let tile = t.tile(&key);
    assert_eq!(tile.level, 15);
    assert_eq!(t.key(&tile), Some(key));
    // past the shell's depth: no tile
    assert!(!t.exists(&TileCoord { z: 128, ..tile }));
    assert!(t.exists(&TileCoord { z: 127, ..tile }));
    assert_eq!(tile.subtree_root().level, 15);
    assert_eq!(TileCoord { level: 17, ..tile }.subtree_root().level, 15);
}

#[test]
fn faces_of_several_top_chunks_get_virtual_levels() {
    // n_c = 12: level 2 has 3 chunks per side, so two virtual levels over them
    let layout = Layout::new(12, 8, 500.0, 2.0, 4).unwrap();
    let t = Tiling::new(layout);
    assert_eq!(layout.max_level(), 2);
    assert_eq!(t.virtual_levels(), 2);
    assert_eq!(t.levels(), 5);
    let root = TileCoord::root(Face::Top);
    assert!(t.exists(&root) && t.key(&root).is_none());
    let l1 = |x, y, z| TileCoord {
        face: Face::Top,
        level: 1,
        x,
        y,
        z,
    };
    assert!(t.exists(&l1(1, 1, 0)) && !t.exists(&l1(1, 1, 1)) && !t.exists(&l1(2, 0, 0)));
    let l2 = TileCoord {
        face: Face::Top,
        level: 2,
        x: 2,
        y: 0,
        z: 0,
    };
    assert_eq!(t.key(&l2).unwrap().level, 2);
    assert!(!t.exists(&TileCoord { x: 3, ..l2 }));
}

fn small_tiles(frame: TileFrame, options: TileOptions) -> TileSet {
    let layout = Layout::new(4, 8, 500.0, 2.0, 4).unwrap();
    let planet = Arc::new(Planet::new(PresetKind::Earthlike, 3, layout));
    let errors = pmc_lod::measure_level_errors(&planet, 256, 0x5eed);
    TileSet::new(planet, errors, frame, options, "pmc test").unwrap()
}

/// The positions of a tile's glTF in ECEF: node translation plus `f32` positions, glTF's Y-up
/// turned back to Z-up.
fn glb_positions(glb: &[u8]) -> (Value, Vec<DVec3>) {
    assert_eq!(&glb[..4], b"glTF");
    let total = u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize;
    assert_eq!(total, glb.len());
    let jlen = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let doc: Value = serde_json::from_slice(&glb[20..20 + jlen]).unwrap();
    let bin = &glb[20 + jlen + 8..];
    let acc = &doc["accessors"][doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        .as_u64()
        .unwrap() as usize];
    let view = &doc["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    let off = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let n = acc["count"].as_u64().unwrap() as usize;
    let t = &doc["nodes"][0]["translation"];
    let tr = DVec3::new(t[0].as_f64().unwrap(), t[1].as_f64().unwrap(), t[2].as_f64().unwrap());
    let pts = (0..n)
        .map(|i| {
            let f = |k: usize| {
                f64::from(f32::from_le_bytes(
                    bin[off + 12 * i + 4 * k..off + 12 * i + 4 * k + 4].try_into().unwrap(),
                ))
            };
            let g = tr + DVec3::new(f(0), f(1), f(2));
            DVec3::new(g.x, -g.z, g.y)
        })
        .collect();
    (doc, pts)
}

/// The triangles of a tile's glTF (its `u32` indices).
fn glb_indices(glb: &[u8]) -> Vec<u32> {
    let jlen = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let doc: Value = serde_json::from_slice(&glb[20..20 + jlen]).unwrap();
    let bin = &glb[20 + jlen + 8..];
    let acc = &doc["accessors"][doc["meshes"][0]["primitives"][0]["indices"].as_u64().unwrap() as usize];
    let view = &doc["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    let off = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    (0..acc["count"].as_u64().unwrap() as usize)
        .map(|i| u32::from_le_bytes(bin[off + 4 * i..off + 4 * i + 4].try_into().unwrap()))
        .collect()
}

/// Each tile's content is a closed, consistently oriented mesh by its own indices (its caps
/// moved out a hair and joined to the surface by flanges), and its caps carry material 255.
#[test]
fn every_tile_content_is_closed() {
    let tiles = small_tiles(TileFrame::Wgs84 { datum: 510.0 }, TileOptions::default());
    let mut capped = 0;
    for b in all_subtrees(&tiles).values() {
        for (t, glb) in &b.contents {
            let idx = glb_indices(glb);
            let mut edges: std::collections::HashMap<(u32, u32), i32> = std::collections::HashMap::new();
            for tri in idx.chunks_exact(3) {
                assert!(
                    tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2],
                    "{t:?}: a collapsed triangle"
                );
                for e in 0..3 {
                    let (a, b) = (tri[e], tri[(e + 1) % 3]);
                    *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
                }
            }
            assert!(
                edges.values().all(|v| *v == 0),
                "{t:?}: an edge not matched by an opposite one"
            );
            let jlen = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
            capped += usize::from(std::str::from_utf8(&glb[20..20 + jlen]).unwrap().contains("_MATERIAL"));
        }
    }
    assert!(capped > 30);
}

/// Every subtree of the tileset, from the faces' roots down.
fn all_subtrees(tiles: &TileSet) -> BTreeMap<TileCoord, pmc_tiles::SubtreeBuild> {
    let mut out = BTreeMap::new();
    let mut todo: Vec<TileCoord> = Face::ALL
        .into_iter()
        .map(TileCoord::root)
        .filter(|t| tiles.available(t))
        .collect();
    while let Some(root) = todo.pop() {
        let b = tiles.build_subtree(root).unwrap();
        todo.extend(b.children.iter().copied());
        out.insert(root, b);
    }
    out
}

#[test]
fn every_tile_lies_in_its_sphere_and_its_ancestors_spheres() {
    for frame in [TileFrame::Sphere, TileFrame::Wgs84 { datum: 510.0 }] {
        let tiles = small_tiles(frame, TileOptions::default());
        let subtrees = all_subtrees(&tiles);
        let mut contents = 0;
        for b in subtrees.values() {
            for (t, glb) in &b.contents {
                contents += 1;
                let (doc, pts) = glb_positions(glb);
                assert_eq!(doc["asset"]["version"], "2.0");
                let mut a = Some(*t);
                while let Some(c) = a {
                    let (centre, r) = tiles.sphere(&c);
                    for p in &pts {
                        assert!(
                            (*p - centre).length() <= r,
                            "{frame:?}: tile {t:?} leaves the sphere of {c:?}"
                        );
                    }
                    a = c.parent();
                }
            }
        }
        assert!(contents > 30, "{contents} tiles with content");
    }
}

/// The tile a subtree file's URL names (`../../../../../KIND/FACE/L/X/Y/Z.EXT`).
fn tile_of(uri: &str) -> (String, TileCoord) {
    let parts: Vec<&str> = uri.trim_start_matches("../../../../../").split('/').collect();
    let n = |i: usize| parts[i].split('.').next().unwrap().parse::<u32>().unwrap();
    let face = Face::ALL.into_iter().find(|f| f.name() == parts[1]).unwrap();
    let t = TileCoord {
        face,
        level: n(2) as u8,
        x: n(3),
        y: n(4),
        z: n(5),
    };
    (parts[0].to_string(), t)
}

/// Every node of a subtree file with the tile its content's URL names (the root's for a node
/// without content, which the checks skip), and whether it stands for a child subtree.
fn walk(node: &Value, root: TileCoord, out: &mut Vec<(TileCoord, Value, bool)>) {
    let (t, is_subtree) = match node["content"]["uri"].as_str().map(tile_of) {
        Some((kind, t)) => (t, kind == "subtrees"),
        None => (root, false),
    };
    out.push((t, node.clone(), is_subtree));
    for c in node["children"].as_array().into_iter().flatten() {
        walk(c, root, out);
    }
}

#[test]
fn subtree_files_hold_their_tiles_spheres_errors_and_contents() {
    let tiles = small_tiles(TileFrame::Sphere, TileOptions::default());
    for (root, b) in all_subtrees(&tiles) {
        let doc: Value = serde_json::from_slice(&b.subtree).unwrap();
        assert_eq!(doc["asset"]["version"], "1.1");
        assert_eq!(doc["root"]["refine"], "REPLACE");
        let mut nodes = Vec::new();
        walk(&doc["root"], root, &mut nodes);
        let (mut contents, mut children) = (Vec::new(), Vec::new());
        for (t, node, is_subtree) in &nodes {
            if node.get("content").is_none() {
                continue;
            }
            let (c, r) = tiles.sphere(t);
            assert_eq!(node["boundingVolume"]["sphere"], json!([c.x, c.y, c.z, r]), "{t:?}");
            assert_eq!(node["geometricError"].as_f64().unwrap(), tiles.geometric_error(t));
            if *is_subtree {
                assert!(tiles.available(t), "{t:?}");
                assert_eq!(t.level, root.level + SUBTREE_LEVELS);
                children.push(*t);
            } else {
                assert!(tiles.available(t), "{t:?}");
                contents.push(*t);
            }
        }
        contents.sort();
        let mut want: Vec<TileCoord> = b.contents.iter().map(|c| c.0).collect();
        want.sort();
        assert_eq!(contents, want, "{root:?}");
        children.sort();
        let mut kids = b.children.clone();
        kids.sort();
        assert_eq!(children, kids);
        assert_eq!(tiles.child_subtrees(root), b.children);
        // every node has a sphere and an error
        assert!(nodes.iter().all(
            |(_, n, _)| n["boundingVolume"]["sphere"].as_array().is_some_and(|a| a.len() == 4)
                && n["geometricError"].is_number()
        ));
    }
}

#[test]
fn tiles_are_the_same_bytes_on_any_thread_count() {
    let tiles = small_tiles(TileFrame::Wgs84 { datum: 510.0 }, TileOptions::default());
    let root = TileCoord::root(Face::South);
    let many = tiles.build_subtree(root).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| tiles.build_subtree(root).unwrap());
    assert_eq!(many.subtree, one.subtree);
    assert_eq!(many.contents, one.contents);
}

#[test]
fn the_tileset_names_the_six_faces_subtree_files() {
    let tiles = small_tiles(TileFrame::Sphere, TileOptions::default());
    let ts = tiles.tileset_json("r2/", json!({"terrain": "earthlike"}));
    assert_eq!(ts["asset"]["version"], "1.1");
    let faces = ts["root"]["children"].as_array().unwrap();
    assert_eq!(faces.len(), 6);
    for (f, face) in faces.iter().zip(Face::ALL) {
        assert_eq!(f["content"]["uri"], format!("r2/subtrees/{}/0/0/0/0.json", face.name()));
        let (c, r) = tiles.sphere(&TileCoord::root(face));
        assert_eq!(f["boundingVolume"]["sphere"], json!([c.x, c.y, c.z, r]));
    }
    assert_eq!(ts["extras"]["pmc"]["terrain"], "earthlike");
    assert_eq!(ts["extras"]["pmc"]["frame"], "sphere");
    assert!(ts["geometricError"].as_f64().unwrap() >= 500.0);
}

fn folder_bytes(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else {
                out.insert(
                    p.strip_prefix(dir).unwrap().to_string_lossy().into_owned(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

fn quiet(_: &BakeStats) {}

#[test]
fn a_bake_resumes_to_the_same_bytes_and_refuses_another_tileset() {
    let tiles = small_tiles(TileFrame::Sphere, TileOptions::default());
    let dir = std::env::temp_dir().join(format!("pmc-tiles-bake-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let stats = bake(&tiles, &dir, json!({"terrain": "earthlike"}), &quiet).unwrap();
    assert!(stats.tiles() > 30 && stats.resumed == 0);
    let whole = folder_bytes(&dir);
    assert!(whole.contains_key("tileset.json") && whole.contains_key("bake.json"));
    assert!(!dir.join(".partial").exists());
    assert_eq!(
        stats.tiles() as usize,
        whole.keys().filter(|k| k.ends_with(".glb")).count()
    );

    // A bake killed half way: a subtree file and some contents gone, the tileset not yet
    // written, a half-written file left in `.partial/`.
    let some = TileCoord::root(Face::West);
    std::fs::remove_file(dir.join(subtree_path(&some))).unwrap();
    let build = tiles.build_subtree(some).unwrap();
    std::fs::remove_file(dir.join(content_path(&build.contents[0].0))).unwrap();
    std::fs::remove_file(dir.join("tileset.json")).unwrap();
    std::fs::create_dir_all(dir.join(".partial")).unwrap();
    std::fs::write(dir.join(".partial/7.tmp"), b"half").unwrap();
    let again = bake(&tiles, &dir, json!({"terrain": "earthlike"}), &quiet).unwrap();
    assert_eq!(again.subtrees, 1);
    assert!(again.resumed > 0);
    assert_eq!(folder_bytes(&dir), whole);

    // Another planet into the same folder: refused, nothing touched.
    let err = bake(&tiles, &dir, json!({"terrain": "moon"}), &quiet).unwrap_err();
    assert!(err.to_string().contains("another tileset"), "{err}");
    assert_eq!(folder_bytes(&dir), whole);
    // A folder with other files: refused.
    let other = dir.with_extension("other");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("notes.txt"), b"mine").unwrap();
    let err = bake(&tiles, &other, json!({}), &quiet).unwrap_err();
    assert!(err.to_string().contains("not empty"), "{err}");
    assert_eq!(std::fs::read(other.join("notes.txt")).unwrap(), b"mine");
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&other).unwrap();
}

#[test]
fn a_region_bake_holds_only_the_tiles_near_the_place_and_the_path_to_them() {
    let region = Region {
        lat: 10.0,
        lon: 20.0,
        radius: 80.0,
    };
    let whole = small_tiles(TileFrame::Sphere, TileOptions::default());
    let tiles = small_tiles(
        TileFrame::Sphere,
        TileOptions {
            region: Some(region),
            min_level: 1,
            ..TileOptions::default()
        },
    );
    let (some, all) = (all_subtrees(&tiles), all_subtrees(&whole));
    let count = |s: &BTreeMap<TileCoord, pmc_tiles::SubtreeBuild>| s.values().map(|b| b.contents.len()).sum::<usize>();
    assert!(
        count(&some) > 0 && count(&some) < count(&all) / 2,
        "{} of {}",
        count(&some),
        count(&all)
    );
    assert!(some.values().flat_map(|b| &b.contents).all(|(t, _)| t.level >= 1));
}

#[test]
fn bad_parameters_are_refused_with_a_reason() {
    let layout = Layout::new(4, 8, 500.0, 2.0, 4).unwrap();
    let planet = Arc::new(Planet::new(PresetKind::Moon, 3, layout));
    let errors = vec![0.0; 3];
    let make = |errors: Vec<f64>, o: TileOptions| TileSet::new(planet.clone(), errors, TileFrame::Sphere, o, "t");
    assert!(matches!(
        make(vec![0.0; 2], TileOptions::default()),
        Err(TilesError::Errors { got: 2, want: 3 })
    ));
    assert!(make(vec![f64::NAN, 0.0, 1.0], TileOptions::default()).is_err());
    let e = make(
        errors.clone(),
        TileOptions {
            max_level: Some(3),
            ..TileOptions::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("--max-level 3"), "{e}");
    for (lat, lon, radius) in [
        (91.0, 0.0, 10.0),
        (0.0, 0.0, -1.0),
        (f64::NAN, 0.0, 5.0),
        (0.0, 0.0, f64::INFINITY),
    ] {
        let o = TileOptions {
            region: Some(Region { lat, lon, radius }),
            ..TileOptions::default()
        };
        assert!(make(errors.clone(), o).is_err(), "{lat} {lon} {radius}");
    }
    let t = make(errors, TileOptions::default()).unwrap();
    assert!(t
        .build_subtree(TileCoord {
            level: 1,
            ..TileCoord::root(Face::Top)
        })
        .is_err());
    let hf = pmc_planet::TerrainSpec::Preset {
        kind: PresetKind::Moon,
        seed: 1,
    };
    if let Ok(p) = Planet::heightfield(&hf) {
        let n = usize::from(p.layout().max_level()) + 1;
        let r = TileSet::new(
            Arc::new(p),
            vec![0.0; n],
            TileFrame::Sphere,
            TileOptions::default(),
            "t",
        );
        assert!(matches!(r, Err(TilesError::Heightfield)));
    }
}

/// Regression (3DTilesRendererJS 0.5 refined past every tile whose error was not below its
/// parent's, and stalled on the empty leaves below): the measured errors of the earth preset are
/// flat over four levels (a running maximum), and the tiles' errors must still fall strictly
/// from each tile to its children, at every level.
#[test]
fn plateau_of_level_errors_gives_strictly_falling_tile_errors() {
    let layout = Layout::new(4, 8, 500.0, 2.0, 4).unwrap();
    let planet = Arc::new(Planet::new(PresetKind::Earthlike, 3, layout));
    let mut errors = pmc_lod::measure_level_errors(&planet, 256, 0x5eed);
    let levels = errors.len();
    assert!(levels >= 3);
    // flat from level 1 up, as the earth preset's are from level 7 to 10
    for e in errors.iter_mut().skip(1) {
        *e = 5.0;
    }
    let tiles = TileSet::new(
        planet,
        errors.clone(),
        TileFrame::Sphere,
        TileOptions::default(),
        "pmc test",
    )
    .unwrap();
    let root = TileCoord::root(Face::Top);
    let mut t = root;
    while t.level + 1 < tiles.available_levels() {
        let child = t.descendant(1, 0, 0, 0);
        let (e, ec) = (tiles.geometric_error(&t), tiles.geometric_error(&child));
        if e > 0.0 {
            assert!(
                ec < e,
                "level {} error {ec} not below level {} error {e}",
                child.level,
                t.level
            );
            // an upper bound of the measured error, by no more than the step per level
            assert!(e <= 5.0 * (1.0 + pmc_tiles::ERROR_STEP).powi(i32::try_from(levels).unwrap()) * 2f64.powi(8));
        }
        t = child;
    }
    assert_eq!(tiles.geometric_error(&t), 0.0, "the finest level is the reference");
    // and in the files: every child below its parent
    fn falls(node: &Value) {
        let e = node["geometricError"].as_f64().unwrap();
        for c in node["children"].as_array().into_iter().flatten() {
            assert!(e == 0.0 || c["geometricError"].as_f64().unwrap() < e, "{c}");
            falls(c);
        }
    }
    for (_, b) in all_subtrees(&tiles) {
        let doc: Value = serde_json::from_slice(&b.subtree).unwrap();
        falls(&doc["root"]);
    }
}

/// Regression (CesiumJS stopped refining 1.5 km over the ground, drawing tiles of level 8: a child
/// subtree listed from the cheap tests alone had an empty root, a leaf without content, and
/// CesiumJS never refines a tile with such a child in view): every subtree file reached from
/// the tileset has a root with content or children, with and without a region.
#[test]
fn no_subtree_file_reached_is_an_empty_leaf() {
    let region = Some(Region {
        lat: 20.0,
        lon: 30.0,
        radius: 150.0,
    });
    // a planet of 16 chunks a side: tile levels 0 to 4, child subtrees at level 3
    let layout = Layout::new(16, 8, 2000.0, 2.0, 4).unwrap();
    let planet = Arc::new(Planet::new(PresetKind::Earthlike, 3, layout));
    let errors = pmc_lod::measure_level_errors(&planet, 64, 0x5eed);
    for options in [
        TileOptions::default(),
        TileOptions {
            region,
            ..TileOptions::default()
        },
    ] {
        let tiles = TileSet::new(planet.clone(), errors.clone(), TileFrame::Sphere, options, "pmc test").unwrap();
        let subtrees = all_subtrees(&tiles);
        assert!(subtrees.keys().any(|t| t.level >= 3), "no child subtree to test");
        for (root, b) in &subtrees {
            let doc: Value = serde_json::from_slice(&b.subtree).unwrap();
            let r = &doc["root"];
            assert!(
                r.get("content").is_some() || r["children"].as_array().is_some_and(|c| !c.is_empty()),
                "{root:?}: an empty leaf"
            );
        }
    }
}
