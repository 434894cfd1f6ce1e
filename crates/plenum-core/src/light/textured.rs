//! Area lights whose radiance varies over their surface: a texture, looked up at the
//! surface's (u, v) as a hit there reports it, multiplies the light's RGB radiance (pbrt-v4's
//! image area lights, glTF's emissive textures, Mitsuba's textured `area` emitters).
//!
//! Rays that meet the light read the texture at their hit. Points sampled on the light
//! (next-event estimation, light paths) find their (u, v) here: on triangles by
//! interpolating each corner's, which the shape's own map gives, and on spheres and disks
//! from the shape's map at the point taken back to the shape's coordinates.

use super::Emitter;
use crate::color::Color;
use crate::geometry::Shape;
use crate::math::{Transform, Vec3};
use crate::texture::{Texture, TextureCoords};

/// The texture of a textured area light, and where on its emitter (u, v) lies.
#[derive(Clone, Debug)]
pub struct EmissionTexture {
    pub texture: Texture,
    coords: EmitterCoords,
}

#[derive(Clone, Debug)]
enum EmitterCoords {
    /// Per triangle of [`Emitter::Triangles`], in its order.
    Corners(Vec<Corners>),
    /// The shape (a sphere or disk) in its own coordinates, and the world-to-object map.
    Shape {
        shape: Shape,
        to_object: Transform,
        to_world: Transform,
    },
}

/// A triangle's corners in the shape's coordinates and in the world, their (u, v), and
/// its world normal.
#[derive(Clone, Debug)]
struct Corners {
    object: [Vec3; 3],
    world: [Vec3; 3],
    uv: [[f64; 2]; 3],
    normal: Vec3,
}

/// A point of an emitter: where a sample landed.
#[derive(Clone, Copy, Debug)]
pub(crate) enum EmitterPoint {
    /// On triangle `triangle`, with weights `b` of its first two corners (the third's is
    /// 1 − b₀ − b₁).
    Triangle { triangle: usize, b: [f64; 2] },
    /// At a world point of a sphere or disk.
    World(Vec3),
}

impl EmissionTexture {
    /// `texture` over the light `emitter` made of `shape` placed by `to_world`
    /// ([`Emitter::of_shape`]); `None` for an emitter that is not that shape's.
    pub fn new(
        texture: Texture,
        emitter: &Emitter,
        shape: &Shape,
        to_world: &Transform,
    ) -> Option<EmissionTexture> {
        let coords = match emitter {
            Emitter::Triangles {
                triangles, normals, ..
            } => {
                let parts = Emitter::object_triangles(shape, to_world)?;
                if parts.len() != triangles.len() {
                    return None;
                }
                EmitterCoords::Corners(
                    parts
                        .into_iter()
                        .zip(normals)
                        .map(|((part, object), &normal)| Corners {
                            object,
                            world: object.map(|p| to_world.point(p)),
                            uv: object.map(|p| shape.uv_at(p, part)),
                            normal,
                        })
                        .collect(),
                )
            }
            _ => EmitterCoords::Shape {
                shape: shape.clone(),
                to_object: to_world.inverted(),
                to_world: to_world.clone(),
            },
        };
        Some(EmissionTexture { texture, coords })
    }

    /// Where the texture is looked up at a sampled point.
    pub(crate) fn coords(&self, at: EmitterPoint) -> TextureCoords {
        match (&self.coords, at) {
            (EmitterCoords::Corners(corners), EmitterPoint::Triangle { triangle, b }) => {
                let w = [b[0], b[1], 1.0 - b[0] - b[1]];
                let c = &corners[triangle];
                let mix = |p: &[Vec3; 3]| p[0] * w[0] + p[1] * w[1] + p[2] * w[2];
                let t = &c.uv;
                TextureCoords {
                    uv: [
                        t[0][0] * w[0] + t[1][0] * w[1] + t[2][0] * w[2],
                        t[0][1] * w[0] + t[1][1] * w[1] + t[2][1] * w[2],
                    ],
                    object_point: mix(&c.object),
                    point: mix(&c.world),
                    normal: c.normal,
                }
            }
            (
                EmitterCoords::Shape {
                    shape,
                    to_object,
                    to_world,
                },
                EmitterPoint::World(q),
            ) => {
                let p = to_object.point(q);
                // The normal of a sphere (from its centre) or a disk.
                let n = match shape {
                    Shape::Sphere(s) => p - s.center,
                    Shape::Disk(d) => d.normal,
                    _ => Vec3::Z,
                };
                TextureCoords {
                    uv: shape.uv_at(p, 0),
                    object_point: p,
                    point: q,
                    normal: to_world.normal(n).normalized(),
                }
            }
            // Not a point of this emitter (cannot happen for a texture made for it).
            (_, _) => TextureCoords::new([0.0, 0.0], Vec3::ZERO),
        }
    }

