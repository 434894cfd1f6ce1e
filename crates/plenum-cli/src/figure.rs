//! `trace-pixel --svg`: a pixel's ray tree as a figure for slides. Two panels: the rays as
//! the camera sees them, over the outline of the image, and the same rays seen from the
//! side (depth along the camera's axis across, its up direction up), over the outlines of
//! the objects they pass (each bounded object's box, each infinite plane's trace); every
//! ray coloured and labelled by kind, hits marked, rays that leave the scene drawn on
//! past it with an arrow.

use crate::trace::Traced;
use plenum_core::camera::Camera;
use plenum_core::geometry::Shape;
use plenum_core::integrator::{RayKind, RayNode};
use plenum_core::render::RenderSettings;
use plenum_core::scene::Scene;
use plenum_core::Vec3;
use std::fmt::Write as _;

/// Each panel's size, in SVG units.
const PANEL: (f64, f64) = (480.0, 360.0);
const GAP: f64 = 20.0;

/// Where the ray of `node` ends: its hit, or (one that met nothing) far past the scene.
pub fn ray_end(scene: &Scene, node: &RayNode) -> (Vec3, bool) {
    let far = 4.0 * scene.geometry.radius().max(1e-3);
    let d = node.direction.normalized();
    match node.distance.filter(|t| t.is_finite()) {
        Some(t) => (node.origin + d * t, true),
        None => {
            let length = far + (node.origin - scene.camera.position).length();
            (node.origin + d * length, false)
        }
    }
}

/// The stroke of a ray of `kind`: colour and dash pattern.
fn stroke(kind: RayKind) -> (&'static str, &'static str) {
    match kind {
        RayKind::Camera => ("#222222", ""),
        RayKind::Reflected => ("#1f5fbf", ""),
        RayKind::Refracted => ("#1a9850", ""),
        RayKind::Shadow => ("#e08214", "6 4"),
        RayKind::Light => ("#c9a100", ""),
        RayKind::Connection => ("#8e44ad", "3 3"),
        RayKind::Photon => ("#c0392b", ""),
    }
}

