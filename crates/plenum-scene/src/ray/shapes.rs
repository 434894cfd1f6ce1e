//! The `.ray` format's shapes: the unit shapes and meshes, placed by nested transform
//! nodes.

use super::lex::Tok;
use super::{zero_material, Parser};
use crate::diagnostics::{did_you_mean, SceneError};
use crate::limits::MAX_NESTING;
use plenum_core::geometry::{Cone, Cuboid, Cylinder, Polygon, Shape, Sphere, TriangleMesh};
use plenum_core::material::PhongMaterial;
use plenum_core::math::{Matrix4, Transform, Vec3};
use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;

impl<'s> Parser<'s> {
    /// A primitive, a transform node or a `{ … }` group, placed by `to_world`. Nesting is
    /// bounded: each level is a call, and a file of thousands would overflow the stack.
    pub(super) fn geometry(&mut self, to_world: Transform) -> Result<(), SceneError> {
        if self.depth >= MAX_NESTING {
            return Err(self.error(
                self.span(),
                format!("groups and transforms nest deeper than {MAX_NESTING} levels here"),
            ));
        }
        self.depth += 1;
        let placed = self.placed(to_world);
        self.depth -= 1;
        placed
    }

    fn placed(&mut self, to_world: Transform) -> Result<(), SceneError> {
        if self.eat('{') {
            while !self.eat('}') {
                if self.eat(';') {
                    continue;
                }
                if self.peek() == Some(&Tok::Word("material".into())) {
                    self.pos += 1;
                    self.punct('=')?;
                    self.current = self.material_value()?;
                    self.eat(';');
                    continue;
                }
                self.geometry(to_world)?;
            }
            return Ok(());
        }
        let (w, span) = self.word()?;
        match w.as_str() {
            "translate" | "scale" | "rotate" | "transform" => {
                self.punct('(')?;
                let local = match w.as_str() {
                    "translate" => {
                        let v = self.numbers_then_comma(3)?;
                        Transform::translate(Vec3::new(v[0], v[1], v[2]))
                    }
                    "scale" => {
                        let mut v = vec![self.number()?];
                        self.punct(',')?;
                        if matches!(self.peek(), Some(Tok::Num(_))) {
                            v.push(self.number()?);
                            self.punct(',')?;
                            v.push(self.number()?);
                            self.punct(',')?;
                        }
                        let s = if v.len() == 3 {
                            Vec3::new(v[0], v[1], v[2])
                        } else {
                            Vec3::splat(v[0])
                        };
                        Transform::scale(s).ok_or_else(|| {
                            self.error(span.clone(), "a scale by zero cannot be inverted")
                        })?
                    }
                    "rotate" => {
                        let v = self.numbers_then_comma(4)?;
                        Transform::rotate(Vec3::new(v[0], v[1], v[2]), v[3].to_degrees())
                            .ok_or_else(|| {
                                self.error(span.clone(), "a rotation needs a non-zero axis")
                            })?
                    }
                    _ => {
                        let mut rows = [[0.0; 4]; 4];
                        for row in &mut rows {
                            *row = self.tuple::<4>()?;
                            self.punct(',')?;
                        }
                        let m = Matrix4(rows);
                        Transform::from_matrix(m).ok_or_else(|| {
                            self.error(
                                span.clone(),
                                "this transform matrix is singular or not affine",
                            )
                        })?
                    }
                };
                self.geometry(to_world.after(&local))?;
                self.punct(')')?;
                self.eat(';');
                Ok(())
            }
            "sphere" | "box" | "square" | "cylinder" | "cone" => self.primitive(&w, span, to_world),
            "trimesh" | "polymesh" => self.mesh(span, to_world),
            _ => {
                let e = self.error(span, format!("unknown statement `{w}`"));
                let known = [
                    "camera",
                    "point_light",
                    "directional_light",
                    "ambient_light",
                    "material",
                    "sphere",
                    "box",
                    "square",
                    "cylinder",
                    "cone",
                    "trimesh",
                    "polymesh",
                    "translate",
                    "scale",
                    "rotate",
                    "transform",
                ];
                Err(match did_you_mean(&w, known) {
                    Some(s) => e.with_help(format!("did you mean `{s}`?")),
                    None => e,
                })
            }
        }
    }

    /// `n, n, …, ` (N numbers, each followed by a comma).
    fn numbers_then_comma(&mut self, n: usize) -> Result<Vec<f64>, SceneError> {
        let mut v = Vec::with_capacity(n);
        for _ in 0..n {
            v.push(self.number()?);
            self.punct(',')?;
        }
        Ok(v)
    }

