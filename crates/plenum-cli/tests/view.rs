//! `plenum view` end to end: the server started as a user starts it, spoken to over HTTP.
//! Its endpoints, the image against `plenum render`'s, restarting and cancelling, bad
//! requests, concurrent clients and the scene file watched.

use serde_json::Value;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A running `plenum view`, killed when dropped.
struct View {
    child: Child,
    address: String,
}

impl Drop for View {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn start(args: &[&str]) -> View {
    let mut child = Command::new(env!("CARGO_BIN_EXE_plenum"))
        .arg("view")
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let address = line
        .split("http://")
        .nth(1)
        .unwrap_or_else(|| panic!("no address in `{line}`"))
        .trim()
        .trim_end_matches('/')
        .to_string();
    View { child, address }
}

/// A raw exchange: the status code, the headers (lower-case names) and the body.
fn exchange(address: &str, raw: &str) -> (u16, Vec<(String, String)>, Vec<u8>) {
    let mut s = TcpStream::connect(address).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    s.write_all(raw.as_bytes()).unwrap();
    let mut all = Vec::new();
    s.read_to_end(&mut all).unwrap();
    let split = all
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("no header end");
    let head = String::from_utf8_lossy(&all[..split]).into_owned();
    let mut lines = head.lines();
    let status = lines
        .next()
        .unwrap()
        .split(' ')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    let headers = lines
        .filter_map(|l| l.split_once(": "))
        .map(|(k, v)| (k.to_ascii_lowercase(), v.to_string()))
        .collect();
    (status, headers, all[split + 4..].to_vec())
}

fn request(view: &View, method: &str, target: &str) -> (u16, Vec<(String, String)>, Vec<u8>) {
    exchange(
        &view.address,
        &format!(
            "{method} {target} HTTP/1.1\r\nHost: {}\r\n\r\n",
            view.address
        ),
    )
}

fn json(view: &View, method: &str, target: &str) -> (u16, Value) {
    let (status, _, body) = request(view, method, target);
    (status, serde_json::from_slice(&body).unwrap())
}

fn header<'a>(headers: &'a [(String, String)], name: &str) -> &'a str {
    &headers.iter().find(|(k, _)| k == name).unwrap().1
}