/// Escapes text for SVG.
fn text(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The figure of `traced` (a tree of `scene` rendered with `settings`), as SVG.
pub fn tree_svg(scene: &Scene, settings: &RenderSettings, traced: &Traced) -> String {
    let (w, h) = (settings.width as f64, settings.height as f64);
    let camera = Camera::new(&scene.camera, settings.width, settings.height);
    let nodes = &traced.tree.nodes;
    let ends: Vec<(Vec3, bool)> = nodes.iter().map(|n| ray_end(scene, n)).collect();
    let mut out = String::new();
    let total_w = 2.0 * PANEL.0 + 3.0 * GAP;
    let total_h = PANEL.1 + 2.0 * GAP + 60.0;
    let _ = writeln!(
        out,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{total_w}" height="{total_h}" viewBox="0 0 {total_w} {total_h}" font-family="sans-serif" font-size="11">"##
    );
    let _ = writeln!(
        out,
        r##"<defs><marker id="arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="6" markerHeight="6" orient="auto-start-reverse"><path d="M 0 0 L 10 5 L 0 10 z" fill="context-stroke"/></marker><clipPath id="camera-panel"><rect x="0" y="0" width="{}" height="{}"/></clipPath><clipPath id="side-panel"><rect x="0" y="0" width="{}" height="{}"/></clipPath></defs>"##,
        PANEL.0, PANEL.1, PANEL.0, PANEL.1
    );
    let (x, y) = traced.pixel;
    let _ = writeln!(
        out,
        r##"<text x="{GAP}" y="14" font-size="13">pixel ({x}, {y}), {}: seen from the camera, and from the side</text>"##,
        text(&traced.which())
    );

    // Seen from the camera: raster coordinates, the image fitted into the panel.
    let s = (PANEL.0 / w).min(PANEL.1 / h);
    let (ox, oy) = (GAP, 2.0 * GAP);
    let _ = writeln!(
        out,
        r##"<g transform="translate({ox} {oy})"><rect x="0" y="0" width="{}" height="{}" fill="#f7f7f7" stroke="#999"/><g clip-path="url(#camera-panel)">"##,
        w * s,
        h * s
    );
    let _ = writeln!(
        out,
        r##"<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="#d00" stroke-width="1.5"/>"##,
        x as f64 * s,
        y as f64 * s,
        s.max(3.0),
        s.max(3.0)
    );
    for (n, &(end, hit)) in nodes.iter().zip(&ends) {
        if let Some((a, b)) = camera.project_segment(n.origin, end) {
            let (a, b) = ([a[0] * s, a[1] * s], [b[0] * s, b[1] * s]);
            segment(&mut out, n, a, b, hit);
        }
    }
    let _ = writeln!(out, "</g></g>");

    // Seen from the side: across, depth along the camera's axis; up, its up direction.
    let eye = camera.position();
    let forward = camera.ray(w / 2.0, h / 2.0).direction.normalized();
    let top = camera.ray(w / 2.0, 0.0).direction.normalized();
    let bottom = camera.ray(w / 2.0, h).direction.normalized();
    let up = {
        let u = top - bottom;
        (u - forward * u.dot(forward)).normalized()
    };
    let view = SideView { eye, forward, up };
    let side = |p: Vec3| view.at(p);
    let mut points: Vec<[f64; 2]> = vec![[0.0, 0.0]];
    for (n, &(end, hit)) in nodes.iter().zip(&ends) {
        points.push(side(n.origin));
        // An escaped ray's far end would squeeze the rest: the frame holds its start.
        if hit {
            points.push(side(end));
        }
    }
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in &points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-6);
    let (lo, hi) = (
        [lo[0] - 0.15 * span, lo[1] - 0.15 * span],
        [hi[0] + 0.15 * span, hi[1] + 0.15 * span],
    );
    let k = (PANEL.0 / (hi[0] - lo[0])).min(PANEL.1 / (hi[1] - lo[1]));
    let to_panel = |p: [f64; 2]| [(p[0] - lo[0]) * k, PANEL.1 - (p[1] - lo[1]) * k];
    let (sx, sy) = (2.0 * GAP + PANEL.0, 2.0 * GAP);
    let _ = writeln!(
        out,
        r##"<g transform="translate({sx} {sy})"><rect x="0" y="0" width="{}" height="{}" fill="#f7f7f7" stroke="#999"/><g clip-path="url(#side-panel)">"##,
        PANEL.0, PANEL.1
    );
    objects(&mut out, scene, &view, &to_panel);
    // The camera: a small wedge opening along its axis.
    let c = to_panel([0.0, 0.0]);
    let _ = writeln!(
        out,
        r##"<path d="M {} {} L {} {} L {} {} z" fill="#444"/><text x="{}" y="{}" fill="#444">camera</text>"##,
        c[0],
        c[1],
        c[0] + 14.0,
        c[1] - 7.0,
        c[0] + 14.0,
        c[1] + 7.0,
        c[0] - 4.0,
        c[1] + 20.0
    );
    for (n, &(end, hit)) in nodes.iter().zip(&ends) {
        segment(
            &mut out,
            n,
            to_panel(side(n.origin)),
            to_panel(side(end)),
            hit,
        );
    }
    let _ = writeln!(out, "</g></g>");

    // The legend: the kinds in this tree.
    let mut kinds: Vec<RayKind> = Vec::new();
    for n in nodes {
        if !kinds.contains(&n.kind) {
            kinds.push(n.kind);
        }
    }
    let ly = 3.0 * GAP + PANEL.1;
    for (i, kind) in kinds.iter().enumerate() {
        let (colour, dash) = stroke(*kind);
        let lx = GAP + 120.0 * i as f64;
        let _ = writeln!(
            out,
            r##"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{colour}" stroke-width="2" stroke-dasharray="{dash}"/><text x="{}" y="{}">{} ray</text>"##,
            lx + 28.0,
            lx + 34.0,
            ly + 4.0,
            kind.name()
        );
    }
    let _ = writeln!(
        out,
        r##"<text x="{GAP}" y="{}" fill="#666">dots: hits; arrows: rays that leave the scene; red square: the pixel</text>"##,
        ly + 24.0
    );
    out.push_str("</svg>\n");
    out
}

