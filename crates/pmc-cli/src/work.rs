//! What several commands share: output checks, the thread pool, meshing with a progress bar.

use crate::error::CliError;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pmc_mesh::ChunkMesh;
use pmc_planet::Planet;
use std::path::{Path, PathBuf};

/// Checks, before any work, that a file can be created at `path`.
pub fn check_writable(path: &Path) -> Result<(), CliError> {
    let err = |reason: String| CliError::Output {
        path: path.to_path_buf(),
        reason,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(err(format!(
            "the directory {} does not exist; create it first",
            dir.display()
        )));
    }
    if path.is_dir() {
        return Err(err("it is a directory; give a file name".into()));
    }
    let probe = dir.join(format!(".pmc-write-check-{}", std::process::id()));
    match std::fs::File::create(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(err(format!("the directory {} is not writable ({e})", dir.display()))),
    }
}

/// Most tiles along a face side for commands that mesh the whole planet at once: about 50
/// million triangles and a few GB of meshes. Larger planets need streaming, not one file.
pub const MAX_WHOLE_PLANET_FACE_TILES: i64 = 2048;
/// Most chunks for commands that mesh the whole planet at once.
pub const MAX_WHOLE_PLANET_CHUNKS: u64 = 200_000;

/// Refuses layouts too large to mesh whole in memory, before any work.
pub fn check_whole_planet(layout: &pmc_geometry::Layout) -> Result<(), CliError> {
    if layout.face_tiles() > MAX_WHOLE_PLANET_FACE_TILES || layout.chunk_count() > MAX_WHOLE_PLANET_CHUNKS {
        return Err(CliError::TooLarge {
            face_tiles: layout.face_tiles(),
            chunks: layout.chunk_count(),
        });
    }
    Ok(())
}

/// A rayon pool of `threads` workers (0: one per core).
pub fn thread_pool(threads: usize) -> Result<rayon::ThreadPool, CliError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| CliError::Threads {
            threads,
            reason: e.to_string(),
        })
}

/// Meshes every chunk of `planet` on `pool`, with a progress bar on stderr unless `quiet`.
pub fn mesh_planet(planet: &Planet, pool: &rayon::ThreadPool, quiet: bool) -> Vec<ChunkMesh> {
    let total = planet.layout().chunk_count();
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr())
    };
    bar.set_style(
        ProgressStyle::with_template("{spinner} meshing chunks {bar:40} {pos}/{len} ({elapsed}, eta {eta})")
            .expect("valid template"),
    );
    let meshes = pool.install(|| planet.generate(|_| bar.inc(1)));
    bar.finish_and_clear();
    meshes
}

/// Meshes the chunks `keys` of `planet` on `pool` (level-of-detail meshes without seams: one
/// level throughout), with a progress bar on stderr unless `quiet`. Returns the non-empty
/// meshes in key order.
pub fn mesh_chunks(
    planet: &Planet,
    keys: &[pmc_geometry::ChunkKey],
    pool: &rayon::ThreadPool,
    quiet: bool,
) -> Vec<ChunkMesh> {
    use rayon::prelude::*;
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::with_draw_target(Some(keys.len() as u64), ProgressDrawTarget::stderr())
    };
    bar.set_style(
        ProgressStyle::with_template("{spinner} meshing chunks {bar:40} {pos}/{len} ({elapsed}, eta {eta})")
            .expect("valid template"),
    );
    let mut meshes: Vec<ChunkMesh> = pool.install(|| {
        keys.par_iter()
            .map_init(pmc_planet::ChunkScratch::default, |scratch, key| {
                let mut m = ChunkMesh::default();
                planet.chunk_mesh_lod_into(*key, pmc_geometry::SideMask::NONE, scratch, &mut m);
                bar.inc(1);
                m
            })
            .collect()
    });
    bar.finish_and_clear();
    meshes.retain(|m| !m.is_empty());
    meshes
}
