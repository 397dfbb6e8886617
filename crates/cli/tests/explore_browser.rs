//! The explorer in a real browser: `needle explore` serves the default set, headless
//! Chromium (driven through chromedriver with WebDriver) loads the page, a pose is set
//! through the number fields and the depth slider, and the six numbers the page shows
//! (their f32 bits) and its status must equal `needle eval --json` for the same pose.
//! A screenshot is saved as target/explore/explorer-<case>.png. chromium and
//! chromedriver are required (apt `chromium`, `chromium-driver`; `.ci/test` installs
//! them); missing, the test fails.

use fantoccini::{key::Key, wd::Capabilities, ClientBuilder, Locator};
use needle_firmware_host::workspace_root;
use std::io::{BufRead, BufReader};
use std::net::{TcpListener, TcpStream};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A child process killed when the test ends, passed or not.
struct Killed(Child);
impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

use needle_contract::COMPONENTS;

/// Starts `needle explore --port 0` and returns it with the URL it printed.
fn start_explorer() -> (Killed, String) {
    let root = workspace_root();
    let mut child = Command::new(env!("CARGO_BIN_EXE_needle"))
        .args(["explore", "--set", "coeffs/default", "--port", "0"])
        .current_dir(&root)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start needle explore");
    let stdout = child.stdout.take().expect("piped stdout");
    let guard = Killed(child);
    for line in BufReader::new(stdout).lines() {
        let line = line.expect("read needle explore's output");
        if let Some(url) = line.strip_prefix("open ").and_then(|s| s.split_whitespace().next()) {
            return (guard, url.to_string());
        }
    }
    panic!("needle explore ended without printing its URL");
}

/// Starts chromedriver on a free port and waits until it accepts connections.
fn start_chromedriver() -> (Killed, String) {
    let port = TcpListener::bind("127.0.0.1:0").and_then(|l| l.local_addr()).expect("a free port").port();
    let child = Command::new("chromedriver")
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("chromedriver must be installed (apt chromium-driver): the browser test needs it");
    let guard = Killed(child);
    let start = Instant::now();
    while TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(start.elapsed() < Duration::from_secs(30), "chromedriver did not listen on port {port} within 30 s");
        std::thread::sleep(Duration::from_millis(100));
    }
    (guard, format!("http://127.0.0.1:{port}"))
}

/// `needle eval --json` at `pose`: the six components' bits and the status bits.
fn needle_eval(pose: &[(&str, &str); 5]) -> (Vec<String>, u32) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_needle"));
    cmd.args(["eval", "--set", "coeffs/default", "--json"]).current_dir(workspace_root());
    for (name, v) in pose {
        cmd.arg(format!("--{}", name.replace('_', "-"))).arg(v);
    }
    let out = cmd.output().expect("run needle eval");
    assert!(out.status.success(), "needle eval failed: {}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("needle eval --json output");
    let bits = COMPONENTS.iter().map(|c| v["wrench_bits"][c].as_str().expect("wrench bits").to_string()).collect();
    let status = v["status"]["bits"].as_str().and_then(|s| u32::from_str_radix(s.trim_start_matches("0x"), 16).ok()).expect("status bits");
    (bits, status)
}

/// The punctures of the page's insertion script (explorer.js `playInsertion`: depths in
/// f64 steps of speed * 1 ms from -1 mm to 5 mm past the first stack's layers and back,
/// each passed to the module as f32) through the library's insertion model.
fn host_punctures(speed_mm_per_s: f64) -> u32 {
    use needle_haptics::insertion::{stacks, Insertion, InsertionConfig};
    let stack = stacks::ALL.first().expect("a shipped stack");
    let deepest: f64 = stack.layers.iter().map(|l| f64::from(l.thickness_mm)).sum::<f64>() + 5.0;
    let step = speed_mm_per_s * 0.001;
    let mut depths = Vec::new();
    let mut d = -1.0;
    while d < deepest {
        depths.push(d);
        d += step;
    }
    let mut d = deepest;
    while d > -1.0 {
        depths.push(d);
        d -= step;
    }
    let mut ins = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("stack");
    depths.iter().map(|&d| u32::from(ins.step(&needle_haptics::Pose { depth_mm: d as f32, ..Default::default() }).punctures)).sum()
}

async fn set_field(c: &fantoccini::Client, name: &str, value: &str) {
    let field = c.find(Locator::Id(&format!("{name}-num"))).await.expect("number field");
    field.clear().await.expect("clear field");
    field.send_keys(value).await.expect("type value");
}

async fn shown(c: &fantoccini::Client) -> (Vec<String>, u32, String) {
    let mut bits = Vec::new();
    for comp in COMPONENTS {
        let cell = c.find(Locator::Id(&format!("w-{comp}"))).await.expect("wrench cell");
        bits.push(cell.attr("data-bits").await.expect("attr").expect("data-bits set"));
    }
    let st = c.find(Locator::Id("status")).await.expect("status");
    let status = st.attr("data-bits").await.expect("attr").expect("status bits").parse().expect("status number");
    let command = c.find(Locator::Id("command")).await.expect("command").text().await.expect("text");
    (bits, status, command)
}