/// One ray from `a` to `b` (panel coordinates): a line of its kind's stroke, a dot where
/// it hit, an arrow where it left, and its kind and depth at its middle.
fn segment(out: &mut String, n: &RayNode, a: [f64; 2], b: [f64; 2], hit: bool) {
    let (colour, dash) = stroke(n.kind);
    let marker = if hit {
        ""
    } else {
        r##" marker-end="url(#arrow)""##
    };
    let name = n.object.as_deref().map(text).unwrap_or_default();
    let _ = writeln!(
        out,
        r##"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="{colour}" stroke-width="1.5" stroke-dasharray="{dash}"{marker}><title>{} ray, depth {}{}{}</title></line>"##,
        a[0],
        a[1],
        b[0],
        b[1],
        n.kind.name(),
        n.depth,
        if name.is_empty() { "" } else { ", hit " },
        name
    );
    if hit {
        let _ = writeln!(
            out,
            r##"<circle cx="{:.2}" cy="{:.2}" r="2.5" fill="{colour}"/>"##,
            b[0], b[1]
        );
    }
    let _ = writeln!(
        out,
        r##"<text x="{:.2}" y="{:.2}" fill="{colour}" font-size="9">{}{}</text>"##,
        0.5 * (a[0] + b[0]) + 3.0,
        0.5 * (a[1] + b[1]) - 3.0,
        n.kind.name(),
        n.depth
    );
}

/// The side panel's projection: across, depth along the camera's axis; up, its up
/// direction; the camera at the origin.
struct SideView {
    eye: Vec3,
    forward: Vec3,
    up: Vec3,
}

impl SideView {
    fn at(&self, p: Vec3) -> [f64; 2] {
        [
            (p - self.eye).dot(self.forward),
            (p - self.eye).dot(self.up),
        ]
    }
}

/// The side panel's objects: each bounded object's box (its corners' extent in the side
/// view), named, and each untransformed infinite plane's trace in the side view's plane.
fn objects(
    out: &mut String,
    scene: &Scene,
    view: &SideView,
    to_panel: &impl Fn([f64; 2]) -> [f64; 2],
) {
    let geometry = &scene.geometry;
    for (i, p) in geometry.primitives.iter().enumerate() {
        let name = text(&geometry.names[i]);
        if let Some(b) = p.world_bounds() {
            let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
            for c in 0..8 {
                let corner = Vec3::new(
                    if c & 1 == 0 { b.min.x } else { b.max.x },
                    if c & 2 == 0 { b.min.y } else { b.max.y },
                    if c & 4 == 0 { b.min.z } else { b.max.z },
                );
                let q = to_panel(view.at(corner));
                for k in 0..2 {
                    lo[k] = lo[k].min(q[k]);
                    hi[k] = hi[k].max(q[k]);
                }
            }
            let _ = writeln!(
                out,
                r##"<rect x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="#e8e8e8" stroke="#aaa"/><text x="{:.2}" y="{:.2}" fill="#777" font-size="9">{name}</text>"##,
                lo[0],
                lo[1],
                hi[0] - lo[0],
                hi[1] - lo[1],
                lo[0] + 2.0,
                lo[1] + 10.0
            );
        } else if let (Shape::Plane(plane), None) = (&p.shape, p.to_world.as_deref()) {
            // The points eye + a·forward + b·up on the plane: a line a·(n·forward) +
            // b·(n·up) = n·(point − eye), drawn through two of its points far apart.
            let n = plane.normal;
            let (na, nb) = (n.dot(view.forward), n.dot(view.up));
            // A plane parallel to the view's plane has no trace in it.
            if na.abs().max(nb.abs()) < 1e-9 {
                continue;
            }
            let c = n.dot(plane.point - view.eye);
            let far = 1e6;
            let ends = if nb.abs() >= na.abs() {
                [[-far, (c + na * far) / nb], [far, (c - na * far) / nb]]
            } else {
                [[(c + nb * far) / na, -far], [(c - nb * far) / na, far]]
            };
            let (a, b) = (to_panel(ends[0]), to_panel(ends[1]));
            let _ = writeln!(
                out,
                r##"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="#aaa" stroke-width="2"><title>{name}</title></line>"##,
                a[0], a[1], b[0], b[1]
            );
        }
    }
}
