//! Eric Haines' Neutral File Format, as the Standard Procedural Databases write it (Haines,
//! "A Proposal for Standard Graphics Environments", IEEE CG&A 1987; notes in
//! shared/design/formats/nff.md). Read by whitespace tokens, not lines: a record's numbers
//! may continue on following lines.
//!
//! How NFF maps onto Plenum:
//! - `v`: the view. `angle` spans the outermost pixel *centres*, so the camera's edge-to-edge
//!   field of view is widened by W/(W−1); with `--nff-corners` the corner rays span `angle`.
//! - `l`: point lights, each of intensity √n/(2n) for n lights, and the same ambient light.
//! - `f colour Kd Ks Shine T ior`: k_d = k_a = Kd·colour; Ks is the Phong k_s and the mirror
//!   k_r; a Shine of 10⁵ or more means no highlight; k_t = T; an ior ≤ 0 means 1.
//! - `c`: open cones and cylinders (negative radii: only the inside shows); `s`: spheres
//!   (negative radius: inside only); `p`: polygons, concave allowed; `pp`: polygons with a
//!   normal per vertex, fanned into a smooth triangle mesh. Polygons are two-sided.
//! - Recursion as the SPD procedure asks: depth 5 counting the eye ray (4 bounces), no
//!   weight cut-off.

use crate::diagnostics::SceneError;
use crate::limits::check_count;
use crate::RenderDefaults;
use plenum_core::camera::CameraSettings;
use plenum_core::color::Color;
use plenum_core::geometry::{Cone, Polygon, Shape, Sphere, TriangleMesh};
use plenum_core::light::{Attenuation, Light};
use plenum_core::material::PhongMaterial;
use plenum_core::math::{Transform, Vec3};
use plenum_core::scene::{MaterialId, SceneBuilder};
use plenum_core::texture::Texture;
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