#[tokio::test(flavor = "current_thread")]
async fn explorer_page_shows_what_needle_eval_computes() {
    let (_explorer, url) = start_explorer();
    let (_driver, driver_url) = start_chromedriver();
    let mut caps = Capabilities::new();
    caps.insert(
        "goog:chromeOptions".to_string(),
        serde_json::json!({ "args": ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1300,1100"] }),
    );
    let c = ClientBuilder::new(hyper_util::client::legacy::connect::HttpConnector::new())
        .capabilities(caps)
        .connect(&driver_url)
        .await
        .expect("WebDriver session with headless Chromium");
    c.goto(&url).await.expect("load the explorer page");
    c.wait().at_most(Duration::from_secs(30)).for_element(Locator::Css("body[data-ready=yes]")).await.expect("page ready (wasm loaded)");
    let shots = workspace_root().join("target/explore");
    std::fs::create_dir_all(&shots).expect("screenshot folder");

    // a pose inside the domain, an FE run's of the set (x+04: its FE points overlaid), one
    // whose x is beyond the domain (clamped, SAT_X), and tx+15's, which the FE could not
    // solve (FE_UNSOLVED: the note shows)
    let cases: [(&str, [(&str, &str); 5]); 4] = [
        ("inside", [("x_mm", "2"), ("z_mm", "1"), ("theta_x_deg", "3"), ("theta_z_deg", "-4.5"), ("depth_mm", "5")]),
        ("fe-run", [("x_mm", "4"), ("z_mm", "0"), ("theta_x_deg", "0"), ("theta_z_deg", "0"), ("depth_mm", "4.2")]),
        ("saturated", [("x_mm", "14"), ("z_mm", "-3"), ("theta_x_deg", "-7"), ("theta_z_deg", "11"), ("depth_mm", "2.5")]),
        ("unsolved", [("x_mm", "0"), ("z_mm", "0"), ("theta_x_deg", "15"), ("theta_z_deg", "0"), ("depth_mm", "4")]),
    ];
    for (case, pose) in &cases {
        for (name, v) in pose {
            set_field(&c, name, v).await;
        }
        let (bits, status, command) = shown(&c).await;
        let (want_bits, want_status) = needle_eval(pose);
        assert_eq!(bits, want_bits, "{case}: the page's wrench bits differ from needle eval at {pose:?}");
        assert_eq!(status, want_status, "{case}: the page's status differs from needle eval at {pose:?}");
        let args: Vec<String> = pose.iter().map(|(n, v)| format!("--{} {v}", n.replace('_', "-"))).collect();
        assert_eq!(command, format!("needle eval --set coeffs/default {}", args.join(" ")), "{case}: copy-as-command text");
        let note = c.find(Locator::Id("fe-note")).await.expect("FE note").text().await.expect("text");
        assert_eq!(note.contains("FE run x+04"), *case == "fe-run", "{case}: FE overlay note {note:?}");
        let unsolved = c.find(Locator::Id("unsolved-note")).await.expect("unsolved note").is_displayed().await.expect("displayed");
        assert_eq!(unsolved, want_status & 0x20 != 0, "{case}: the FE_UNSOLVED note shows exactly when the status has it");
        let png = c.screenshot().await.expect("screenshot");
        std::fs::write(shots.join(format!("explorer-{case}.png")), png).expect("save screenshot");
        println!("{case}: page = needle eval at {pose:?}: status {want_status:#04x}, bits {want_bits:?}");
    }
    assert_eq!(needle_eval(&cases[2].1).1 & 0x01, 0x01, "the saturated case must raise SAT_X");
    assert_eq!(needle_eval(&cases[3].1).1, 0x20, "the unsolved case must raise FE_UNSOLVED alone");

    // the depth slider: End moves it to the domain's end, the number field follows, and
    // the numbers equal needle eval at depth 6 mm
    let slider = c.find(Locator::Id("depth_mm-range")).await.expect("depth slider");
    slider.send_keys(&String::from(char::from(Key::End))).await.expect("press End on the slider");
    let depth = c.find(Locator::Id("depth_mm-num")).await.expect("depth field").prop("value").await.expect("prop").expect("value");
    assert_eq!(depth, "6", "the depth field follows the slider to the domain's end");
    let mut pose = cases[0].1;
    for (name, v) in pose.iter_mut() {
        if *name == "depth_mm" {
            *v = "6";
        } else {
            set_field(&c, name, v).await;
        }
    }
    let (bits, status, _) = shown(&c).await;
    let (want_bits, want_status) = needle_eval(&pose);
    assert_eq!((bits, status), (want_bits, want_status), "slider case at {pose:?}");

    // the insertion player: the centred vertical needle in and out of the first stack at
    // 3 mm/s; the punctures the page counts are the host library's for the same ticks
    for (name, v) in [("x_mm", "0"), ("z_mm", "0"), ("theta_x_deg", "0"), ("theta_z_deg", "0")] {
        set_field(&c, name, v).await;
    }
    c.find(Locator::Id("play")).await.expect("play button").click().await.expect("click play");
    let shown_punctures: u32 = c
        .wait()
        .at_most(Duration::from_secs(30))
        .for_element(Locator::Css("body[data-insertion-punctures]"))
        .await
        .expect("the insertion ran")
        .attr("data-insertion-punctures")
        .await
        .expect("attr")
        .expect("punctures")
        .parse()
        .expect("a count");
    let png = c.screenshot().await.expect("screenshot");
    std::fs::write(shots.join("explorer-insertion.png"), png).expect("save screenshot");
    assert_eq!(shown_punctures, host_punctures(3.0), "the page's insertion punctures differ from the library's");
    assert!(shown_punctures > 0, "the insertion crosses at least one puncture");
    c.close().await.expect("close the browser");
}
