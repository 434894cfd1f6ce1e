//! `plenum view` in a real browser: headless Chromium loads the page, which draws the image
//! and, asked by its address (`#trace=X,Y`), the ray tree of the glass sphere's middle pixel
//! with its rays over the image and in the 3-D view, and (`#show=cost`) the cost view; the
//! DOM it leaves is checked and a screenshot kept.
//!
//! And driven as a user drives it, through ChromeDriver (WebDriver): the page loaded, the
//! glass sphere clicked, the tree, the overlay and the 3-D view awaited, a screenshot kept.
//!
//! Skipped, saying so, where Chromium (or ChromeDriver) is not installed, unless
//! PLENUM_REQUIRE_BROWSER=1 (`.ci/run` installs Debian's `chromium` and `chromium-driver`
//! and sets it), where that fails the test.

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn chromium() -> Option<&'static str> {
    ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|name| {
            Command::new(name)
                .arg("--version")
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status()
                .is_ok_and(|s| s.success())
        })
}

/// Runs Chromium headless on `url` with `args`, killed after two minutes.
fn headless(browser: &str, args: &[String], url: &str) -> String {
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-dev-shm-usage",
            "--no-first-run",
            "--hide-scrollbars",
            "--window-size=1280,800",
            // Timers run ahead of the clock while the page waits on nothing else; the
            // server answers in real time.
            "--virtual-time-budget=30000",
        ])
        .args(args)
        .arg(url)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut out = String::new();
    let reader = std::thread::spawn({
        let stdout = child.stdout.take().unwrap();
        move || {
            let mut s = String::new();
            let _ = std::io::Read::read_to_string(&mut BufReader::new(stdout), &mut s);
            s
        }
    });
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("Chromium did not finish within two minutes");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    out.push_str(&reader.join().unwrap());
    out
}

/// The page's tree of the glass sphere's middle pixel: a camera ray hitting the glass, with
/// reflected and refracted children.
fn assert_glass_tree(tree: &str) {
    assert!(
        tree.contains(">camera<") && tree.contains("glass sphere"),
        "{tree}"
    );
    assert!(
        tree.contains(">reflected<") && tree.contains(">refracted<"),
        "{tree}"
    );
}

#[test]
fn the_page_shows_the_image_and_a_pixels_ray_tree() {
    let Some(browser) = chromium() else {
        assert!(
            std::env::var("PLENUM_REQUIRE_BROWSER").as_deref() != Ok("1"),
            "PLENUM_REQUIRE_BROWSER=1 but no Chromium is installed"
        );
        eprintln!("skipped: no Chromium (Debian: apt-get install chromium)");
        return;
    };
    let (view, base) = start_view(&["--width", "64", "--height", "48", "--spp", "4"]);
    // The glass sphere of the built-in scene is in the middle of the image.
    let url = format!("{base}#trace=32,24");

    let dom = headless(browser, &["--dump-dom".to_string()], &url);
    let shot = std::env::temp_dir().join(format!("plenum-view-{}.png", std::process::id()));
    let _ = headless(browser, &[format!("--screenshot={}", shot.display())], &url);

    assert!(
        dom.contains("data-image-version="),
        "no image drawn:\n{dom}"
    );
    assert!(dom.contains("data-pixel=\"32,24\""), "no ray tree:\n{dom}");
    let tree = &dom[dom.find("id=\"tree\"").unwrap()..];
    assert_glass_tree(tree);
    let svg = &dom[dom.find("id=\"rays\"").unwrap()..];
    let svg = &svg[..svg.find("</svg>").unwrap()];
    assert!(
        svg.matches("<line").count() >= 3,
        "no rays drawn over the image: {svg}"
    );
    // The 3-D view draws the scene's objects and the tree's rays.
    let space = &dom[dom.find("id=\"space\"").unwrap()..];
    let space = &space[..space.find('>').unwrap()];
    let count = |attribute: &str| -> usize {
        let at = space
            .find(&format!("{attribute}=\""))
            .unwrap_or_else(|| panic!("no {attribute}: {space}"));
        let rest = &space[at + attribute.len() + 2..];
        rest[..rest.find('"').unwrap()].parse().unwrap()
    };
    assert!(count("data-objects") >= 3, "{space}");
    assert!(count("data-segments") >= 3, "{space}");
    // The cost view in false colour, with its scale.
    let dom = headless(
        browser,
        &["--dump-dom".to_string()],
        &format!("{base}#show=cost"),
    );
    assert!(dom.contains("data-shown=\"cost\""), "no cost view:\n{dom}");
    assert!(
        dom.contains("node visits + primitive tests per pixel"),
        "{dom}"
    );
    drop(view);
    let png = std::fs::read(&shot).expect("Chromium wrote no screenshot");
    assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000);
    eprintln!("screenshot: {}", shot.display());
}

