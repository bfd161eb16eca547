//! The chunk encoding (`docs/specs/chunk-mesh-v1.md`): round trips, the shared test vector of the
//! viewer, and a reader that never panics on arbitrary bytes.

use pmc_formats::chunk_encoding::{decode_chunk, encode_chunk, encoded_len, DecodedChunk, HEADER_LEN};
use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkKey, Face};
use pmc_mesh::ChunkMesh;
use proptest::prelude::*;
use serde_json::{json, Value};
use std::path::PathBuf;

/// Checks that `d` holds `m` exactly (normals to within the snorm rounding).
fn assert_round_trip(m: &ChunkMesh, d: &DecodedChunk) {
    assert_eq!(Some(d.key), m.key);
    assert_eq!(
        d.origin.to_array().map(f64::to_bits),
        m.origin.to_array().map(f64::to_bits)
    );
    assert_eq!(d.positions, m.positions);
    assert_eq!(d.indices, m.indices);
    assert_eq!(d.colors, m.colors);
    assert_eq!(d.heights, m.heights);
    assert_eq!(d.water_depths, m.water_depths);
    assert_eq!(d.materials, m.materials);
    for (a, b) in d.unit_normals().iter().zip(&m.normals) {
        for c in 0..3 {
            assert!((a[c] - b[c]).abs() <= 1.0 / 127.0, "normal {a:?} vs {b:?}");
        }
    }
}

/// The shared test vector: 5 vertices, 2 triangles, every attribute, values exact in f32 (so
/// JSON readers compare them without rounding), a far-away origin and a level-1 key.
fn fixture_mesh() -> ChunkMesh {
    ChunkMesh {
        key: Some(ChunkKey {
            face: Face::East,
            level: 1,
            i: 3,
            j: 5,
            k: 2,
        }),
        origin: DVec3::new(1000.5, -2.25, 6371000.125),
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.5, -0.25, 2.0],
            [-3.75, 4.5, 0.125],
            [10.0, 20.0, -30.5],
            [0.5, -1.25, 12.375],
        ],
        normals: vec![
            [0.0, 1.0, 0.0],
            [0.6, -0.8, 0.0],
            [0.0, 0.0, -1.0],
            [-0.6, 0.0, 0.8],
            [0.48, 0.6, 0.64],
        ],
        indices: vec![0, 1, 2, 2, 3, 4],
        edge_keys: Vec::new(),
        heights: vec![-12.5, 0.0, 3.25, 100.0, 7.75],
        water_depths: vec![12.5, 0.0, 0.0, 0.0, 0.25],
        colors: vec![
            [255, 0, 0, 255],
            [0, 255, 0, 255],
            [0, 0, 255, 255],
            [12, 34, 56, 255],
            [200, 100, 50, 128],
        ],
        materials: vec![0, 1, 2, 5, 255],
        ..ChunkMesh::default()
    }
}

/// What a reader must get out of the test vector, as JSON (the viewer's test reads this file).
fn describe(d: &DecodedChunk, bytes: &[u8]) -> Value {
    let v = d.vertex_count() as u64;
    let n = d.indices.len() as u64;
    let pad = |x: u64| x.div_ceil(4) * 4;
    let mut at = HEADER_LEN as u64;
    let mut offsets = serde_json::Map::new();
    for (name, size) in [
        ("positions", 12 * v),
        ("normals", 3 * v),
        ("colors", 4 * v),
        ("heights", 4 * v),
        ("water_depths", 4 * v),
        ("materials", v),
        ("indices", if d.u32_indices { 4 } else { 2 } * n),
    ] {
        offsets.insert(name.into(), json!(at));
        at += pad(size);
    }
    json!({
        "comment": "Expected decoding of chunk-v1.bin (docs/specs/chunk-mesh-v1.md). Written by crates/pmc-formats/tests/chunk_encoding.rs (PMC_WRITE_FIXTURES=1 rewrites it). Normals are the stored snorm bytes; a reader's floats are max(c / 127, -1).",
        "byte_length": bytes.len(),
        "magic": "PMCM",
        "version": 1,
        "flags": u16::from(d.u32_indices),
        "index_type": if d.u32_indices { "u32" } else { "u16" },
        "face": d.key.face.name(),
        "face_index": d.key.face.index(),
        "level": d.key.level,
        "i": d.key.i,
        "j": d.key.j,
        "k": d.key.k,
        "origin": d.origin.to_array(),
        "vertex_count": v,
        "index_count": n,
        "section_offsets": offsets,
        "positions": d.positions,
        "normals_snorm": d.normals,
        "colors": d.colors,
        "heights": d.heights,
        "water_depths": d.water_depths,
        "materials": d.materials,
        "indices": d.indices,
    })
}

