//! OBJ and PLY layout version 1: one welded, world-space, closed mesh.

use crate::common::{box_triangles, box_vertices, check_closed, meta, split_box, FAR, OFFSETS};
use pmc_formats::{write_obj, write_ply, PLY_FACE_BYTES, PLY_VERTEX_BYTES};
use pmc_geometry::glam::DVec3;
use pmc_mesh::ChunkMesh;
use std::collections::HashMap;

/// A parsed OBJ: positions, normals, faces (0-based), comment lines.
struct Obj {
    v: Vec<DVec3>,
    vn: Vec<[f32; 3]>,
    f: Vec<[u32; 3]>,
    comments: Vec<String>,
}

fn parse_obj(bytes: &[u8]) -> Obj {
    let text = std::str::from_utf8(bytes).expect("OBJ is UTF-8");
    assert!(text.is_ascii(), "OBJ is ASCII");
    let mut o = Obj {
        v: vec![],
        vn: vec![],
        f: vec![],
        comments: vec![],
    };
    let mut objects = 0;
    for line in text.lines() {
        let mut w = line.split(' ');
        match w.next().unwrap() {
            "#" => o.comments.push(line[2..].to_string()),
            "o" => {
                assert_eq!(line, "o planet");
                objects += 1;
            }
            "v" => {
                let c: Vec<f64> = w.map(|x| x.parse().unwrap()).collect();
                assert_eq!(c.len(), 3, "{line}");
                o.v.push(DVec3::new(c[0], c[1], c[2]));
            }
            "vn" => {
                let c: Vec<f32> = w.map(|x| x.parse().unwrap()).collect();
                o.vn.push([c[0], c[1], c[2]]);
            }
            "f" => {
                let c: Vec<u32> = w
                    .map(|x| {
                        let (a, b) = x.split_once("//").unwrap();
                        assert_eq!(a, b, "vertex and normal index agree");
                        a.parse::<u32>().unwrap() - 1
                    })
                    .collect();
                o.f.push([c[0], c[1], c[2]]);
            }
            other => panic!("unexpected OBJ line kind {other:?}: {line}"),
        }
    }
    assert_eq!(objects, 1);
    assert_eq!(o.v.len(), o.vn.len());
    o
}

/// A parsed PLY vertex.
#[derive(Clone, Copy, Debug)]
struct PlyVertex {
    p: DVec3,
    n: [f32; 3],
    rgba: [u8; 4],
    height: f32,
    water: f32,
    material: u8,
}

struct Ply {
    comments: Vec<String>,
    v: Vec<PlyVertex>,
    f: Vec<[u32; 3]>,
}

const PLY_PROPERTIES: &str = "property double x
property double y
property double z
property float nx
property float ny
property float nz
property uchar red
property uchar green
property uchar blue
property uchar alpha
property float height
property float water_depth
property uchar material
";

/// Checks the header line by line and that the body is exactly as long as the header says.
fn parse_ply(bytes: &[u8]) -> Ply {
    let end = b"end_header\n";
    let at = bytes.windows(end.len()).position(|w| w == end).expect("end_header") + end.len();
    let header = std::str::from_utf8(&bytes[..at]).unwrap();
    assert!(header.is_ascii());
    let mut lines = header.lines();
    assert_eq!(lines.next(), Some("ply"));
    assert_eq!(lines.next(), Some("format binary_little_endian 1.0"));
    let mut comments = Vec::new();
    let mut rest = Vec::new();
    for l in lines {
        match l.strip_prefix("comment ") {
            Some(c) if rest.is_empty() => comments.push(c.to_string()),
            _ => rest.push(l),
        }
    }
    let nv: usize = rest[0].strip_prefix("element vertex ").unwrap().parse().unwrap();
    let props = rest[1..14].join("\n") + "\n";
    assert_eq!(props, PLY_PROPERTIES);
    let nf: usize = rest[14].strip_prefix("element face ").unwrap().parse().unwrap();
    assert_eq!(rest[15], "property list uchar uint vertex_indices");
    assert_eq!(rest[16], "end_header");
    assert_eq!(rest.len(), 17);
    let body = &bytes[at..];
    assert_eq!(
        body.len() as u64,
        nv as u64 * PLY_VERTEX_BYTES + nf as u64 * PLY_FACE_BYTES,
        "body length"
    );
    let f64_at = |b: &[u8], i: usize| f64::from_le_bytes(b[i..i + 8].try_into().unwrap());
    let f32_at = |b: &[u8], i: usize| f32::from_le_bytes(b[i..i + 4].try_into().unwrap());
    let v = body[..nv * PLY_VERTEX_BYTES as usize]
        .chunks_exact(PLY_VERTEX_BYTES as usize)
        .map(|r| PlyVertex {
            p: DVec3::new(f64_at(r, 0), f64_at(r, 8), f64_at(r, 16)),
            n: [f32_at(r, 24), f32_at(r, 28), f32_at(r, 32)],
            rgba: [r[36], r[37], r[38], r[39]],
            height: f32_at(r, 40),
            water: f32_at(r, 44),
            material: r[48],
        })
        .collect();
    let f = body[nv * PLY_VERTEX_BYTES as usize..]
        .chunks_exact(PLY_FACE_BYTES as usize)
        .map(|r| {
            assert_eq!(r[0], 3);
            let u = |i: usize| u32::from_le_bytes(r[i..i + 4].try_into().unwrap());
            [u(1), u(5), u(9)]
        })
        .collect();
    Ply { comments, v, f }
}