/// A child process killed when dropped (the test's server and driver, however it ends).
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// `plenum view` started with `args`, and the address it prints.
fn start_view(args: &[&str]) -> (Killed, String) {
    let mut view = Command::new(env!("CARGO_BIN_EXE_plenum"))
        .arg("view")
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(view.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let base = line.split_whitespace().last().unwrap().to_string();
    (Killed(view), base)
}

/// One WebDriver command: `method` on `path` of the driver at `port` with a JSON body; the
/// reply's `value`.
fn webdriver(port: u16, method: &str, path: &str, body: Option<Value>) -> Value {
    let body = body.map(|b| b.to_string()).unwrap_or_default();
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    )
    .unwrap();
    // The driver keeps the connection open: read the headers, then Content-Length bytes.
    let mut reply = Vec::new();
    let mut byte = [0u8; 1];
    while !reply.ends_with(b"\r\n\r\n") {
        assert_eq!(
            s.read(&mut byte).unwrap(),
            1,
            "{method} {path}: the driver hung up"
        );
        reply.push(byte[0]);
    }
    let head = String::from_utf8_lossy(&reply).to_ascii_lowercase();
    let length: usize = head
        .lines()
        .find_map(|l| l.strip_prefix("content-length:"))
        .map(|v| v.trim().parse().unwrap())
        .unwrap_or_else(|| panic!("{method} {path}: no length in {head}"));
    let mut text = vec![0u8; length];
    s.read_exact(&mut text).unwrap();
    let text = String::from_utf8_lossy(&text);
    let v: Value =
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("{method} {path}: {e}: {text}"));
    v["value"].clone()
}

/// Standard base64, as the WebDriver screenshot comes.
fn base64_decode(s: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    };
    let digits: Vec<u8> = s
        .bytes()
        .filter(|c| c.is_ascii_alphanumeric() || *c == b'+' || *c == b'/')
        .map(value)
        .collect();
    let mut out = Vec::with_capacity(digits.len() * 3 / 4);
    for chunk in digits.chunks(4) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &d)| n | (d as u32) << (18 - 6 * i));
        out.extend_from_slice(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}