/// Polls the status until `done` holds (at most a minute).
fn wait_for(view: &View, what: &str, done: impl Fn(&Value) -> bool) -> Value {
    let start = Instant::now();
    loop {
        let (_, st) = json(view, "GET", "/api/status");
        if done(&st) {
            return st;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "never {what}: {st}"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn finished(st: &Value) -> bool {
    st["running"] == false
}

/// Linear RGB of a PFM file, rows from the top.
fn read_pfm(path: &Path) -> (u32, u32, Vec<f32>) {
    let bytes = std::fs::read(path).unwrap();
    let mut parts = bytes.splitn(4, |&b| b == b'\n');
    assert_eq!(parts.next().unwrap(), b"PF");
    let dims = String::from_utf8(parts.next().unwrap().to_vec()).unwrap();
    let (w, h) = dims.trim().split_once(' ').unwrap();
    let (w, h): (u32, u32) = (w.parse().unwrap(), h.parse().unwrap());
    let scale: f64 = String::from_utf8(parts.next().unwrap().to_vec())
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    assert!(scale < 0.0, "little-endian PFM");
    let data: Vec<f32> = parts
        .next()
        .unwrap()
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    let row = 3 * w as usize;
    let rgb = data.chunks(row).rev().flatten().copied().collect();
    (w, h, rgb)
}

/// The page, the status, the image (the same, to the byte, as `plenum render`'s of those
/// settings, though the view renders in passes), a pixel's ray tree with the segments to
/// draw, and the errors of the trace endpoint.
#[test]
fn serves_the_page_the_image_and_a_ray_tree() {
    let settings = [
        "--width",
        "48",
        "--height",
        "36",
        "--spp",
        "6",
        "--sampler",
        "random",
    ];
    for method in ["whitted", "path", "bdpt", "sppm"] {
        let view = start(&[&settings[..], &["--integrator", method]].concat());
        let st = wait_for(&view, "finished", finished);
        assert_eq!(st["settings"]["integrator"], method);
        assert_eq!(st["samples_done"], 6, "{st}");
        assert!(st["rays"].as_u64().unwrap() > 0);
        let (status, headers, body) = request(&view, "GET", "/api/image");
        assert_eq!(status, 200);
        assert_eq!(header(&headers, "x-width"), "48");
        assert_eq!(header(&headers, "x-height"), "36");
        let served: Vec<f32> = body
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let pfm = dir.path().join("x.pfm");
        let out = Command::new(env!("CARGO_BIN_EXE_plenum"))
            .arg("render")
            .args(settings)
            .args(["--integrator", method, "--quiet", "-o"])
            .arg(&pfm)
            .output()
            .unwrap();
        assert!(out.status.success());
        let (w, h, rendered) = read_pfm(&pfm);
        assert_eq!((w, h), (48, 36));
        assert!(
            served == rendered,
            "{method}: the view's image differs from render's"
        );

        if method != "whitted" {
            continue;
        }
        let (status, _, page) = request(&view, "GET", "/");
        assert_eq!(status, 200);
        assert!(String::from_utf8_lossy(&page).contains("/api/trace"));
        // The glass sphere of the built-in scene, in the middle of the image.
        let (status, tree) = json(&view, "GET", "/api/trace?x=24&y=18");
        assert_eq!(status, 200, "{tree}");
        assert_eq!(tree["pixel"], serde_json::json!([24, 18]));
        let rays = tree["rays"].as_array().unwrap();
        assert_eq!(rays[0]["kind"], "camera");
        assert_eq!(rays[0]["object"], "glass sphere");
        let kinds: Vec<&str> = rays.iter().map(|r| r["kind"].as_str().unwrap()).collect();
        assert!(
            kinds.contains(&"reflected") && kinds.contains(&"refracted"),
            "{kinds:?}"
        );
        // A camera ray through the pixel's centre projects to (nearly) a point in it.
        let s = &rays[0]["segment"];
        let (x, y) = (s[0][0].as_f64().unwrap(), s[0][1].as_f64().unwrap());
        assert!(
            (24.0..25.0).contains(&x) && (18.0..19.0).contains(&y),
            "{s}"
        );
        assert!(rays.iter().skip(1).all(|r| r["segment"].is_array()));
        // The same tree as a figure for slides (`trace-pixel --svg`).
        let (status, headers, svg) = request(&view, "GET", "/api/figure?x=24&y=18");
        assert_eq!(status, 200);
        assert!(header(&headers, "content-type").starts_with("image/svg+xml"));
        let svg = String::from_utf8_lossy(&svg);
        assert!(
            svg.starts_with("<svg") && svg.contains("refracted ray"),
            "{svg}"
        );
        let (status, v) = json(&view, "GET", "/api/figure?x=99&y=0");
        assert_eq!(status, 400, "{v}");
        for bad in [
            "/api/trace?x=48&y=0",
            "/api/trace?x=0&y=-1",
            "/api/trace?x=abc&y=1",
            "/api/trace?y=1",
            "/api/trace?x=%zz&y=1",
        ] {
            let (status, v) = json(&view, "GET", bad);
            assert_eq!(status, 400, "{bad}: {v}");
            assert!(v["error"].as_str().is_some_and(|e| !e.is_empty()));
        }
    }
}

/// The views of where the work goes (`/api/view`): rays and cost per pixel that add up to
/// the status's counters, the samples per pixel, brute force costing more than the BVH;
/// none under SPPM, an unknown view refused. The scene for the 3-D view (`/api/scene`):
/// every object outlined and named, the camera's frustum, the lights; the trace's rays
/// carry their 3-D ends.
#[test]
fn shows_where_the_work_goes_and_the_scene_in_3d() {
    let view = start(&[
        "--width",
        "32",
        "--height",
        "24",
        "--spp",
        "4",
        "--integrator",
        "path",
    ]);
    let values = |name: &str| -> (Vec<f64>, u64) {
        let (status, headers, body) = request(&view, "GET", &format!("/api/view?name={name}"));
        assert_eq!(status, 200, "{name}: {}", String::from_utf8_lossy(&body));
        assert_eq!(
            (header(&headers, "x-width"), header(&headers, "x-height")),
            ("32", "24")
        );
        let v: Vec<f64> = body
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64)
            .collect();
        assert_eq!(v.len(), 32 * 24);
        (v, header(&headers, "x-max").parse().unwrap())
    };
    let mut costs = Vec::new();
    for accel in ["bvh", "none"] {
        let (status, _) = json(&view, "POST", &format!("/api/render?accel={accel}"));
        assert_eq!(status, 200);
        let st = wait_for(&view, "finished", |st| {
            finished(st) && st["settings"]["accel"] == accel
        });
        let (rays, most) = values("rays");
        assert_eq!(
            rays.iter().sum::<f64>(),
            st["rays"].as_f64().unwrap(),
            "{st}"
        );
        assert_eq!(rays.iter().cloned().fold(0.0, f64::max), most as f64);
        assert!(values("spp").0.iter().all(|&n| n == 4.0));
        let cost: f64 = values("cost").0.iter().sum();
        let counted = st["node_visits"].as_f64().unwrap() + st["primitive_tests"].as_f64().unwrap();
        assert_eq!(cost, counted, "{st}");
        costs.push(cost);
    }
    assert!(
        costs[1] > 1.5 * costs[0],
        "brute force {} against the BVH {}",
        costs[1],
        costs[0]
    );
    let (status, v) = json(&view, "GET", "/api/view?name=bogus");
    assert_eq!(status, 400);
    assert!(v["error"]
        .as_str()
        .unwrap()
        .contains("unknown view `bogus`"));

    let (status, scene) = json(&view, "GET", "/api/scene");
    assert_eq!(status, 200);
    let objects = scene["objects"].as_array().unwrap();
    assert!(
        objects.iter().any(|o| o["name"] == "glass sphere"),
        "{scene}"
    );
    for o in objects {
        let lines = o["lines"].as_array().unwrap();
        assert!(!lines.is_empty(), "{o}");
        assert!(lines.iter().flat_map(|l| l.as_array().unwrap()).all(|p| p
            .as_array()
            .unwrap()
            .len()
            == 3));
    }
    assert_eq!(scene["camera"]["corners"].as_array().unwrap().len(), 4);
    // A perspective camera's corner rays all start at the eye.
    let origins = scene["camera"]["origins"].as_array().unwrap();
    assert!(
        origins.iter().all(|o| *o == scene["camera"]["position"]),
        "{scene}"
    );
    assert!(!scene["lights"].as_array().unwrap().is_empty(), "{scene}");
    let (_, tree) = json(&view, "GET", "/api/trace?x=16&y=12");
    assert!(tree["rays"]
        .as_array()
        .unwrap()
        .iter()
        .all(|r| r["end"].as_array().is_some_and(|e| e.len() == 3)));

    let (status, _) = json(&view, "POST", "/api/render?integrator=sppm");
    assert_eq!(status, 200);
    wait_for(&view, "finished", |st| {
        finished(st) && st["settings"]["integrator"] == "sppm"
    });
    let (status, v) = json(&view, "GET", "/api/view?name=rays");
    assert_eq!(status, 409);
    assert!(v["error"].as_str().unwrap().contains("no one pixel"), "{v}");
}

/// A new setting restarts the render (cancelling a long one within a second or so), a bad
/// one is refused with the option's own error and leaves the render be; unknown paths,
/// methods, settings and malformed requests get an error each; many clients at once are
/// all answered.
#[test]
fn restarts_cancels_and_refuses_bad_requests() {
    let view = start(&[
        "--width",
        "64",
        "--height",
        "48",
        "--spp",
        "65536",
        "--integrator",
        "path",
    ]);
    let first = wait_for(&view, "rendering", |st| st["rays"].as_u64() > Some(0));
    assert_eq!(first["running"], true);
    let generation = first["generation"].as_u64().unwrap();

    for (target, needle) in [
        ("/api/render?bogus=1", "unknown setting `bogus`"),
        ("/api/render?spp=0", "--spp"),
        ("/api/render?integrator=pathh", "did you mean `path`"),
        ("/api/render?width=0", "--width"),
    ] {
        let (status, v) = json(&view, "POST", target);
        assert_eq!(status, 400, "{target}");
        assert!(
            v["error"].as_str().unwrap().contains(needle),
            "{target}: {v}"
        );
    }
    let (_, st) = json(&view, "GET", "/api/status");
    assert_eq!(st["generation"].as_u64(), Some(generation));
    assert_eq!(st["running"], true);

    let asked = Instant::now();
    let (status, st) = json(&view, "POST", "/api/render?spp=4&integrator=local");
    assert_eq!(status, 200, "{st}");
    assert!(st["generation"].as_u64().unwrap() > generation);
    let st = wait_for(&view, "finished the short render", finished);
    assert!(asked.elapsed() < Duration::from_secs(20));
    assert_eq!(st["settings"]["integrator"], "local");
    assert_eq!(st["settings"]["spp"], 4);
    // Settings not given again stay as the page left them.
    let (_, st) = json(&view, "POST", "/api/render?max-depth=3");
    assert_eq!(st["settings"]["integrator"], "local");

    assert_eq!(json(&view, "GET", "/nowhere").0, 404);
    assert_eq!(json(&view, "DELETE", "/api/status").0, 405);
    assert_eq!(json(&view, "GET", "/api/render").0, 405);
    for raw in ["nonsense\r\n\r\n", "GET / SPDY/9\r\n\r\n", "\r\n\r\n"] {
        let (status, _, body) = exchange(&view.address, raw);
        assert_eq!(status, 400, "{raw:?}: {}", String::from_utf8_lossy(&body));
    }
    let long = format!("GET /{} HTTP/1.1\r\n\r\n", "a".repeat(40_000));
    assert_eq!(exchange(&view.address, &long).0, 400);

    let clients: Vec<_> = (0..12)
        .map(|_| {
            let address = view.address.clone();
            std::thread::spawn(move || {
                (0..10)
                    .map(|_| exchange(&address, "GET /api/status HTTP/1.1\r\n\r\n").0)
                    .all(|s| s == 200)
            })
        })
        .collect();
    assert!(clients.into_iter().all(|c| c.join().unwrap()));
}

/// Writes `text` to `path` as an editor saves: a new file renamed over the old, so the
/// watcher never reads half of it.
fn save(path: &Path, text: &str) {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, text).unwrap();
    std::fs::rename(&tmp, path).unwrap();
}

/// Saving the scene re-renders it; a scene with an error shows the error, located, and
/// keeps the last image; fixing it renders again.
#[test]
fn watches_the_scene_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    let good = "[camera]\nposition = [0, 1, 4]\nlook_at = [0, 0, 0]\nresolution = [24, 16]\n\n\
                [materials.red]\ndiffuse = [0.8, 0.1, 0.1]\n\n\
                [[lights]]\ntype = \"point\"\nposition = [2, 4, 3]\nintensity = 1\n\n\
                [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"red\"\n";
    std::fs::write(&scene, good).unwrap();
    let view = start(&[scene.to_str().unwrap(), "--spp", "1"]);
    let st = wait_for(&view, "finished", finished);
    let generation = st["generation"].as_u64().unwrap();

    save(&scene, &good.replace("0.8, 0.1, 0.1", "0.1, 0.8, 0.1"));
    let st = wait_for(&view, "re-rendered", |st| {
        st["generation"].as_u64() > Some(generation) && finished(st)
    });
    let generation = st["generation"].as_u64().unwrap();

    save(
        &scene,
        &format!("{good}\n[[objects]]\ntype = \"sphere\"\nradius = \"big\"\n"),
    );
    let st = wait_for(&view, "shown the error", |st| st["error"].is_string());
    let error = st["error"].as_str().unwrap();
    assert!(
        error.contains("scene.toml:") && error.contains("radius"),
        "{error}"
    );
    assert_eq!(st["generation"].as_u64(), Some(generation));
    assert_eq!(request(&view, "GET", "/api/image").0, 200);

    save(&scene, good);
    let st = wait_for(&view, "recovered", |st| {
        st["error"].is_null() && st["generation"].as_u64() > Some(generation)
    });
    assert!(st["error"].is_null());
}
