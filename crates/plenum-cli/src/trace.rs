//! `plenum trace-pixel`: the ray tree of one pixel, as text or JSON.

use crate::{load, settings, TracePixelArgs};
use plenum_core::accel::AccelKind;
use plenum_core::integrator::IntegratorKind;
use plenum_core::integrator::{RayNode, RayTree};
use plenum_core::render::{samples_per_pixel, trace_pixel, trace_sample, RenderSettings};
use plenum_core::scene::Scene;
use plenum_core::{Color, Vec3};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::io::Write as _;
use std::process::ExitCode;

pub fn run(args: TracePixelArgs) -> ExitCode {
    let mut loaded = match load(Some(&args.scene), AccelKind::Bvh) {
        Ok(l) => l,
        Err(code) => return code,
    };
    let settings = match settings(&args.view, &mut loaded) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let (w, h) = (settings.width, settings.height);
    if !(0..w as i64).contains(&args.x) || !(0..h as i64).contains(&args.y) {
        eprintln!(
            "error: pixel ({}, {}) is outside the {w}×{h} image: X must be from 0 to {}, Y from 0 to {}",
            args.x,
            args.y,
            w - 1,
            h - 1
        );
        return ExitCode::from(2);
    }
    let (x, y) = (args.x as u32, args.y as u32);
    let traced = match trace(&loaded.scene, &settings, (x, y), args.sample) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let mut out = String::new();
    if args.json {
        out = serde_json::to_string_pretty(&tree_json(&traced)).unwrap_or_default();
        out.push('\n');
    } else {
        let _ = writeln!(
            out,
            "pixel ({x}, {y}), {}: colour {}",
            traced.which(),
            fmt_color(traced.color)
        );
        let tree = &traced.tree;
        for l in &tree.wavelengths {
            let nm: Vec<String> = l.iter().map(|v| format!("{v:.1}")).collect();
            let _ = writeln!(out, "wavelengths {} nm", nm.join(", "));
        }
        for root in (0..tree.nodes.len()).filter(|&i| tree.nodes[i].parent.is_none()) {
            print_node(&mut out, tree, root, 0);
        }
        // BDPT and light tracing: what the listed strategies add up to, here and elsewhere.
        let strategies = tree.nodes.iter().filter_map(|n| Some((n, n.strategy?)));
        let (mut here, mut splatted_here, mut elsewhere, mut any) =
            (Color::BLACK, Color::BLACK, 0, false);
        for (n, s) in strategies {
            any = true;
            match s.splat {
                None => here += n.color,
                Some([rx, ry]) if (rx.floor(), ry.floor()) == (x as f64, y as f64) => {
                    splatted_here += n.color
                }
                Some(_) => elsewhere += 1,
            }
        }
        if any {
            let _ = writeln!(
                out,
                "the strategies of this sample add {} to its pixel, and {} more through the film's splats (t = 1); {elsewhere} more land in other pixels",
                fmt_color(here),
                fmt_color(splatted_here)
            );
        }
    }
    // A reader that stops early (`| head`) is not an error.
    let _ = std::io::stdout().lock().write_all(out.as_bytes());
    if let Some(path) = &args.svg {
        let svg = crate::figure::tree_svg(&loaded.scene, &settings, &traced);
        if let Err(e) = std::fs::write(path, svg) {
            eprintln!("error: cannot write {}: {e}", path.display());
            return ExitCode::from(1);
        }
    }
    ExitCode::SUCCESS
}

/// `--sample`: one sample of the pixel by its index, or all of them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum SampleArg {
    Index(u32),
    All,
}

impl std::str::FromStr for SampleArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "all" => Ok(SampleArg::All),
            _ => s.parse().map(SampleArg::Index).map_err(|_| {
                format!("expected a sample index (a whole number from 0) or `all`, not `{s}`")
            }),
        }
    }
}

/// A pixel's ray tree: of one sample, or of all of them.
pub(crate) struct Traced {
    pub pixel: (u32, u32),
    pub tree: RayTree,
    /// The sample's colour (before the filter weighs it), or the pixel's.
    pub color: Color,
    /// The sample traced, of how many; `None`: all of them.
    pub sample: Option<(u32, u32)>,
    /// Why all of the pixel was traced where one sample was asked for.
    pub whole: Option<&'static str>,
}

