//! Welding chunk meshes into one mesh by canonical vertex identity.
//!
//! Vertices of different chunks with equal [`EdgeKey`]s are the same vertex (the mesher computes
//! them bit-identically from the same grid edge), so welding is exact: no distance tolerance.
//! Vertices of a mesh without edge keys are never merged. Only vertices used by a triangle are
//! kept, numbered in order of first use; a welded vertex takes its position, normal and attributes
//! from that first use. Triangles that collapse (two corners the same vertex) are dropped.

use crate::check::{check_meshes, Checked};
use crate::export::Counting;
use crate::{ExportError, ExportMeta, ExportStats};
use pmc_geometry::EdgeKey;
use pmc_mesh::ChunkMesh;
use std::collections::HashMap;
use std::io::{BufWriter, Write};

/// The part the welded exports (OBJ, PLY) share: the metadata and every mesh checked, the meshes
/// welded, and a buffered writer that counts its bytes. A writer begins one, writes its header
/// and body into `out`, then calls [`WeldedExport::finish`].
pub(crate) struct WeldedExport<'a, W: Write> {
    /// The meshes with triangles, checked, in input order.
    pub checked: Vec<Checked<'a>>,
    /// Their welded mesh.
    pub welded: Welded,
    /// Where the file goes.
    pub out: BufWriter<Counting<W>>,
}

impl<'a, W: Write> WeldedExport<'a, W> {
    /// Checks `meta` and `meshes` and welds the meshes, before anything is written to `out`.
    pub(crate) fn begin(meshes: &'a [ChunkMesh], meta: &ExportMeta, out: W) -> Result<Self, ExportError> {
        meta.check()?;
        let checked = check_meshes(meshes)?;
        let welded = weld(&checked)?;
        Ok(WeldedExport {
            checked,
            welded,
            out: BufWriter::with_capacity(1 << 16, Counting::new(out)),
        })
    }

    /// Flushes the file and says what was written.
    pub(crate) fn finish(mut self) -> Result<ExportStats, ExportError> {
        self.out.flush()?;
        Ok(ExportStats {
            bytes: self.out.get_ref().bytes(),
            vertices: self.welded.sources.len() as u64,
            triangles: self.welded.triangle_count() as u64,
            meshes: self.checked.len(),
        })
    }
}

/// One welded mesh, as references into the source meshes.
#[derive(Debug, Default)]
pub(crate) struct Welded {
    /// For each welded vertex: (position in the checked slice, vertex index in that mesh).
    pub sources: Vec<(u32, u32)>,
    /// Triangle list into `sources`, three per triangle, winding kept.
    pub indices: Vec<u32>,
    /// Triangles dropped because two of their corners welded together.
    pub collapsed: usize,
}

impl Welded {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

/// Welds `meshes` (already checked) into one mesh.
pub(crate) fn weld(meshes: &[Checked<'_>]) -> Result<Welded, ExportError> {
    let mut out = Welded::default();
    let mut by_key: HashMap<EdgeKey, u32> = HashMap::new();
    let mut local: Vec<u32> = Vec::new();
    for (mi, c) in meshes.iter().enumerate() {
        let m = c.mesh;
        local.clear();
        local.resize(m.positions.len(), u32::MAX);
        let mi = u32::try_from(mi).map_err(|_| ExportError::TooLarge("more than 2^32 chunk meshes".into()))?;
        for tri in m.indices.chunks_exact(3) {
            let mut t = [0u32; 3];
            for (slot, &vi) in t.iter_mut().zip(tri) {
                let vi = vi as usize;
                if local[vi] == u32::MAX {
                    let next = out.sources.len() as u32;
                    let id = if m.edge_keys.is_empty() {
                        next
                    } else {
                        *by_key.entry(m.edge_keys[vi]).or_insert(next)
                    };
                    if id == next {
                        if next == u32::MAX {
                            return Err(ExportError::TooLarge(
                                "the welded mesh has more than 2^32 - 1 vertices, more than OBJ/PLY indices can address here"
                                    .into(),
                            ));
                        }
                        out.sources.push((mi, vi as u32));
                    }
                    local[vi] = id;
                }
                *slot = local[vi];
            }
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                out.collapsed += 1;
            } else {
                out.indices.extend_from_slice(&t);
            }
        }
    }
    if out.collapsed > 0 {
        drop_unused(&mut out);
    }
    Ok(out)
}

/// Chunk meshes welded into one indexed mesh with every vertex attribute, in f64 world space:
/// what OBJ and PLY exports write, as arrays (the Python package's regions).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WeldedArrays {
    /// World positions, metres, planet-centred.
    pub positions: Vec<[f64; 3]>,
    /// Unit outward normals.
    pub normals: Vec<[f32; 3]>,
    /// Linear RGBA colours (all 0 where the meshes carry none).
    pub colors: Vec<[u8; 4]>,
    /// Heights above the datum, metres.
    pub heights: Vec<f32>,
    /// Depths of sea water above the vertex, metres.
    pub water_depths: Vec<f32>,
    /// Material ids.
    pub materials: Vec<u8>,
    /// Triangles, winding kept.
    pub triangles: Vec<[u32; 3]>,
}

