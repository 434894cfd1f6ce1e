//! The `plenum` command end to end: outputs, the ray tree, bad input, Ctrl-C.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn plenum() -> Command {
    Command::new(env!("CARGO_BIN_EXE_plenum"))
}

/// A fresh folder per test, removed with what it holds when the test ends.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("plenum-cli-{name}-"))
        .tempdir()
        .unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn renders_the_builtin_scene_in_every_format() {
    let tmp = temp_dir("formats");
    let dir = tmp.path();
    for ext in ["png", "exr", "pfm", "hdr"] {
        let out = dir.join(format!("w.{ext}"));
        let o = plenum()
            .args(["render", "--width", "64", "--height", "48", "-o"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(std::fs::metadata(&out).unwrap().len() > 100);
        let summary = stderr(&o);
        assert!(
            summary.contains("64×48, 1 spp") && summary.contains("Mrays/s"),
            "{summary}"
        );
        assert!(
            summary.contains("camera")
                && summary.contains("shadow")
                && summary.contains("refraction")
        );
    }
    // No arguments at all: the built-in scene to plenum.png in the working directory.
    let o = plenum().current_dir(dir).arg("--help").output().unwrap();
    assert!(o.status.success());
}

#[test]
fn example_scenes_render() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let tmp = temp_dir("examples");
    let dir = tmp.path();
    let mut count = 0;
    for entry in std::fs::read_dir(&scenes).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            count += 1;
            let o = plenum()
                .arg("render")
                .arg(&path)
                .args(["--width", "80", "--height", "60", "--quiet", "-o"])
                .arg(dir.join("x.png"))
                .output()
                .unwrap();
            assert!(o.status.success(), "{}: {}", path.display(), stderr(&o));
        }
    }
    assert!(count >= 1);
}

