//! What the server serves and how much it may hold.

use crate::ServerError;
use pmc_geometry::Layout;
use pmc_planet::PresetKind;
use std::net::{IpAddr, Ipv4Addr};

/// The server's settings. [`ServerConfig::default`] serves the default planet (earthlike, seed 7,
/// the default layout) on `127.0.0.1:8080`.
#[derive(Clone, Debug, PartialEq)]
pub struct ServerConfig {
    /// Address to listen on.
    pub host: IpAddr,
    /// Port to listen on; 0 picks a free one (see [`Server::local_addr`](crate::Server::local_addr)).
    pub port: u16,
    /// The preset of the planet served when a request names none.
    pub preset: PresetKind,
    /// The seed of the planet served when a request names none.
    pub seed: u64,
    /// The layout of every planet served (fixed for the server's life).
    pub layout: Layout,
    /// Most bytes of encoded chunks kept in the cache (default 512 MiB).
    pub cache_bytes: u64,
    /// Most planets (preset and seed pairs) kept at once, with their cached chunks (default 4).
    pub max_planets: usize,
    /// Most chunk jobs waiting for a worker; a request that would add one more is answered 503
    /// (default 256).
    pub queue_limit: usize,
    /// Worker threads that generate chunks; 0 uses every core.
    pub threads: usize,
}

impl Default for ServerConfig {
    fn default() -> Self {
        ServerConfig {
            host: IpAddr::V4(Ipv4Addr::LOCALHOST),
            port: 8080,
            preset: PresetKind::Earthlike,
            seed: 7,
            layout: Layout::default(),
            cache_bytes: 512 << 20,
            max_planets: 4,
            queue_limit: 256,
            threads: 0,
        }
    }
}

impl ServerConfig {
    /// Checks the limits.
    pub fn validate(&self) -> Result<(), ServerError> {
        if self.max_planets == 0 {
            return Err(ServerError::Config("max_planets must be at least 1".into()));
        }
        if self.queue_limit == 0 {
            return Err(ServerError::Config(
                "queue_limit must be at least 1 (jobs waiting for a worker)".into(),
            ));
        }
        Ok(())
    }
}