/// Welds `meshes` by their canonical vertex identity (see the module's documentation): each
/// welded vertex takes its attributes from its first use; collapsed triangles are dropped.
/// Errors as the welded exports: a mesh that fails its checks, or more than 2^32 - 1 vertices.
pub fn weld_arrays(meshes: &[ChunkMesh]) -> Result<WeldedArrays, ExportError> {
    let checked = check_meshes(meshes)?;
    let welded = weld(&checked)?;
    let n = welded.sources.len();
    let mut out = WeldedArrays {
        positions: Vec::with_capacity(n),
        normals: Vec::with_capacity(n),
        colors: Vec::with_capacity(n),
        heights: Vec::with_capacity(n),
        water_depths: Vec::with_capacity(n),
        materials: Vec::with_capacity(n),
        triangles: welded.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    };
    for &(mi, vi) in &welded.sources {
        let c = &checked[mi as usize];
        let (m, v) = (c.mesh, vi as usize);
        out.positions.push(m.world_position_full(v).to_array());
        out.normals.push(m.normals[v]);
        if c.attributes {
            out.colors.push(m.colors[v]);
            out.heights.push(m.heights[v]);
            out.water_depths.push(m.water_depths[v]);
            out.materials.push(m.materials[v]);
        } else {
            out.colors.push([0; 4]);
            out.heights.push(0.0);
            out.water_depths.push(0.0);
            out.materials.push(0);
        }
    }
    Ok(out)
}

/// Removes vertices only collapsed triangles used, keeping the order of the others.
fn drop_unused(w: &mut Welded) {
    let mut remap = vec![u32::MAX; w.sources.len()];
    for &i in &w.indices {
        remap[i as usize] = 0;
    }
    let mut next = 0u32;
    let mut kept = Vec::with_capacity(w.sources.len());
    for (r, &s) in remap.iter_mut().zip(&w.sources) {
        if *r == 0 {
            *r = next;
            next += 1;
            kept.push(s);
        }
    }
    w.sources = kept;
    for i in &mut w.indices {
        *i = remap[*i as usize];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::check_meshes;
    use pmc_mesh::ChunkMesh;

    fn mesh(keys: &[u128], indices: &[u32]) -> ChunkMesh {
        let n = keys.len();
        ChunkMesh {
            positions: (0..n).map(|i| [i as f32, 0.0, 0.0]).collect(),
            normals: vec![[0.0, 0.0, 1.0]; n],
            indices: indices.to_vec(),
            edge_keys: keys.iter().map(|&k| EdgeKey(k, k + 1)).collect(),
            ..Default::default()
        }
    }

    #[test]
    fn welded_arrays_carry_the_first_use_of_each_vertex() {
        let mut a = mesh(&[1, 2, 3], &[0, 1, 2]);
        let mut b = mesh(&[3, 2, 4], &[1, 0, 2]);
        for (m, base) in [(&mut a, 0u8), (&mut b, 10)] {
            m.origin = pmc_geometry::glam::DVec3::new(1e6, 0.0, 0.0);
            m.heights = vec![1.0, 2.0, 3.0];
            m.water_depths = vec![0.0; 3];
            m.colors = vec![[base, 0, 0, 255]; 3];
            m.materials = vec![base; 3];
        }
        let w = weld_arrays(&[a, b]).unwrap();
        assert_eq!(w.positions.len(), 4);
        assert_eq!(w.triangles, vec![[0, 1, 2], [1, 2, 3]]);
        assert_eq!(w.positions[0], [1e6, 0.0, 0.0]);
        assert_eq!(w.materials, vec![0, 0, 0, 10]);
        assert_eq!(w.heights, vec![1.0, 2.0, 3.0, 3.0]);
    }

    #[test]
    fn merges_equal_keys_across_chunks_and_keeps_first_source() {
        let a = mesh(&[1, 2, 3], &[0, 1, 2]);
        let b = mesh(&[3, 2, 4], &[1, 0, 2]);
        let meshes = [a, b];
        let w = weld(&check_meshes(&meshes).unwrap()).unwrap();
        assert_eq!(w.sources, vec![(0, 0), (0, 1), (0, 2), (1, 2)]);
        assert_eq!(w.indices, vec![0, 1, 2, 1, 2, 3]);
        assert_eq!(w.collapsed, 0);
    }

    #[test]
    fn meshes_without_keys_are_not_welded_and_unused_vertices_are_dropped() {
        let mut a = mesh(&[1, 2, 3, 9], &[0, 1, 2]);
        a.edge_keys.clear();
        let b = a.clone();
        let meshes = [a, b];
        let w = weld(&check_meshes(&meshes).unwrap()).unwrap();
        assert_eq!(w.sources.len(), 6);
        assert_eq!(w.triangle_count(), 2);
    }

    #[test]
    fn drops_collapsed_triangles() {
        let a = mesh(&[1, 1, 3], &[0, 1, 2]);
        let meshes = [a];
        let w = weld(&check_meshes(&meshes).unwrap()).unwrap();
        assert_eq!(w.triangle_count(), 0);
        assert_eq!(w.collapsed, 1);
        assert!(w.sources.is_empty());
        let b = mesh(&[5, 5, 6, 7, 8], &[0, 1, 2, 2, 3, 4]);
        let meshes = [b];
        let w = weld(&check_meshes(&meshes).unwrap()).unwrap();
        assert_eq!(w.sources, vec![(0, 2), (0, 3), (0, 4)]);
        assert_eq!(w.indices, vec![0, 1, 2]);
    }
}