fn fixtures_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../viewer/test/fixtures")
}

#[test]
fn shared_test_vector_matches_the_committed_fixture() {
    let mesh = fixture_mesh();
    let mut bytes = Vec::new();
    encode_chunk(&mesh, &mut bytes).unwrap();
    assert_eq!(bytes.len() as u64, encoded_len(5, 6, false));
    assert_eq!(bytes.len(), 212);
    let decoded = decode_chunk(&bytes).unwrap();
    assert_round_trip(&mesh, &decoded);
    let expected = describe(&decoded, &bytes);
    let dir = fixtures_dir();
    let (bin, json_path) = (dir.join("chunk-v1.bin"), dir.join("chunk-v1.json"));
    if std::env::var("PMC_WRITE_FIXTURES").as_deref() == Ok("1") {
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(&bin, &bytes).unwrap();
        let mut text = serde_json::to_string_pretty(&expected).unwrap();
        text.push('\n');
        std::fs::write(&json_path, text).unwrap();
        return;
    }
    let committed = std::fs::read(&bin).unwrap_or_else(|e| {
        panic!(
            "cannot read {}: {e}; run with PMC_WRITE_FIXTURES=1 to write it",
            bin.display()
        )
    });
    assert!(
        committed == bytes,
        "{} differs from the encoder's output",
        bin.display()
    );
    let text = std::fs::read_to_string(&json_path).unwrap();
    let committed_json: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(committed_json, expected, "{} is out of date", json_path.display());
    // And the committed bytes decode to the committed description.
    assert_eq!(describe(&decode_chunk(&committed).unwrap(), &committed), committed_json);
}

#[test]
fn test_vector_bytes_follow_the_spec_by_hand() {
    let mut b = Vec::new();
    encode_chunk(&fixture_mesh(), &mut b).unwrap();
    assert_eq!(&b[0..4], b"PMCM");
    assert_eq!(&b[4..8], &[1, 0, 0, 0]);
    assert_eq!(&b[8..12], &[4, 1, 0, 0]); // east, level 1, reserved
    assert_eq!(&b[12..24], &[3, 0, 0, 0, 5, 0, 0, 0, 2, 0, 0, 0]);
    assert_eq!(f64::from_le_bytes(b[24..32].try_into().unwrap()), 1000.5);
    assert_eq!(f64::from_le_bytes(b[40..48].try_into().unwrap()), 6371000.125);
    assert_eq!(&b[48..56], &[5, 0, 0, 0, 6, 0, 0, 0]);
    assert_eq!(f32::from_le_bytes(b[56 + 12..56 + 16].try_into().unwrap()), 1.5);
    // Normals at 116: (0, 127, 0), (76, -102, 0), ..., then one zero pad byte.
    assert_eq!(&b[116..122], &[0, 127, 0, 76, (-102i8) as u8, 0]);
    assert_eq!(b[131], 0);
    assert_eq!(&b[132..136], &[255, 0, 0, 255]);
    assert_eq!(f32::from_le_bytes(b[152..156].try_into().unwrap()), -12.5);
    assert_eq!(f32::from_le_bytes(b[172..176].try_into().unwrap()), 12.5);
    assert_eq!(&b[192..200], &[0, 1, 2, 5, 255, 0, 0, 0]);
    assert_eq!(&b[200..212], &[0, 0, 1, 0, 2, 0, 2, 0, 3, 0, 4, 0]);
}