/// Parses NFF text into a scene and its render settings.
pub fn parse(path: &Path, text: &str) -> Result<(SceneBuilder, RenderDefaults), SceneError> {
    let mut p = Parser {
        path,
        text,
        tokens: tokens(text).peekable(),
        last: 0..0,
    };
    let mut builder = SceneBuilder::default();
    let mut defaults = RenderDefaults {
        width: 512,
        height: 512,
        max_depth: 4,
        min_weight: 0.0,
        ..RenderDefaults::default()
    };
    let mut lights: Vec<Vec3> = Vec::new();
    let mut light_colors: Vec<Option<Color>> = Vec::new();
    let mut material: Option<MaterialId> = None;
    let mut patches = PatchMesh::default();
    let mut counts = [0usize; 4];
    let mut saw_view = false;
    while let Some((keyword, span)) = p.tokens.next() {
        p.last = span.clone();
        match keyword {
            "v" => {
                let (camera, angle, w, h) = p.view()?;
                builder.camera = camera;
                defaults.width = w;
                defaults.height = h;
                defaults.nff_angle = Some(angle);
                saw_view = true;
            }
            "b" => builder.background = p.color()?,
            "l" => {
                lights.push(p.vec3()?);
                // An optional colour: three more numbers, if a number follows.
                let color = if p.next_is_number() {
                    Some(p.color()?)
                } else {
                    None
                };
                light_colors.push(color);
            }
            "f" => {
                let color = p.color()?;
                let [kd, ks, shine, t, ior] = p.numbers::<5>()?;
                let m = PhongMaterial {
                    emissive: Texture::Constant(Color::BLACK),
                    ambient: Texture::Constant(color * kd),
                    diffuse: Texture::Constant(color * kd),
                    specular: Texture::Constant(if shine >= 1e5 {
                        Color::BLACK
                    } else {
                        Color::gray(ks)
                    }),
                    shininess: shine.max(0.0),
                    reflective: Texture::Constant(Color::gray(ks)),
                    transmissive: Texture::Constant(Color::gray(t)),
                    ior: if ior > 0.0 { ior } else { 1.0 },
                    fresnel: false,
                    gloss: None,
                };
                let id = builder.add_material(format!("f{}", counts[3] + 1), m);
                counts[3] += 1;
                material = Some(id);
            }
            "s" | "c" | "p" | "pp" => {
                let Some(m) = material else {
                    return Err(p.error(
                        span,
                        "expected an `f` surface record before the first object",
                    ));
                };
                match keyword {
                    "s" => {
                        let [x, y, z, r] = p.numbers::<4>()?;
                        if r == 0.0 {
                            return Err(
                                p.error(p.last.clone(), "expected a non-zero sphere radius")
                            );
                        }
                        let mut sphere = Sphere::new(Vec3::new(x, y, z), r.abs());
                        sphere.inside_only = r < 0.0;
                        counts[0] += 1;
                        builder.add_object(
                            format!("sphere {}", counts[0]),
                            Shape::Sphere(sphere),
                            Transform::IDENTITY,
                            m,
                        );
                    }
                    "c" => {
                        let (base, r0) = (p.vec3()?, p.number()?);
                        let (apex, r1) = (p.vec3()?, p.number()?);
                        let (shape, frame) = cone(base, r0, apex, r1).ok_or_else(|| {
                            p.error(span.start..p.last.end, "expected a cone with distinct base and apex and radii not both zero")
                        })?;
                        counts[1] += 1;
                        builder.add_object(format!("cone {}", counts[1]), shape, frame, m);
                    }
                    "p" => {
                        let n = p.count(3)?;
                        let vertices = (0..n).map(|_| p.vec3()).collect::<Result<Vec<_>, _>>()?;
                        let polygon = Polygon::new(vertices)
                            .map_err(|e| p.error(span.start..p.last.end, e.to_string()))?;
                        counts[2] += 1;
                        builder.add_object(
                            format!("polygon {}", counts[2]),
                            Shape::Polygon(Box::new(polygon)),
                            Transform::IDENTITY,
                            m,
                        );
                    }
                    _ => {
                        let n = p.count(6)?;
                        let mut corners = Vec::with_capacity(n);
                        for _ in 0..n {
                            corners.push((p.vec3()?, p.vec3()?));
                        }
                        if n < 3 {
                            return Err(p.error(
                                span.start..p.last.end,
                                format!("expected a patch of at least 3 vertices, found {n}"),
                            ));
                        }
                        patches.add(m, &corners);
                    }
                }
            }
            other => {
                return Err(p.error(
                    span,
                    format!("unknown NFF record `{other}`: expected v, b, l, f, c, s, p or pp"),
                ))
            }
        }
    }
    if !saw_view {
        return Err(SceneError::file(path, "the file has no `v` view record"));
    }
    for (m, mesh) in patches.finish(path)? {
        builder.add_object(
            format!("patches ({})", mesh.triangle_count()),
            Shape::Mesh(Arc::new(mesh)),
            Transform::IDENTITY,
            m,
        );
    }
    // SPD: n lights of √n/(2n) each, and the same ambient.
    let n = lights.len().max(1) as f64;
    let level = n.sqrt() / (2.0 * n);
    for (i, (position, color)) in lights.iter().zip(&light_colors).enumerate() {
        builder.add_light(
            format!("light {}", i + 1),
            Light::Point {
                position: *position,
                intensity: color.unwrap_or(Color::WHITE) * level,
                attenuation: Attenuation::default(),
            },
        );
    }
    builder.ambient = Color::gray(level);
    Ok((builder, defaults))
}

/// An open cone from `base` (radius r0) to `apex` (radius r1) as a canonical cone and the
/// frame placing it; `None` when degenerate.
fn cone(base: Vec3, r0: f64, apex: Vec3, r1: f64) -> Option<(Shape, Transform)> {
    let axis = apex - base;
    let height = axis.length();
    if height.is_nan() || height <= 0.0 || (r0 == 0.0 && r1 == 0.0) {
        return None;
    }
    let z = axis / height;
    let (x, y) = z.orthonormal_basis();
    let frame = Transform::frame(base, x, y, z)?;
    let shape = Shape::Cone(Cone {
        radius0: r0.abs(),
        radius1: r1.abs(),
        height,
        capped: false,
        inside_only: r0 < 0.0 && r1 < 0.0,
        partial: None,
    });
    Some((shape, frame))
}

/// The patches of one surface: positions, normals and triangles of a smooth mesh.
struct PatchGroup(MaterialId, Vec<Vec3>, Vec<Vec3>, Vec<[u32; 3]>);

/// `pp` patches gathered per surface into one smooth mesh each.
#[derive(Default)]
struct PatchMesh {
    groups: Vec<PatchGroup>,
}

impl PatchMesh {
    fn add(&mut self, m: MaterialId, corners: &[(Vec3, Vec3)]) {
        if self.groups.last().is_none_or(|g| g.0 != m) {
            self.groups
                .push(PatchGroup(m, Vec::new(), Vec::new(), Vec::new()));
        }
        let g = self.groups.last_mut().expect("a group was just pushed");
        let first = g.1.len() as u32;
        for &(p, n) in corners {
            g.1.push(p);
            g.2.push(n);
        }
        for i in 1..corners.len() as u32 - 1 {
            g.3.push([first, first + i, first + i + 1]);
        }
    }

