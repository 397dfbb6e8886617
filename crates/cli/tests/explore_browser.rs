//! The explorer in a real browser: `needle explore` serves the default set, headless
//! Chromium (driven through chromedriver with WebDriver) loads the page, a pose is set
//! through the number fields and the depth slider, and the six numbers the page shows
//! (their f32 bits) and its status must equal `needle eval --json` for the same pose.
//! A screenshot is saved as target/explore/explorer-<case>.png. chromium and
//! chromedriver are required (apt `chromium`, `chromium-driver`; `.ci/test` installs
//! them); missing, the test fails.

use fantoccini::{key::Key, wd::Capabilities, ClientBuilder, Locator};
use needle_stdx::workspace_root;
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

mod common;
use common::{shipped_set, NEEDLE};

/// Starts `needle explore --port 0` and returns it with the URL it printed.
fn start_explorer() -> (Killed, String) {
    let root = workspace_root();
    let mut child = Command::new(NEEDLE)
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
    let mut cmd = Command::new(NEEDLE);
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

/// The page's insertion script (explorer.js `script`): depths in f64 steps of
/// `step` from -1 mm, to `stop` (when given) then `hold_ticks` ticks at the last depth
/// reached, on to `deepest`, back to -1 mm.
fn script(step: f64, deepest: f64, stop: Option<f64>, hold_ticks: usize) -> Vec<f64> {
    let mut depths = Vec::new();
    let mut d = -1.0;
    if let Some(stop) = stop {
        while d < stop {
            depths.push(d);
            d += step;
        }
        let held = depths.last().copied().unwrap_or(-1.0);
        depths.extend(std::iter::repeat_n(held, hold_ticks));
    }
    while d < deepest {
        depths.push(d);
        d += step;
    }
    let mut d = deepest;
    while d > -1.0 {
        depths.push(d);
        d -= step;
    }
    depths
}

/// What the page's insertion player computes (explorer.js `playInsertion`, the centred
/// vertical needle through the first shipped stack with `prony` on every layer, stopped
/// at 80 % of the unstopped insertion's first puncture depth for `hold_ticks` ticks),
/// through the library: the punctures, and Fy (N) when the needle stops and at the end
/// of the hold.
fn host_insertion(speed_mm_per_s: f64, hold_ticks: usize, prony: &[needle_haptics::viscoelastic::PronyTerm]) -> (u32, f32, f32) {
    use needle_haptics::insertion::{stacks, Insertion, InsertionConfig, Stack};
    use needle_haptics::viscoelastic::PronyTerms;
    let stack = stacks::ALL.first().expect("a shipped stack");
    let terms = PronyTerms::new(prony).expect("terms in range");
    let layers: Vec<_> = stack.layers.iter().map(|l| needle_haptics::insertion::Layer { prony: terms, ..*l }).collect();
    let with = Stack { layers: &layers, ..*stack };
    let deepest: f64 = stack.layers.iter().map(|l| f64::from(l.thickness_mm)).sum::<f64>() + 5.0;
    let step = speed_mm_per_s * 0.001;
    let run = |depths: &[f64]| {
        let mut ins = Insertion::new(&with, InsertionConfig::DEFAULT_1KHZ).expect("stack");
        depths.iter().map(|&d| ins.step(&needle_haptics::Pose { depth_mm: d as f32, ..Default::default() })).collect::<Vec<_>>()
    };
    let dry = script(step, deepest, None, 0);
    let first = run(&dry).iter().position(|e| e.punctures > 0).expect("the unstopped insertion punctures");
    let depths = script(step, deepest, Some(0.8 * dry[first]), hold_ticks);
    let ticks = run(&depths);
    let stopped = depths.windows(2).position(|w| w[0] == w[1]).expect("a hold");
    let punctures = ticks.iter().map(|e| u32::from(e.punctures)).sum();
    (punctures, ticks[stopped].wrench.fy_n, ticks[stopped + hold_ticks].wrench.fy_n)
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
    // whose x is beyond the domain (clamped, SAT_X), and tx+15's at 6 mm, below the
    // 5.70 mm its furthest attempt reached (FE_UNSOLVED: the note shows)
    let cases: [(&str, [(&str, &str); 5]); 4] = [
        ("inside", [("x_mm", "2"), ("z_mm", "1"), ("theta_x_deg", "3"), ("theta_z_deg", "-4.5"), ("depth_mm", "5")]),
        ("fe-run", [("x_mm", "4"), ("z_mm", "0"), ("theta_x_deg", "0"), ("theta_z_deg", "0"), ("depth_mm", "4.2")]),
        ("saturated", [("x_mm", "14"), ("z_mm", "-3"), ("theta_x_deg", "-7"), ("theta_z_deg", "11"), ("depth_mm", "2.5")]),
        ("unsolved", [("x_mm", "0"), ("z_mm", "0"), ("theta_x_deg", "15"), ("theta_z_deg", "0"), ("depth_mm", "6")]),
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
    // 3 mm/s, stopped for 3 s (the page's defaults) with the Prony terms the page starts
    // with (the campaign's [viscoelastic]); the punctures and the Fy the page shows before
    // and after the hold are the host library's for the same ticks, and the force relaxes
    for (name, v) in [("x_mm", "0"), ("z_mm", "0"), ("theta_x_deg", "0"), ("theta_z_deg", "0")] {
        set_field(&c, name, v).await;
    }
    let prony_text = c.find(Locator::Id("prony")).await.expect("Prony field").prop("value").await.expect("prop").expect("a value");
    let (spec, _) = needle_set::spec::load(&shipped_set()).expect("campaign.toml");
    let visco = spec.viscoelastic.expect("the default set has [viscoelastic]");
    let want_text = visco.g.iter().zip(&visco.tau_s).map(|(g, t)| format!("{g}:{t}")).collect::<Vec<_>>().join(", ");
    assert_eq!(prony_text, want_text, "the page's Prony terms are the campaign's [viscoelastic]");
    #[allow(clippy::cast_possible_truncation)] // the page passes the terms to the module as f32
    let prony: Vec<_> = visco
        .g
        .iter()
        .zip(&visco.tau_s)
        .map(|(&g, &tau_s)| needle_haptics::viscoelastic::PronyTerm { g: g as f32, tau_s: tau_s as f32 })
        .collect();
    c.find(Locator::Id("play")).await.expect("play button").click().await.expect("click play");
    let body = c
        .wait()
        .at_most(Duration::from_secs(30))
        .for_element(Locator::Css("body[data-insertion-punctures]"))
        .await
        .expect("the insertion ran");
    let attr = |name: &'static str| {
        let body = body.clone();
        async move { body.attr(name).await.expect("attr").unwrap_or_else(|| panic!("{name} set")) }
    };
    let shown_punctures: u32 = attr("data-insertion-punctures").await.parse().expect("a count");
    let fy_start: f64 = attr("data-hold-fy-start").await.parse().expect("a number");
    let fy_end: f64 = attr("data-hold-fy-end").await.parse().expect("a number");
    let png = c.screenshot().await.expect("screenshot");
    std::fs::write(shots.join("explorer-insertion.png"), png).expect("save screenshot");
    let (punctures, want_start, want_end) = host_insertion(3.0, 3000, &prony);
    assert_eq!(shown_punctures, punctures, "the page's insertion punctures differ from the library's");
    assert!(shown_punctures > 0, "the insertion crosses at least one puncture");
    assert_eq!(
        (fy_start, fy_end),
        (f64::from(want_start), f64::from(want_end)),
        "the page's Fy before and after the hold differ from the library's"
    );
    assert!(want_end < 0.9 * want_start, "the force relaxes while the needle is still: Fy {want_start} -> {want_end} N");
    c.close().await.expect("close the browser");
}