    /// A name for the next object of the file: its kind and its position.
    fn next_name(&mut self, kind: &str) -> String {
        self.objects += 1;
        format!("{kind} {}", self.objects)
    }

    fn add(&mut self, name: &str, shape: Shape, to_world: Transform, material: PhongMaterial) {
        let id = self.builder.add_material(name, material);
        self.builder.add_object(name, shape, to_world, id);
    }

    fn primitive(
        &mut self,
        kind: &str,
        span: Range<usize>,
        to_world: Transform,
    ) -> Result<(), SceneError> {
        const KNOWN: &[&str] = &[
            "material",
            "name",
            "height",
            "bottom_radius",
            "top_radius",
            "capped",
        ];
        self.punct('{')?;
        let mut material = None;
        let (mut height, mut bottom, mut top, mut capped) = (1.0, 1.0, 0.0, true);
        while !self.eat('}') {
            let (field, fspan) = self.word()?;
            match (field.as_str(), kind) {
                ("material", _) => material = Some(self.field(Self::material_value)?),
                ("name", _) => {
                    self.punct('=')?;
                    self.pos += 1;
                    self.eat(';');
                }
                ("height", "cone") => height = self.field(Self::number)?,
                ("bottom_radius", "cone") => bottom = self.field(Self::number)?,
                ("top_radius", "cone") => top = self.field(Self::number)?,
                ("capped", "cone") => {
                    capped = self.field(|p| match p.peek() {
                        Some(Tok::Word(b)) if b == "true" || b == "false" => {
                            let v = b == "true";
                            p.pos += 1;
                            Ok(v)
                        }
                        _ => Err(p.expected("true or false")),
                    })?
                }
                _ => self.unknown_field(&field, fspan, KNOWN)?,
            }
        }
        let material = match material {
            Some(m) => m,
            None if self.classic => {
                return Err(self.error(
                    span,
                    format!("a {kind} needs a material in this dialect of the format"),
                ))
            }
            None => self.current.clone(),
        };
        let shape = match kind {
            "sphere" => Shape::Sphere(Sphere::new(Vec3::ZERO, 1.0)),
            "box" => Shape::Cuboid(Cuboid::new(Vec3::splat(-0.5), Vec3::splat(0.5))),
            "square" => {
                let square = Polygon::new(vec![
                    Vec3::new(-0.5, -0.5, 0.0),
                    Vec3::new(0.5, -0.5, 0.0),
                    Vec3::new(0.5, 0.5, 0.0),
                    Vec3::new(-0.5, 0.5, 0.0),
                ])
                .map_err(|e| self.error(span.clone(), e.to_string()))?;
                Shape::Polygon(Box::new(square))
            }
            "cylinder" => Shape::Cylinder(Cylinder::new(1.0, 1.0, true)),
            _ => {
                if height.is_nan()
                    || height <= 0.0
                    || bottom < 0.0
                    || top < 0.0
                    || bottom + top == 0.0
                {
                    return Err(self.error(
                        span,
                        "expected a cone with height > 0 and radii ≥ 0, not both zero",
                    ));
                }
                Shape::Cone(Cone {
                    radius0: bottom,
                    radius1: top,
                    height,
                    capped,
                    inside_only: false,
                    partial: None,
                })
            }
        };
        let name = self.next_name(kind);
        self.add(&name, shape, to_world, material);
        Ok(())
    }

    fn points(&mut self) -> Result<Vec<Vec3>, SceneError> {
        self.punct('(')?;
        let mut v = Vec::new();
        if self.eat(')') {
            return Ok(v);
        }
        loop {
            v.push(self.vec3()?);
            if self.eat(')') {
                return Ok(v);
            }
            self.punct(',')?;
        }
    }

