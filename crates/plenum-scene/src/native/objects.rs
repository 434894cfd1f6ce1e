//! The native format's `[[objects]]` and `[meshes.NAME]`: shapes, meshes from files or given
//! inline, their materials and emission.

use super::Reader;
use crate::diagnostics::did_you_mean;
use crate::reader::{Fields, Result, Value};
use crate::{obj, ply};
use plenum_core::color::Color;
use plenum_core::geometry::{
    Cone, Cuboid, Cylinder, Disk, Partial, Plane, Polygon, Polyhedron, Shape, Sphere, TriangleMesh,
    UvMap,
};
use plenum_core::material::PhongMaterial;
use plenum_core::math::{Transform, Vec3};
use plenum_core::scene::{Alpha, MaterialId};
use std::sync::Arc;
use toml::de::DeValue;

impl<'s> Reader<'s> {
    pub(super) fn object(&mut self, index: usize, v: &Value<'s>) -> Result<()> {
        const KINDS: &[&str] = &[
            "sphere",
            "plane",
            "disk",
            "box",
            "cylinder",
            "cone",
            "polygon",
            "polyhedron",
            "mesh",
        ];
        let kind = self.kind(v, "an object", KINDS)?;
        let fields: &[&'static str] = match kind.as_str() {
            "sphere" => &[
                "center",
                "radius",
                "inside_only",
                "z_min",
                "z_max",
                "phi_max",
                "uv_map",
            ],
            "plane" => &["point", "normal"],
            "disk" => &[
                "center",
                "normal",
                "radius",
                "inner_radius",
                "phi_max",
                "uv_map",
            ],
            "box" => &["min", "max"],
            "cylinder" => &["base", "top", "radius", "capped", "phi_max", "uv_map"],
            "cone" => &[
                "base",
                "top",
                "radius",
                "top_radius",
                "capped",
                "inside_only",
                "phi_max",
            ],
            "polygon" => &["vertices"],
            "polyhedron" => &["vertices", "faces"],
            _ => &[
                "mesh",
                "file",
                "positions",
                "indices",
                "normals",
                "uvs",
                "vertex_materials",
            ],
        };
        const EMISSION: [&str; 4] = ["emission", "emission_scale", "two_sided", "light_samples"];
        let allowed: Vec<&'static str> = super::COMMON
            .iter()
            .chain(fields)
            .chain(&EMISSION)
            .copied()
            .collect();
        let f = self.src.table(v, &kind, &allowed)?;
        let (shape, frame) = self.shape(&kind, &f)?;
        let placement = match f.get("transform") {
            Some(t) => self.transform(t)?,
            None => Transform::IDENTITY,
        };
        let material = self.material_ref(f.get("material"))?;
        let name = f
            .string("name")?
            .map_or_else(|| format!("{kind} {}", index + 1), str::to_string);
        let to_world = placement.after(&frame);
        let close = match f.get("transform_close") {
            Some(t) => Some(self.transform(t)?.after(&frame)),
            None => None,
        };
        let alpha = self.alpha(&f)?;
        if let Some(e) = f.get("emission") {
            // An area light is sampled over its whole shape.
            if let Some(k) = ["z_min", "z_max", "inner_radius", "phi_max"]
                .iter()
                .find_map(|k| f.get(k))
            {
                return Err(self.src.error(
                    k.span(),
                    "an emitting object cannot be partial: drop the cut",
                ));
            }
            if let Some(a) = f.get("alpha") {
                return Err(self.src.error(
                    a.span(),
                    "an emitting object cannot be cut out: drop `alpha`",
                ));
            }
            if f.get("vertex_materials").is_some() {
                return Err(self.src.error(
                    e.span(),
                    "an emitting object has one material: drop `vertex_materials`",
                ));
            }
            if close.is_some() {
                return Err(self.src.error(
                    e.span(),
                    "an emitting object cannot move (`transform_close`)",
                ));
            }
            let scale = f.non_negative_or("emission_scale", 1.0)?;
            // A texture (a table naming one) varies the radiance over the surface.
            let texture = match e.get_ref() {
                DeValue::Table(t) if t.contains_key("texture") => Some(self.texture(e)?),
                _ => None,
            };
            let (radiance, spectrum) = match texture {
                Some(_) => (Color::gray(scale), None),
                None => self.emission(e, scale)?,
            };
            let samples = self.light_samples(&f, "light_samples")?;
            let two_sided = f.bool_or("two_sided", true)?;
            // Without a material of its own the object only shows its light.
            let material = match f.get("material") {
                Some(_) => material,
                None => self.builder.black_material(),
            };
            let what = f.required("emission")?.span();
            let added = self.builder.add_emissive_object(
                name, shape, to_world, material, radiance, two_sided, samples,
            );
            // A mesh without area is placed, dark, as before; other shapes cannot be sampled.
            if !added && kind != "mesh" {
                return Err(self.src.error(
                    what,
                    format!("a {kind} cannot be an area light: use a mesh, sphere, disk, polygon, box or polyhedron"),
                ));
            }
            if let Some(s) = spectrum {
                self.builder.set_last_light_spectrum(s, scale);
            }
            if let Some(t) = texture.filter(|_| added) {
                if !self.builder.set_last_light_texture(t) {
                    return Err(self.src.error(
                        what,
                        format!("a {kind} placed this way cannot have textured emission"),
                    ));
                }
            }
            return Ok(());
        }
        match (f.get("vertex_materials"), shape) {
            (Some(list), Shape::Mesh(mesh)) => {
                let items = self
                    .src
                    .array(list, "an array of material names, one per vertex")?;
                if items.len() != mesh.vertex_count() {
                    return Err(self.src.error(
                        list.span(),
                        format!(
                            "{} vertex materials for {} vertices: give one per vertex",
                            items.len(),
                            mesh.vertex_count()
                        ),
                    ));
                }
                let ids = items
                    .iter()
                    .map(|v| self.material_ref(Some(v)))
                    .collect::<Result<Vec<_>>>()?;
                self.builder
                    .add_mesh_with_vertex_materials(name, mesh, to_world, ids);
            }
            (_, shape) => self.builder.add_object(name, shape, to_world, material),
        }
        if let Some(close) = close {
            self.builder.set_last_motion(close);
        }
        if let Some(alpha) = alpha {
            self.builder.set_last_alpha(alpha);
        }
        Ok(())
    }