#[test]
fn meshes_without_attributes_get_the_defaults() {
    let mut m = fixture_mesh();
    m.heights.clear();
    m.water_depths.clear();
    m.colors.clear();
    m.materials.clear();
    let mut b = Vec::new();
    encode_chunk(&m, &mut b).unwrap();
    let d = decode_chunk(&b).unwrap();
    assert_eq!(d.colors, vec![[255; 4]; 5]);
    assert_eq!(d.heights, vec![0.0; 5]);
    assert_eq!(d.water_depths, vec![0.0; 5]);
    assert_eq!(d.materials, vec![255; 5]);
    assert_eq!(d.positions, m.positions);
}

#[test]
fn u32_indices_round_trip() {
    let n = 70_000usize;
    let mut m = fixture_mesh();
    m.positions = (0..n).map(|i| [i as f32, -(i as f32), 0.5]).collect();
    m.normals = vec![[0.0, 0.0, 1.0]; n];
    m.heights = vec![1.0; n];
    m.water_depths = vec![0.0; n];
    m.colors = vec![[1, 2, 3, 4]; n];
    m.materials = vec![3; n];
    m.indices = vec![0, 65535, 65536, 69_999, 1, 2];
    let mut b = Vec::new();
    encode_chunk(&m, &mut b).unwrap();
    assert_eq!(b[6], 1, "flag bit 0: u32 indices");
    let d = decode_chunk(&b).unwrap();
    assert!(d.u32_indices);
    assert_round_trip(&m, &d);
}

fn arb_mesh() -> impl Strategy<Value = ChunkMesh> {
    (1usize..40, any::<bool>(), 0usize..6, any::<u8>(), any::<[u32; 3]>()).prop_flat_map(
        |(v, attributes, face, level, [i, j, k])| {
            let f = -1.0e6f32..1.0e6f32;
            (
                prop::collection::vec([f.clone(), f.clone(), f], v),
                prop::collection::vec([-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0], v),
                prop::collection::vec(0..v as u32, 0..20).prop_map(|mut x| {
                    x.truncate(x.len() / 3 * 3);
                    x
                }),
                prop::collection::vec((any::<[u8; 4]>(), -1e4f32..1e4, 0f32..1e3, any::<u8>()), v),
                [-1e7f64..1e7, -1e7f64..1e7, -1e7f64..1e7],
            )
                .prop_map(move |(positions, normals, indices, attrs, origin)| {
                    let normals = normals
                        .into_iter()
                        .map(|n| {
                            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                            if l < 1e-3 {
                                [0.0, 1.0, 0.0]
                            } else {
                                n.map(|c| c / l)
                            }
                        })
                        .collect();
                    let mut m = ChunkMesh {
                        key: Some(ChunkKey {
                            face: Face::ALL[face],
                            level,
                            i,
                            j,
                            k,
                        }),
                        origin: DVec3::from_array(origin),
                        positions,
                        normals,
                        indices,
                        ..Default::default()
                    };
                    if attributes {
                        for (c, h, w, mat) in attrs {
                            m.colors.push(c);
                            m.heights.push(h);
                            m.water_depths.push(w);
                            m.materials.push(mat);
                        }
                    }
                    m
                })
        },
    )
}

