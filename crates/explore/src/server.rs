//! The explorer's HTTP server: one page, its script, the wasm module and `/set.json`,
//! on one thread (a local tool for one user; every answer is in memory).

use anyhow::{anyhow, Result};
use std::net::SocketAddr;
use tiny_http::{Header, Response, Server};

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

    /// Answers requests until the process ends: GET of the page's files, `/needle.wasm`
    /// and `/set.json`; 404 for any other path, 405 for other methods. A failed answer (the
    /// browser went away) is reported on stderr and the server goes on.
    pub fn serve(self) {
        for request in self.server.incoming_requests() {
            let path = request.url().split('?').next().unwrap_or("/").to_string();
            let (status, kind, body): (u16, &str, &[u8]) = if *request.method() != tiny_http::Method::Get {
                (405, "text/plain; charset=utf-8", b"only GET\n")
            } else if let Some((_, kind, bytes)) = PAGE.iter().find(|(p, _, _)| *p == path || (path == "/index.html" && *p == "/")) {
                (200, kind, bytes)
            } else if path == "/needle.wasm" {
                (200, "application/wasm", &self.content.wasm)
            } else if path == "/set.json" {
                (200, "application/json", self.content.set_json.as_bytes())
            } else {
                (404, "text/plain; charset=utf-8", b"not found\n")
            };
            let mut response = Response::from_data(body.to_vec()).with_status_code(status);
            for (name, value) in [("Content-Type", kind), ("Cache-Control", "no-store")] {
                if let Ok(h) = Header::from_bytes(name.as_bytes(), value.as_bytes()) {
                    response.add_header(h);
                }
            }
            if let Err(e) = request.respond(response) {
                eprintln!("needle explore: answering GET {path}: {e}");
            }
        }
    }
}