    /// `alpha` (a number in [0, 1] or a texture: the surface's coverage) and `alpha_cutoff`
    /// (present exactly where alpha reaches it; without it, present with probability alpha).
    fn alpha(&self, f: &Fields<'_, 's>) -> Result<Option<Alpha>> {
        let cutoff = match f.get("alpha_cutoff") {
            None => None,
            Some(v) => {
                if f.get("alpha").is_none() {
                    return Err(self
                        .src
                        .error(v.span(), "`alpha_cutoff` needs an `alpha` to compare"));
                }
                Some(f.number_or("alpha_cutoff", 0.5)?)
            }
        };
        let Some(v) = f.get("alpha") else {
            return Ok(None);
        };
        let texture = self.fraction(v, "an alpha")?;
        Ok(Some(Alpha { texture, cutoff }))
    }

    /// The material a `material` value names; none given: the default matte grey.
    pub(super) fn material_ref(&mut self, value: Option<&Value<'s>>) -> Result<MaterialId> {
        let Some(v) = value else {
            if let Some(&id) = self.materials.get("default") {
                return Ok(id);
            }
            let id = self
                .builder
                .add_material("default", PhongMaterial::default());
            self.materials.insert("default".into(), id);
            return Ok(id);
        };
        let name = self.src.string(v)?;
        if let Some(&id) = self.materials.get(name) {
            return Ok(id);
        }
        let e = self
            .src
            .error(v.span(), format!("no material named `{name}` is defined"));
        let mut known: Vec<&str> = self.materials.keys().map(String::as_str).collect();
        known.sort();
        Err(match did_you_mean(name, known.iter().copied()) {
            Some(s) => e.with_help(format!("did you mean `{s}`?")),
            None if known.is_empty() => e.with_help("define it in a [materials.NAME] table"),
            None => e.with_help(format!("defined materials: {}", known.join(", "))),
        })
    }

