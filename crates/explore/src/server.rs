//! The explorer's HTTP server: one page, its script, the wasm module and `/set.json`
//! (a local tool for one user; every answer is in memory).
//!
//! - Answers are written by a fixed pool of [`WORKERS`] threads, each answering one
//!   connection at a time (its answers go out in order): a client that sends requests and
//!   never reads the answers (its socket buffer full) holds one worker, never one thread
//!   per request (it was 2,984 threads and 575 MB for 3,000 pipelined requests, issue
//!   66); the other workers answer the other clients.
//! - One connection gets at most [`MAX_REQUESTS_PER_CONNECTION`] answers; later requests
//!   on it get 503 with `Connection: close`, asking the client for a new connection (a
//!   page needs six requests).
//! - Only requests whose `Host` is this server by address (`localhost`, an IP literal)
//!   and port are answered (else 421): a page of another site whose name the attacker
//!   points at 127.0.0.1 (DNS rebinding) sends its own name as `Host` and gets nothing.

use anyhow::{anyhow, Result};
use std::collections::{HashMap, HashSet, VecDeque};
use std::net::SocketAddr;
use std::sync::{Arc, Condvar, Mutex};
use tiny_http::{Header, Request, Response, Server};

/// Threads that write the answers.
pub const WORKERS: usize = 4;
/// Requests answered on one connection (a page load is six; a browser's keep-alive
/// reuse for a session stays far below).
pub const MAX_REQUESTS_PER_CONNECTION: usize = 200;
/// Connections remembered for [`MAX_REQUESTS_PER_CONNECTION`]; the count starts again when
/// more have been seen.
const CONNECTIONS_REMEMBERED: usize = 4096;

/// The page's files, embedded at compile time: (URL path, content type, bytes).
const PAGE: [(&str, &str, &[u8]); 4] = [
    ("/", "text/html; charset=utf-8", include_bytes!("page/index.html")),
    ("/explorer.css", "text/css; charset=utf-8", include_bytes!("page/explorer.css")),
    ("/explorer.js", "text/javascript; charset=utf-8", include_bytes!("page/explorer.js")),
    ("/needle-wasm.mjs", "text/javascript; charset=utf-8", include_bytes!("page/needle-wasm.mjs")),
];

/// What the server answers besides the page.
pub struct Content {
    /// The evaluator module (`/needle.wasm`).
    pub wasm: Vec<u8>,
    /// The set's data (`/set.json`, [`super::set_json::set_json`]).
    pub set_json: String,
    /// Tissue files and tissues drawn within their spread (`/stacks.json`,
    /// [`super::stacks_json::stacks_json`]; `[]` without `--stack`).
    pub stacks_json: String,
}

/// A bound, not yet serving, explorer server.
pub struct Explorer {
    server: Server,
    content: Content,
}

impl Explorer {
    /// Binds `addr` (port 0: a free port).
    ///
    /// # Errors
    /// The address cannot be bound (in use, no permission).
    pub fn bind(addr: SocketAddr, content: Content) -> Result<Self> {
        let server = Server::http(addr).map_err(|e| anyhow!("cannot listen on http://{addr}/: {e}"))?;
        Ok(Self { server, content })
    }

    /// The page's URL (with the port actually bound).
    #[must_use]
    pub fn url(&self) -> String {
        match self.server.server_addr().to_ip() {
            Some(a) => format!("http://{a}/"),
            None => "http://(not an IP socket)/".to_string(),
        }
    }

    /// Answers requests until the process ends: GET of the page's files, `/needle.wasm`,
    /// `/set.json` and `/stacks.json`; 404 for any other path, 405 for other methods, 421 for a `Host`
    /// that is not this server ([`host_is_local`]). A failed answer (the browser went
    /// away) is reported on stderr and the server goes on.
    pub fn serve(self) {
        let port = self.server.server_addr().to_ip().map_or(0, |a| a.port());
        let content = Arc::new(self.content);
        let shared = Arc::new((Mutex::new(Pending::default()), Condvar::new()));
        for _ in 0..WORKERS {
            let (content, shared) = (Arc::clone(&content), Arc::clone(&shared));
            std::thread::spawn(move || work(&shared, &content, port));
        }
        let mut seen: HashMap<SocketAddr, usize> = HashMap::new();
        let unknown: SocketAddr = ([0, 0, 0, 0], 0).into();
        for request in self.server.incoming_requests() {
            let connection = request.remote_addr().copied().unwrap_or(unknown);
            if seen.len() >= CONNECTIONS_REMEMBERED && !seen.contains_key(&connection) {
                seen.clear();
            }
            let n = seen.entry(connection).or_insert(0);
            *n += 1;
            let over_limit = *n > MAX_REQUESTS_PER_CONNECTION;
            let (lock, ready) = &*shared;
            let Ok(mut pending) = lock.lock() else { return };
            pending.queues.entry(connection).or_default().push_back((request, over_limit));
            ready.notify_one();
        }
    }
}