/// As a user does: the page loads, the image appears, a click at the middle of the image
/// (the glass sphere of the built-in scene) brings its ray tree: a camera ray hitting the
/// glass with reflected and refracted children, its rays over the image and in the 3-D
/// view; then the `show` control's cost view. A screenshot is kept.
#[test]
fn a_click_on_the_glass_sphere_shows_its_ray_tree() {
    let required = std::env::var("PLENUM_REQUIRE_BROWSER").as_deref() == Ok("1");
    let driver_there = Command::new("chromedriver")
        .arg("--version")
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    let Some(browser) = chromium().filter(|_| driver_there) else {
        assert!(
            !required,
            "PLENUM_REQUIRE_BROWSER=1 but Chromium or ChromeDriver is not installed"
        );
        eprintln!("skipped: no Chromium and ChromeDriver (Debian: apt-get install chromium chromium-driver)");
        return;
    };
    let (_view, base) = start_view(&["--width", "64", "--height", "48", "--spp", "4"]);
    let port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let _driver = Killed(
        Command::new("chromedriver")
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    let started = Instant::now();
    while TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "ChromeDriver did not start"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let path = Command::new("sh")
        .args(["-c", &format!("command -v {browser}")])
        .output()
        .unwrap();
    let binary = String::from_utf8_lossy(&path.stdout).trim().to_string();
    let session = webdriver(
        port,
        "POST",
        "/session",
        Some(
            json!({"capabilities": {"alwaysMatch": {"goog:chromeOptions": {
                "binary": binary,
                "args": ["--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                         "--window-size=1280,800"],
            }}}}),
        ),
    );
    let id = session["sessionId"]
        .as_str()
        .unwrap_or_else(|| panic!("no session: {session}"))
        .to_string();
    // Ended however the test ends: the driver's browser outlives the driver otherwise.
    let _session = Session {
        port,
        id: id.clone(),
    };
    let at = |p: &str| format!("/session/{id}{p}");
    let script = |code: &str| {
        webdriver(
            port,
            "POST",
            &at("/execute/sync"),
            Some(json!({"script": code, "args": []})),
        )
    };
    let wait = |code: &str, what: &str| {
        let started = Instant::now();
        loop {
            let v = script(code);
            if !v.is_null() && v != json!(false) {
                return v;
            }
            assert!(started.elapsed() < Duration::from_secs(60), "never {what}");
            std::thread::sleep(Duration::from_millis(100));
        }
    };
    webdriver(port, "POST", &at("/url"), Some(json!({ "url": base })));
    wait(
        "return document.body.dataset.imageVersion || null",
        "an image",
    );
    let element = webdriver(
        port,
        "POST",
        &at("/element"),
        Some(json!({"using": "css selector", "value": "#viewport"})),
    );
    let element = element
        .as_object()
        .and_then(|o| o.values().next())
        .and_then(Value::as_str)
        .unwrap()
        .to_string();
    // The image is fitted and centred in the viewport: its middle is the glass sphere's.
    webdriver(
        port,
        "POST",
        &at(&format!("/element/{element}/click")),
        Some(json!({})),
    );
    let pixel = wait(
        "return document.getElementById('tree').dataset.pixel || null",
        "a ray tree",
    );
    let (x, y) = pixel.as_str().unwrap().split_once(',').unwrap();
    let (x, y): (i32, i32) = (x.parse().unwrap(), y.parse().unwrap());
    assert!(
        (x - 32).abs() <= 2 && (y - 24).abs() <= 2,
        "clicked pixel ({x}, {y})"
    );
    let tree = script("return document.getElementById('tree').innerHTML").to_string();
    assert_glass_tree(&tree);
    let overlay = script("return document.querySelectorAll('#rays line').length");
    assert!(overlay.as_u64() >= Some(3), "{overlay}");
    let segments = script("return +document.getElementById('space').dataset.segments");
    assert!(segments.as_u64() >= Some(3), "3-D view: {segments}");
    let shot = webdriver(port, "GET", &at("/screenshot"), None);
    let png = base64_decode(shot.as_str().unwrap());
    assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000);
    let file = std::env::temp_dir().join(format!("plenum-view-click-{}.png", std::process::id()));
    std::fs::write(&file, &png).unwrap();
    eprintln!("screenshot: {}", file.display());
    // The cost view, by the control.
    script("const s = document.getElementById('show'); s.value = 'cost'; s.dispatchEvent(new Event('change'));");
    wait(
        "return document.body.dataset.shown === 'cost'",
        "the cost view",
    );
}

/// A WebDriver session, deleted (its browser closed) when dropped.
struct Session {
    port: u16,
    id: String,
}

impl Drop for Session {
    /// Best effort and never a panic (it may run while a failed test unwinds).
    fn drop(&mut self) {
        if let Ok(mut s) = TcpStream::connect(("127.0.0.1", self.port)) {
            let _ = s.set_read_timeout(Some(Duration::from_secs(10)));
            let request = format!(
                "DELETE /session/{} HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 0\r\n\r\n",
                self.id
            );
            if s.write_all(request.as_bytes()).is_ok() {
                // The browser is closed once the driver answers.
                let _ = s.read(&mut [0u8; 256]);
            }
        }
    }
}