fn obj(meshes: &[ChunkMesh]) -> Obj {
    let mut b = Vec::new();
    write_obj(meshes, &meta(Some(2000.0)), &mut b).unwrap();
    parse_obj(&b)
}

fn ply(meshes: &[ChunkMesh]) -> Ply {
    let mut b = Vec::new();
    write_ply(meshes, &meta(None), &mut b).unwrap();
    parse_ply(&b)
}

/// World positions of all vertices by edge key (the first chunk's copy).
fn expected_by_key(meshes: &[ChunkMesh]) -> HashMap<pmc_geometry::EdgeKey, (DVec3, usize, usize)> {
    let mut m = HashMap::new();
    for (ci, c) in meshes.iter().enumerate() {
        for (vi, k) in c.edge_keys.iter().enumerate() {
            m.entry(*k).or_insert((c.world_position(vi), ci, vi));
        }
    }
    m
}

#[test]
fn obj_is_welded_closed_and_exact() {
    for (h, centre) in [(1, DVec3::ZERO), (2, DVec3::ZERO), (3, FAR)] {
        let meshes = split_box(h, 10.0, centre, OFFSETS, true);
        let unwelded: usize = meshes.iter().map(|m| m.positions.len()).sum();
        assert!(unwelded > box_vertices(h), "the test must actually need welding");
        let o = obj(&meshes);
        assert_eq!(o.v.len(), box_vertices(h), "h={h}");
        assert_eq!(o.f.len(), box_triangles(h));
        let side = 20.0 * h as f64;
        let vol = check_closed(&o.v, &o.f);
        assert!(
            (vol - side * side * side).abs() < 1e-6 * side * side * side,
            "h={h}: volume {vol}"
        );
        // Every written position is exactly origin + position of the first chunk holding it.
        let expected = expected_by_key(&meshes);
        let by_pos: HashMap<[u64; 3], [f32; 3]> = expected
            .values()
            .map(|(p, ci, vi)| ([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()], meshes[*ci].normals[*vi]))
            .collect();
        for (v, n) in o.v.iter().zip(&o.vn) {
            let normal = by_pos.get(&[v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]);
            assert_eq!(
                normal,
                Some(n),
                "h={h}: {v} is not a chunk vertex, or its normal differs"
            );
        }
    }
}

#[test]
fn obj_header_carries_meta() {
    let o = obj(&split_box(1, 1.0, DVec3::ZERO, OFFSETS, true));
    assert_eq!(o.comments[0], "pmc-obj version 1");
    for want in [
        "generator \"pmc-formats tests\"",
        "preset \"test \\\"box\\\"\\nZ\\u00fcrich\"",
        "seed 18446744073709551614",
        "n_c 4",
        "n_t 16",
        "d_b 1744",
        "l_d 4",
        "d_c 2",
        "radius 2000",
        "sea_radius 2000",
        "materials [\"rock\",\"sand\",\"snow\"]",
        "vertices 26",
        "faces 48",
    ] {
        assert!(
            o.comments.iter().any(|c| c == want),
            "missing comment {want:?} in {:?}",
            o.comments
        );
    }
}

