//! Bad input gives errors, never panics; `export` never leaves half files behind.

use crate::common::{meta, split_box, temp_dir, OFFSETS};
use pmc_formats::{export, write_glb, write_obj, write_ply, ExportError, ExportMeta, Format};
use pmc_geometry::glam::DVec3;
use pmc_mesh::ChunkMesh;
use proptest::prelude::*;
use std::io::Write;
use std::path::Path;

type Writer = fn(&[ChunkMesh], &ExportMeta, &mut Vec<u8>) -> Result<(), ExportError>;

const WRITERS: [(&str, Writer); 3] = [
    ("glb", |m, x, o| write_glb(m, x, o)),
    ("obj", |m, x, o| write_obj(m, x, o)),
    ("ply", |m, x, o| write_ply(m, x, o)),
];

fn good() -> Vec<ChunkMesh> {
    split_box(1, 1.0, DVec3::ZERO, OFFSETS, true)
}

/// Files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn inconsistent_meshes_are_errors_for_every_writer() {
    type Breakage = (&'static str, fn(&mut ChunkMesh));
    let breakages: [Breakage; 6] = [
        ("normals", |m| {
            m.normals.pop();
        }),
        ("out of range", |m| {
            let n = m.positions.len() as u32;
            m.indices[4] = n;
        }),
        ("multiple of 3", |m| {
            m.indices.pop();
        }),
        ("colors", |m| {
            m.colors.truncate(2);
        }),
        ("edge_keys", |m| {
            m.edge_keys.pop();
        }),
        ("not finite", |m| m.positions[0][1] = f32::INFINITY),
    ];
    for (what, breakage) in breakages {
        let mut meshes = good();
        breakage(&mut meshes[2]);
        for (fmt, write) in WRITERS {
            let mut out = Vec::new();
            match write(&meshes, &meta(Some(1.0)), &mut out) {
                Err(e @ ExportError::InvalidMesh { index: 2, .. }) => {
                    let msg = e.to_string();
                    assert!(msg.contains(what) && msg.contains("#2"), "{fmt}: {msg}");
                }
                other => panic!("{fmt} / {what}: expected InvalidMesh for mesh 2, got {other:?}"),
            }
            assert!(
                out.is_empty(),
                "{fmt} / {what}: nothing may be written before the check"
            );
        }
    }
}

#[test]
fn bad_sea_radius_is_an_error() {
    for (fmt, write) in WRITERS {
        let r = write(&good(), &meta(Some(f64::NAN)), &mut Vec::new());
        assert!(matches!(r, Err(ExportError::InvalidMeta(_))), "{fmt}: {r:?}");
    }
}

#[test]
fn format_from_path() {
    assert_eq!(Format::from_path(Path::new("a/b/planet.Glb")).unwrap(), Format::Glb);
    assert_eq!(Format::from_path(Path::new("planet.obj")).unwrap(), Format::Obj);
    assert_eq!(Format::from_path(Path::new("planet.PLY")).unwrap(), Format::Ply);
    for p in ["x.stl", "noext"] {
        let e = Format::from_path(Path::new(p)).unwrap_err();
        assert!(matches!(e, ExportError::UnsupportedFormat { .. }));
        let msg = e.to_string();
        assert!(
            msg.contains(p) && msg.contains(".glb") && msg.contains(".obj") && msg.contains(".ply"),
            "{msg}"
        );
    }
}