    /// The shape in its own coordinates and the frame that places it (identity for most).
    /// `phi_max` (degrees in (0, 360]) sweeps a sphere, disk, cylinder or cone through less
    /// than a turn.
    fn shape(&mut self, kind: &str, f: &Fields<'_, 's>) -> Result<(Shape, Transform)> {
        let src = self.src;
        let phi_max = |f: &Fields<'_, 's>| -> Result<f64> {
            let degrees = f.number_or("phi_max", 360.0)?;
            if !(degrees > 0.0 && degrees <= 360.0) {
                return Err(src.error(
                    f.required("phi_max")?.span(),
                    format!("expected phi_max in (0, 360] degrees, found {degrees}"),
                ));
            }
            Ok(if degrees >= 360.0 {
                std::f64::consts::TAU
            } else {
                degrees.to_radians()
            })
        };
        // Whose (u, v) a sphere, disk or cylinder reports.
        let uv_map = match f.get("uv_map") {
            None => UvMap::Plenum,
            Some(v) => match src.string(v)? {
                "plenum" => UvMap::Plenum,
                "pbrt" => UvMap::Pbrt,
                "mitsuba" => UvMap::Mitsuba,
                other => {
                    return Err(src
                        .error(v.span(), format!("unknown uv_map `{other}`"))
                        .with_help("expected \"plenum\", \"pbrt\" or \"mitsuba\""))
                }
            },
        };
        let shape = match kind {
            "sphere" => {
                let mut sphere = Sphere::new(
                    f.vec3_or("center", Vec3::ZERO)?,
                    f.positive("radius", None)?,
                )
                .with_uv_map(uv_map);
                sphere.inside_only = f.bool_or("inside_only", false)?;
                let (z_min, z_max) = (
                    f.number_or("z_min", f64::NEG_INFINITY)?,
                    f.number_or("z_max", f64::INFINITY)?,
                );
                if z_min >= z_max {
                    return Err(src.error(
                        f.required("z_max")?.span(),
                        format!("expected z_max > z_min, found {z_max} and {z_min}"),
                    ));
                }
                Shape::Sphere(sphere.with_partial(Partial {
                    z_min,
                    z_max,
                    phi_max: phi_max(f)?,
                    ..Partial::WHOLE
                }))
            }
            "plane" => Shape::Plane(Plane::new(
                f.vec3_or("point", Vec3::ZERO)?,
                f.direction("normal", None)?,
            )),
            "disk" => {
                let radius = f.positive("radius", None)?;
                let inner_radius = f.non_negative_or("inner_radius", 0.0)?;
                if inner_radius >= radius {
                    return Err(src.error(
                        f.required("inner_radius")?.span(),
                        format!("expected an inner_radius below the radius {radius}"),
                    ));
                }
                let disk = Disk::new(
                    f.vec3_or("center", Vec3::ZERO)?,
                    f.direction("normal", None)?,
                    radius,
                )
                .with_uv_map(uv_map);
                Shape::Disk(disk.with_partial(Partial {
                    inner_radius,
                    phi_max: phi_max(f)?,
                    ..Partial::WHOLE
                }))
            }
            "box" => {
                let (min, max) = (f.required_vec3("min")?, f.required_vec3("max")?);
                if min.x >= max.x || min.y >= max.y || min.z >= max.z {
                    return Err(src.error(
                        f.required("max")?.span(),
                        "expected max greater than min on every axis",
                    ));
                }
                Shape::Cuboid(Cuboid::new(min, max))
            }
            "cylinder" | "cone" => {
                let base = f.vec3_or("base", Vec3::ZERO)?;
                let top = f.vec3_or("top", Vec3::Y)?;
                let axis = top - base;
                let height = axis.length();
                let z = axis / height;
                let (x, y) = z.orthonormal_basis();
                let frame = Transform::frame(base, x, y, z)
                    .filter(|_| height > 0.0 && height.is_finite() && z.is_finite());
                let Some(frame) = frame else {
                    let span = f.get("top").map_or(f.span.clone(), |v| v.span());
                    return Err(src.error(
                        span,
                        "expected `top` apart from `base` by a finite, non-zero distance",
                    ));
                };
                let radius = f.positive("radius", None)?;
                let capped = f.bool_or("capped", true)?;
                let sector = Partial {
                    phi_max: phi_max(f)?,
                    ..Partial::WHOLE
                };
                let shape = if kind == "cylinder" {
                    let cylinder = Cylinder::new(radius, height, capped).with_uv_map(uv_map);
                    Shape::Cylinder(cylinder.with_partial(sector))
                } else {
                    let top_radius = f.number_or("top_radius", 0.0)?;
                    if top_radius < 0.0 {
                        return Err(src.error(
                            f.required("top_radius")?.span(),
                            format!("expected a top_radius ≥ 0, found {top_radius}"),
                        ));
                    }
                    Shape::Cone(Cone {
                        radius0: radius,
                        radius1: top_radius,
                        height,
                        capped,
                        inside_only: f.bool_or("inside_only", false)?,
                        partial: sector.cut(),
                    })
                };
                return Ok((shape, frame));
            }
            "polygon" => {
                let v = f.required("vertices")?;
                let vertices = self.points(v)?;
                Shape::Polygon(Box::new(
                    Polygon::new(vertices).map_err(|e| src.error(v.span(), e.to_string()))?,
                ))
            }
            "polyhedron" => {
                let vs = f.required("vertices")?;
                let vertices = self.points(vs)?;
                let fv = f.required("faces")?;
                let mut faces = Vec::new();
                for face in src.array(fv, "an array of faces, each an array of vertex indices")? {
                    if src.array(face, "a face: an array of vertex indices")?.len() < 3 {
                        return Err(
                            src.error(face.span(), "expected a face of at least 3 vertex indices")
                        );
                    }
                    let mut loop_ = Vec::new();
                    for i in src.array(face, "a face: an array of vertex indices")? {
                        let index = src.index(i)?;
                        if index as usize >= vertices.len() {
                            return Err(src.error(
                                i.span(),
                                format!(
                                    "vertex index {index} is out of range: there are {} vertices",
                                    vertices.len()
                                ),
                            ));
                        }
                        loop_.push(index);
                    }
                    faces.push(loop_);
                }
                Shape::Polyhedron(Box::new(
                    Polyhedron::new(&vertices, &faces)
                        .map_err(|e| src.error(fv.span(), e.to_string()))?,
                ))
            }
            _ => {
                f.one_of(&["mesh", "file", "positions"])?;
                if let Some(m) = f.get("mesh") {
                    let name = src.string(m)?;
                    let Some(mesh) = self.meshes.get(name) else {
                        let e = src.error(m.span(), format!("no mesh named `{name}` is defined"));
                        return Err(
                            match did_you_mean(name, self.meshes.keys().map(String::as_str)) {
                                Some(s) => e.with_help(format!("did you mean `{s}`?")),
                                None => e.with_help("define it in a [meshes.NAME] table"),
                            },
                        );
                    };
                    Shape::Mesh(mesh.clone())
                } else {
                    Shape::Mesh(self.mesh_data(f)?)
                }
            }
        };
        Ok((shape, Transform::IDENTITY))
    }