/// An encoded mesh to mutate.
fn arb_encoded() -> impl Strategy<Value = Vec<u8>> {
    arb_mesh().prop_map(|m| {
        let mut b = Vec::new();
        encode_chunk(&m, &mut b).unwrap();
        b
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn decode_inverts_encode(m in arb_mesh()) {
        let mut b = Vec::new();
        encode_chunk(&m, &mut b).unwrap();
        prop_assert_eq!(b.len() as u64, encoded_len(if m.indices.is_empty() { 0 } else { m.positions.len() as u64 }, m.indices.len() as u64, !m.indices.is_empty() && m.positions_low.len() == m.positions.len()));
        prop_assert_eq!(b.len() % 4, 0);
        let d = decode_chunk(&b).unwrap();
        if m.indices.is_empty() {
            prop_assert_eq!(d.vertex_count(), 0);
            prop_assert_eq!(b.len(), HEADER_LEN);
        } else if m.colors.is_empty() {
            prop_assert_eq!(&d.positions, &m.positions);
            prop_assert!(d.materials.iter().all(|&x| x == 255));
        } else {
            assert_round_trip(&m, &d);
        }
        // Encoding what was decoded gives the same bytes.
        let mut again = Vec::new();
        encode_chunk(&d.to_chunk_mesh(), &mut again).unwrap();
        prop_assert_eq!(again, b);
    }

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        let _ = decode_chunk(&bytes);
        // With a valid magic and version, the checks past them run too.
        let mut b = bytes.clone();
        if b.len() >= 8 {
            b[..4].copy_from_slice(b"PMCM");
            b[4..8].copy_from_slice(&[1, 0, 0, 0]);
        }
        let _ = decode_chunk(&b);
    }

    #[test]
    fn truncated_chunks_are_refused(b in arb_encoded(), cut in 1usize..64) {
        let len = b.len().saturating_sub(cut);
        prop_assert!(decode_chunk(&b[..len]).is_err());
    }

    #[test]
    fn mutated_chunks_never_panic(b in arb_encoded(), edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6)) {
        let mut b = b;
        for (at, val) in edits {
            let i = at.index(b.len());
            b[i] = val;
        }
        if let Ok(d) = decode_chunk(&b) {
            prop_assert!(d.indices.iter().all(|&x| (x as usize) < d.vertex_count()));
            prop_assert_eq!(d.indices.len() % 3, 0);
        }
    }

    #[test]
    fn huge_counts_in_a_short_buffer_are_refused_without_allocating(v in any::<u32>(), i in any::<u32>()) {
        let mut b = Vec::new();
        encode_chunk(&fixture_mesh(), &mut b).unwrap();
        b[48..52].copy_from_slice(&v.to_le_bytes());
        b[52..56].copy_from_slice(&(i / 3 * 3).to_le_bytes());
        let r = decode_chunk(&b);
        if !(v == 5 && i / 3 * 3 == 6) {
            prop_assert!(r.is_err());
        }
    }
}

/// The inputs `cargo fuzz` found (`fuzz/regressions/chunk_decode/`), replayed: each is refused or
/// decodes into a consistent chunk. `nan-origin`: a header whose origin's y is NaN decoded into
/// a chunk no vertex of which could be placed (the viewer's decoder refused it); now refused.
#[test]
fn fuzz_findings_are_refused_or_consistent() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/regressions/chunk_decode");
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let bytes = std::fs::read(&path).unwrap();
        match pmc_formats::chunk_encoding::decode_chunk(&bytes) {
            Ok(c) => {
                let v = c.positions.len();
                assert!(c.origin.is_finite(), "{}", path.display());
                assert!(c.indices.iter().all(|&i| (i as usize) < v), "{}", path.display());
            }
            Err(e) => assert!(!e.to_string().is_empty()),
        }
        seen += 1;
    }
    assert!(seen >= 1, "no inputs under {}", dir.display());
    let nan = std::fs::read(dir.join("nan-origin")).unwrap();
    let e = pmc_formats::chunk_encoding::decode_chunk(&nan).unwrap_err();
    assert!(
        e.to_string().contains("origin") && e.to_string().contains("not finite"),
        "{e}"
    );
}
