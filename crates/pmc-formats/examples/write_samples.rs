//! Writes sample files for the external checkers:
//!
//! ```text
//! cargo run -p pmc-formats --example write_samples -- /tmp/pmc-samples
//! node tools/gltf-validate/validate.mjs /tmp/pmc-samples/*.glb
//! python3 tools/check_mesh.py /tmp/pmc-samples/box.ply --expect-volume 64000 --expect-euler 2
//! ```
//!
//! The samples are a closed box (40 m wide, 4x4 quads per side) split into three chunks with
//! shared edge keys: `box.glb` (with sea), `far.glb` (the box on the surface of an Earth-sized
//! planet, with sea), `plain.glb` (no attributes, no sea), and the welded `box.obj`, `box.ply`.

#[path = "../tests/common/mod.rs"]
mod common;

use common::{meta, split_box, FAR, OFFSETS};
use pmc_geometry::glam::DVec3;
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "out/samples".to_string()));
    std::fs::create_dir_all(&dir)?;
    let near = split_box(2, 10.0, DVec3::ZERO, OFFSETS, true);
    let far = split_box(2, 10.0, FAR, OFFSETS, true);
    let plain = split_box(1, 1.0, DVec3::ZERO, OFFSETS, false);
    let jobs = [
        ("box.glb", &near, Some(15.0)),
        ("far.glb", &far, Some(6_371_000.0)),
        ("plain.glb", &plain, None),
        ("box.obj", &near, None),
        ("box.ply", &near, None),
    ];
    for (name, meshes, sea) in jobs {
        let path = dir.join(name);
        let s = pmc_formats::export(&path, meshes, &meta(sea))?;
        println!(
            "{}: {} bytes, {} vertices, {} triangles, {} chunks",
            path.display(),
            s.bytes,
            s.vertices,
            s.triangles,
            s.meshes
        );
    }
    Ok(())
}