impl Traced {
    /// "sample K of N", or what else was traced.
    pub fn which(&self) -> String {
        match (self.sample, self.whole) {
            (Some((k, n)), _) => format!("sample {k} of {n} (counted from 0)"),
            (None, Some(why)) => format!("all its samples ({why})"),
            (None, None) => "all its samples".to_string(),
        }
    }
}

/// Traces sample `sample` of pixel (x, y) (the first if `None`), or all its samples where
/// asked or where the method's pixel is not a list of samples; an index beyond them is an
/// error.
pub(crate) fn trace(
    scene: &Scene,
    settings: &RenderSettings,
    (x, y): (u32, u32),
    sample: Option<SampleArg>,
) -> Result<Traced, String> {
    let spp = samples_per_pixel(settings);
    let whole = |why| {
        let (tree, color) = trace_pixel(scene, settings, x, y);
        Ok(Traced {
            pixel: (x, y),
            tree,
            color,
            sample: None,
            whole: why,
        })
    };
    let k = match (sample, spp) {
        (Some(SampleArg::All), _) => return whole(None),
        (_, None) => {
            let why = if settings.integrator.kind == IntegratorKind::Sppm {
                "SPPM's pixel is its iterations' photon statistics, not a list of samples"
            } else {
                "this pixel is its corner rays, not a list of samples"
            };
            return whole(Some(why));
        }
        (Some(SampleArg::Index(k)), _) => k,
        (None, _) => 0,
    };
    let n = spp.unwrap_or(0);
    match trace_sample(scene, settings, x, y, k) {
        Some((tree, color)) => Ok(Traced {
            pixel: (x, y),
            tree,
            color,
            sample: Some((k, n)),
            whole: None,
        }),
        None => Err(format!(
            "--sample {k} is beyond the pixel's {n} samples: give 0 to {}, or all",
            n.saturating_sub(1)
        )),
    }
}

/// A traced pixel as `--json` prints it.
pub(crate) fn tree_json(t: &Traced) -> Value {
    let (x, y) = t.pixel;
    json!({
        "pixel": [x, y],
        "sample": t.sample.map(|(k, _)| k),
        "samples": t.sample.map(|(_, n)| n),
        "traced": t.which(),
        "color": rgb(t.color),
        "wavelengths": t.tree.wavelengths,
        "rays": t.tree.nodes.iter().enumerate().map(|(i, n)| node_json(i, n)).collect::<Vec<_>>(),
    })
}

/// The photons of a density estimate the text listing shows; `--json` gives them all.
const PHOTONS_LISTED: usize = 8;

fn rgb(c: Color) -> Value {
    json!([c.r, c.g, c.b])
}

fn xyz(v: Vec3) -> Value {
    json!([v.x, v.y, v.z])
}

fn node_json(id: usize, n: &RayNode) -> Value {
    let mut v = json!({
        "id": id,
        "parent": n.parent,
        "kind": n.kind.name(),
        "depth": n.depth,
        "origin": xyz(n.origin),
        "direction": xyz(n.direction),
        "weight": rgb(n.weight),
        "object": n.object,
        "material": n.material,
        "distance": n.distance,
        "color": rgb(n.color),
        "stopped": n.stops.iter().map(|s| s.name()).collect::<Vec<_>>(),
        "total_internal_reflection": n.total_internal_reflection,
    });
    if let Some(s) = &n.strategy {
        v["strategy"] = json!({"s": s.s, "t": s.t, "mis_weight": s.mis_weight, "unweighted": rgb(s.unweighted), "splat": s.splat});
    }
    if let Some(g) = &n.photons {
        v["photons"] = json!({
            "source": g.source,
            "radius": g.radius,
            "estimate": rgb(g.estimate),
            "found": g.photons.iter().map(|p| json!({
                "position": xyz(p.position),
                "wi": xyz(p.wi),
                "power": rgb(p.power),
                "distance": p.distance,
            })).collect::<Vec<_>>(),
        });
    }
    if let Some(o) = &n.optics {
        v["optics"] = json!({
            "incidence_degrees": o.incidence,
            "eta": o.eta.map(|(a, b)| [a, b]),
            "refraction_degrees": o.refraction,
            "critical_degrees": o.critical,
            "fresnel_reflectance": o.fresnel,
        });
    }
    if !n.lights_behind.is_empty() {
        v["lights_behind"] = json!(n.lights_behind);
    }
    if let Some(s) = &n.shadow {
        v["light"] = json!(s.light);
        v["blocked"] = json!(s.blocked);
        v["occluders"] = json!(s.occluders);
        v["transmittance"] = rgb(s.transmittance);
    }
    v
}