    pub(super) fn points(&self, v: &Value<'s>) -> Result<Vec<Vec3>> {
        self.src
            .array(v, "an array of points [[x, y, z], …]")?
            .iter()
            .map(|p| self.src.vec3(p))
            .collect()
    }

    /// A mesh from `file` (OBJ or PLY) or from inline `positions` and `indices`, keeping its
    /// vertex indices: an object may give it `vertex_materials`.
    pub(super) fn mesh_data(&mut self, f: &Fields<'_, 's>) -> Result<Arc<TriangleMesh>> {
        let src = self.src;
        f.one_of(&["mesh", "file", "positions"])?;
        if let Some(file) = f.get("file") {
            let rel = src.string(file)?;
            let path = self.base_dir.join(rel);
            let extension = path
                .extension()
                .and_then(|e| e.to_str())
                .unwrap_or("")
                .to_ascii_lowercase();
            let unreadable = |e: std::io::Error| {
                src.error(
                    file.span(),
                    format!("cannot read mesh file `{}`: {e}", path.display()),
                )
            };
            return match extension.as_str() {
                "obj" => {
                    let (text, not_utf8) = crate::text::read_lenient(&path).map_err(unreadable)?;
                    self.warnings.extend(not_utf8);
                    let mut model = obj::parse_obj_model_with(&path, &text, false, true)?;
                    self.warnings.append(&mut model.warnings);
                    Ok(Arc::new(model.groups.remove(0).1))
                }
                "ply" => {
                    std::fs::metadata(&path).map_err(unreadable)?;
                    ply::load_ply_with(&path, true).map(Arc::new)
                }
                _ => Err(src.error(file.span(), "expected a mesh file: .obj or .ply")),
            };
        }
        let pv = f.required("positions")?;
        let positions = self.points(pv)?;
        let iv = f.required("indices")?;
        let mut triangles = Vec::new();
        for tri in src.array(iv, "an array of triangles [[i, j, k], …]")? {
            let items = src.array(tri, "a triangle: [i, j, k]")?;
            if items.len() != 3 {
                return Err(src.error(
                    tri.span(),
                    format!("expected a triangle of 3 indices, found {}", items.len()),
                ));
            }
            let mut t = [0u32; 3];
            for (slot, i) in t.iter_mut().zip(items) {
                *slot = src.index(i)?;
                if *slot as usize >= positions.len() {
                    return Err(src.error(
                        i.span(),
                        format!(
                            "vertex index {} is out of range: there are {} positions",
                            slot,
                            positions.len()
                        ),
                    ));
                }
            }
            triangles.push(t);
        }
        let normals = match f.get("normals") {
            Some(n) => self.points(n)?,
            None => Vec::new(),
        };
        let uvs = match f.get("uvs") {
            Some(u) => src
                .array(u, "an array of [u, v] pairs")?
                .iter()
                .map(|p| src.numbers::<2>(p, "a texture coordinate [u, v]"))
                .collect::<Result<Vec<_>>>()?,
            None => Vec::new(),
        };
        TriangleMesh::new_keeping_indices(positions, triangles, normals, uvs)
            .map(Arc::new)
            .map_err(|e| src.error(pv.span(), e.to_string()))
    }
}