/// The requests waiting for a worker, per connection, and the connections a worker is
/// answering (one at a time each: a connection's answers go out in order anyway).
#[derive(Default)]
struct Pending {
    queues: HashMap<SocketAddr, VecDeque<(Request, bool)>>,
    busy: HashSet<SocketAddr>,
}

/// A worker: the next request of a connection no other worker is answering, until the
/// process ends.
fn work(shared: &(Mutex<Pending>, Condvar), content: &Content, port: u16) {
    let (lock, ready) = shared;
    loop {
        let (connection, request, over_limit) = {
            let Ok(mut pending) = lock.lock() else { return };
            loop {
                let p = &mut *pending;
                let next = p.queues.iter_mut().find(|(c, q)| !q.is_empty() && !p.busy.contains(*c));
                if let Some((c, q)) = next {
                    let c = *c;
                    if let Some((r, over)) = q.pop_front() {
                        p.busy.insert(c);
                        break (c, r, over);
                    }
                }
                pending = match ready.wait(pending) {
                    Ok(p) => p,
                    Err(_) => return,
                };
            }
        };
        answer(request, content, port, over_limit);
        let Ok(mut pending) = lock.lock() else { return };
        pending.busy.remove(&connection);
        if pending.queues.get(&connection).is_some_and(VecDeque::is_empty) {
            pending.queues.remove(&connection);
        }
        // another worker may take this connection's next request
        ready.notify_one();
    }
}

/// Whether a request's `Host` header names this server: `localhost`, or an IP literal
/// (IPv4, or IPv6 in brackets), with the server's `port` (or no port at all only when it
/// is 80). A name of any other site (DNS rebinding) is not.
#[must_use]
pub fn host_is_local(host: &str, port: u16) -> bool {
    let (name, p) = match host.rsplit_once(':') {
        Some((n, p)) if !p.contains(']') => (n, p.parse::<u16>().ok()),
        _ => (host, Some(80)),
    };
    let name_ok = name.eq_ignore_ascii_case("localhost")
        || name.parse::<std::net::Ipv4Addr>().is_ok()
        || name.strip_prefix('[').and_then(|n| n.strip_suffix(']')).is_some_and(|n| n.parse::<std::net::Ipv6Addr>().is_ok());
    name_ok && p == Some(port)
}

/// One request's answer (module rules); `over_limit`: its connection has had
/// [`MAX_REQUESTS_PER_CONNECTION`].
fn answer(request: Request, content: &Content, port: u16, over_limit: bool) {
    let path = request.url().split('?').next().unwrap_or("/").to_string();
    let host = request.headers().iter().find(|h| h.field.equiv("Host")).map(|h| h.value.as_str().to_string());
    let (status, kind, body): (u16, &str, &[u8]) = if over_limit {
        (503, "text/plain; charset=utf-8", b"too many requests on one connection: open a new one\n")
    } else if !host.as_deref().is_some_and(|h| host_is_local(h, port)) {
        (421, "text/plain; charset=utf-8", b"Host is not this server (localhost or its IP address with its port)\n")
    } else if *request.method() != tiny_http::Method::Get {
        (405, "text/plain; charset=utf-8", b"only GET\n")
    } else if let Some((_, kind, bytes)) = PAGE.iter().find(|(p, _, _)| *p == path || (path == "/index.html" && *p == "/")) {
        (200, kind, bytes)
    } else if path == "/needle.wasm" {
        (200, "application/wasm", &content.wasm)
    } else if path == "/set.json" {
        (200, "application/json", content.set_json.as_bytes())
    } else if path == "/stacks.json" {
        (200, "application/json", content.stacks_json.as_bytes())
    } else {
        (404, "text/plain; charset=utf-8", b"not found\n")
    };
    let mut response = Response::from_data(body.to_vec()).with_status_code(status);
    let connection = if over_limit { "close" } else { "keep-alive" };
    for (name, value) in [("Content-Type", kind), ("Cache-Control", "no-store"), ("Connection", connection)] {
        if let Ok(h) = Header::from_bytes(name.as_bytes(), value.as_bytes()) {
            response.add_header(h);
        }
    }
    if let Err(e) = request.respond(response) {
        needle_stdx::noteln!("needle explore: answering GET {path}: {e}");
    }
}
