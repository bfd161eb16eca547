//! Flat, reusable mesh buffers for one chunk.

use pmc_geometry::glam::DVec3;
use pmc_geometry::{ChunkKey, EdgeKey};

/// The mesh of one chunk as flat arrays (one entry per vertex unless noted).
///
/// Positions are `f32` metres relative to [`ChunkMesh::origin`] (an `f64` world point), so
/// precision holds at any planet radius. Normals are unit length and point out of the solid.
/// Triangles wind counter-clockwise seen from outside (the air side), as glTF expects.
///
/// Call [`ChunkMesh::clear`] to reuse the buffers: it keeps their capacity.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChunkMesh {
    /// The chunk this mesh belongs to.
    pub key: Option<ChunkKey>,
    /// World position (metres, planet-centred) that positions are relative to.
    pub origin: DVec3,
    /// Vertex positions relative to `origin`.
    pub positions: Vec<[f32; 3]>,
    /// What `f32` could not hold of each position: `(world - origin) - positions`, rounded to
    /// `f32`, so `origin + positions + positions_low` is the world position to about `1e-14` of
    /// the chunk's size. The copies of a vertex in neighbouring chunks (other origins, other
    /// levels) then agree far below a millimetre, where `positions` alone differ by up to half an
    /// `f32` step of the larger chunk (centimetres for chunks hundreds of kilometres wide): a
    /// viewer that draws positions relative to the eye from high and low parts rasterises both
    /// copies the same, with no hairline gap. Empty for meshes made without it (then all 0).
    pub positions_low: Vec<[f32; 3]>,
    /// Unit outward normals, from the density gradient.
    pub normals: Vec<[f32; 3]>,
    /// Triangle list, three indices per triangle.
    pub indices: Vec<u32>,
    /// Canonical identity of each vertex (the grid edge it lies on). Vertices of neighbouring
    /// chunks with equal keys are the same vertex, bit for bit in world space.
    pub edge_keys: Vec<EdgeKey>,
    /// Height above sea level (or above the base radius of the shell when there is no sea), metres.
    pub heights: Vec<f32>,
    /// Depth of sea water above the vertex, metres (0 above sea level).
    pub water_depths: Vec<f32>,
    /// Linear RGBA colour.
    pub colors: Vec<[u8; 4]>,
    /// Material id (see the terrain's material list).
    pub materials: Vec<u8>,
    /// Per vertex of a marching-cubes mesh, the grid edge it lies on: the flat indices
    /// ([`pmc_geometry::ChunkGrid::index`]) of the two padded samples it lies between, in the
    /// canonical order every chunk holding the edge uses (along depth the lower layer first,
    /// across the surface the column with the smaller lattice point first). Empty for meshes made
    /// otherwise (height-field patches). Shaders read the chunk's columns at the two ends.
    pub vertex_edges: Vec<[u32; 2]>,
    /// The cubes of a marching-cubes mesh that emitted triangles, in emission order (the order of
    /// their flat indices): the flat index of the cube's lowest corner, and the end of its
    /// triangles (a triangle count; the cube's triangles start where the previous cube's end).
    /// Transition patches (level-of-detail seams) are not cubes: their triangles come after the
    /// last cube's. Remeshing after an edit copies the triangles of the cubes the edit cannot
    /// change from here ([`crate::Mesher::remesh_cubes`]).
    pub cube_runs: Vec<[u32; 2]>,
}

impl ChunkMesh {
    /// Empties every buffer, keeping capacity.
    pub fn clear(&mut self) {
        self.key = None;
        self.origin = DVec3::ZERO;
        self.positions.clear();
        self.positions_low.clear();
        self.normals.clear();
        self.indices.clear();
        self.edge_keys.clear();
        self.heights.clear();
        self.water_depths.clear();
        self.colors.clear();
        self.materials.clear();
        self.vertex_edges.clear();
        self.cube_runs.clear();
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Whether the mesh has no triangles.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// [`ChunkMesh::world_position`] with [`ChunkMesh::positions_low`] added where the mesh has
    /// them: the world position to about `1e-14` of the chunk's size.
    pub fn world_position_full(&self, i: usize) -> DVec3 {
        let low = self
            .positions_low
            .get(i)
            .map_or(DVec3::ZERO, |l| DVec3::from(l.map(f64::from)));
        self.world_position(i) + low
    }

    /// World position of vertex `i` (`origin + position`, in `f64`).
    pub fn world_position(&self, i: usize) -> DVec3 {
        let p = self.positions[i];
        self.origin + DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
    }

    /// Whether the per-vertex attribute buffers (heights, water depths, colours, materials) are
    /// filled for every vertex.
    pub fn has_attributes(&self) -> bool {
        let n = self.positions.len();
        self.heights.len() == n && self.water_depths.len() == n && self.colors.len() == n && self.materials.len() == n
    }
}
