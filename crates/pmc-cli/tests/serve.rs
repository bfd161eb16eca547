//! `pmc serve` as a user runs it: the URL line, a few requests, clean stops, clear errors.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

const SMALL: [&str; 8] = ["--n-c", "2", "--n-t", "8", "--d-b", "200", "--l-d", "2"];

fn pmc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pmc"))
        .args(args)
        .output()
        .expect("pmc runs")
}

/// Kills the child when dropped, so a failing test leaves no server behind.
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts `pmc serve --port 0` on a small planet and returns it with the address of its URL line.
fn start(extra: &[&str]) -> (Running, SocketAddr) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_pmc"))
        .args(["serve", "--port", "0", "--threads", "2"])
        .args(SMALL)
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("pmc starts");
    let stdout = child.stdout.take().unwrap();
    let running = Running(child);
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut line = String::new();
        let _ = BufReader::new(stdout).read_line(&mut line);
        let _ = tx.send(line);
    });
    let line = rx
        .recv_timeout(Duration::from_secs(60))
        .expect("the URL line within a minute");
    let url = line
        .trim()
        .strip_prefix("PMC viewer: http://")
        .unwrap_or_else(|| panic!("unexpected first line: {line:?}"));
    let hostport = url.strip_suffix('/').expect("URL ends in /");
    let addr = hostport.to_socket_addrs().unwrap().next().unwrap();
    assert_ne!(addr.port(), 0, "the URL shows the bound port");
    (running, addr)
}

