//! `plenum view` in a real browser: headless Chromium loads the page, which draws the image
//! and, asked by its address (`#trace=X,Y`), the ray tree of the glass sphere's middle pixel
//! with its rays over the image and in the 3-D view, and (`#show=cost`) the cost view; the
//! DOM it leaves is checked and a screenshot kept.
//!
//! Skipped, saying so, where Chromium is not installed, unless PLENUM_REQUIRE_BROWSER=1
//! (`.ci/run` installs Debian's `chromium` and sets it), where that fails the test.

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
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
    let mut view = Command::new(env!("CARGO_BIN_EXE_plenum"))
        .args(["view", "--width", "64", "--height", "48", "--spp", "4"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(view.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let base = line.split_whitespace().last().unwrap().to_string();
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
    assert!(
        tree.contains(">camera<") && tree.contains("glass sphere"),
        "{tree}"
    );
    assert!(
        tree.contains(">reflected<") && tree.contains(">refracted<"),
        "{tree}"
    );
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
    let _ = view.kill();
    let _ = view.wait();
    let png = std::fs::read(&shot).expect("Chromium wrote no screenshot");
    assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000);
    eprintln!("screenshot: {}", shot.display());
}
