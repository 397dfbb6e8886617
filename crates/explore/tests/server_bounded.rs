//! Issue 66 item 15: the explorer's server under a client that pipelines thousands of
//! requests on one connection and never reads: the threads stay bounded (a fixed worker
//! pool; it was one thread per request, 2,984 threads and 575 MB); and one connection
//! gets at most `MAX_REQUESTS_PER_CONNECTION` answers, then 503 and the connection closed.
//! One file, one process: the thread count is this process's.
use needle_explore::server::{Content, Explorer, MAX_REQUESTS_PER_CONNECTION, WORKERS};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::Duration;

fn start() -> SocketAddr {
    let e = Explorer::bind(
        "127.0.0.1:0".parse().expect("addr"),
        Content { wasm: vec![7; 1 << 20], set_json: "{}".into(), stacks_json: "[]".into() },
    )
    .expect("bind");
    let addr: SocketAddr = e.url().trim_start_matches("http://").trim_end_matches('/').parse().expect("url");
    std::thread::spawn(move || e.serve());
    addr
}

fn threads() -> usize {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    status.lines().find_map(|l| l.strip_prefix("Threads:")).and_then(|n| n.trim().parse().ok()).expect("Threads:")
}

#[cfg(target_os = "linux")]
#[test]
fn issue66_15_thousands_of_pipelined_unread_requests_keep_the_threads_bounded() {
    let addr = start();
    let host = format!("127.0.0.1:{}", addr.port());
    std::thread::sleep(Duration::from_millis(200));
    let before = threads();
    let mut greedy = TcpStream::connect(addr).expect("connect");
    let mut burst = String::new();
    for _ in 0..3000 {
        burst.push_str(&format!("GET /needle.wasm HTTP/1.1\r\nHost: {host}\r\n\r\n"));
    }
    greedy.write_all(burst.as_bytes()).expect("send");
    std::thread::sleep(Duration::from_secs(2));
    let during = threads();
    println!("threads: {before} before, {during} with 3,000 unread requests");
    assert!(during <= before + WORKERS + 4, "threads grew from {before} to {during}");
    drop(greedy);
}

#[test]
fn issue66_15_one_connection_gets_at_most_its_request_limit() {
    let addr = start();
    let host = format!("127.0.0.1:{}", addr.port());
    let mut s = TcpStream::connect(addr).expect("connect");
    s.set_read_timeout(Some(Duration::from_secs(3))).expect("timeout");
    let mut burst = String::new();
    for _ in 0..MAX_REQUESTS_PER_CONNECTION + 20 {
        burst.push_str(&format!("GET /missing HTTP/1.1\r\nHost: {host}\r\n\r\n"));
    }
    s.write_all(burst.as_bytes()).expect("send");
    let mut text = String::new();
    let _ = s.read_to_string(&mut text);
    let answered = text.matches("HTTP/1.1 404").count();
    let refused = text.matches("HTTP/1.1 503").count();
    assert_eq!(answered, MAX_REQUESTS_PER_CONNECTION, "{refused} refused");
    assert!(refused >= 1 && text.contains("too many requests on one connection"), "{refused} refused");
}