fn fmt_color(c: Color) -> String {
    format!("({:.4}, {:.4}, {:.4})", c.r, c.g, c.b)
}

fn fmt_vec(v: Vec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
}

fn print_node(out: &mut String, tree: &RayTree, id: usize, indent: usize) {
    let n = &tree.nodes[id];
    let pad = "  ".repeat(indent);
    let head = format!(
        "{pad}{} ray (depth {}, weight {}) from {} along {}",
        n.kind.name(),
        n.depth,
        fmt_color(n.weight),
        fmt_vec(n.origin),
        fmt_vec(n.direction)
    );
    let _ = writeln!(out, "{head}");
    if let Some(s) = &n.shadow {
        let status = if s.blocked {
            format!("blocked by {}", s.occluders.join(", then "))
        } else if s.occluders.is_empty() {
            "unblocked".to_string()
        } else {
            format!("through {}", s.occluders.join(", then "))
        };
        let _ = writeln!(
            out,
            "{pad}  to light \"{}\" at distance {:.4}: {status}; S_L = {}",
            s.light,
            n.distance.unwrap_or(f64::INFINITY),
            fmt_color(s.transmittance)
        );
        return;
    }
    if let (Some(object), Some(material)) = (&n.object, &n.material) {
        let _ = writeln!(
            out,
            "{pad}  hit \"{object}\" (material \"{material}\") at distance {:.4}",
            n.distance.unwrap_or(0.0)
        );
    }
    if let Some(s) = &n.strategy {
        let _ = writeln!(
            out,
            "{pad}  strategy s = {}, t = {}: unweighted {}, MIS weight {:.4}{}",
            s.s,
            s.t,
            fmt_color(s.unweighted),
            s.mis_weight,
            match s.splat {
                Some([x, y]) => format!(
                    "; lands at raster ({x:.2}, {y:.2}), pixel ({}, {}), not in this sample",
                    x.floor(),
                    y.floor()
                ),
                None => String::new(),
            }
        );
    }
    if let Some(g) = &n.photons {
        let _ = writeln!(
            out,
            "{pad}  {}: {} photons within radius {:.5}, giving {}",
            g.source,
            g.photons.len(),
            g.radius,
            fmt_color(g.estimate)
        );
        for p in g.photons.iter().take(PHOTONS_LISTED) {
            let _ = writeln!(
                out,
                "{pad}    photon at {}, {:.5} away, arriving from {}, flux ({:.3e}, {:.3e}, {:.3e})",
                fmt_vec(p.position),
                p.distance,
                fmt_vec(p.wi),
                p.power.r,
                p.power.g,
                p.power.b
            );
        }
        if g.photons.len() > PHOTONS_LISTED {
            let more = g.photons.len() - PHOTONS_LISTED;
            let _ = writeln!(out, "{pad}    … {more} more (--json lists them all)");
        }
    }
    if let Some(o) = &n.optics {
        let mut line = format!("{pad}  angle of incidence {:.2}°", o.incidence);
        if let Some((a, b)) = o.eta {
            let _ = write!(line, "; η {a:.4} → {b:.4}");
        }
        if let Some(t) = o.refraction {
            let _ = write!(line, ", refracted at {t:.2}°");
        }
        if let Some(c) = o.critical {
            let _ = write!(line, ", critical angle {c:.2}°");
        }
        if let Some(f) = o.fresnel {
            let _ = write!(line, "; Fresnel reflectance {f:.4}");
        }
        let _ = writeln!(out, "{line}");
    }
    for light in &n.lights_behind {
        let _ = writeln!(
            out,
            "{pad}  light \"{light}\" is behind the surface: no shadow ray"
        );
    }
    if n.total_internal_reflection {
        let _ = writeln!(
            out,
            "{pad}  total internal reflection: the refracted weight goes to the reflected ray"
        );
    }
    for stop in &n.stops {
        let _ = writeln!(out, "{pad}  stopped: {}", stop.name());
    }
    let _ = writeln!(out, "{pad}  returned {}", fmt_color(n.color));
    for child in tree.children(id) {
        print_node(out, tree, child, indent + 1);
    }
}
