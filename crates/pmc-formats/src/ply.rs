//! Binary PLY export, layout version 1 (`docs/specs/ply-v1.md`): one welded world-space mesh with
//! `f64` positions and the per-vertex attributes.

use crate::weld::WeldedExport;
use crate::{ExportError, ExportMeta, ExportStats};
use pmc_mesh::ChunkMesh;
use std::io::Write;

/// Bytes of one vertex record: 3 doubles, 3 floats, 4 uchars, 2 floats, 1 uchar.
pub const PLY_VERTEX_BYTES: u64 = 3 * 8 + 3 * 4 + 4 + 2 * 4 + 1;
/// Bytes of one face record: the uchar count (3) and three uints.
pub const PLY_FACE_BYTES: u64 = 1 + 3 * 4;

/// Colour written for vertices of meshes without attributes (opaque white).
const NO_COLOR: [u8; 4] = [255; 4];
/// Material id written for vertices of meshes without attributes.
const NO_MATERIAL: u8 = 255;

/// Writes `meshes` as one welded world-space binary little-endian PLY mesh (layout:
/// `docs/specs/ply-v1.md`).
///
/// Vertices with equal edge keys are merged; positions are `origin + position` as `double`.
/// Meshes without triangles are skipped; every mesh is checked before the first byte is written.
pub fn write_ply<W: Write>(meshes: &[ChunkMesh], meta: &ExportMeta, out: W) -> Result<(), ExportError> {
    write(meshes, meta, out).map(|_| ())
}

/// Writes the PLY and returns what it wrote.
pub(crate) fn write<W: Write>(meshes: &[ChunkMesh], meta: &ExportMeta, out: W) -> Result<ExportStats, ExportError> {
    let mut export = WeldedExport::begin(meshes, meta, out)?;
    let (checked, welded, out) = (&export.checked, &export.welded, &mut export.out);
    let mut header = String::from("ply\nformat binary_little_endian 1.0\n");
    for line in meta.comment_lines("pmc-ply") {
        header.push_str(&format!("comment {line}\n"));
    }
    header.push_str(&format!("comment chunks {}\n", checked.len()));
    header.push_str(&format!("element vertex {}\n", welded.sources.len()));
    for p in ["double x", "double y", "double z", "float nx", "float ny", "float nz"] {
        header.push_str(&format!("property {p}\n"));
    }
    for p in [
        "uchar red",
        "uchar green",
        "uchar blue",
        "uchar alpha",
        "float height",
        "float water_depth",
    ] {
        header.push_str(&format!("property {p}\n"));
    }
    header.push_str("property uchar material\n");
    header.push_str(&format!("element face {}\n", welded.triangle_count()));
    header.push_str("property list uchar uint vertex_indices\nend_header\n");
    out.write_all(header.as_bytes())?;

    let mut rec = Vec::with_capacity(PLY_VERTEX_BYTES as usize);
    for &(mi, vi) in &welded.sources {
        let c = &checked[mi as usize];
        let (m, vi) = (c.mesh, vi as usize);
        rec.clear();
        let p = m.world_position(vi);
        for x in [p.x, p.y, p.z] {
            rec.extend_from_slice(&x.to_le_bytes());
        }
        for x in m.normals[vi] {
            rec.extend_from_slice(&x.to_le_bytes());
        }
        let (color, height, water, material) = if c.attributes {
            (m.colors[vi], m.heights[vi], m.water_depths[vi], m.materials[vi])
        } else {
            (NO_COLOR, f32::NAN, f32::NAN, NO_MATERIAL)
        };
        rec.extend_from_slice(&color);
        rec.extend_from_slice(&height.to_le_bytes());
        rec.extend_from_slice(&water.to_le_bytes());
        rec.push(material);
        out.write_all(&rec)?;
    }
    for t in welded.indices.chunks_exact(3) {
        rec.clear();
        rec.push(3);
        for i in t {
            rec.extend_from_slice(&i.to_le_bytes());
        }
        out.write_all(&rec)?;
    }
    export.finish()
}