    fn mesh(&mut self, span: Range<usize>, to_world: Transform) -> Result<(), SceneError> {
        const KNOWN: &[&str] = &[
            "points",
            "faces",
            "normals",
            "materials",
            "gennormals",
            "material",
            "name",
        ];
        self.punct('{')?;
        let (mut points, mut normals, mut faces) = (Vec::new(), Vec::new(), Vec::new());
        let mut materials: Vec<PhongMaterial> = Vec::new();
        let mut material = None;
        let mut gennormals = false;
        while !self.eat('}') {
            let (field, fspan) = self.word()?;
            match field.as_str() {
                "points" => points = self.field(Self::points)?,
                "normals" => normals = self.field(Self::points)?,
                "faces" => {
                    faces = self.field(|p| {
                        p.punct('(')?;
                        let mut faces = Vec::new();
                        while !p.eat(')') {
                            let fs = p.span();
                            p.punct('(')?;
                            let mut face = vec![];
                            loop {
                                let s = p.span();
                                let i = p.number()?;
                                if i < 0.0 || i.fract() != 0.0 {
                                    return Err(p.error(s, "expected a vertex index ≥ 0"));
                                }
                                face.push((i as u32, s));
                                if p.eat(')') {
                                    break;
                                }
                                p.punct(',')?;
                            }
                            if face.len() < 3 {
                                return Err(p.error(fs, "expected a face of at least 3 indices"));
                            }
                            faces.push(face);
                            p.eat(',');
                        }
                        Ok(faces)
                    })?
                }
                "materials" => {
                    materials = self.field(|p| {
                        p.punct('(')?;
                        let mut list = Vec::new();
                        while !p.eat(')') {
                            list.push(p.material_value()?);
                            p.eat(',');
                        }
                        Ok(list)
                    })?
                }
                "gennormals" => {
                    gennormals = true;
                    if self.eat('=') {
                        self.pos += 1;
                    }
                    self.eat(';');
                }
                "material" => material = Some(self.field(Self::material_value)?),
                "name" => {
                    self.punct('=')?;
                    self.pos += 1;
                    self.eat(';');
                }
                _ => self.unknown_field(&field, fspan, KNOWN)?,
            }
        }
        let mut triangles = Vec::new();
        for face in &faces {
            for (i, s) in face {
                if *i as usize >= points.len() {
                    return Err(self.error(
                        s.clone(),
                        format!(
                            "vertex index {i} is out of range: there are {} points",
                            points.len()
                        ),
                    ));
                }
            }
            for k in 1..face.len() - 1 {
                triangles.push([face[0].0, face[k].0, face[k + 1].0]);
            }
        }
        // Degenerate triangles are dropped, as the reference parser does.
        triangles.retain(|t| {
            let [a, b, c] = t.map(|i| points[i as usize]);
            (b - a).cross(c - a).length_squared() > 0.0
        });
        if triangles.is_empty() {
            self.warnings.push(format!(
                "warning: {}: a mesh with no triangles is skipped",
                self.path.display()
            ));
            return Ok(());
        }
        if gennormals && normals.is_empty() {
            normals = vec![Vec3::ZERO; points.len()];
            for t in &triangles {
                let [a, b, c] = t.map(|i| points[i as usize]);
                let n = (b - a).cross(c - a);
                for &i in t {
                    normals[i as usize] += n;
                }
            }
            for n in &mut normals {
                *n = n.normalized();
            }
        }
        for (what, n) in [("normals", normals.len()), ("materials", materials.len())] {
            if n != 0 && n != points.len() {
                return Err(self.error(
                    span.clone(),
                    format!("{n} {what} for {} points: give one per point", points.len()),
                ));
            }
        }
        let base = material.unwrap_or_else(|| {
            if self.classic {
                zero_material()
            } else {
                self.current.clone()
            }
        });
        let name = self.next_name("mesh");
        if materials.is_empty() {
            let mesh = TriangleMesh::new(points, triangles, normals, Vec::new())
                .map_err(|e| self.error(span.clone(), e.to_string()))?;
            self.add(&name, Shape::Mesh(Arc::new(mesh)), to_world, base);
            return Ok(());
        }
        // Per-vertex materials, blended across each triangle; each distinct one is added once.
        let mut ids: HashMap<String, u32> = HashMap::new();
        let mut vertex_materials = Vec::with_capacity(materials.len());
        for (i, m) in materials.iter().enumerate() {
            let key = format!("{m:?}");
            let id = match ids.get(&key) {
                Some(&id) => id,
                None => {
                    let id = self
                        .builder
                        .add_material(format!("{name} vertex {i}"), m.clone());
                    ids.insert(key, id);
                    id
                }
            };
            vertex_materials.push(id);
        }
        let mesh = TriangleMesh::new_keeping_indices(points, triangles, normals, Vec::new())
            .map_err(|e| self.error(span.clone(), e.to_string()))?;
        self.builder.add_mesh_with_vertex_materials(
            name,
            Arc::new(mesh),
            to_world,
            vertex_materials,
        );
        Ok(())
    }
}
