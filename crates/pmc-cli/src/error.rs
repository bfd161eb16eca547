//! Errors the command reports to the user.

use std::path::PathBuf;

/// A failure of a `pmc` command. Printed as `error: <message>`; the process exits with code 2
/// for invalid input and 1 for failures while working.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// Invalid layout parameters.
    #[error("invalid planet layout: {0}")]
    Layout(#[from] pmc_geometry::LayoutError),
    /// A `--radius` no layout can be chosen for.
    #[error("invalid --radius: {0}")]
    Radius(#[from] pmc_density::presets::RadiusError),
    /// The planet is too large to mesh whole in memory.
    #[error(
        "the planet is too large to mesh whole: {face_tiles} tiles per face side and {chunks} chunks (at most {} and {}); export a region of it instead (pmc generate --region LAT,LON,RADIUS_M [--level L | --max-error M]), fly over it with pmc serve, or lower n_c, n_t or d_c",
        crate::work::MAX_WHOLE_PLANET_FACE_TILES,
        crate::work::MAX_WHOLE_PLANET_CHUNKS
    )]
    TooLarge {
        /// `n_c n_t`.
        face_tiles: i64,
        /// Eq. (2).
        chunks: u64,
    },
    /// The output path cannot be written.
    #[error("cannot write {path}: {reason}")]
    Output {
        /// The output path.
        path: PathBuf,
        /// What is wrong and how to fix it.
        reason: String,
    },
    /// Export failed.
    #[error(transparent)]
    Export(#[from] pmc_formats::ExportError),
    /// Rendering failed (bad camera or options, or the PNG could not be written).
    #[error(transparent)]
    Render(#[from] pmc_render::RenderError),
    /// `--host` is neither an IP address nor "localhost".
    #[error("--host '{0}' is not an IP address; use 127.0.0.1 (this machine only), 0.0.0.0 (every interface), ::1 or localhost")]
    Host(String),
    /// The server could not start (port in use, address not available, ...) or failed.
    #[error(transparent)]
    Serve(#[from] pmc_server::ServerError),
    /// The world file of `pmc edit` could not be used.
    #[error(transparent)]
    World(#[from] pmc_world::WorldError),
    /// A brush operation was refused (centre, radius or strength).
    #[error("{0}")]
    Brush(#[from] pmc_edit::BrushError),
    /// An elevation model could not be imported, opened or used (the message names the file and
    /// the problem).
    #[error("{0}")]
    Dem(String),
    /// Imagery could not be imported, read or written (the message names the file and the
    /// problem).
    #[error(transparent)]
    Imagery(#[from] pmc_imagery::ImageryError),
    /// Invalid `pmc edit` options, or planet options that disagree with the world file.
    #[error("{0}")]
    Edit(String),
    /// An invalid `--region` (or its level or error), or a region too large.
    #[error("invalid --region: {0}")]
    Region(String),
    /// 3D Tiles could not be made (bad options, a folder holding something else, a write that
    /// failed).
    #[error(transparent)]
    Tiles(#[from] pmc_tiles::TilesError),
    /// The thread pool could not start.
    #[error("cannot start {threads} worker threads: {reason}")]
    Threads {
        /// Requested thread count.
        threads: usize,
        /// The system's reason.
        reason: String,
    },
}

impl CliError {
    /// The process exit code for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Layout(_)
            | CliError::Radius(_)
            | CliError::Output { .. }
            | CliError::TooLarge { .. }
            | CliError::Region(_)
            | CliError::Host(_) => 2,
            CliError::Serve(pmc_server::ServerError::Config(_)) => 2,
            CliError::Serve(pmc_server::ServerError::Imagery(e)) if e.is_input_error() => 2,
            CliError::Serve(_) => 1,
            CliError::Render(pmc_render::RenderError::Io { .. } | pmc_render::RenderError::Png { .. }) => 1,
            CliError::Render(_) => 2,
            CliError::Export(_) | CliError::Threads { .. } => 1,
            CliError::World(pmc_world::WorldError::Io { .. } | pmc_world::WorldError::Sqlite { .. }) => 1,
            CliError::World(_) | CliError::Brush(_) | CliError::Edit(_) | CliError::Dem(_) => 2,
            CliError::Imagery(e) if e.is_input_error() => 2,
            CliError::Imagery(_) => 1,
            CliError::Tiles(pmc_tiles::TilesError::Io { .. } | pmc_tiles::TilesError::Content { .. }) => 1,
            CliError::Tiles(_) => 2,
        }
    }
}
