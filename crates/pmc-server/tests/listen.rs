//! The server on a real socket (127.0.0.1 only): serving, shutdown, and a taken port.

use crate::common::small_config;
use pmc_server::{Server, ServerConfig, ServerError};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::Duration;

/// One HTTP/1.1 GET with `Connection: close`; returns the status line and the body.
fn http_get(addr: SocketAddr, path: &str) -> (String, Vec<u8>) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n").unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let split = raw.windows(4).position(|w| w == b"\r\n\r\n").expect("a header block");
    let head = String::from_utf8_lossy(&raw[..split]).into_owned();
    let status = head.lines().next().unwrap_or_default().to_string();
    (status, raw[split + 4..].to_vec())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn serves_on_a_socket_and_stops_on_request() {
    let server = Server::bind(small_config()).await.unwrap();
    let addr = server.local_addr();
    assert!(addr.ip().is_loopback() && addr.port() != 0);
    assert_eq!(server.url(), format!("http://127.0.0.1:{}/", addr.port()));
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let run = tokio::spawn(server.run(async {
        let _ = stopped.await;
    }));
    let (status, body) = tokio::task::spawn_blocking(move || http_get(addr, "/api/v1/health"))
        .await
        .unwrap();
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert!(String::from_utf8_lossy(&body).contains("\"ok\":true"));
    let (status, body) = tokio::task::spawn_blocking(move || http_get(addr, "/api/v1/chunk/north/0/1/1/1"))
        .await
        .unwrap();
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert!(pmc_formats::chunk_encoding::decode_chunk(&body).is_ok());
    stop.send(()).unwrap();
    tokio::time::timeout(Duration::from_secs(10), run)
        .await
        .expect("the server stops")
        .unwrap()
        .unwrap();
}

#[tokio::test]
async fn a_taken_port_is_a_clear_error() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port();
    let err = Server::bind(ServerConfig { port, ..small_config() }).await.unwrap_err();
    assert!(matches!(err, ServerError::PortInUse { .. }), "{err:?}");
    assert_eq!(
        err.to_string(),
        format!("port {port} is in use; pick another with --port")
    );
}

#[tokio::test]
async fn invalid_limits_are_refused() {
    let err = Server::bind(ServerConfig {
        queue_limit: 0,
        ..small_config()
    })
    .await
    .unwrap_err();
    assert!(err.to_string().contains("queue_limit"), "{err}");
    let err = Server::bind(ServerConfig {
        max_planets: 0,
        ..small_config()
    })
    .await
    .unwrap_err();
    assert!(err.to_string().contains("max_planets"), "{err}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_watching_browser_does_not_keep_the_server_from_stopping() {
    let d = std::env::temp_dir().join(format!("pmc-server-listen-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let config = ServerConfig {
        world: Some(d.join("w.pmcw")),
        ..small_config()
    };
    let server = Server::bind(config).await.unwrap();
    let addr = server.local_addr();
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let run = tokio::spawn(server.run(async {
        let _ = stopped.await;
    }));
    // A client subscribed to the event stream, which never hangs up by itself.
    let watcher = tokio::task::spawn_blocking(move || {
        let mut s = TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
        write!(s, "GET /api/v1/events HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
        let mut raw = Vec::new();
        let mut buf = [0u8; 4096];
        // Read until the hello event, then until the server closes the stream.
        loop {
            match s.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => raw.extend_from_slice(&buf[..n]),
                Err(e) => panic!("the stream was not closed: {e}"),
            }
        }
        String::from_utf8_lossy(&raw).into_owned()
    });
    tokio::time::sleep(Duration::from_millis(300)).await;
    stop.send(()).unwrap();
    tokio::time::timeout(Duration::from_secs(10), run)
        .await
        .expect("the server stops although a client watches the events")
        .unwrap()
        .unwrap();
    let seen = watcher.await.unwrap();
    assert!(seen.contains("event: hello"), "{seen}");
}
