//! GLB layout version 1: container, JSON, accessors, node transforms, sea.

use crate::common;

use common::{meta, split_box, FAR, OFFSETS};
use gltf_json::mesh::Semantic;
use gltf_json::validation::{Checked::Valid, Validate};
use gltf_json::Root;
use pmc_formats::write_glb;
use pmc_geometry::glam::DVec3;
use pmc_mesh::ChunkMesh;
use serde_json::Value;

/// A parsed GLB: the raw JSON, the typed root, and the BIN chunk.
struct Glb {
    json: Value,
    root: Root,
    bin: Vec<u8>,
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

/// Checks the container byte by byte and parses it.
fn parse(bytes: &[u8]) -> Glb {
    assert_eq!(&bytes[0..4], b"glTF", "magic");
    assert_eq!(u32_at(bytes, 4), 2, "version");
    assert_eq!(u32_at(bytes, 8) as usize, bytes.len(), "header length");
    assert_eq!(bytes.len() % 4, 0);
    let json_len = u32_at(bytes, 12) as usize;
    assert_eq!(u32_at(bytes, 16), 0x4E4F_534A, "JSON chunk type");
    assert_eq!(json_len % 4, 0, "JSON chunk padded to 4 bytes");
    let json_bytes = &bytes[20..20 + json_len];
    let trimmed = json_bytes.iter().rposition(|&b| b != b' ').unwrap() + 1;
    assert!(json_len - trimmed < 4, "JSON padding is at most 3 spaces");
    let json: Value = serde_json::from_slice(json_bytes).expect("JSON chunk parses");
    let root: Root = serde_json::from_slice(json_bytes).expect("JSON chunk parses as gltf_json::Root");
    let mut errors = Vec::new();
    root.validate(&root, gltf_json::Path::new, &mut |path, err| {
        errors.push(format!("{}: {err:?}", path()))
    });
    assert!(errors.is_empty(), "gltf-json validation: {errors:?}");
    let at = 20 + json_len;
    let bin = if at == bytes.len() {
        Vec::new()
    } else {
        assert_eq!(at % 4, 0, "BIN chunk aligned");
        let bin_len = u32_at(bytes, at) as usize;
        assert_eq!(u32_at(bytes, at + 4), 0x004E_4942, "BIN chunk type");
        assert_eq!(bin_len % 4, 0, "BIN chunk padded to 4 bytes");
        assert_eq!(at + 8 + bin_len, bytes.len(), "BIN chunk ends the file");
        let declared = root.buffers[0].byte_length.0 as usize;
        assert!(
            declared <= bin_len && bin_len - declared < 4,
            "buffer byteLength {declared} vs chunk {bin_len}"
        );
        bytes[at + 8..].to_vec()
    };
    Glb { json, root, bin }
}

impl Glb {
    fn node(&self, name: &str) -> usize {
        self.root
            .nodes
            .iter()
            .position(|n| n.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("node {name}"))
    }

    /// The bytes of accessor `a`, with its count, after checking alignment.
    fn accessor_bytes(&self, a: usize, elem: usize) -> (&[u8], usize) {
        let acc = &self.root.accessors[a];
        let view = &self.root.buffer_views[acc.buffer_view.unwrap().value()];
        let off = view.byte_offset.map_or(0, |o| o.0 as usize) + acc.byte_offset.map_or(0, |o| o.0 as usize);
        assert_eq!(off % 4, 0, "accessor {a} offset {off} not 4-aligned");
        let count = acc.count.0 as usize;
        assert!(count * elem <= view.byte_length.0 as usize);
        (&self.bin[off..off + count * elem], count)
    }