    /// The texture's value at a sampled point.
    pub(crate) fn at(&self, point: EmitterPoint) -> Color {
        self.texture.evaluate(&self.coords(point))
    }
}

/// Equal when it is the same texture (as environment maps are compared).
impl PartialEq for EmissionTexture {
    fn eq(&self, o: &Self) -> bool {
        std::ptr::eq(self, o)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Cuboid, Polygon, Polyhedron, Sphere, TriangleMesh};
    use crate::math::Ray;
    use crate::sampling::Rng;
    use std::sync::Arc;

    /// The (u, v) a sampled point of each emitter gets is the one a ray hitting the shape
    /// there reports: for a box (each face its own part), a polyhedron, a concave polygon,
    /// a mesh with uvs (under a mirroring transform, which rewinds the emitter's
    /// triangles) and a placed sphere.
    #[test]
    fn sampled_points_get_the_uv_a_hit_there_gets() {
        let v = Vec3::new;
        let octahedron = Polyhedron::new(
            &[
                v(1.0, 0.0, 0.0),
                v(-1.0, 0.0, 0.0),
                v(0.0, 1.0, 0.0),
                v(0.0, -1.0, 0.0),
                v(0.0, 0.0, 1.0),
                v(0.0, 0.0, -1.0),
            ],
            &[
                vec![0, 2, 4],
                vec![2, 1, 4],
                vec![1, 3, 4],
                vec![3, 0, 4],
                vec![2, 0, 5],
                vec![1, 2, 5],
                vec![3, 1, 5],
                vec![0, 3, 5],
            ],
        )
        .unwrap();
        let notch = Polygon::new(vec![
            v(0.0, 0.0, 0.0),
            v(2.0, 0.0, 0.0),
            v(2.0, 2.0, 0.0),
            v(1.0, 0.7, 0.0),
            v(0.0, 2.0, 0.0),
        ])
        .unwrap();
        let mesh = TriangleMesh::new(
            vec![
                v(0.0, 0.0, 0.0),
                v(1.0, 0.0, 0.0),
                v(1.3, 1.0, 0.0),
                v(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
            Vec::new(),
            vec![[0.1, 0.2], [0.9, 0.1], [0.7, 0.8], [0.2, 0.6]],
        )
        .unwrap();
        let turn = Transform::rotate(v(1.0, 2.0, 0.5), 40.0).unwrap();
        let mirror = Transform::scale(v(-1.0, 2.0, 1.0)).unwrap().after(&turn);
        let sphere_place = Transform::translate(v(0.3, -1.0, 2.0))
            .after(&Transform::scale(Vec3::splat(2.0)).unwrap())
            .after(&turn);
        let cases = [
            (
                Shape::Cuboid(Cuboid::new(v(-1.0, -0.5, 0.0), v(2.0, 1.0, 0.5))),
                turn,
            ),
            (Shape::Polyhedron(Box::new(octahedron)), turn),
            (Shape::Polygon(Box::new(notch)), Transform::IDENTITY),
            (Shape::Mesh(Arc::new(mesh)), mirror),
            (
                Shape::Sphere(Sphere::new(v(0.0, 0.0, 0.0), 1.0)),
                sphere_place,
            ),
        ];
        let mut rng = Rng::new(5, 1);
        for (shape, to_world) in cases {
            let emitter = Emitter::of_shape(&shape, &to_world).unwrap();
            let t =
                EmissionTexture::new(Texture::Constant(Color::WHITE), &emitter, &shape, &to_world)
                    .unwrap();
            let to_object = to_world.inverted();
            for _ in 0..200 {
                let (q, n, at) = emitter
                    .sample_point([rng.uniform(), rng.uniform()])
                    .unwrap();
                let coords = t.coords(at);
                let got = coords.uv;
                // The world point and normal are the sampled ones.
                assert!((coords.point - q).length() < 1e-9 * (1.0 + q.length()));
                assert!((coords.normal.dot(n).abs() - 1.0).abs() < 1e-9);
                // A ray down the normal onto the point, in the shape's coordinates.
                let (p, d) = (to_object.point(q + n * 1e-3), to_object.vector(-n));
                let ray = Ray::new(p, d);
                let hit = shape.intersect(&ray, 1.0).expect("the ray meets the shape");
                let want = shape.surface(&ray, &hit, true).uv;
                // u wraps around on the sphere.
                let du = (got[0] - want[0]).abs();
                let du = du.min((1.0 - du).abs());
                assert!(
                    du < 1e-4 && (got[1] - want[1]).abs() < 1e-4,
                    "{}: sampled {got:?}, hit {want:?}",
                    shape.kind_name()
                );
            }
        }
    }
}