/// A dispersive scene rendered in RGB says that it needs wavelengths.
#[test]
fn rgb_mode_warns_about_dispersion() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/prism.toml");
    let tmp = temp_dir("prism");
    let o = plenum()
        .arg("render")
        .arg(&scene)
        .args([
            "--width", "16", "--height", "12", "--spp", "1", "--color", "rgb", "-o",
        ])
        .arg(tmp.path().join("x.png"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("material `flint` (a dispersive η) needs wavelengths"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn trace_pixel_shows_the_ray_tree() {
    // The centre of the glass sphere in the built-in scene at 64×48.
    let o = plenum()
        .args([
            "trace-pixel",
            "-",
            "36",
            "22",
            "--width",
            "64",
            "--height",
            "48",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rays = doc["rays"].as_array().unwrap();
    assert_eq!(rays[0]["kind"], "camera");
    assert_eq!(rays[0]["object"], "glass sphere");
    assert!(rays.iter().any(|r| r["kind"] == "refracted"));
    assert!(rays.iter().any(|r| r["kind"] == "reflected"));
    let shadow = rays.iter().find(|r| r["kind"] == "shadow").unwrap();
    assert!(shadow["light"].is_string() && shadow["blocked"].is_boolean());
    let text = plenum()
        .args([
            "trace-pixel",
            "-",
            "36",
            "22",
            "--width",
            "64",
            "--height",
            "48",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("camera ray") && text.contains("hit \"glass sphere\""),
        "{text}"
    );
}

/// `--sample K` traces one sample, and the samples' colours average to the pixel's
/// (`--sample all`, box filter); an index beyond them is refused. The tree shows the optics
/// of each hit, the lights behind a surface, and why a branch of Whitted's was not traced
/// (the other going on); local illumination says it does not recurse; SPPM traces its pixel.
#[test]
fn trace_pixel_traces_one_sample_and_shows_why() {
    let base = [
        "trace-pixel",
        "-",
        "32",
        "24",
        "--width",
        "64",
        "--height",
        "48",
        "--spp",
        "4",
    ];
    let json = |extra: &[&str]| -> serde_json::Value {
        let o = plenum()
            .args(base)
            .args(extra)
            .arg("--json")
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let color = |v: &serde_json::Value| -> Vec<f64> {
        v["color"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_f64().unwrap())
            .collect()
    };
    let first = json(&[]);
    assert_eq!(first["sample"], 0);
    assert_eq!(first["samples"], 4);
    let mut mean = vec![0.0; 3];
    for k in 0..4 {
        let doc = json(&["--sample", &k.to_string()]);
        assert_eq!(doc["sample"], k);
        // One camera ray per sample.
        let rays = doc["rays"].as_array().unwrap();
        assert_eq!(rays.iter().filter(|r| r["kind"] == "camera").count(), 1);
        for (m, c) in mean.iter_mut().zip(color(&doc)) {
            *m += c / 4.0;
        }
    }
    let all = json(&["--sample", "all"]);
    assert!(all["sample"].is_null());
    for (m, c) in mean.iter().zip(color(&all)) {
        assert!(
            (m - c).abs() < 1e-6,
            "samples {mean:?} against the pixel {:?}",
            color(&all)
        );
    }
    for bad in ["4", "-1", "first"] {
        let o = plenum()
            .args(base)
            .args(["--sample", bad])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "--sample {bad}");
    }

    let text = |extra: &[&str]| {
        let o = plenum().args(base).args(extra).output().unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let glass = text(&[]);
    assert!(
        glass.starts_with("pixel (32, 24), sample 0 of 4"),
        "{glass}"
    );
    for needle in [
        "angle of incidence",
        "η 1.0000 → 1.5000, refracted at",
        "critical angle 41.81°",
        "Fresnel reflectance",
        "is behind the surface: no shadow ray",
    ] {
        assert!(glass.contains(needle), "no `{needle}` in\n{glass}");
    }
    let shallow = text(&["--max-depth", "1"]);
    assert!(shallow.contains("ray not traced: depth"), "{shallow}");
    assert!(!shallow.contains("stopped: depth"), "{shallow}");
    let local = text(&["--integrator", "local"]);
    assert!(local.contains("no recursion"), "{local}");
    let path = text(&["--integrator", "path", "--color", "spectral"]);
    assert_eq!(path.matches("wavelengths ").count(), 1, "{path}");
    // BDPT's tree adds up: the strategies that stay in the pixel sum to the sample's colour
    // (the built-in scene has no Phong emission); every surface a subpath hit is named.
    let mut refracted = false;
    for k in 0..4 {
        let doc = json(&["--integrator", "bdpt", "--sample", &k.to_string()]);
        let rays = doc["rays"].as_array().unwrap();
        let mut sum = [0.0; 3];
        for r in rays
            .iter()
            .filter(|r| r["strategy"]["splat"].is_null() && r["strategy"].is_object())
        {
            for (s, c) in sum.iter_mut().zip(r["color"].as_array().unwrap()) {
                *s += c.as_f64().unwrap();
            }
        }
        for (s, c) in sum.iter().zip(color(&doc)) {
            assert!(
                (s - c).abs() <= 1e-9 + 1e-9 * c.abs(),
                "sample {k}: {sum:?} against {:?}",
                color(&doc)
            );
        }
        let camera = rays.iter().find(|r| r["kind"] == "camera").unwrap();
        assert_eq!(camera["object"], "glass sphere");
        refracted |= rays.iter().any(|r| r["kind"] == "refracted");
    }
    assert!(refracted, "no sample's camera subpath went into the glass");
    // In the Cornell box, light subpaths reach the camera directly (t = 1) and land in
    // other pixels: the tree says where.
    let cbox = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    let o = plenum()
        .arg("trace-pixel")
        .arg(&cbox)
        .args([
            "64", "64", "--width", "128", "--height", "128", "--spp", "8",
        ])
        .args(["--integrator", "bdpt", "--sample", "2"])
        .output()
        .unwrap();
    let t = String::from_utf8_lossy(&o.stdout);
    assert!(
        t.contains("s = 2, t = 1") && t.contains("lands at raster"),
        "{t}"
    );
    assert!(t.contains("more land in other pixels"), "{t}");
    let sppm = text(&["--integrator", "sppm", "--spp", "1"]);
    assert!(sppm.contains("all its samples (SPPM"), "{sppm}");
}

/// Each bad scene exits with code 2 and names file:line:column and what was expected.
#[test]
fn bad_scenes_give_located_errors() {
    let tmp = temp_dir("errors");
    let dir = tmp.path();
    let cases = [
        (
            "[[objects]]\ntype = \"sphere\"\nradus = 1\n",
            "3:1",
            "did you mean `radius`?",
        ),
        (
            "[[objects]]\ntype = \"sphere\"\nradius = -2\n",
            "3:10",
            "expected a positive radius",
        ),
        (
            "[materials.glass]\nior = 1.5\n[[objects]]\ntype = \"sphere\"\nradius = 1\nmaterial = \"glas\"\n",
            "6:12",
            "no material named `glas`",
        ),
        (
            "[[objects]]\ntype = \"mesh\"\nfile = \"missing.obj\"\n",
            "3:8",
            "cannot read mesh file",
        ),
        (
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, nan, 0]\nradius = 1\n",
            "3:14",
            "expected a finite number",
        ),
        ("[camera\nfov = 3\n", "1:", "error"),
        (
            "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = -1\n",
            "4:13",
            "expected intensity ≥ 0",
        ),
        ("[render]\nspp = 0\n", "2:7", "expected between 1 and 65536 samples"),
        ("[render]\nmax_depth = 1000\n", "2:13", "at most 100"),
        (
            "[[objects]]\ntype = \"polyhedron\"\nvertices = [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]\nfaces = [[0,2,1],[0,1,3],[0,3,2],[1,2,3],[]]\n",
            "4:42",
            "at least 3 vertex indices",
        ),
        (
            "[meshes.m]\npositions = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = [[0, 1, 2]]\n[[objects]]\ntype = \"mesh\"\nmesh = \"m\"\nfile = \"m.obj\"\n",
            "7:8",
            "give only one of mesh, file, positions",
        ),
        (
            "[[objects]]\ntype = \"spere\"\n",
            "2:8",
            "did you mean `sphere`?",
        ),
        (
            "[camera]\nf_number = 2.8\n",
            "2:12",
            "needs a `focal_length`",
        ),
        ("[camera]\nblades = 2\n", "2:10", "3 to 64 blades"),
        ("[camera]\nshutter = [1, 0]\n", "2:11", "closes (0) before it opens (1)"),
        ("[render]\nfilter = \"sinc\"\n", "2:10", "expected box, tent"),
        ("[render]\nsampler = \"halton\"\n", "2:11", "jittered, cook16, sobol"),
        (
            "[[lights]]\ntype = \"rectangle\"\ncorner = [0, 0, 0]\nedge_u = [1, 0, 0]\nedge_v = [2, 0, 0]\n",
            "5:10",
            "no area",
        ),
        ("[materials.m]\ngloss = 0\n", "2:9", "positive"),
        (
            "[[objects]]\ntype = \"cylinder\"\nbase = [0, 0, 0]\ntop = [0, 1, 0]\nradius = 1\nemission = 1\n",
            "6:12",
            "cannot be an area light",
        ),
        (
            "[materials.gold]\ntype = \"conductor\"\nmetal = \"Gold\"\n",
            "3:9",
            "unknown metal `Gold`",
        ),
        (
            "[materials.glass]\ntype = \"dielectric\"\neta = \"glass-BK8\"\n",
            "3:7",
            "did you mean `glass-BK7`?",
        ),
        (
            "[materials.m]\ntype = \"difuse\"\n",
            "2:8",
            "did you mean `diffuse`?",
        ),
        (
            "[materials.m]\ntype = \"diffuse\"\nroughness = 0.5\n",
            "3:1",
            "unknown field `roughness`",
        ),
        (
            "[materials.m]\ntype = \"dielectric\"\neta = { sellmeier = [[1, 0, 0], [0.3, 0, 0]] }\n",
            "3:7",
            "expected an index η > 0 over 360–830 nm",
        ),
        (
            "[materials.m]\ntype = \"conductor\"\neta = 1.5\nk = { spectrum = [[300, -1], [900, 2]] }\n",
            "4:5",
            "expected k ≥ 0",
        ),
        ("[render]\nintegrator = \"photons\"\n", "2:14", "unknown integrator"),
        ("[render]\nphoton_nearest = 0\n", "2:18", "density estimate"),
        ("[render]\nsppm_alpha = 1\n", "2:14", "alpha"),
        ("[render]\ncolor = \"hsv\"\n", "2:9", "unknown colour mode"),
        (
            "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nspectrum = { spectrum = [[500, 1], [400, 2]] }\n",
            "4:25",
            "not increasing",
        ),
    ];
    for (i, (text, location, message)) in cases.iter().enumerate() {
        let scene = write(dir, &format!("bad{i}.toml"), text);
        let o = plenum()
            .arg("render")
            .arg(&scene)
            .arg("-o")
            .arg(dir.join("x.png"))
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "case {i}: {err}");
        assert!(
            err.contains(&format!("bad{i}.toml:{location}")),
            "case {i}: {err}"
        );
        assert!(err.contains(message), "case {i}: {err}");
        assert!(err.contains('^'), "case {i} shows a caret: {err}");
    }
    let o = plenum()
        .args(["render", "no-such-scene.toml"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// Ctrl-C during a render writes what was rendered and exits 130.
#[test]
fn interrupt_writes_the_partial_image() {
    let tmp = temp_dir("interrupt");
    let dir = tmp.path();
    let out = dir.join("partial.png");
    let child = plenum()
        .args([
            "render",
            "--width",
            "1600",
            "--height",
            "1200",
            "--spp",
            "64",
            "--threads",
            "1",
            "-o",
        ])
        .arg(&out)
        .spawn()
        .unwrap();
    // Signal only once the process catches SIGINT (bit 1 of SigCgt in /proc): a fixed wait
    // lets a slow start on a loaded machine die of the default action instead.
    let catches_sigint = || {
        let status = std::fs::read_to_string(format!("/proc/{}/status", child.id()));
        status.ok().is_some_and(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("SigCgt:"))
                .and_then(|m| u64::from_str_radix(m.trim(), 16).ok())
                .is_some_and(|m| m & 2 != 0)
        })
    };
    let start = std::time::Instant::now();
    let procfs = std::path::Path::new("/proc/self/status").exists();
    while procfs && !catches_sigint() {
        let waited = start.elapsed().as_secs();
        assert!(
            waited < 60,
            "the render set no Ctrl-C handler in {waited} s"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // Without /proc, a fixed wait.
    let wait = if procfs { 300 } else { 700 };
    std::thread::sleep(std::time::Duration::from_millis(wait));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130));
    assert!(std::fs::metadata(&out).unwrap().len() > 0);
}

#[test]
fn nff_files_render_and_report_located_errors() {
    let tmp = temp_dir("nff");
    let dir = tmp.path();
    let good = write(
        dir,
        "ok.nff",
        "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0\nresolution 32 32\nl 2 2 5\nf 1 0 0 1 0 0 0 1\ns 0 0 0 1\n",
    );
    let o = plenum()
        .arg("render")
        .arg(&good)
        .args(["--nff-corners", "-o"])
        .arg(dir.join("ok.png"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("32×32") && stderr(&o).contains("1089 camera"),
        "{}",
        stderr(&o)
    );
    let bad = write(dir, "bad.nff", "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0\nresolution 32 32\nf 1 0 0 1 0 0 0 1\ns 0 0 x 1\n");
    let o = plenum().arg("render").arg(&bad).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("bad.nff:9:7") && stderr(&o).contains("expected a finite number"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn convert_writes_a_native_scene_that_renders() {
    let tmp = temp_dir("convert");
    let dir = tmp.path();
    let nff = write(
        dir,
        "in.nff",
        "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0\nresolution 32 32\nl 2 2 5\nf 1 0 0 1 0 0 0 1\ns 0 0 0 1\n",
    );
    let out = dir.join("out.toml");
    let o = plenum()
        .arg("convert")
        .arg(&nff)
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("type = \"sphere\"") && text.contains("[camera]"),
        "{text}"
    );
    let o = plenum()
        .arg("render")
        .arg(&out)
        .args(["-q", "-o"])
        .arg(dir.join("x.png"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let bad = write(dir, "bad.nff", "v\nfrom 0 0 5\n");
    let o = plenum()
        .arg("convert")
        .arg(&bad)
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn mitsuba_scenes_render_warn_and_fail_where_they_are_written() {
    let tmp = temp_dir("mitsuba");
    let dir = tmp.path();
    let scene = write(
        dir,
        "scene.xml",
        r#"<scene version="3.0.0">
    <default name="spp" value="2"/>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0 0 4" target="0 0 0" up="0 1 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="16"/></film>
    </sensor>
    <emitter type="constant"/>
    <shape type="sphere"><bsdf type="diffuse"><float name="glitter" value="1"/></bsdf></shape>
</scene>
"#,
    );
    let png = dir.join("x.png");
    let o = plenum()
        .arg("render")
        .arg(&scene)
        .args(["-q", "-o"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    // The film's size, and the property nothing reads, named where it is written.
    let size = image_size(&png);
    assert_eq!(size, (24, 16));
    assert!(
        stderr(&o).contains("scene.xml:10:47") && stderr(&o).contains("`glitter`"),
        "{}",
        stderr(&o)
    );
    let bad = write(dir, "bad.xml", "<scene version=\"3.0.0\">\n  <shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>\n</scene>\n");
    let o = plenum()
        .arg("render")
        .arg(&bad)
        .args(["-q", "-o"])
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("bad.xml:2:") && stderr(&o).contains("undefined parameter `$r`"),
        "{}",
        stderr(&o)
    );
}

fn image_size(png: &Path) -> (u32, u32) {
    let bytes = std::fs::read(png).unwrap();
    // The IHDR chunk: width and height, big-endian, after the 8-byte signature and the
    // chunk's length and type.
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    (be(16), be(20))
}

/// A rays file (PLRAYS1, ../shared/bench/README.md): origin, t_min, direction, t_max each.
fn write_rays(path: &Path, rays: &[[f32; 8]]) {
    let mut bytes = b"PLRAYS1\0".to_vec();
    bytes.extend((rays.len() as u64).to_le_bytes());
    for value in rays.iter().flatten() {
        bytes.extend(value.to_le_bytes());
    }
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn bench_traces_the_rays_and_compares_with_a_baseline() {
    let tmp = temp_dir("bench");
    let dir = tmp.path();
    // The unit square at z = 0 as two triangles, split along y = x.
    let mesh = write(
        dir,
        "square.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n",
    );
    // Rays straight down from z = 2 on a 10 × 10 lattice over [-0.45, 1.35]², off the
    // diagonal: those over the square hit it at t = 2, the lower triangle where y < x.
    let mut rays = Vec::new();
    let mut expected = Vec::new();
    for i in 0..10 {
        for j in 0..10 {
            let (x, y) = (-0.45 + 0.2 * i as f32, -0.45 + 0.2 * j as f32 + 0.01);
            rays.push([x, y, 2.0, 0.0, 0.0, 0.0, -1.0, f32::INFINITY]);
            let inside = (0.0..1.0).contains(&x) && (0.0..1.0).contains(&y);
            expected.push(inside.then_some(if y < x { 0u32 } else { 1 }));
        }
    }
    let rays_path = dir.join("down.rays");
    write_rays(&rays_path, &rays);
    let hits_path = dir.join("down.hits");
    let o = plenum()
        .arg("bench")
        .arg("--mesh")
        .arg(&mesh)
        .arg("--rays")
        .arg(&rays_path)
        .args([
            "--accel",
            "grid",
            "--baseline",
            "none",
            "--passes",
            "3",
            "--threads",
            "2",
        ])
        .arg("--hits-out")
        .arg(&hits_path)
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let hit_count = expected.iter().filter(|e| e.is_some()).count();
    assert_eq!(hit_count, 25);
    assert_eq!(report["accel"], "grid");
    assert_eq!(report["primitives"], 2);
    assert_eq!(report["rays"], 100);
    assert_eq!(report["hit_fraction"], 0.25);
    assert_eq!(report["occluded_fraction"], 0.25);
    let baseline = &report["baseline"];
    assert_eq!(baseline["report"]["accel"], "none");
    assert_eq!(baseline["report"]["hit_fraction"], 0.25);
    assert_eq!(baseline["agreeing_hits"], 100);
    for query in ["closest_speedup", "any_speedup"] {
        let spread = &baseline[query];
        let [least, median, most] =
            ["least", "median", "most"].map(|k| spread[k].as_f64().unwrap());
        assert!(0.0 < least && least <= median && median <= most, "{spread}");
    }
    // The hits file: the closest hit of every ray, in order.
    let bytes = std::fs::read(&hits_path).unwrap();
    assert_eq!(&bytes[..8], b"PLHITS1\0");
    assert_eq!(u64::from_le_bytes(bytes[8..16].try_into().unwrap()), 100);
    for (k, want) in expected.iter().enumerate() {
        let record = &bytes[16 + 8 * k..24 + 8 * k];
        let t = f32::from_le_bytes(record[..4].try_into().unwrap());
        let prim = u32::from_le_bytes(record[4..].try_into().unwrap());
        match want {
            Some(p) => assert_eq!((t, prim), (2.0, *p), "ray {k}"),
            None => assert_eq!((t, prim), (f32::INFINITY, u32::MAX), "ray {k}"),
        }
    }
}

#[test]
fn bench_rejects_bad_rays_files_and_arguments() {
    let tmp = temp_dir("bench-bad");
    let dir = tmp.path();
    let mesh = write(dir, "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let truncated = dir.join("short.rays");
    write_rays(&truncated, &[[0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0, 1.0]]);
    let bytes = std::fs::read(&truncated).unwrap();
    std::fs::write(&truncated, &bytes[..bytes.len() - 4]).unwrap();
    let good = dir.join("one.rays");
    write_rays(&good, &[[0.2, 0.2, 1.0, 0.0, 0.0, 0.0, -1.0, 1.0]]);
    let bench = |extra: &[&str], rays: &Path| {
        plenum()
            .arg("bench")
            .arg("--mesh")
            .arg(&mesh)
            .arg("--rays")
            .arg(rays)
            .args(extra)
            .output()
            .unwrap()
    };
    let o = bench(&[], &truncated);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("short.rays"), "{}", stderr(&o));
    let o = bench(&["--passes", "0"], &good);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--passes"), "{}", stderr(&o));
    let o = bench(&["--baseline", "kd-tree"], &good);
    assert_eq!(o.status.code(), Some(2));
    #[cfg(not(feature = "embree"))]
    {
        let o = bench(&["--baseline", "embree"], &good);
        assert_eq!(o.status.code(), Some(2));
        assert!(stderr(&o).contains("--features embree"), "{}", stderr(&o));
    }
    let o = bench(&["--json"], &good);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["hit_fraction"], 1.0);
    assert!(report.get("baseline").is_none());
}

/// Bad photon settings on the command line exit with 2 and say what is wrong; good ones
/// render with `photon` and `sppm`.
#[test]
fn photon_flags_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let run = |args: &[&str]| {
        plenum()
            .arg("render")
            .args(["--width", "8", "--height", "8", "-o"])
            .arg(&out)
            .args(args)
            .output()
            .unwrap()
    };
    for (args, says) in [
        (
            &["--integrator", "sppm", "--sppm-alpha", "1.5"][..],
            "alpha",
        ),
        (&["--integrator", "photon", "--photons", "0"][..], "photons"),
        (
            &["--integrator", "photon", "--gather-rays", "0"][..],
            "final-gather",
        ),
        (
            &["--integrator", "photon", "--photon-radius=-1"][..],
            "radius",
        ),
        (
            &["--integrator", "sppm", "--filter", "gaussian"][..],
            "box filter",
        ),
        (
            &[
                "--integrator",
                "bdpt",
                "--filter",
                "gaussian",
                "--write-strategies",
                "strategies-never-written",
            ][..],
            "box filter",
        ),
    ] {
        let o = run(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
    }
    for method in ["photon", "sppm"] {
        let o = run(&[
            "--integrator",
            method,
            "--photons",
            "2000",
            "--caustic-photons",
            "500",
            "--sppm-photons",
            "500",
            "--spp",
            "4",
        ]);
        assert!(o.status.success(), "{method}: {}", stderr(&o));
    }
}

#[test]
fn bad_options_and_outputs_are_refused_before_rendering() {
    let tmp = temp_dir("refused");
    let dir = tmp.path();
    let out = dir.join("out.png");
    let refused = |args: &[&str], what: &str| {
        let o = plenum().arg("render").args(args).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(what), "{args:?}: {}", stderr(&o));
    };
    let missing = dir.join("no-such-folder/out.png");
    // Before, found only after the render, with exit code 1.
    refused(
        &[
            "--width",
            "8",
            "--height",
            "8",
            "-o",
            missing.to_str().unwrap(),
        ],
        "cannot write",
    );
    let o = out.to_str().unwrap();
    refused(&["--exposure", "nan", "-o", o], "--exposure");
    refused(&["--exposure", "1e300", "-o", o], "--exposure");
    refused(&["--threads", "100000", "-o", o], "--threads");
    // Nothing was left behind by the checks.
    assert!(!out.exists());
}

#[cfg(target_os = "linux")]
#[test]
fn an_image_larger_than_memory_is_refused_before_rendering() {
    // The largest size accepted, under a 2 GB address-space limit: it aborted when the film
    // could not be allocated; now it is refused at once.
    let tmp = temp_dir("memory");
    let out = tmp.path().join("big.png");
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 2000000 && exec '{}' render --width 16384 --height 16384 -o '{}'",
            env!("CARGO_BIN_EXE_plenum"),
            out.display()
        ))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("needs about"), "{}", stderr(&o));
    assert!(stderr(&o).contains("ulimit -v"), "{}", stderr(&o));
}

/// What a newcomer tries in the first hour: negative numbers where an option takes them, a
/// range where it does not, a name mistyped, a file that is not a scene, a scene with no
/// light, a coefficient above 1.
#[test]
fn a_newcomers_mistakes_get_clear_answers() {
    let tmp = temp_dir("newcomer");
    let dir = tmp.path();
    let out = dir.join("out.png");
    let o_path = out.to_str().unwrap();
    let small = ["--width", "8", "--height", "6", "--quiet", "-o", o_path];
    let run = |args: &[&str]| plenum().args(args).output().unwrap();
    let refused = |args: &[&str], says: &[&str]| {
        let o = run(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        for s in says {
            assert!(stderr(&o).contains(s), "{args:?}: {}", stderr(&o));
        }
        stderr(&o)
    };

    // A negative exposure is a value, not an unknown argument.
    let o = run(&[&["render", "--exposure", "-6"][..], &small].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&[&["render", "--exposure", "-6.5", "--seed", "3"][..], &small].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    // Where an option takes no negative value, its range is the answer.
    refused(
        &[&["render", "--spp", "-4"][..], &small].concat(),
        &["--spp", "from 1 to 65536", "`-4`"],
    );
    refused(
        &[&["render", "--max-depth", "-1"][..], &small].concat(),
        &["--max-depth", "from 0 to 100"],
    );
    refused(
        &[&["render", "--seed", "-1"][..], &small].concat(),
        &["--seed", "≥ 0"],
    );
    refused(
        &[
            "trace-pixel",
            "-",
            "-1",
            "5",
            "--width",
            "8",
            "--height",
            "6",
        ],
        &["(-1, 5)", "X must be from 0 to 7"],
    );
    refused(
        &[
            "trace-pixel",
            "-",
            "3",
            "6",
            "--width",
            "8",
            "--height",
            "6",
        ],
        &["Y from 0 to 5"],
    );
    // A mistyped name is answered with the likely one.
    refused(
        &[&["render", "--integrator", "bpdt"][..], &small].concat(),
        &["unknown integrator `bpdt`", "did you mean `bdpt`?"],
    );
    refused(
        &[&["render", "--sampler", "jitered"][..], &small].concat(),
        &["did you mean `jittered`?"],
    );
    refused(
        &[&["render", "--accel", "octtree"][..], &small].concat(),
        &["did you mean `octree`?"],
    );
    // A bad photon setting names itself alone.
    let e = refused(
        &[
            &["render", "--integrator", "sppm", "--sppm-alpha", "2"][..],
            &small,
        ]
        .concat(),
        &["--sppm-alpha", "between 0 and 1"],
    );
    assert!(
        !e.contains("--photons") && !e.contains("--gather-rays"),
        "{e}"
    );
    let e = refused(
        &[
            &["render", "--integrator", "photon", "--gather-rays", "0"][..],
            &small,
        ]
        .concat(),
        &["--gather-rays"],
    );
    assert!(!e.contains("--sppm-alpha"), "{e}");

    // Options the chosen method does not read are named, with the method.
    for (args, says) in [
        (
            &[
                "--integrator",
                "path",
                "--photons",
                "1000",
                "--sppm-alpha",
                "0.5",
            ][..],
            "`path` does not read --photons, --sppm-alpha",
        ),
        (
            &[
                "--integrator",
                "whitted",
                "--rr-depth",
                "3",
                "--color",
                "spectral",
            ][..],
            "`whitted` does not read --rr-depth, --color spectral",
        ),
        (
            &["--integrator", "local", "--max-depth", "3"][..],
            "`local` does not read --max-depth",
        ),
        (
            &["--integrator", "sppm", "--gather-rays", "4", "--spp", "2"][..],
            "`sppm` does not read --gather-rays",
        ),
    ] {
        let o = run(&[&["render"][..], args, &small].concat());
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
    }
    for args in [
        &[
            "--integrator",
            "photon",
            "--photons",
            "1000",
            "--photon-radius",
            "0.5",
        ][..],
        &["--integrator", "sppm", "--sppm-alpha", "0.5", "--spp", "2"][..],
        &["--integrator", "appel", "--color", "rgb"][..],
    ] {
        let o = run(&[&["render"][..], args, &small].concat());
        assert!(
            o.status.success() && !stderr(&o).contains("does not read"),
            "{args:?}: {}",
            stderr(&o)
        );
    }

    // A file that is not a scene, and a converted scene named as an image.
    let readme = write(dir, "README.md", "# Not a scene\n\nSome text.\n");
    refused(
        &[&["render", readme.to_str().unwrap()][..], &small].concat(),
        &[
            "README.md",
            "not a scene file",
            ".toml",
            ".nff",
            ".ray",
            ".obj",
            ".ply",
        ],
    );
    let scene = write(
        dir,
        "dark.toml",
        "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n\n[materials.glass]\ndiffuse = 0.2\ntransmissive = 1.5\n\n[[objects]]\ntype = \"sphere\"\nmaterial = \"glass\"\ncenter = [0, 0, 0]\nradius = 1\n",
    );
    let png = dir.join("dark.png");
    refused(
        &["convert", scene.to_str().unwrap(), png.to_str().unwrap()],
        &["name the output .toml"],
    );
    assert!(!png.exists(), "nothing is written under a wrong name");
    let toml = dir.join("dark-copy.toml");
    let o = run(&["convert", scene.to_str().unwrap(), toml.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));

    // No light at all, and k_t above 1: rendered, with located warnings.
    let o = run(&[&["render", scene.to_str().unwrap()][..], &small].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("warning:") && e.contains("no light"), "{e}");
    assert!(
        e.contains("transmissive 1.5 exceeds 1") && e.contains("dark.toml:7:"),
        "{e}"
    );
    // A lit scene gets neither warning.
    let o = run(&[&["render"][..], &small].concat());
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
}

/// The Cornell box at a size that takes about a second on one thread.
fn cornell_args(size: &str, spp: &str) -> Vec<String> {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml");
    [
        scene.to_str().unwrap(),
        "--width",
        size,
        "--height",
        size,
        "--spp",
        spp,
        "--color",
        "rgb",
        "--threads",
        "1",
        "--quiet",
    ]
    .map(String::from)
    .to_vec()
}

/// A render killed with SIGKILL at random moments (seeded; checkpoints every 50 ms, so some
/// kills land while one is being written) and resumed each time from its last checkpoint
/// ends with the same bytes as a render never stopped, and removes its checkpoint.
#[cfg(unix)]
#[test]
fn a_render_killed_at_random_moments_resumes_to_the_same_bytes() {
    let tmp = temp_dir("kill");
    let dir = tmp.path();
    let args = cornell_args("128", "96");
    let o = plenum()
        .current_dir(dir)
        .arg("render")
        .args(&args)
        .args(["-o", "reference.pfm"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let reference = std::fs::read(dir.join("reference.pfm")).unwrap();

    let checkpoint = dir.join("state.plf");
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let (mut kills, mut resumes) = (0, 0);
    loop {
        let mut command = plenum();
        command.current_dir(dir).arg("render");
        if checkpoint.exists() {
            resumes += 1;
            command.args(["--resume", "state.plf"]);
        } else {
            command.args(&args).args([
                "--checkpoint",
                "state.plf",
                "--checkpoint-every",
                "0.05",
                "-o",
                "out.pfm",
            ]);
        }
        let mut child = command
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        if kills < 5 {
            std::thread::sleep(std::time::Duration::from_millis(150 + random() % 350));
            if child.try_wait().unwrap().is_none() {
                child.kill().unwrap();
                child.wait().unwrap();
                kills += 1;
                continue;
            }
        }
        let o = child.wait_with_output().unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        break;
    }
    assert!(
        kills >= 3 && resumes >= 2,
        "{kills} kills, {resumes} resumes"
    );
    let out = std::fs::read(dir.join("out.pfm")).unwrap();
    assert!(
        out == reference,
        "the resumed image differs from the uninterrupted one"
    );
    assert!(
        !checkpoint.exists(),
        "the checkpoint is removed once the image is written"
    );
}

/// --time-limit stops with an image, a checkpoint and exit code 3; --resume finishes it to
/// the bytes of one render. A checkpoint is refused, exit 2, when damaged, when its scene has
/// changed, or when other settings are asked for.
#[test]
fn checkpoints_stop_resume_and_refuse_what_does_not_match() {
    let tmp = temp_dir("checkpoint");
    let dir = tmp.path();
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml"),
    )
    .unwrap();
    let scene = write(dir, "box.toml", &text);
    let mut args = cornell_args("128", "64");
    args[0] = "box.toml".to_string();
    let run = |extra: &[&str]| {
        plenum()
            .current_dir(dir)
            .arg("render")
            .args(extra)
            .output()
            .unwrap()
    };
    let o = run(&[
        &args.iter().map(String::as_str).collect::<Vec<_>>()[..],
        &["-o", "reference.pfm"],
    ]
    .concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let reference = std::fs::read(dir.join("reference.pfm")).unwrap();

    let started = [
        &args.iter().map(String::as_str).collect::<Vec<_>>()[..],
        &["-o", "out.pfm", "--time-limit", "0.3"],
    ]
    .concat();
    let o = run(&started);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("time limit") && e.contains("--resume"), "{e}");
    let checkpoint = dir.join("out.plf");
    assert!(checkpoint.exists() && dir.join("out.pfm").exists());
    let saved = std::fs::read(&checkpoint).unwrap();

    // Refused: other settings, a damaged file, a file that is not a film, another scene.
    let refused = |extra: &[&str], says: &str| {
        let o = run(extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{extra:?}: {}", stderr(&o));
    };
    refused(
        &["--resume", "out.plf", "--spp", "32"],
        "cannot be given with --resume",
    );
    let mut damaged = saved.clone();
    let middle = damaged.len() / 2;
    damaged[middle] ^= 1;
    std::fs::write(dir.join("damaged.plf"), &damaged).unwrap();
    refused(&["--resume", "damaged.plf"], "checksum does not match");
    std::fs::write(dir.join("short.plf"), &saved[..saved.len() - 100]).unwrap();
    refused(&["--resume", "short.plf"], "checksum does not match");
    refused(&["--resume", "box.toml"], "not a Plenum film file");
    std::fs::write(&scene, text.replace("spp = ", "# changed\nspp = ")).unwrap();
    refused(&["--resume", "out.plf"], "another scene");
    std::fs::write(&scene, &text).unwrap();

    // Resumed (from another folder: its paths are the ones it was started with).
    let o = plenum()
        .current_dir(std::env::temp_dir())
        .args(["render", "--resume"])
        .arg(&checkpoint)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(dir.join("out.pfm")).unwrap() == reference);
    assert!(!checkpoint.exists());

    refused(&["--checkpoint", "x.png"], "name the checkpoint .plf");
}

/// SPPM stops at its time limit after a whole iteration, with an image and a checkpoint of
/// every pixel's radius, photons, flux and direct light, and resumes from it to the bytes of
/// one render; --samples cannot split it.
#[test]
fn sppm_stops_and_resumes_to_the_bytes_of_one_render() {
    let tmp = temp_dir("sppm-checkpoint");
    let dir = tmp.path();
    let mut args = cornell_args("64", "150");
    args.extend(["--integrator", "sppm", "--sppm-photons", "1500"].map(String::from));
    let run = |extra: &[&str]| {
        plenum()
            .current_dir(dir)
            .arg("render")
            .args(&args)
            .args(extra)
            .output()
            .unwrap()
    };
    let o = run(&["-o", "reference.pfm"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let reference = std::fs::read(dir.join("reference.pfm")).unwrap();

    let o = run(&[
        "-o",
        "out.pfm",
        "--time-limit",
        "0.2",
        "--checkpoint-every",
        "0.05",
    ]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let checkpoint = dir.join("out.plf");
    assert!(checkpoint.exists());
    let partial = std::fs::read(dir.join("out.pfm")).unwrap();
    assert!(partial != reference, "the time limit stopped it early");
    let o = plenum()
        .current_dir(dir)
        .args(["render", "--resume", "out.plf"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(dir.join("out.pfm")).unwrap() == reference);
    assert!(!checkpoint.exists());

    let o = run(&["-o", "part.plf", "--samples", "0..2"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("cannot split integrator `sppm`"),
        "{}",
        stderr(&o)
    );
}

/// Sample ranges rendered apart (as a farm's tasks would) and merged give the bytes of one
/// render, for the path tracer and for light tracing, whose splats land in other pixels;
/// overlaps, gaps, other settings and adaptive sampling are refused.
#[test]
fn sample_ranges_merge_to_the_bytes_of_one_render() {
    let tmp = temp_dir("merge");
    let dir = tmp.path();
    let run = |args: &[String], extra: &[&str]| {
        plenum()
            .current_dir(dir)
            .arg("render")
            .args(args)
            .args(extra)
            .output()
            .unwrap()
    };
    let merge = |extra: &[&str]| {
        plenum()
            .current_dir(dir)
            .arg("merge")
            .args(extra)
            .output()
            .unwrap()
    };
    for method in ["path", "light"] {
        let mut args = cornell_args("40", "12");
        args.extend(["--integrator", method, "--filter", "mitchell"].map(String::from));
        let o = run(&args, &["-o", "whole.pfm"]);
        assert!(o.status.success(), "{}", stderr(&o));
        for (range, name) in [("0..5", "a.plf"), ("5..6", "b.plf"), ("6..12", "c.plf")] {
            let o = run(&args, &["--samples", range, "-o", name]);
            assert!(o.status.success(), "{}", stderr(&o));
        }
        let o = merge(&["c.plf", "a.plf", "b.plf", "-o", "merged.pfm"]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            std::fs::read(dir.join("merged.pfm")).unwrap()
                == std::fs::read(dir.join("whole.pfm")).unwrap(),
            "{method}: merged parts differ from one render"
        );
        // Merged in two levels: a film of films.
        let o = merge(&["a.plf", "b.plf", "-o", "ab.plf"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let o = merge(&["ab.plf", "c.plf", "-o", "merged2.pfm"]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            std::fs::read(dir.join("merged2.pfm")).unwrap()
                == std::fs::read(dir.join("whole.pfm")).unwrap()
        );

        let refused = |o: Output, says: &str| {
            assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
            assert!(stderr(&o).contains(says), "{}", stderr(&o));
        };
        refused(
            merge(&["a.plf", "c.plf", "-o", "x.pfm"]),
            "5..6 are missing",
        );
        refused(merge(&["a.plf", "ab.plf", "-o", "x.pfm"]), "overlap");
        let o = run(
            &args,
            &["--samples", "5..6", "--seed", "7", "-o", "other.plf"],
        );
        assert!(o.status.success(), "{}", stderr(&o));
        refused(
            merge(&["a.plf", "other.plf", "c.plf", "-o", "x.pfm"]),
            "different settings",
        );
        refused(
            run(&args, &["--samples", "0..13", "-o", "x.plf"]),
            "beyond the 12 samples",
        );
        refused(
            run(&args, &["--samples", "0..4", "-o", "x.png"]),
            "name the output .plf",
        );
    }
    let args = cornell_args("40", "12");
    let o = run(
        &args,
        &["--sampler", "adaptive", "--samples", "0..4", "-o", "x.plf"],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("adaptive"), "{}", stderr(&o));
}

/// Whether the farm tests must run (`.ci/run` sets it, having installed Slurm and Dask):
/// then a missing tool fails them instead of skipping them.
fn farm_required() -> bool {
    std::env::var("PLENUM_REQUIRE_FARM").is_ok_and(|v| v == "1")
}

fn skip_farm(what: &str) {
    assert!(!farm_required(), "{what} (PLENUM_REQUIRE_FARM=1)");
    eprintln!("skipped: {what}");
}

/// Stops the one-node cluster when the test ends, passed or not.
struct Cluster(PathBuf);

impl Drop for Cluster {
    fn drop(&mut self) {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../farm/one-node-cluster.sh");
        let _ = Command::new("bash")
            .arg(script)
            .arg("stop")
            .arg(&self.0)
            .output();
    }
}

/// The farm scripts end to end: a Slurm job array on a one-node cluster the test starts
/// itself (munged, slurmctld, slurmd), then its merge job (afterok); and a Dask local
/// cluster. Each merged image has the bytes of one render.
#[test]
fn slurm_and_dask_renders_merge_to_the_bytes_of_one_render() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let farm = root.join("farm");
    let tmp = temp_dir("farm");
    let dir = tmp.path();
    let bin = env!("CARGO_BIN_EXE_plenum");
    let scene = root.join("scenes/cornell-box.toml");
    let options = [
        "--width",
        "48",
        "--height",
        "48",
        "--color",
        "rgb",
        "--integrator",
        "bdpt",
        "--threads",
        "1",
    ];
    let o = plenum()
        .arg("render")
        .arg(&scene)
        .args(["--spp", "12", "--quiet", "-o"])
        .arg(dir.join("one.pfm"))
        .args(options)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let one = std::fs::read(dir.join("one.pfm")).unwrap();

    let root_user = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.starts_with(b"0\n"));
    let have = |p: &str| {
        Path::new("/usr/sbin").join(p).exists()
            || Command::new("which")
                .arg(p)
                .output()
                .is_ok_and(|o| o.status.success())
    };
    if !(root_user && have("slurmctld") && have("slurmd") && have("munged") && have("sbatch")) {
        skip_farm("Slurm (slurm-wlm, munge, as root) is not here");
    } else {
        let cluster_dir = dir.join("cluster");
        let o = Command::new("bash")
            .arg(farm.join("one-node-cluster.sh"))
            .arg("start")
            .arg(&cluster_dir)
            .output()
            .unwrap();
        let _cluster = Cluster(cluster_dir.clone());
        assert!(
            o.status.success(),
            "the cluster did not start: {}",
            stderr(&o)
        );
        let o = Command::new("bash")
            .env("SLURM_CONF", cluster_dir.join("slurm.conf"))
            .current_dir(dir)
            .arg(farm.join("slurm-render.sh"))
            .args(["-w", "-p", "3", "-b", bin])
            .arg(&scene)
            .args(["slurm.pfm", "12"])
            .args(options)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            stderr(&o)
        );
        assert!(String::from_utf8_lossy(&o.stdout).contains("3 parts"));
        assert!(
            std::fs::read(dir.join("slurm.pfm")).unwrap() == one,
            "Slurm's merged image differs"
        );
        for i in 0..3 {
            assert!(dir.join(format!("slurm.parts/part-{i}.plf")).exists());
        }
    }

    let dask = Command::new("python3")
        .args(["-c", "import dask.distributed"])
        .output();
    if !dask.is_ok_and(|o| o.status.success()) {
        skip_farm("Dask (pip dask[distributed]) is not here");
    } else {
        let o = Command::new("python3")
            .current_dir(dir)
            .arg(farm.join("dask_render.py"))
            .arg(&scene)
            .args([
                "dask.pfm",
                "12",
                "--parts",
                "4",
                "--workers",
                "2",
                "--plenum",
                bin,
                "--",
            ])
            .args(options)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            stderr(&o)
        );
        assert!(
            std::fs::read(dir.join("dask.pfm")).unwrap() == one,
            "Dask's merged image differs"
        );
    }
}

/// `--aov variance` writes NAME.variance.EXT beside the output (positive where the image is
/// noisy); it is refused, exit 2, where pixels are not their own samples' mean.
#[test]
fn the_variance_aov_is_written_beside_the_image() {
    let tmp = temp_dir("aov");
    let dir = tmp.path();
    let args = cornell_args("16", "8");
    let o = plenum()
        .current_dir(dir)
        .arg("render")
        .args(&args)
        .args(["--aov", "variance", "-o", "out.pfm"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let v = plenum_image::read_float_image(&dir.join("out.variance.pfm")).unwrap();
    assert_eq!((v.width, v.height), (16, 16));
    assert!(v
        .pixels
        .iter()
        .all(|p| p.iter().all(|c| *c >= 0.0 && c.is_finite())));
    assert!(v.pixels.iter().any(|p| p[0] > 0.0));
    for (extra, says) in [
        (
            &["--integrator", "bdpt"][..],
            "not available with integrator `bdpt`",
        ),
        (
            &["--integrator", "sppm"][..],
            "not available with integrator `sppm`",
        ),
        (&["-o", "x.plf"][..], "writes an image"),
    ] {
        assert_refused(
            dir,
            &[&args[..], &["--aov".into(), "variance".into()]].concat(),
            extra,
            says,
        );
    }
}

/// `plenum render ARGS EXTRA`, run in `dir`, is refused: exit 2, and the error says `says`.
fn assert_refused(dir: &Path, args: &[String], extra: &[&str], says: &str) {
    let o = plenum()
        .current_dir(dir)
        .arg("render")
        .args(args)
        .args(extra)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
    assert!(stderr(&o).contains(says), "{extra:?}: {}", stderr(&o));
}

/// `--crop` renders a part of the image: in pixels, or in fractions as pbrt's crop window,
/// each pixel the whole render's (PFM, bit for bit); a crop outside the image, a malformed
/// one and one under BDPT are refused, exit 2.
#[test]
fn a_crop_renders_part_of_the_image_as_the_whole_render_does() {
    let tmp = temp_dir("crop");
    let dir = tmp.path();
    let args = cornell_args("16", "4");
    let run = |extra: &[&str]| {
        plenum()
            .current_dir(dir)
            .arg("render")
            .args(&args)
            .args(extra)
            .output()
            .unwrap()
    };
    let o = run(&["-o", "whole.pfm"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let whole = plenum_image::read_float_image(&dir.join("whole.pfm")).unwrap();
    for (crop, (x0, y0, w, h)) in [
        ("4,12,2,7", (4, 2, 8, 5)),
        ("0.25,0.5,0.5,1.0", (4, 8, 4, 8)),
    ] {
        let o = run(&["--crop", crop, "-o", "part.pfm"]);
        assert!(o.status.success(), "{crop}: {}", stderr(&o));
        let part = plenum_image::read_float_image(&dir.join("part.pfm")).unwrap();
        assert_eq!((part.width, part.height), (w, h), "{crop}");
        for y in 0..h {
            for x in 0..w {
                assert_eq!(
                    part.pixels[(y * w + x) as usize],
                    whole.pixels[((y + y0) * 16 + x + x0) as usize],
                    "{crop}: pixel ({}, {})",
                    x + x0,
                    y + y0
                );
            }
        }
    }
    for (extra, says) in [
        (
            &["--crop", "0,17,0,4"][..],
            "is not a part of the 16×16 image",
        ),
        (
            &["--crop", "4,4,0,4"][..],
            "is not a part of the 16×16 image",
        ),
        (&["--crop", "1,2,3"][..], "expected X0,X1,Y0,Y1"),
        (&["--crop", "0.5,1.5,0,1"][..], "expected X0,X1,Y0,Y1"),
        (
            &["--crop", "0,8,0,8", "--integrator", "bdpt"][..],
            "integrator `bdpt` cannot render a part of the image",
        ),
    ] {
        assert_refused(dir, &args, extra, says);
    }
}

/// `--aov rays,spp,depth,cost,normal,albedo,position` beside the image: the rays per pixel
/// add up to the summary line's (camera, shadow, reflection, refraction), the camera rays
/// per pixel are the samples, the deepest bounce within `max_depth`, the node visits and
/// primitive tests per pixel add up to the summary line's; the first-hit views are of the
/// image's size, the normals unit length, the albedo within [0, 1]; a PNG's view says what
/// its white (or its false colour) stands for. An unknown view, and rays under SPPM, are
/// refused, exit 2.
#[test]
fn the_views_of_where_the_work_goes_add_up_to_the_render() {
    let tmp = temp_dir("views");
    let dir = tmp.path();
    let args: Vec<String> = cornell_args("12", "4")
        .into_iter()
        .filter(|a| a != "--quiet")
        .collect();
    let o = plenum()
        .current_dir(dir)
        .arg("render")
        .args(&args)
        .args(["--integrator", "path", "--max-depth", "5"])
        .args(["--aov", "rays,spp,depth,cost,normal,albedo,position"])
        .args(["-o", "out.pfm"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let rays_line = err
        .split("rays: ")
        .nth(1)
        .and_then(|s| s.split(';').next())
        .unwrap_or_else(|| panic!("no summary: {err}"));
    let summary: f64 = rays_line
        .split(", ")
        .map(|part| part.split(' ').next().unwrap().parse::<f64>().unwrap())
        .sum();
    let read =
        |view: &str| plenum_image::read_float_image(&dir.join(format!("out.{view}.pfm"))).unwrap();
    let rays = read("rays");
    assert_eq!((rays.width, rays.height), (12, 12));
    let per_pixel: f64 = rays.pixels.iter().map(|p| p[0] as f64).sum();
    assert_eq!(per_pixel, summary, "{err}");
    assert!(read("spp").pixels.iter().all(|p| p[0] == 4.0));
    // The cost view: node visits, primitive tests and their sum, summing to the summary's.
    let said = |what: &str| -> f64 {
        let before = err.split(what).next().unwrap();
        before.rsplit(' ').next().unwrap().parse().unwrap()
    };
    let cost = read("cost");
    let channel = |k: usize| -> f64 { cost.pixels.iter().map(|p| p[k] as f64).sum() };
    let (nodes, tests) = (said(" node visits"), said(" primitive tests"));
    assert!(nodes > 0.0 && tests > 0.0, "{err}");
    assert_eq!((channel(0), channel(1)), (nodes, tests), "{err}");
    assert_eq!(channel(2), nodes + tests);
    let depth = read("depth");
    assert!(depth
        .pixels
        .iter()
        .all(|p| p[0] <= 5.0 && p[0].fract() == 0.0));
    assert!(
        depth.pixels.iter().any(|p| p[0] >= 2.0),
        "paths bounce in the box"
    );
    for n in read("normal").pixels {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!(len < 1.0001, "{n:?}");
    }
    assert!(read("albedo")
        .pixels
        .iter()
        .flatten()
        .all(|c| (0.0..=1.0001).contains(c)));
    assert_eq!(read("position").pixels.len(), 144);
    // An EXR holds the views as its layers, the image as its R, G, B.
    let o = plenum()
        .current_dir(dir)
        .arg("render")
        .args(&args)
        .args(["--integrator", "path", "--max-depth", "5"])
        .args(["--aov", "rays,cost,normal", "-o", "out.exr"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("out.exr: the views are its layers rays.Y, cost.R/G/B, normal.R/G/B"),
        "{}",
        stderr(&o)
    );
    let (w, h, channels) = plenum_image::read_exr_channels(&dir.join("out.exr")).unwrap();
    assert_eq!((w, h), (12, 12));
    let channel = |n: &str| -> f64 {
        let c = channels
            .iter()
            .find(|c| c.0 == n)
            .unwrap_or_else(|| panic!("no {n}"));
        c.1.iter().map(|&v| v as f64).sum()
    };
    assert_eq!(channel("rays.Y"), summary);
    // The same render as the PFM's: the same rays, the same cost.
    assert_eq!((channel("cost.R"), channel("cost.G")), (nodes, tests));
    let image = plenum_image::read_float_image(&dir.join("out.exr")).unwrap();
    let pfm = plenum_image::read_float_image(&dir.join("out.pfm")).unwrap();
    assert_eq!(image.pixels, pfm.pixels, "the same render's image");
    assert!(!dir.join("out.rays.exr").exists());
    let o = plenum()
        .current_dir(dir)
        .arg("render")
        .args(&args)
        .args([
            "--aov",
            "rays,normal,cost",
            "--aov-max",
            "5000",
            "-o",
            "out.png",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("out.rays.png: black 0, white 5000 rays per pixel"),
        "{}",
        stderr(&o)
    );
    assert_eq!(image_size(&dir.join("out.normal.png")), (12, 12));
    assert!(
        stderr(&o).contains("out.cost.png: false colour from black (0)"),
        "{}",
        stderr(&o)
    );
    for (extra, says) in [
        (&["--aov", "rays,depht"][..], "unknown view `depht`"),
        (
            &["--aov", "normal", "--aov-max", "9"][..],
            "--aov-max sets the scale",
        ),
        (
            &["--aov", "rays", "--aov-max", "0"][..],
            "expected a whole number ≥ 1",
        ),
        (
            &["--aov", "rays", "--integrator", "sppm"][..],
            "not available with integrator `sppm`",
        ),
    ] {
        assert_refused(dir, &args, extra, says);
    }
}

/// `trace-pixel --svg` draws the tree: well-formed SVG, one line per ray of the tree (in
/// each of its two panels where the camera sees it), titled by kind, a legend of the kinds,
/// the objects it passes; a file it cannot write is an error, exit 1.
#[test]
fn trace_pixel_draws_the_tree_as_a_figure() {
    let tmp = temp_dir("svg");
    let dir = tmp.path();
    let base = [
        "trace-pixel",
        "-",
        "32",
        "24",
        "--width",
        "64",
        "--height",
        "48",
    ];
    let o = plenum()
        .current_dir(dir)
        .args(base)
        .args(["--json", "--svg", "tree.svg"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rays = doc["rays"].as_array().unwrap().len();
    let svg = std::fs::read_to_string(dir.join("tree.svg")).unwrap();
    let xml = roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{e}\n{svg}"));
    let titled: Vec<String> = xml
        .descendants()
        .filter(|n| n.has_tag_name("line"))
        .filter_map(|n| n.children().find(|c| c.has_tag_name("title")))
        .filter_map(|t| t.text().map(str::to_string))
        .filter(|t| t.contains(" ray, depth "))
        .collect();
    // The side view shows every ray; the camera's view those in front of the lens.
    assert!(
        titled.len() > rays && titled.len() <= 2 * rays,
        "{rays} rays, {titled:?}"
    );
    assert!(titled.iter().any(|t| t.starts_with("refracted ray")));
    for legend in ["camera ray", "refracted ray", "glass sphere"] {
        assert!(svg.contains(legend), "no `{legend}` in the figure");
    }
    let o = plenum()
        .current_dir(dir)
        .args(base)
        .args(["--svg", "no/such/folder/tree.svg"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("cannot write"), "{}", stderr(&o));
}

/// docs/tutorial.sh makes every picture and tree docs/tutorial.md shows (run small here:
/// 32 × 24, the ladder at 16 × 16, into a temporary folder), and each is in docs/tutorial.
#[test]
fn the_tutorials_script_makes_every_picture_it_shows() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let tmp = temp_dir("tutorial");
    let o = Command::new("bash")
        .arg(root.join("docs/tutorial.sh"))
        .arg(env!("CARGO_BIN_EXE_plenum"))
        .envs([("W", "32"), ("H", "24"), ("LADDER", "16")])
        .env("OUT", tmp.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let page = std::fs::read_to_string(root.join("docs/tutorial.md")).unwrap();
    let shown: Vec<&str> = page
        .split("](tutorial/")
        .skip(1)
        .map(|rest| &rest[..rest.find(')').unwrap()])
        .collect();
    assert!(shown.len() > 40, "{shown:?}");
    for name in shown {
        assert!(
            tmp.path().join(name).is_file(),
            "the script makes no {name}"
        );
        assert!(
            root.join("docs/tutorial").join(name).is_file(),
            "docs/tutorial/{name} is not there: run docs/tutorial.sh"
        );
    }
}

/// Through an orthographic camera the methods that start at the camera render; light
/// tracing and BDPT, whose light paths cannot meet its one direction, are refused, exit 2.
#[test]
fn an_orthographic_camera_is_refused_by_light_tracing_and_bdpt() {
    let tmp = temp_dir("ortho");
    let dir = tmp.path();
    std::fs::write(
        dir.join("ortho.toml"),
        "[camera]\nposition = [0, 1, 5]\nlook_at = [0, 0, 0]\northographic = 3\nresolution = [16, 12]\n\
         [[lights]]\ntype = \"point\"\nposition = [2, 4, 3]\n\
         [materials.white]\ntype = \"diffuse\"\nreflectance = [0.8, 0.8, 0.8]\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"white\"\n",
    )
    .unwrap();
    let args: Vec<String> = ["ortho.toml", "--spp", "1", "--quiet"]
        .map(String::from)
        .to_vec();
    for method in ["path", "whitted", "photon"] {
        let o = plenum()
            .current_dir(dir)
            .arg("render")
            .args(&args)
            .args(["--integrator", method, "-o", "o.pfm"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{method}: {}", stderr(&o));
    }
    for method in ["light", "bdpt"] {
        assert_refused(
            dir,
            &args,
            &["--integrator", method, "-o", "o.pfm"],
            "cannot render through an orthographic camera",
        );
    }
}