    fn finish(self, path: &Path) -> Result<Vec<(MaterialId, TriangleMesh)>, SceneError> {
        self.groups
            .into_iter()
            .map(|PatchGroup(m, positions, normals, triangles)| {
                TriangleMesh::new(positions, triangles, normals, Vec::new())
                    .map(|mesh| (m, mesh))
                    .map_err(|e| SceneError::file(path, e.to_string()))
            })
            .collect()
    }
}

struct Parser<'s, I: Iterator<Item = (&'s str, Range<usize>)>> {
    path: &'s Path,
    text: &'s str,
    tokens: std::iter::Peekable<I>,
    /// Span of the last token read, for errors about missing data.
    last: Range<usize>,
}

impl<'s, I: Iterator<Item = (&'s str, Range<usize>)>> Parser<'s, I> {
    fn error(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        SceneError::at(self.path, self.text, span, message)
    }

    fn next(&mut self, what: &str) -> Result<(&'s str, Range<usize>), SceneError> {
        match self.tokens.next() {
            Some((t, span)) => {
                self.last = span.clone();
                Ok((t, span))
            }
            None => Err(self.error(
                self.last.end..self.last.end,
                format!("expected {what}, found the end of the file"),
            )),
        }
    }

    fn number(&mut self) -> Result<f64, SceneError> {
        let (t, span) = self.next("a number")?;
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.error(span, format!("expected a finite number, found `{t}`"))),
        }
    }

    fn numbers<const N: usize>(&mut self) -> Result<[f64; N], SceneError> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.number()?;
        }
        Ok(out)
    }

    fn vec3(&mut self) -> Result<Vec3, SceneError> {
        let [x, y, z] = self.numbers::<3>()?;
        Ok(Vec3::new(x, y, z))
    }

    fn color(&mut self) -> Result<Color, SceneError> {
        let [r, g, b] = self.numbers::<3>()?;
        if r < 0.0 || g < 0.0 || b < 0.0 {
            return Err(self.error(self.last.clone(), "expected colour components ≥ 0"));
        }
        Ok(Color::new(r, g, b))
    }

    /// A vertex count, each vertex `numbers` numbers, which the rest of the file must be
    /// able to hold (each number is at least a separator and a digit).
    fn count(&mut self, numbers: u64) -> Result<usize, SceneError> {
        let (t, span) = self.next("a vertex count")?;
        let n = t.parse::<u64>().map_err(|_| {
            self.error(
                span.clone(),
                format!("expected a vertex count, found `{t}`"),
            )
        })?;
        let remaining = self.text.len() - span.end;
        check_count(n, 2 * numbers, remaining, "vertices").map_err(|e| self.error(span, e))?;
        Ok(n as usize)
    }

    fn next_is_number(&mut self) -> bool {
        self.tokens
            .peek()
            .is_some_and(|(t, _)| t.parse::<f64>().is_ok())
    }

    fn keyword(&mut self, word: &str) -> Result<(), SceneError> {
        let (t, span) = self.next(&format!("`{word}`"))?;
        if t == word {
            Ok(())
        } else {
            Err(self.error(
                span,
                format!("expected `{word}` in the view record, found `{t}`"),
            ))
        }
    }

    /// The `v` block: camera, the angle between outermost pixel centres, and resolution.
    fn view(&mut self) -> Result<(CameraSettings, f64, u32, u32), SceneError> {
        let start = self.last.start;
        self.keyword("from")?;
        let from = self.vec3()?;
        self.keyword("at")?;
        let at = self.vec3()?;
        self.keyword("up")?;
        let up = self.vec3()?;
        self.keyword("angle")?;
        let angle = self.number()?;
        self.keyword("hither")?;
        self.number()?;
        self.keyword("resolution")?;
        let [w, h] = self.numbers::<2>()?;
        let span = start..self.last.end;
        if !(angle > 0.0 && angle < 180.0) {
            return Err(self.error(
                span,
                format!("expected a view angle between 0 and 180 degrees, found {angle}"),
            ));
        }
        if w < 2.0 || h < 2.0 || w.fract() != 0.0 || h.fract() != 0.0 || w * h > (1u64 << 28) as f64
        {
            return Err(self.error(span, "expected a resolution of whole pixels, at least 2×2"));
        }
        if (at - from).length_squared() == 0.0 || up.cross(at - from).length_squared() == 0.0 {
            return Err(self.error(
                span,
                "expected `at` apart from `from` and `up` not along the view",
            ));
        }
        // `angle` spans the outermost pixel centres: widen to the image edges.
        let h_px = h as u32;
        let half = (angle.to_radians() * 0.5).tan() * h / (h - 1.0);
        let camera = CameraSettings {
            position: from,
            look_at: at,
            up,
            fov_degrees: 2.0 * half.atan().to_degrees(),
            ..CameraSettings::default()
        };
        Ok((camera, angle, w as u32, h_px))
    }
}

