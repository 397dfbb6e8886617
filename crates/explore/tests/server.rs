//! The explorer's server against the bad clients of issue 38: a `Host` of another site
//! (DNS rebinding) gets nothing, a client that pipelines requests and never reads does
//! not stall another client, and `/set.json` leaves out a CSV the manifest does not
//! vouch for.
use needle_explore::server::{host_is_local, Content, Explorer};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::Duration;

fn start(wasm: Vec<u8>) -> SocketAddr {
    let e = Explorer::bind("127.0.0.1:0".parse().expect("addr"), Content { wasm, set_json: "{}".into(), stacks_json: "[]".into() })
        .expect("bind");
    let addr: SocketAddr = e.url().trim_start_matches("http://").trim_end_matches('/').parse().expect("url");
    std::thread::spawn(move || e.serve());
    addr
}

/// One GET on a fresh connection with `host` as its Host header: the status line.
fn get(addr: SocketAddr, path: &str, host: &str) -> String {
    let mut s = TcpStream::connect(addr).expect("connect");
    s.set_read_timeout(Some(Duration::from_secs(10))).expect("timeout");
    write!(s, "GET {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n").expect("send");
    let mut text = String::new();
    let _ = s.read_to_string(&mut text);
    text.lines().next().unwrap_or_default().to_string()
}

#[test]
fn only_this_servers_host_is_answered() {
    let addr = start(vec![0; 16]);
    let port = addr.port();
    assert!(get(addr, "/set.json", &format!("127.0.0.1:{port}")).contains(" 200"));
    assert!(get(addr, "/set.json", &format!("localhost:{port}")).contains(" 200"));
    for host in ["evil.example", &format!("evil.example:{port}"), &format!("127.0.0.1:{}", port.wrapping_add(1))] {
        let status = get(addr, "/set.json", host);
        assert!(status.contains(" 421"), "Host {host}: {status}");
    }
    assert!(host_is_local(&format!("[::1]:{port}"), port) && !host_is_local("[::1]", port) && host_is_local("localhost", 80));
}

#[test]
fn a_client_that_never_reads_does_not_stall_another() {
    // 4 MiB answers, 64 of them pipelined: far more than the socket buffers hold
    let addr = start(vec![7; 4 << 20]);
    let host = format!("127.0.0.1:{}", addr.port());
    let mut greedy = TcpStream::connect(addr).expect("connect");
    for _ in 0..64 {
        write!(greedy, "GET /needle.wasm HTTP/1.1\r\nHost: {host}\r\n\r\n").expect("send");
    }
    std::thread::sleep(Duration::from_millis(500));
    let t = std::time::Instant::now();
    let status = get(addr, "/", &host);
    assert!(status.contains(" 200"), "the second client got {status:?} after {:?}", t.elapsed());
    assert!(t.elapsed() < Duration::from_secs(5), "the second client waited {:?}", t.elapsed());
    drop(greedy);
}

#[test]
fn set_json_leaves_out_a_run_without_a_manifest_entry() {
    let root = needle_stdx::workspace_root().join("coeffs/default");
    let d = tempfile::tempdir().expect("tempdir");
    let set = d.path().join("set");
    std::fs::create_dir_all(set.join("fe")).expect("mkdir");
    std::fs::copy(root.join("campaign.toml"), set.join("campaign.toml")).expect("copy spec");
    for f in ["centre.csv", "x+04.csv", "manifest.toml"] {
        std::fs::copy(root.join("fe").join(f), set.join("fe").join(f)).expect("copy run");
    }
    let path = set.join("fe").join("manifest.toml");
    let mut m = needle_set::manifest::read_manifest(&path).expect("manifest");
    m.pose.retain(|name, _| name == "centre");
    std::fs::write(&path, needle_set::manifest::manifest_text(&m).expect("text")).expect("write");
    let opened = needle_set::set_folder::SetFolder::open(&set).expect("open the set");
    let v = needle_explore::set_json::set_json(&opened).expect("set.json");
    let names: Vec<&str> = v["runs"].as_array().expect("runs").iter().filter_map(|r| r["name"].as_str()).collect();
    assert_eq!(names, ["centre"], "x+04.csv has no manifest entry: not served");
}