    fn f32s(&self, a: usize) -> Vec<f32> {
        let (b, _) = self.accessor_bytes(a, 4);
        b.chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    fn vec3s(&self, a: usize) -> Vec<[f32; 3]> {
        let (b, n) = self.accessor_bytes(a, 12);
        let f: Vec<f32> = b
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(f.len(), 3 * n);
        f.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
    }

    fn u32s(&self, a: usize) -> Vec<u32> {
        let (b, _) = self.accessor_bytes(a, 4);
        b.chunks_exact(4)
            .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    fn translation(&self, node: usize) -> DVec3 {
        let t = &self.json["nodes"][node]["translation"];
        DVec3::new(t[0].as_f64().unwrap(), t[1].as_f64().unwrap(), t[2].as_f64().unwrap())
    }

    fn primitive(&self, node: usize) -> &gltf_json::mesh::Primitive {
        let mesh = self.root.nodes[node].mesh.expect("node has a mesh").value();
        assert_eq!(self.root.meshes[mesh].primitives.len(), 1);
        &self.root.meshes[mesh].primitives[0]
    }
}

fn glb(meshes: &[ChunkMesh], sea: Option<f64>) -> Glb {
    let mut bytes = Vec::new();
    write_glb(meshes, &meta(sea), &mut bytes).unwrap();
    parse(&bytes)
}

fn attr(p: &gltf_json::mesh::Primitive, s: Semantic) -> Option<usize> {
    p.attributes.get(&Valid(s)).map(|i| i.value())
}

#[test]
fn chunks_round_trip_exactly() {
    let meshes = split_box(2, 10.0, FAR, OFFSETS, true);
    let g = glb(&meshes, None);
    let planet = g.node("planet");
    assert_eq!(g.root.scenes.len(), 1);
    assert_eq!(g.root.scene.unwrap().value(), 0);
    assert_eq!(
        g.root.scenes[0].nodes.iter().map(|n| n.value()).collect::<Vec<_>>(),
        vec![planet]
    );
    let children: Vec<usize> = g.root.nodes[planet]
        .children
        .as_ref()
        .unwrap()
        .iter()
        .map(|c| c.value())
        .collect();
    assert_eq!(children.len(), 3);
    for (i, m) in meshes.iter().enumerate() {
        // Node names as glb-v1.md fixes them: `face/L<level>/<i>_<j>_<k>`.
        let name = m.key.map_or(format!("chunk-{i}"), |k| {
            format!("{}/L{}/{}_{}_{}", k.face, k.level, k.i, k.j, k.k)
        });
        let n = g.node(&name);
        assert_eq!(children[i], n, "chunk nodes are the planet's children in input order");
        // f64 origin survives bit for bit in the JSON.
        assert_eq!(g.translation(n), m.origin, "{name}");
        let p = g.primitive(n);
        let pos = attr(p, Semantic::Positions).unwrap();
        let acc = &g.root.accessors[pos];
        assert_eq!(acc.count.0 as usize, m.positions.len());
        assert_eq!(g.vec3s(pos), m.positions);
        let lo: Vec<f64> = (0..3)
            .map(|k| m.positions.iter().map(|v| v[k]).fold(f32::INFINITY, f32::min) as f64)
            .collect();
        let hi: Vec<f64> = (0..3)
            .map(|k| m.positions.iter().map(|v| v[k]).fold(f32::NEG_INFINITY, f32::max) as f64)
            .collect();
        assert_eq!(acc.min.as_ref().unwrap(), &serde_json::json!(lo), "{name} min");
        assert_eq!(acc.max.as_ref().unwrap(), &serde_json::json!(hi), "{name} max");
        assert_eq!(g.vec3s(attr(p, Semantic::Normals).unwrap()), m.normals);
        let idx = p.indices.unwrap().value();
        assert_eq!(g.json["accessors"][idx]["componentType"], 5125, "UNSIGNED_INT indices");
        assert_eq!(g.u32s(idx), m.indices);
        let col = attr(p, Semantic::Colors(0)).unwrap();
        assert!(g.root.accessors[col].normalized);
        let (bytes, count) = g.accessor_bytes(col, 4);
        assert_eq!(count, m.colors.len());
        assert_eq!(bytes, m.colors.concat());
        assert_eq!(g.f32s(attr(p, Semantic::Extras("HEIGHT".into())).unwrap()), m.heights);
        assert_eq!(
            g.f32s(attr(p, Semantic::Extras("WATER_DEPTH".into())).unwrap()),
            m.water_depths
        );
        let mats: Vec<f32> = m.materials.iter().map(|&x| x as f32).collect();
        assert_eq!(g.f32s(attr(p, Semantic::Extras("MATERIAL".into())).unwrap()), mats);
    }
    // Attribute views are ARRAY_BUFFER, index views ELEMENT_ARRAY_BUFFER, all 4-aligned.
    for v in &g.json["bufferViews"].as_array().unwrap().clone() {
        assert_eq!(v["byteOffset"].as_u64().unwrap() % 4, 0);
        let t = v["target"].as_u64().unwrap();
        assert!(t == 34962 || t == 34963);
    }
    let p = g.primitive(children[0]);
    let idx_view = g.root.accessors[p.indices.unwrap().value()]
        .buffer_view
        .unwrap()
        .value();
    assert_eq!(g.json["bufferViews"][idx_view]["target"], 34963);
    let pos_view = g.root.accessors[attr(p, Semantic::Positions).unwrap()]
        .buffer_view
        .unwrap()
        .value();
    assert_eq!(g.json["bufferViews"][pos_view]["target"], 34962);
}

#[test]
fn asset_carries_generator_and_meta() {
    let g = glb(&split_box(1, 1.0, DVec3::ZERO, OFFSETS, true), Some(1000.0));
    let asset = &g.json["asset"];
    assert_eq!(asset["version"], "2.0");
    assert_eq!(asset["generator"], "pmc-formats tests");
    let x = &asset["extras"];
    assert_eq!(x["pmc_format"], "pmc-glb");
    assert_eq!(x["pmc_format_version"], 1);
    assert_eq!(x["preset"], "test \"box\"\nZürich");
    assert_eq!(x["seed"], (u64::MAX - 1).to_string());
    assert_eq!(
        (x["n_c"].clone(), x["n_t"].clone(), x["d_c"].clone()),
        (4.into(), 16.into(), 2.into())
    );
    assert_eq!((x["d_b"].as_f64(), x["l_d"].as_f64()), (Some(1744.0), Some(4.0)));
    assert_eq!(
        (x["radius"].as_f64(), x["sea_radius"].as_f64()),
        (Some(2000.0), Some(1000.0))
    );
    assert_eq!(x["materials"], serde_json::json!(["rock", "sand", "snow"]));
    let mat = &g.json["materials"][0];
    assert_eq!(mat["name"], "terrain");
    assert_eq!(mat["pbrMetallicRoughness"]["metallicFactor"], 0.0);
    assert_eq!(
        mat["pbrMetallicRoughness"]["baseColorFactor"],
        serde_json::json!([1.0, 1.0, 1.0, 1.0])
    );
    assert!(mat["pbrMetallicRoughness"]["roughnessFactor"].as_f64().unwrap() > 0.8);
}

#[test]
fn sea_is_a_translucent_cube_sphere_at_sea_radius() {
    let r = 6_371_000.5;
    let g = glb(&split_box(1, 1.0, DVec3::ZERO, OFFSETS, true), Some(r));
    let planet = g.node("planet");
    let sea = g.node("sea");
    assert!(g.root.nodes[planet]
        .children
        .as_ref()
        .unwrap()
        .iter()
        .any(|c| c.value() == sea));
    let faces: Vec<usize> = g.root.nodes[sea]
        .children
        .as_ref()
        .unwrap()
        .iter()
        .map(|c| c.value())
        .collect();
    assert_eq!(faces.len(), 6);
    let mut total_tris = 0;
    for f in faces {
        let name = g.root.nodes[f].name.clone().unwrap();
        assert!(name.starts_with("sea/"), "{name}");
        let centre = g.translation(f);
        assert!((centre.length() - r).abs() < 1e-6, "{name} centre {centre}");
        let p = g.primitive(f);
        let mat = &g.root.materials[p.material.unwrap().value()];
        assert!(matches!(mat.alpha_mode, Valid(gltf_json::material::AlphaMode::Blend)));
        assert!(!mat.double_sided);
        let pos = g.vec3s(attr(p, Semantic::Positions).unwrap());
        let nor = g.vec3s(attr(p, Semantic::Normals).unwrap());
        assert!(attr(p, Semantic::Colors(0)).is_none());
        for (v, n) in pos.iter().zip(&nor) {
            let w = centre + DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
            assert!((w.length() - r).abs() < 1.0, "{name}: {w} off the sphere");
            let radial = w.normalize();
            let n = DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64);
            assert!((n - radial).length() < 1e-5, "{name}: normal {n} not radial");
        }
        let idx = g.u32s(p.indices.unwrap().value());
        total_tris += idx.len() / 3;
        for t in idx.chunks_exact(3) {
            let w = |i: u32| {
                let v = pos[i as usize];
                DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
            };
            let (a, b, c) = (w(t[0]), w(t[1]), w(t[2]));
            assert!(
                (b - a).cross(c - a).dot(centre + a) > 0.0,
                "{name}: triangle faces inward"
            );
        }
    }
    assert_eq!(total_tris, 6 * 48 * 48 * 2);
}

#[test]
fn meshes_without_attributes_and_empty_meshes() {
    let mut meshes = split_box(1, 1.0, DVec3::ZERO, OFFSETS, false);
    meshes.insert(1, ChunkMesh::default());
    let g = glb(&meshes, None);
    assert_eq!(g.root.nodes.len(), 4, "planet + 3 chunks, the empty mesh skipped");
    assert!(g.root.nodes.iter().all(|n| n.name.as_deref() != Some("chunk-1")));
    // The chunk without key is named by its position in the input.
    let n = g.node("chunk-2");
    let p = g.primitive(n);
    assert_eq!(p.attributes.len(), 2, "POSITION and NORMAL only");
    assert!(g.root.materials.iter().all(|m| m.name.as_deref() != Some("sea")));
}

#[test]
fn nothing_to_write_still_gives_a_valid_file() {
    let g = glb(&[ChunkMesh::default()], None);
    assert!(g.bin.is_empty());
    assert!(g.root.buffers.is_empty());
    assert_eq!(g.root.nodes.len(), 1);
    assert!(g.root.nodes[0].children.is_none());
}

/// Writes sample GLBs and checks them with the Khronos validator (`tools/gltf-validate`, which
/// `scripts/test.sh` installs with `npm ci` before running the tests).
#[test]
fn khronos_validator_accepts_our_files() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    assert!(
        root.join("tools/gltf-validate/node_modules/gltf-validator").is_dir(),
        "the Khronos glTF validator is not installed: run `npm ci` in tools/gltf-validate (scripts/test.sh does)"
    );
    let dir = common::temp_dir("khronos");
    let good = dir.join("box.glb");
    let far = dir.join("far.glb");
    let plain = dir.join("plain.glb");
    let mut metas = meta(Some(2000.0));
    pmc_formats::export(&good, &split_box(2, 10.0, DVec3::ZERO, OFFSETS, true), &metas).unwrap();
    metas.sea_radius = Some(6_371_000.0);
    pmc_formats::export(&far, &split_box(2, 10.0, FAR, OFFSETS, true), &metas).unwrap();
    metas.sea_radius = None;
    pmc_formats::export(&plain, &split_box(1, 1.0, DVec3::ZERO, OFFSETS, false), &metas).unwrap();
    let run = |files: &[&std::path::Path]| {
        std::process::Command::new("node")
            .arg(root.join("tools/gltf-validate/validate.mjs"))
            .args(files)
            .output()
            .expect("node runs")
    };
    let out = run(&[&good, &far, &plain]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(text.matches(": ok 0 errors").count(), 3, "{text}");
    // A truncated file must fail.
    let bytes = std::fs::read(&good).unwrap();
    let bad = dir.join("truncated.glb");
    std::fs::write(&bad, &bytes[..bytes.len() / 2]).unwrap();
    let out = run(&[&good, &bad]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stdout));
    let _ = std::fs::remove_dir_all(&dir);
}
