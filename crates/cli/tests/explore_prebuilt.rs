//! Issue 66 (explore): `needle explore --help` says what it builds and where, and
//! `--wasm FILE` serves a prebuilt evaluator without cargo (a user with only the binary
//! and a set can run it); a file that is not a wasm module is refused.
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::Duration;

mod common;
use common::{help, needle, shipped_set_arg, show, NEEDLE};

#[test]
fn issue66_explore_help_says_what_it_builds_and_where() {
    let text = help(&["explore", "--help"]);
    for want in ["cargo build --release -p needle-wasm", "NEEDLE_COEFFS=<set>", "source tree", "--wasm FILE"] {
        assert!(text.contains(want), "help lacks {want:?}:\n{text}");
    }
}

#[test]
fn issue66_explore_refuses_a_wasm_file_that_is_not_a_module() {
    let d = tempfile::tempdir().expect("tempdir");
    let fake = d.path().join("x.wasm");
    std::fs::write(&fake, "not wasm").expect("write");
    let o = needle(&["explore", "--set", &shipped_set_arg(), "--port", "0", "--wasm", fake.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(2), "{}", show(&o));
    assert!(String::from_utf8_lossy(&o.stderr).contains("not a WebAssembly module"), "{}", show(&o));
}

#[test]
fn issue66_explore_serves_a_prebuilt_wasm_without_cargo() {
    let d = tempfile::tempdir().expect("tempdir");
    let module = d.path().join("needle_wasm.wasm");
    let bytes = b"\0asm\x01\0\0\0prebuilt".to_vec();
    std::fs::write(&module, &bytes).expect("write");
    // no cargo on PATH: nothing may be built
    let mut child = Command::new(NEEDLE)
        .args(["explore", "--set", &shipped_set_arg(), "--port", "0", "--wasm", module.to_str().expect("utf-8")])
        .env("PATH", "/nonexistent")
        .env("CARGO", "/nonexistent/cargo")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let stdout = child.stdout.take().expect("stdout");
    let url = BufReader::new(stdout)
        .lines()
        .map_while(Result::ok)
        .find_map(|l| l.strip_prefix("open http://").map(|r| r.split('/').next().unwrap_or_default().to_string()));
    let Some(addr) = url else {
        let _ = child.kill();
        let o = child.wait_with_output().expect("wait");
        panic!("no URL printed: {}", show(&o));
    };
    let mut s = TcpStream::connect(&addr).expect("connect");
    s.set_read_timeout(Some(Duration::from_secs(10))).expect("timeout");
    write!(s, "GET /needle.wasm HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n").expect("send");
    let mut answer = Vec::new();
    let _ = s.read_to_end(&mut answer);
    let _ = child.kill();
    let _ = child.wait();
    assert!(answer.starts_with(b"HTTP/1.1 200"), "{}", String::from_utf8_lossy(&answer));
    assert!(answer.ends_with(&bytes), "the prebuilt module is served");
}