#[test]
fn export_into_missing_directory_names_it_and_leaves_nothing() {
    let dir = temp_dir("missing");
    let path = dir.join("no/such/dir/planet.glb");
    let e = export(&path, &good(), &meta(None)).unwrap_err();
    assert!(matches!(e, ExportError::DirectoryMissing { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(msg.contains(&path.display().to_string()), "{msg}");
    assert!(msg.contains("does not exist") && msg.contains("create it"), "{msg}");
    assert!(listing(&dir).is_empty(), "{:?}", listing(&dir));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_with_unsupported_extension_writes_nothing() {
    let dir = temp_dir("ext");
    let e = export(&dir.join("planet.stl"), &good(), &meta(None)).unwrap_err();
    assert!(matches!(e, ExportError::UnsupportedFormat { .. }));
    assert!(listing(&dir).is_empty());
    let e = export(&dir, &good(), &meta(None)).unwrap_err();
    assert!(
        matches!(e, ExportError::UnsupportedFormat { .. }),
        "a directory without extension: {e:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_onto_a_directory_is_an_error() {
    let dir = temp_dir("isdir");
    std::fs::create_dir(dir.join("x.glb")).unwrap();
    let e = export(&dir.join("x.glb"), &good(), &meta(None)).unwrap_err();
    assert!(matches!(e, ExportError::IsDirectory { .. }), "{e:?}");
    assert_eq!(listing(&dir), vec!["x.glb"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_replaces_an_existing_file_completely() {
    let dir = temp_dir("replace");
    for (fmt, write) in WRITERS {
        let path = dir.join(format!("planet.{fmt}"));
        // A larger old file: the new one must not keep its tail.
        std::fs::write(&path, vec![b'x'; 1 << 20]).unwrap();
        let stats = export(&path, &good(), &meta(Some(5.0))).unwrap();
        let mut expected = Vec::new();
        write(&good(), &meta(Some(5.0)), &mut expected).unwrap();
        let got = std::fs::read(&path).unwrap();
        assert!(got == expected, "{fmt}: file differs from write_{fmt} output");
        assert_eq!(stats.bytes, got.len() as u64);
        assert_eq!(stats.meshes, 3);
    }
    assert_eq!(
        listing(&dir),
        vec!["planet.glb", "planet.obj", "planet.ply"],
        "no temporary files left"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn failed_export_keeps_the_old_file() {
    let dir = temp_dir("keep");
    let path = dir.join("planet.ply");
    std::fs::write(&path, b"old good file").unwrap();
    let mut meshes = good();
    meshes[0].normals.clear();
    let e = export(&path, &meshes, &meta(None)).unwrap_err();
    assert!(matches!(e, ExportError::InvalidMesh { index: 0, .. }), "{e:?}");
    assert_eq!(std::fs::read(&path).unwrap(), b"old good file");
    assert_eq!(listing(&dir), vec!["planet.ply"], "no temporary files left");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn export_stats_count_welded_output() {
    let dir = temp_dir("stats");
    let s = export(&dir.join("a.obj"), &good(), &meta(None)).unwrap();
    assert_eq!((s.vertices, s.triangles, s.meshes), (26, 48, 3));
    let s = export(&dir.join("a.glb"), &good(), &meta(Some(3.0))).unwrap();
    assert_eq!(
        (s.vertices, s.triangles, s.meshes),
        (39, 48, 3),
        "GLB: per-chunk vertices, sea not counted"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A writer that fails after `left` bytes.
struct Failing {
    left: usize,
}

impl Write for Failing {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.left == 0 {
            return Err(std::io::Error::other("disk full"));
        }
        let n = buf.len().min(self.left);
        self.left -= n;
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn writer_failures_are_errors() {
    let m = good();
    let x = meta(Some(2.0));
    for (fmt, write) in WRITERS {
        let mut full = Vec::new();
        write(&m, &x, &mut full).unwrap();
        for left in [0, 10, full.len() / 2, full.len() - 1] {
            let r = match fmt {
                "glb" => write_glb(&m, &x, Failing { left }),
                "obj" => write_obj(&m, &x, Failing { left }),
                _ => write_ply(&m, &x, Failing { left }),
            };
            assert!(
                matches!(r, Err(ExportError::Write(_))),
                "{fmt} failing after {left} bytes: {r:?}"
            );
        }
        assert!(write_glb(&m, &x, Failing { left: usize::MAX }).is_ok());
    }
}

fn arb_mesh() -> impl Strategy<Value = ChunkMesh> {
    let v3 = || prop::array::uniform3(prop_oneof![-1e3f32..1e3, Just(f32::NAN)]);
    (
        0usize..6,
        0usize..6,
        0usize..12,
        0usize..7,
        0usize..7,
        any::<bool>(),
        prop_oneof![Just(0.0), -1e7f64..1e7],
    )
        .prop_flat_map(move |(np, nn, ni, nk, na, key, o)| {
            (
                prop::collection::vec(v3(), np),
                prop::collection::vec(v3(), nn),
                prop::collection::vec(0u32..8, ni),
                prop::collection::vec(0u128..4, nk),
                prop::collection::vec(any::<u8>(), na),
                Just((key, o)),
            )
        })
        .prop_map(|(positions, normals, indices, keys, attrs, (key, o))| ChunkMesh {
            key: key.then(|| pmc_geometry::ChunkKey::new(pmc_geometry::Face::East, 1, 2, 3)),
            origin: DVec3::new(o, -o, 0.5),
            positions,
            normals,
            indices,
            edge_keys: keys.iter().map(|&k| pmc_geometry::EdgeKey(k, 0)).collect(),
            heights: attrs.iter().map(|&a| a as f32).collect(),
            water_depths: attrs.iter().map(|&a| a as f32 * 0.5).collect(),
            colors: attrs.iter().map(|&a| [a; 4]).collect(),
            materials: attrs.clone(),
            ..ChunkMesh::default()
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Whatever the buffers hold, the writers return Ok or Err and never panic; when they succeed
    /// the PLY body length and the GLB header length are right.
    #[test]
    fn arbitrary_meshes_never_panic(meshes in prop::collection::vec(arb_mesh(), 0..4), sea in any::<bool>()) {
        let x = meta(sea.then_some(10.0));
        for (_, write) in WRITERS {
            let mut out = Vec::new();
            if write(&meshes, &x, &mut out).is_err() {
                prop_assert!(out.is_empty());
            }
        }
        let mut out = Vec::new();
        if write_glb(&meshes, &x, &mut out).is_ok() {
            prop_assert_eq!(u32::from_le_bytes(out[8..12].try_into().unwrap()) as usize, out.len());
        }
    }
}
