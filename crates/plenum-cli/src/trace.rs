//! `plenum trace-pixel`: the ray tree of one pixel, as text or JSON.

use crate::{load, settings, TracePixelArgs};
use plenum_core::accel::AccelKind;
use plenum_core::integrator::{RayNode, RayTree};
use plenum_core::render::trace_pixel;
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
    let (tree, color) = trace_pixel(&loaded.scene, &settings, x, y);
    let mut out = String::new();
    if args.json {
        out = serde_json::to_string_pretty(&tree_json((x, y), &tree, color)).unwrap_or_default();
        out.push('\n');
    } else {
        let _ = writeln!(out, "pixel ({x}, {y}): colour {}", fmt_color(color));
        for root in (0..tree.nodes.len()).filter(|&i| tree.nodes[i].parent.is_none()) {
            print_node(&mut out, &tree, root, 0);
        }
    }
    // A reader that stops early (`| head`) is not an error.
    let _ = std::io::stdout().lock().write_all(out.as_bytes());
    ExitCode::SUCCESS
}

/// The ray tree of pixel (x, y) and its colour, as `--json` prints it.
pub(crate) fn tree_json((x, y): (u32, u32), tree: &RayTree, color: Color) -> Value {
    json!({
        "pixel": [x, y],
        "color": rgb(color),
        "rays": tree.nodes.iter().enumerate().map(|(i, n)| node_json(i, n)).collect::<Vec<_>>(),
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
        v["strategy"] = json!({"s": s.s, "t": s.t, "mis_weight": s.mis_weight, "unweighted": rgb(s.unweighted)});
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
            "{pad}  strategy s = {}, t = {}: unweighted {}, MIS weight {:.4}",
            s.s,
            s.t,
            fmt_color(s.unweighted),
            s.mis_weight
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