/// Whitespace-separated tokens with byte spans; `#` comments run to the end of the line.
fn tokens(text: &str) -> impl Iterator<Item = (&str, Range<usize>)> {
    let bytes = text.as_bytes();
    let mut i = 0;
    std::iter::from_fn(move || {
        loop {
            while i < bytes.len() && bytes[i].is_ascii_whitespace() {
                i += 1;
            }
            if i < bytes.len() && bytes[i] == b'#' {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            break;
        }
        if i >= bytes.len() {
            return None;
        }
        let start = i;
        while i < bytes.len() && !bytes[i].is_ascii_whitespace() && bytes[i] != b'#' {
            i += 1;
        }
        Some((&text[start..i], start..i))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const VIEW: &str =
        "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0.01\nresolution 64 64\n";

    fn read(text: &str) -> Result<(SceneBuilder, RenderDefaults), SceneError> {
        parse(Path::new("t.nff"), text)
    }

    #[test]
    fn records_span_lines_and_comments() {
        let text = format!("b 0.1 0.2 0.3\n{VIEW}l 1 2 3\nl 4 5 6 1 0 0 # red\nf 1 0 0 0.8 0.2 30 0 1\ns 0 0\n0 1\nc 0 0 0 1 0 1 0 0.5\np 3 0 0 0 1 0 0 0 1 0\npp 3\n0 0 1 0 0 1\n1 0 1 0 0 1\n0 1 1 0 0 1\n");
        let (builder, defaults) = read(&text).unwrap();
        let scene = builder.build();
        assert_eq!(scene.background, Color::new(0.1, 0.2, 0.3));
        // Two point lights, and the background as the physically based methods' light.
        assert_eq!(scene.lights.len(), 3);
        assert_eq!(scene.lights.background, Some(2));
        assert_eq!(scene.geometry.primitives.len(), 4);
        let level = 2f64.sqrt() / 4.0;
        assert!((scene.ambient.r - level).abs() < 1e-15);
        match &scene.lights[1] {
            Light::Point { intensity, .. } => assert_eq!(*intensity, Color::new(level, 0.0, 0.0)),
            _ => panic!("point light expected"),
        }
        assert_eq!(
            (defaults.width, defaults.max_depth, defaults.min_weight),
            (64, 4, 0.0)
        );
        // Pixel centres span 45°: the edge-to-edge angle is wider by 64/63.
        let want = 2.0 * ((22.5f64.to_radians().tan() * 64.0 / 63.0).atan()).to_degrees();
        assert!((scene.camera.fov_degrees - want).abs() < 1e-12);
        let m = scene.materials[0].phong().unwrap();
        assert!(matches!(m.reflective, Texture::Constant(c) if c == Color::gray(0.2)));
    }

    #[test]
    fn errors_are_located() {
        let e = read(&format!("{VIEW}f 1 1 1 1 0 0 0 0\ns 0 0 nan 1\n")).unwrap_err();
        assert_eq!((e.line, e.column), (9, 7));
        let e = read(&format!("{VIEW}s 0 0 0 1\n")).unwrap_err();
        assert!(e.message.contains("`f` surface record"), "{}", e.message);
        let e = read(&format!(
            "{VIEW}f 1 1 1 1 0 0 0 0\np 3 0 0 0 1 0 0 1 1 # cut short\n"
        ))
        .unwrap_err();
        assert!(e.message.contains("end of the file"), "{}", e.message);
        // A count the rest of the file cannot hold is refused at the count, before anything
        // is allocated for it (this one asked for 48 MB).
        let e = read(&format!(
            "{VIEW}f 1 1 1 1 0 0 0 0\npp 1048576\n0 0 0 0 0 1\n"
        ))
        .unwrap_err();
        assert_eq!((e.line, e.column), (9, 4));
        assert!(
            e.message.contains("asks for 1048576 vertices"),
            "{}",
            e.message
        );
        let e = read(&format!("{VIEW}q 1\n")).unwrap_err();
        assert!(e.message.contains("unknown NFF record `q`"));
        let e = read("f 1 1 1 1 0 0 0 0\n").unwrap_err();
        assert!(e.message.contains("no `v`"));
    }
}