/// Sends one HTTP/1.1 request (with `Connection: close`) and reads the status code and body
/// (servers answer these without chunked encoding or compression).
fn http_exchange(addr: SocketAddr, request: &str) -> (u16, Vec<u8>) {
    let mut s = TcpStream::connect_timeout(&addr, Duration::from_secs(10)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    s.write_all(request.as_bytes()).unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let split = raw.windows(4).position(|w| w == b"\r\n\r\n").expect("a header block");
    let head = String::from_utf8_lossy(&raw[..split]).into_owned();
    assert!(
        !head.to_ascii_lowercase().contains("transfer-encoding: chunked"),
        "{head}"
    );
    let code = head
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .expect("a status code");
    (code, raw[split + 4..].to_vec())
}

/// One GET.
fn http_get(addr: SocketAddr, path: &str) -> (u16, Vec<u8>) {
    http_exchange(
        addr,
        &format!("GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"),
    )
}

#[test]
fn serve_answers_and_stops_cleanly() {
    let (mut running, addr) = start(&["--preset", "moon", "--seed", "5"]);
    assert!(addr.ip().is_loopback());
    let (code, body) = http_get(addr, "/api/v1/health");
    assert_eq!(code, 200);
    let v: serde_json::Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(v["ok"], true);
    let (code, body) = http_get(addr, "/api/v1/planet");
    assert_eq!(code, 200);
    let v: serde_json::Value = serde_json::from_slice(&body).unwrap();
    assert_eq!((v["preset"].as_str(), v["seed"].as_str()), (Some("moon"), Some("5")));
    assert_eq!(v["layout"]["n_c"], 2);
    let (code, body) = http_get(addr, "/api/v1/chunk/south/0/1/0/1");
    assert_eq!(code, 200);
    let chunk = pmc_formats::chunk_encoding::decode_chunk(&body).unwrap();
    assert!(chunk.triangle_count() > 0);
    let (code, body) = http_get(addr, "/api/v1/chunk/south/0/2/0/1");
    assert_eq!(code, 404);
    assert!(String::from_utf8_lossy(&body).contains("\"error\""));
    let (code, body) = http_get(addr, "/");
    assert_eq!(code, 200);
    assert!(String::from_utf8_lossy(&body).to_lowercase().contains("<html"));

    // SIGTERM stops it cleanly (exit status 0).
    #[cfg(unix)]
    {
        let pid = running.0.id().to_string();
        assert!(Command::new("kill").args(["-TERM", &pid]).status().unwrap().success());
        let start = Instant::now();
        loop {
            if let Some(status) = running.0.try_wait().unwrap() {
                assert!(status.success(), "{status}");
                break;
            }
            assert!(
                start.elapsed() < Duration::from_secs(20),
                "pmc serve did not stop on SIGTERM"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

#[test]
fn help_lists_the_server_options() {
    let o = pmc(&["serve", "--help"]);
    assert!(o.status.success());
    let s = String::from_utf8_lossy(&o.stdout);
    for opt in [
        "--host",
        "--port",
        "--threads",
        "--cache-mb",
        "--preset",
        "--seed",
        "--n-c",
        "--n-t",
        "--d-c",
        "--world",
        "--max-brush-radius",
        "--edit-rate",
        "--edit-burst",
    ] {
        assert!(s.contains(opt), "serve --help lacks {opt}");
    }
}

#[test]
fn bad_ports_and_hosts_are_refused_clearly() {
    let o = pmc(&["serve", "--port", "99999"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("99999") && e.contains("--port"), "{e}");
    let o = pmc(&["serve", "--host", "not-an-ip", "--port", "0"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("--host 'not-an-ip' is not an IP address"), "{e}");
    let o = pmc(&["serve", "--n-t", "0", "--port", "0"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("n_t"));
}

#[test]
fn a_port_in_use_is_refused_clearly() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let mut args = vec!["serve", "--port", &port];
    args.extend(SMALL);
    let o = pmc(&args);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains(&format!("error: port {port} is in use; pick another with --port")),
        "{e}"
    );
    assert!(o.stdout.is_empty(), "no URL line when it cannot listen");
    assert!(!e.contains("panicked"));
}

/// A fresh directory for one test.
fn dir(test: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("pmc-cli-serve-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// One POST of a JSON body.
fn http_post(addr: SocketAddr, path: &str, json: &str) -> (u16, Vec<u8>) {
    http_exchange(
        addr,
        &format!(
            "POST {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{json}",
            json.len()
        ),
    )
}

fn json_of(body: &[u8]) -> serde_json::Value {
    serde_json::from_slice(body).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(body)))
}

#[test]
fn serve_world_creates_edits_durably_and_follows_pmc_edit() {
    let d = dir("world");
    let world = d.join("w.pmcw");
    let w = world.to_str().unwrap();
    let (mut running, addr) = start(&["--world", w, "--preset", "moon", "--seed", "9"]);
    assert!(world.exists(), "the world was created");
    let planet = json_of(&http_get(addr, "/api/v1/planet").1);
    assert_eq!(
        (planet["preset"].as_str(), planet["seed"].as_str()),
        (Some("moon"), Some("9"))
    );
    assert_eq!(planet["edit"]["enabled"], true);
    // The radius the brush was made for: the surface is between d_b and the radius.
    let r = planet["surface_bounds"][1].as_f64().unwrap();
    let body = format!(r#"{{"brush":"remove","x":0,"y":{r},"z":0,"radius":6}}"#);
    let (code, answer) = http_post(addr, "/api/v1/edits", &body);
    assert_eq!(code, 200, "{}", String::from_utf8_lossy(&answer));
    assert_eq!(json_of(&answer)["id"], 1);
    let (code, answer) = http_post(
        addr,
        "/api/v1/edits",
        r#"{"brush":"remove","x":0,"y":0,"z":0,"radius":1e9}"#,
    );
    assert_eq!(code, 400);
    assert!(String::from_utf8_lossy(&answer).contains("radius must be from 0.5 to 64"));

    // Killed without warning: the acknowledged edit is in the file.
    running.0.kill().unwrap();
    running.0.wait().unwrap();
    let o = pmc(&["edit", "--world", w, "--list", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let list = json_of(&o.stdout);
    assert_eq!(list["edits"].as_array().map(Vec::len), Some(1), "{list}");

    // Restarted without planet options: the world's planet; with other ones: refused.
    let (_running, addr) = start(&["--world", w]);
    let planet = json_of(&http_get(addr, "/api/v1/planet").1);
    assert_eq!(
        (planet["preset"].as_str(), planet["edit"]["active"].as_u64()),
        (Some("moon"), Some(1))
    );
    // An edit made by `pmc edit` while the server runs reaches the server within seconds.
    let o = pmc(&["edit", "--world", w, "add", "--at", "10,20", "--radius", "5"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let start_wait = Instant::now();
    loop {
        let list = json_of(&http_get(addr, "/api/v1/edits").1);
        if list["active"] == 2 {
            assert_eq!(list["edits"][1]["brush"], "add");
            break;
        }
        assert!(
            start_wait.elapsed() < Duration::from_secs(20),
            "the server did not see pmc edit's edit: {list}"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    let mut args = vec!["serve", "--port", "0", "--world", w, "--preset", "earthlike"];
    args.extend(SMALL);
    let o = pmc(&args);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("already holds another planet: --preset earthlike (the world has moon)"),
        "{e}"
    );
}

#[test]
fn bad_world_files_and_limits_are_refused_clearly() {
    let d = dir("bad-world");
    let notes = d.join("notes.txt");
    std::fs::write(&notes, "shopping list\n").unwrap();
    let o = pmc(&["serve", "--port", "0", "--world", notes.to_str().unwrap()]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("not a PMC world"), "{e}");
    assert_eq!(std::fs::read(&notes).unwrap(), b"shopping list\n", "left untouched");
    let w = d.join("w.pmcw");
    for (opt, value, needle) in [
        ("--max-brush-radius", "0", "brush radius"),
        ("--max-brush-radius", "1e9", "largest brush radius"),
        ("--edit-rate", "0", "edit rate"),
        ("--edit-burst", "0", "burst"),
    ] {
        let o = pmc(&["serve", "--port", "0", "--world", w.to_str().unwrap(), opt, value]);
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{opt} {value}: {e}");
        assert!(e.contains(needle), "{opt} {value}: {e}");
    }
}
