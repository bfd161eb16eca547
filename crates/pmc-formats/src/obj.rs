//! Wavefront OBJ export, layout version 1 (`docs/specs/obj-v1.md`): one welded world-space mesh.

use crate::weld::WeldedExport;
use crate::{ExportError, ExportMeta, ExportStats};
use pmc_mesh::ChunkMesh;
use std::io::Write;

/// Writes `meshes` as one welded world-space OBJ mesh (layout: `docs/specs/obj-v1.md`).
///
/// Vertices with equal edge keys are merged; positions are `origin + position` in `f64` metres,
/// written with full precision. Meshes without triangles are skipped; every mesh is checked
/// before the first byte is written.
pub fn write_obj<W: Write>(meshes: &[ChunkMesh], meta: &ExportMeta, out: W) -> Result<(), ExportError> {
    write(meshes, meta, out).map(|_| ())
}

/// Writes the OBJ and returns what it wrote.
pub(crate) fn write<W: Write>(meshes: &[ChunkMesh], meta: &ExportMeta, out: W) -> Result<ExportStats, ExportError> {
    let mut export = WeldedExport::begin(meshes, meta, out)?;
    let (checked, welded, out) = (&export.checked, &export.welded, &mut export.out);
    for line in meta.comment_lines("pmc-obj") {
        writeln!(out, "# {line}")?;
    }
    writeln!(out, "# chunks {}", checked.len())?;
    writeln!(out, "# vertices {}", welded.sources.len())?;
    writeln!(out, "# faces {}", welded.triangle_count())?;
    writeln!(out, "o planet")?;
    for &(mi, vi) in &welded.sources {
        let p = checked[mi as usize].mesh.world_position(vi as usize);
        writeln!(out, "v {} {} {}", p.x, p.y, p.z)?;
    }
    for &(mi, vi) in &welded.sources {
        let n = checked[mi as usize].mesh.normals[vi as usize];
        writeln!(out, "vn {} {} {}", n[0], n[1], n[2])?;
    }
    for t in welded.indices.chunks_exact(3) {
        let (a, b, c) = (t[0] as u64 + 1, t[1] as u64 + 1, t[2] as u64 + 1);
        writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")?;
    }
    export.finish()
}
