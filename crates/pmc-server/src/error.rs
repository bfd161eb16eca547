//! Errors of starting and running the server.

use std::net::SocketAddr;

/// Why the server could not start or stopped. Every message says what to do about it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ServerError {
    /// The port is taken by another program.
    #[error("port {} is in use; pick another with --port", .addr.port())]
    PortInUse {
        /// The address that could not be bound.
        addr: SocketAddr,
    },
    /// The system refused the port (ports below 1024 need privileges).
    #[error("not allowed to listen on {addr}: ports below 1024 need privileges; pick another with --port")]
    PermissionDenied {
        /// The address that could not be bound.
        addr: SocketAddr,
    },
    /// The host is not an address of this machine.
    #[error("cannot listen on {addr}: the address is not one of this machine's; use --host 127.0.0.1 (this machine only) or 0.0.0.0 (every interface)")]
    AddressNotAvailable {
        /// The address that could not be bound.
        addr: SocketAddr,
    },
    /// Any other failure to listen.
    #[error("cannot listen on {addr}: {source}")]
    Bind {
        /// The address that could not be bound.
        addr: SocketAddr,
        /// The system's error.
        #[source]
        source: std::io::Error,
    },
    /// An invalid setting.
    #[error("invalid server setting: {0}")]
    Config(String),
    /// The worker threads could not start.
    #[error("cannot start {threads} worker threads: {reason}")]
    Threads {
        /// Requested thread count (0: every core).
        threads: usize,
        /// The system's reason.
        reason: String,
    },
    /// The world file could not be opened or created.
    #[error(transparent)]
    World(#[from] pmc_world::WorldError),
    /// The imagery file could not be read (missing, damaged, not a `.pmcimg` file).
    #[error(transparent)]
    Imagery(#[from] pmc_imagery::ImageryError),
    /// The elevation model's file could not be read for its relief.
    #[error(transparent)]
    Dem(#[from] pmc_dem::DemError),
    /// Serving failed after start.
    #[error("the server stopped: {0}")]
    Io(#[from] std::io::Error),
}

impl ServerError {
    /// The error of binding `addr` that failed with `e`.
    pub(crate) fn bind(addr: SocketAddr, e: std::io::Error) -> ServerError {
        match e.kind() {
            std::io::ErrorKind::AddrInUse => ServerError::PortInUse { addr },
            std::io::ErrorKind::PermissionDenied => ServerError::PermissionDenied { addr },
            std::io::ErrorKind::AddrNotAvailable => ServerError::AddressNotAvailable { addr },
            _ => ServerError::Bind { addr, source: e },
        }
    }
}
