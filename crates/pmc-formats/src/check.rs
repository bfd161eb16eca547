//! Validation of chunk meshes before anything is written.

use crate::ExportError;
use pmc_mesh::ChunkMesh;

/// A chunk mesh that passed [`check_meshes`] and has triangles.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Checked<'a> {
    /// Position in the slice that was passed in.
    pub index: usize,
    /// The mesh.
    pub mesh: &'a ChunkMesh,
    /// Whether heights, water depths, colours and materials are all present.
    pub attributes: bool,
}

/// The display name of a chunk: its key (`top/0/3/4/1`), or `chunk-N` without one.
pub(crate) fn chunk_name(index: usize, mesh: &ChunkMesh) -> String {
    match &mesh.key {
        Some(k) => k.to_string(),
        None => format!("chunk-{index}"),
    }
}

/// Checks every mesh with triangles and returns those, in input order; meshes without indices are
/// skipped unchecked.
pub(crate) fn check_meshes(meshes: &[ChunkMesh]) -> Result<Vec<Checked<'_>>, ExportError> {
    let mut out = Vec::new();
    for (index, mesh) in meshes.iter().enumerate() {
        if mesh.indices.is_empty() {
            continue;
        }
        let attributes = check_mesh(mesh).map_err(|reason| ExportError::InvalidMesh {
            index,
            name: chunk_name(index, mesh),
            reason,
        })?;
        out.push(Checked {
            index,
            mesh,
            attributes,
        });
    }
    Ok(out)
}

/// Checks one non-empty mesh; returns whether it has attributes, or what is wrong.
fn check_mesh(m: &ChunkMesh) -> Result<bool, String> {
    let n = m.positions.len();
    if n > u32::MAX as usize {
        return Err(format!("{n} vertices, more than u32 indices can address"));
    }
    if m.normals.len() != n {
        return Err(format!("normals has {} entries but positions has {n}", m.normals.len()));
    }
    if !m.positions_low.is_empty() && m.positions_low.len() != n {
        return Err(format!(
            "positions_low has {} entries but positions has {n} (it must be empty or match)",
            m.positions_low.len()
        ));
    }
    if !m.edge_keys.is_empty() && m.edge_keys.len() != n {
        return Err(format!(
            "edge_keys has {} entries but positions has {n} (it must be empty or match)",
            m.edge_keys.len()
        ));
    }
    let lens = [
        ("heights", m.heights.len()),
        ("water_depths", m.water_depths.len()),
        ("colors", m.colors.len()),
        ("materials", m.materials.len()),
    ];
    let attributes = lens.iter().any(|&(_, l)| l != 0);
    if attributes {
        if let Some((name, l)) = lens.iter().find(|&&(_, l)| l != n) {
            return Err(format!(
                "{name} has {l} entries but positions has {n} (heights, water_depths, colors and materials must all be \
                 empty or all match positions)"
            ));
        }
    }
    if !m.indices.len().is_multiple_of(3) {
        return Err(format!("indices has {} entries, not a multiple of 3", m.indices.len()));
    }
    if let Some((at, &i)) = m.indices.iter().enumerate().find(|&(_, &i)| i as usize >= n) {
        return Err(format!("index {i} at position {at} is out of range for {n} vertices"));
    }
    let o = m.origin;
    if !(o.x.is_finite() && o.y.is_finite() && o.z.is_finite()) {
        return Err(format!("origin {o} is not finite"));
    }
    if let Some(i) = m.positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(format!("position {i} {:?} is not finite", m.positions[i]));
    }
    if let Some(i) = m.positions_low.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(format!("position low part {i} {:?} is not finite", m.positions_low[i]));
    }
    if let Some(i) = m.normals.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(format!("normal {i} {:?} is not finite", m.normals[i]));
    }
    if let Some(i) = m.heights.iter().position(|h| !h.is_finite()) {
        return Err(format!("height {i} ({}) is not finite", m.heights[i]));
    }
    if let Some(i) = m.water_depths.iter().position(|h| !h.is_finite()) {
        return Err(format!("water depth {i} ({}) is not finite", m.water_depths[i]));
    }
    Ok(attributes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> ChunkMesh {
        ChunkMesh {
            positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            normals: vec![[0.0, 0.0, 1.0]; 3],
            indices: vec![0, 1, 2],
            ..Default::default()
        }
    }

    fn reason(m: ChunkMesh) -> String {
        match check_meshes(std::slice::from_ref(&m)) {
            Err(ExportError::InvalidMesh { reason, .. }) => reason,
            other => panic!("expected InvalidMesh, got {other:?}"),
        }
    }

    #[test]
    fn accepts_plain_and_attributed_meshes() {
        let meshes = [tri()];
        let c = check_meshes(&meshes).unwrap();
        assert_eq!(c.len(), 1);
        assert!(!c[0].attributes);
        let mut m = tri();
        m.heights = vec![0.0; 3];
        m.water_depths = vec![0.0; 3];
        m.colors = vec![[1; 4]; 3];
        m.materials = vec![2; 3];
        assert!(check_meshes(&[m]).unwrap()[0].attributes);
    }

    #[test]
    fn skips_empty_meshes_unchecked() {
        let mut bad = tri();
        bad.indices.clear();
        bad.normals.clear();
        let meshes = [bad, tri()];
        let c = check_meshes(&meshes).unwrap();
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].index, 1);
    }

    #[test]
    fn rejects_each_kind_of_inconsistency() {
        let mut m = tri();
        m.normals.pop();
        assert!(reason(m).contains("normals"));
        let mut m = tri();
        m.indices.push(0);
        assert!(reason(m).contains("multiple of 3"));
        let mut m = tri();
        m.indices[2] = 3;
        assert!(reason(m).contains("out of range"));
        let mut m = tri();
        m.heights = vec![0.0; 3];
        assert!(reason(m).contains("water_depths"));
        let mut m = tri();
        m.edge_keys = vec![pmc_geometry::EdgeKey(0, 1)];
        assert!(reason(m).contains("edge_keys"));
        let mut m = tri();
        m.positions[1][2] = f32::NAN;
        assert!(reason(m).contains("not finite"));
        let mut m = tri();
        m.origin.y = f64::INFINITY;
        assert!(reason(m).contains("origin"));
    }

    #[test]
    fn names_chunks_by_key_or_index() {
        let mut m = tri();
        assert_eq!(chunk_name(7, &m), "chunk-7");
        m.key = Some(pmc_geometry::ChunkKey::new(pmc_geometry::Face::Top, 3, 4, 1));
        assert_eq!(chunk_name(7, &m), "top/0/3/4/1");
    }
}
