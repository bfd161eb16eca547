//! The router, listening, and shutdown.

use crate::{
    api, assets, batch_api, cesium, edit_api, imagery_api, nav_api, relief_api, tiles_api, AppState, ServerConfig,
    ServerError,
};
use axum::extract::Request;
use axum::http::{header, HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{any, get, post};
use axum::Router;
use std::future::Future;
use std::net::SocketAddr;
use std::time::{Duration, Instant};
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::compression::predicate::{DefaultPredicate, NotForContentType, Predicate};
use tower_http::compression::CompressionLayer;

/// Logs one line per request at debug level.
async fn log_request(req: Request, next: Next) -> Response {
    let (method, path) = (req.method().clone(), req.uri().path().to_owned());
    let start = Instant::now();
    let res = next.run(req).await;
    tracing::debug!(
        target: "pmc_server::request",
        "{method} {path} {} {:.1} ms",
        res.status().as_u16(),
        start.elapsed().as_secs_f64() * 1e3
    );
    res
}

/// The answer when a handler panicked (it never should).
fn panic_response(_: Box<dyn std::any::Any + Send + 'static>) -> Response {
    tracing::error!("a request handler panicked; this is a bug in pmc");
    let mut r = (
        StatusCode::INTERNAL_SERVER_ERROR,
        axum::Json(serde_json::json!({ "error": "internal error (a bug in pmc); see the server log" })),
    )
        .into_response();
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    r
}

/// The HTTP routes of `docs/specs/http-api-v1.md` plus the embedded viewer, with gzip
/// compression, request logging and a guard that turns a panic into a 500.
pub fn router(state: AppState) -> Router {
    Router::new()
        .route("/api/v1/health", get(api::health))
        .route("/api/v1/planet", get(api::planet))
        .route("/api/v1/chunks", get(api::chunks))
        .route("/api/v1/chunk/{face}/{level}/{i}/{j}/{k}", get(api::chunk))
        .route("/api/v1/chunk-batch", post(batch_api::chunk_batch))
        .route("/api/v1/stats", get(api::stats))
        .route(imagery_api::IMAGERY_PATH, get(imagery_api::imagery))
        .route(relief_api::RELIEF_PATH, get(relief_api::relief))
        .route("/api/v1/edits", get(edit_api::list).post(edit_api::post_edit))
        .route("/api/v1/edits/undo", post(edit_api::undo))
        .route("/api/v1/edits/redo", post(edit_api::redo))
        .route("/api/v1/events", get(edit_api::events))
        .route("/api/v1/path", get(nav_api::path))
        .route("/api/v1/navgrid", get(nav_api::navgrid))
        .route("/tiles/tileset.json", get(tiles_api::tileset_json))
        .route("/cesium", get(cesium::redirect))
        .route("/cesium/", get(cesium::page))
        .route("/cesium/Cesium/{*path}", get(cesium::file))
        .route(
            "/tiles/{rev}/{kind}/{face}/{level}/{x}/{y}/{file}",
            get(tiles_api::tile_file),
        )
        .route("/tiles/{frame}/tileset.json", get(tiles_api::tileset_json_framed))
        .route(
            "/tiles/{frame}/{rev}/{kind}/{face}/{level}/{x}/{y}/{file}",
            get(tiles_api::tile_file_framed),
        )
        .route("/api", any(api::not_found))
        .route("/api/", any(api::not_found))
        .route("/api/{*rest}", any(api::not_found))
        .method_not_allowed_fallback(api::method_not_allowed)
        .fallback(assets::static_file)
        .with_state(state)
        .layer(middleware::from_fn(log_request))
        .layer(CatchPanicLayer::custom(panic_response))
        // (not the chunk batches' streams: the encoder holds what it has compressed until its
        // buffer fills, and a batch's records must leave as each chunk is ready)
        .layer(
            CompressionLayer::new().compress_when(
                DefaultPredicate::new().and(NotForContentType::const_new(batch_api::BATCH_CONTENT_TYPE)),
            ),
        )
}

/// A server bound to its address, not yet answering.
#[derive(Debug)]
pub struct Server {
    listener: tokio::net::TcpListener,
    addr: SocketAddr,
    state: AppState,
}

impl Server {
    /// Checks `config`, starts the workers and binds `host:port` (port 0 picks a free one).
    pub async fn bind(config: ServerConfig) -> Result<Server, ServerError> {
        let addr = SocketAddr::new(config.host, config.port);
        let state = AppState::new(config)?;
        let listener = tokio::net::TcpListener::bind(addr)
            .await
            .map_err(|e| ServerError::bind(addr, e))?;
        let addr = listener.local_addr().map_err(|e| ServerError::bind(addr, e))?;
        Ok(Server { listener, addr, state })
    }

    /// The bound address (with the real port when 0 was asked for).
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// The viewer's URL, `http://HOST:PORT/`.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// The shared state.
    pub fn state(&self) -> &AppState {
        &self.state
    }

    /// Answers requests until `shutdown` completes, then lets open requests finish.
    pub async fn run(self, shutdown: impl Future<Output = ()> + Send + 'static) -> Result<(), ServerError> {
        let c = self.state.config();
        tracing::info!(
            "PMC server listening on {}: terrain {}, layout n_c={} n_t={} d_b={} l_d={} d_c={}{}",
            self.url(),
            c.terrain,
            c.layout.n_c(),
            c.layout.n_t(),
            c.layout.d_b(),
            c.layout.l_d(),
            c.layout.d_c(),
            if assets::viewer_is_built() {
                ""
            } else {
                " (viewer not built: / shows how to build it)"
            }
        );
        if let Some(e) = self.state.editing() {
            tracing::info!("editing world {}", e.path().display());
            tokio::spawn(watch_world(self.state.clone()));
        }
        let state = self.state.clone();
        let shutdown = async move {
            shutdown.await;
            // Event streams never end by themselves: end them, or the graceful shutdown would
            // wait for every watching browser to close.
            state.begin_shutdown();
        };
        let app = router(self.state).into_make_service_with_connect_info::<SocketAddr>();
        axum::serve(self.listener, app).with_graceful_shutdown(shutdown).await?;
        tracing::info!("PMC server stopped");
        Ok(())
    }
}

/// How often the world file is checked for edits made by other programs.
const WORLD_CHECK: Duration = Duration::from_secs(1);

/// Takes edits that other programs (`pmc edit`) make to the world file, once a second.
async fn watch_world(state: AppState) {
    let mut tick = tokio::time::interval(WORLD_CHECK);
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let mut failing = false;
    loop {
        tick.tick().await;
        match state.sync_world().await {
            Ok(_) => failing = false,
            Err(e) if !failing => {
                failing = true;
                tracing::warn!("cannot check the world file for changes by other programs: {e}");
            }
            Err(_) => {}
        }
    }
}

/// Binds per `config` and serves until `shutdown` completes.
pub async fn serve(
    config: ServerConfig,
    shutdown: impl Future<Output = ()> + Send + 'static,
) -> Result<(), ServerError> {
    Server::bind(config).await?.run(shutdown).await
}

/// Completes on Ctrl-C (SIGINT) or, on Unix, SIGTERM.
pub async fn shutdown_signal() {
    let ctrl_c = async {
        if tokio::signal::ctrl_c().await.is_err() {
            std::future::pending::<()>().await;
        }
    };
    #[cfg(unix)]
    let term = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut s) => {
                s.recv().await;
            }
            Err(_) => std::future::pending::<()>().await,
        }
    };
    #[cfg(not(unix))]
    let term = std::future::pending::<()>();
    tokio::select! {
        () = ctrl_c => {},
        () = term => {},
    }
}