#[test]
fn ply_is_welded_closed_and_carries_attributes() {
    for (h, centre) in [(1, DVec3::ZERO), (2, FAR)] {
        let meshes = split_box(h, 10.0, centre, OFFSETS, true);
        let p = ply(&meshes);
        assert_eq!(p.v.len(), box_vertices(h));
        assert_eq!(p.f.len(), box_triangles(h));
        let pos: Vec<DVec3> = p.v.iter().map(|v| v.p).collect();
        let side = 20.0 * h as f64;
        let vol = check_closed(&pos, &p.f);
        assert!(
            (vol - side * side * side).abs() < 1e-6 * side * side * side,
            "volume {vol}"
        );
        let expected = expected_by_key(&meshes);
        let by_pos: HashMap<[u64; 3], (usize, usize)> = expected
            .values()
            .map(|(p, ci, vi)| ([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()], (*ci, *vi)))
            .collect();
        for v in &p.v {
            let &(ci, vi) = by_pos
                .get(&[v.p.x.to_bits(), v.p.y.to_bits(), v.p.z.to_bits()])
                .expect("chunk vertex");
            let m = &meshes[ci];
            assert_eq!(v.n, m.normals[vi]);
            assert_eq!(v.rgba, m.colors[vi]);
            assert_eq!(v.height.to_bits(), m.heights[vi].to_bits());
            assert_eq!(v.water.to_bits(), m.water_depths[vi].to_bits());
            assert_eq!(v.material, m.materials[vi]);
        }
    }
}

#[test]
fn ply_header_carries_meta() {
    let p = ply(&split_box(1, 1.0, DVec3::ZERO, OFFSETS, true));
    assert_eq!(p.comments[0], "pmc-ply version 1");
    for want in [
        "seed 18446744073709551614",
        "sea_radius none",
        "materials [\"rock\",\"sand\",\"snow\"]",
        "chunks 3",
    ] {
        assert!(
            p.comments.iter().any(|c| c == want),
            "missing comment {want:?} in {:?}",
            p.comments
        );
    }
}

#[test]
fn ply_without_attributes_uses_documented_defaults() {
    let p = ply(&split_box(1, 1.0, DVec3::ZERO, OFFSETS, false));
    assert_eq!(p.v.len(), box_vertices(1));
    for v in &p.v {
        assert_eq!(v.rgba, [255; 4]);
        assert!(v.height.is_nan() && v.water.is_nan());
        assert_eq!(v.material, 255);
    }
}

#[test]
fn meshes_without_edge_keys_are_not_welded() {
    let mut meshes = split_box(1, 1.0, DVec3::ZERO, OFFSETS, true);
    meshes[1].edge_keys.clear();
    let o = obj(&meshes);
    // Chunk 1 keeps its own copies of the vertices it shares with chunks 0 and 2.
    let shared_with_1: usize = {
        let k1: std::collections::HashSet<_> = split_box(1, 1.0, DVec3::ZERO, OFFSETS, true)[1]
            .edge_keys
            .iter()
            .copied()
            .collect();
        let others: std::collections::HashSet<_> = meshes[0]
            .edge_keys
            .iter()
            .chain(&meshes[2].edge_keys)
            .copied()
            .collect();
        k1.intersection(&others).count()
    };
    assert!(shared_with_1 > 0);
    assert_eq!(o.v.len(), box_vertices(1) + shared_with_1);
    let p = ply(&meshes);
    assert_eq!(p.v.len(), o.v.len());
}

#[test]
fn empty_meshes_are_skipped_and_an_empty_export_is_well_formed() {
    let mut meshes = split_box(1, 1.0, DVec3::ZERO, OFFSETS, true);
    meshes.insert(0, ChunkMesh::default());
    assert_eq!(ply(&meshes).v.len(), box_vertices(1));
    let p = ply(&[]);
    assert!(p.v.is_empty() && p.f.is_empty());
    let o = obj(&[ChunkMesh::default()]);
    assert!(o.v.is_empty() && o.f.is_empty());
}
