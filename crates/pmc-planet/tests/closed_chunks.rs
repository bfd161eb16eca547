//! Closed chunks for clients that pick levels on their own (`Planet::chunk_mesh_closed`): on
//! every preset, at every level, each chunk with a surface is a closed manifold by edge key, its
//! surface is the ordinary mesh's bit for bit, and its attributes cover the cap vertices.

use pmc_geometry::Layout;
use pmc_mesh::WeldedMesh;
use pmc_planet::{Planet, PresetKind};

#[test]
fn closed_chunks_of_every_level_are_closed_manifolds_on_every_preset() {
    for (n, preset) in PresetKind::ALL.into_iter().enumerate() {
        let layout = Layout::new(4, 8, 500.0, 2.0, 4).unwrap();
        let planet = Planet::new(preset, 3 + n as u64, layout);
        let (mut meshed, mut capped) = (0, 0);
        for level in 0..=layout.max_level() {
            for key in layout.chunks(level) {
                let open = planet.chunk_mesh(key);
                let closed = planet.chunk_mesh_closed(key);
                if open.indices.is_empty() {
                    assert!(closed.indices.is_empty(), "{preset:?} {key:?}: no surface, no caps");
                    continue;
                }
                meshed += 1;
                let r = WeldedMesh::weld(std::slice::from_ref(&closed)).report();
                assert!(r.is_closed_manifold(), "{preset:?} {key:?}: {r:?}");
                // The surface comes first, unchanged; the caps add triangles after it.
                assert_eq!(closed.indices[..open.indices.len()], open.indices[..]);
                capped += usize::from(closed.indices.len() > open.indices.len());
                let v = open.vertex_count();
                assert_eq!(closed.positions[..v], open.positions[..]);
                assert_eq!(closed.normals[..v], open.normals[..]);
                assert_eq!(closed.colors[..v], open.colors[..]);
                assert!(
                    closed.has_attributes(),
                    "{preset:?} {key:?}: attributes on every vertex"
                );
            }
        }
        assert!(meshed > 20, "{preset:?}: {meshed} chunks with a surface");
        // (a surface wholly inside its chunk, a floating rock or a bubble, needs no cap)
        assert!(capped * 2 > meshed, "{preset:?}: {capped} of {meshed} chunks have caps");
    }
}
