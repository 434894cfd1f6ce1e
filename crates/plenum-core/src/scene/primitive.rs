//! A shape placed in the world (a transform, perhaps moving, and a material), and a hit on it
//! in world space.

use super::alpha::Alpha;
use super::bump::{Bump, UvDerivatives};
use crate::accel::Coherence;
use crate::geometry::{HitRecord, Shape, SurfaceGeometry};
use crate::material::MaterialId;
use crate::math::{gamma, offset_ray_origin, Bounds3, Motion, Ray, Transform, Vec3};
use crate::texture::TextureCoords;
use std::sync::Arc;

/// A shape placed in the world with a material.
#[derive(Clone, Debug)]
pub struct Primitive {
    pub shape: Shape,
    /// Object-to-world transform; `None` when the shape is already in world coordinates.
    pub to_world: Option<Box<Transform>>,
    /// For an object that moves while the shutter is open: its transforms at times 0 and 1,
    /// which replace `to_world` (the pose at time 0).
    pub motion: Option<Box<Motion>>,
    pub material: MaterialId,
    /// For meshes: a material per vertex, blended across each triangle by its barycentric
    /// coordinates (the course `.ray` format's per-vertex materials). Replaces `material`.
    pub vertex_materials: Option<Arc<Vec<MaterialId>>>,
    /// The area light whose surface this is: hits on it see that light's emission.
    pub light: Option<u32>,
    /// A cut-out: the surface is there only where this says (none: everywhere).
    pub alpha: Option<Arc<Alpha>>,
    /// A normal or bump map that turns the shading normal (none: the shape's own).
    pub bump: Option<Arc<Bump>>,
}

/// The most cut-away hits one query passes on one primitive before it gives up and reports
/// a miss: a bound that keeps a pathological mesh from stalling a ray.
const MAX_CUTS: u32 = 1024;

/// Everything the integrator needs about a hit, in world space.
#[derive(Clone, Copy, Debug)]
pub struct Interaction {
    pub p: Vec3,
    pub p_error: Vec3,
    /// Unit geometric normal, outward for solids.
    pub n: Vec3,
    /// Unit shading normal, on the same side as `n`.
    pub shading_n: Vec3,
    /// Texture coordinates (when asked for).
    pub uv: [f64; 2],
    /// The hit point in the object's coordinates.
    pub object_point: Vec3,
    pub primitive: u32,
    /// The shape's record of the hit: which triangle, and where in it.
    pub hit: HitRecord,
}

impl Interaction {
    /// Where textures are looked up at this hit. (Built when asked: storing it would
    /// repeat the point and normal in every hit the integrators pass around.)
    #[inline]
    pub fn texture(&self) -> TextureCoords {
        TextureCoords {
            uv: self.uv,
            object_point: self.object_point,
            point: self.p,
            normal: self.n,
        }
    }
}

impl Primitive {
    /// Calls `f` with the object-to-world transform at `time` (`None`: identity).
    #[inline(always)]
    fn placed<R>(&self, time: f64, f: impl FnOnce(Option<&Transform>) -> R) -> R {
        match &self.motion {
            None => f(self.to_world.as_deref()),
            Some(m) => f(Some(&m.at(time))),
        }
    }

    /// The nearest hit in (0, t_max) where the surface is present.
    #[inline(never)]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        let hit = self.intersect_shape(ray, t_max);
        match &self.alpha {
            None => hit,
            Some(alpha) => self.past_cut_outs(alpha, ray, t_max, hit?),
        }
    }

    /// The nearest hit from `hit` on where the surface is present. As pbrt-v4 does, a ray
    /// that meets a cut-away part goes on from just past it (its origin pushed beyond the
    /// hit's error bounds, so it cannot meet the same point again), and distances are kept
    /// along the first ray.
    #[cold]
    #[inline(never)]
    fn past_cut_outs(
        &self,
        alpha: &Alpha,
        ray: &Ray,
        t_max: f64,
        mut hit: HitRecord,
    ) -> Option<HitRecord> {
        if alpha.is_absent() {
            return None;
        }
        let want_uv = alpha.needs_uv();
        let mut from = *ray;
        let mut t_from = 0.0;
        for _ in 0..MAX_CUTS {
            let it = self.interaction(&from, &hit, 0, want_uv);
            if alpha.keeps(&it.texture(), || super::hash_hit(it.p, ray.direction)) {
                hit.t += t_from;
                return Some(hit);
            }
            from.origin = offset_ray_origin(it.p, it.p_error, it.n, ray.direction);
            t_from = (from.origin - ray.origin).dot(ray.direction) / ray.direction.length_squared();
            hit = self.intersect_shape(&from, t_max - t_from)?;
        }
        None
    }

    /// The nearest hit on the shape in (0, t_max), cut-outs or not.
    #[inline(always)]
    fn intersect_shape(&self, ray: &Ray, t_max: f64) -> Option<HitRecord> {
        self.placed(ray.time, |placement| match placement {
            None => self.shape.intersect(ray, t_max),
            Some(t) => {
                let (local, dt) = t.ray_to_object(ray);
                let mut hit = self.shape.intersect(&local, t_max - dt)?;
                hit.t += dt;
                Some(hit)
            }
        })
    }

    /// The hit in world space; `want_uv` asks for texture coordinates.
    pub fn interaction(
        &self,
        ray: &Ray,
        hit: &HitRecord,
        primitive: u32,
        want_uv: bool,
    ) -> Interaction {
        let want_uv = want_uv || self.bump.is_some();
        self.placed(ray.time, |placement| match placement {
            None => {
                let g = self.shape.surface(ray, hit, want_uv);
                let shading_n = match &self.bump {
                    None => g.shading_n,
                    Some(bump) => {
                        let texture = TextureCoords {
                            uv: g.uv,
                            object_point: g.p,
                            point: g.p,
                            normal: g.n,
                        };
                        self.bumped(bump, hit, &g, &texture, g.n, g.shading_n, None)
                    }
                };
                Interaction {
                    p: g.p,
                    p_error: g.p_error,
                    n: g.n,
                    shading_n,
                    uv: g.uv,
                    object_point: g.p,
                    primitive,
                    hit: *hit,
                }
            }
            Some(t) => {
                let (local, dt) = t.ray_to_object(ray);
                let local_hit = HitRecord {
                    t: hit.t - dt,
                    ..*hit
                };
                let g = self.shape.surface(&local, &local_hit, want_uv);
                let (p, p_error) = t.point_with_error(g.p, g.p_error);
                // A spawned ray is intersected in object space, where what keeps it off the
                // surface is its distance along the object normal. Offsetting by the world
                // error box alone falls short under anisotropic scales: require the world
                // offset to map to more than the object-space error along the normal (that of
                // the hit, that of taking the new origin back into object space, and that of
                // the stored inverse itself).
                let normal = t.normal(g.n);
                // A degenerate normal (a shape's singular point) keeps the world's error box.
                let stretch = normal.length().max(f64::MIN_POSITIVE);
                let n = normal / stretch;
                let inverse_mismatch = t.inverse_residual() * (g.p.abs().max_component() + 1.0);
                let object_error = g.n.abs().dot(g.p_error + t.inverse_error(p))
                    + inverse_mismatch * g.n.abs().dot(Vec3::ONE);
                let p_error = p_error + n.abs() * (object_error / stretch * (1.0 + gamma(4)));
                let shading_n = t.normal(g.shading_n).normalized();
                let shading_n = match &self.bump {
                    None => shading_n,
                    Some(bump) => {
                        let texture = TextureCoords {
                            uv: g.uv,
                            object_point: g.p,
                            point: p,
                            normal: n,
                        };
                        self.bumped(bump, &local_hit, &g, &texture, n, shading_n, Some(t))
                    }
                };
                Interaction {
                    p,
                    p_error,
                    n,
                    shading_n,
                    uv: g.uv,
                    object_point: g.p,
                    primitive,
                    hit: *hit,
                }
            }
        })
    }

    /// The shading normal `shading_n` (world space) turned by `bump`, at a hit whose
    /// object-space geometry is `g`. The tangent frame is placed in the world first, as
    /// pbrt-v4 does.
    #[cold]
    #[allow(clippy::too_many_arguments)]
    fn bumped(
        &self,
        bump: &Bump,
        hit: &HitRecord,
        g: &SurfaceGeometry,
        texture: &TextureCoords,
        n: Vec3,
        shading_n: Vec3,
        placement: Option<&Transform>,
    ) -> Vec3 {
        let object = self.shape.uv_derivatives(hit, g);
        let world = match placement {
            None => object,
            Some(t) => object.map(|d| t.vector(d)),
        };
        bump.shading_normal(texture, n, shading_n, &UvDerivatives { world, object })
    }

    /// Some hit in (0, t_max), not necessarily the nearest (see [`Shape::intersect_any`]).
    /// Past a cut-out the nearest is sought, so that no present part before it is missed.
    pub fn intersect_any(&self, ray: &Ray, t_max: f64, coherence: Coherence) -> Option<HitRecord> {
        if self.alpha.is_some() {
            return self.intersect(ray, t_max);
        }
        self.placed(ray.time, |placement| match placement {
            None => self.shape.intersect_any(ray, t_max, coherence),
            Some(t) => {
                let (local, dt) = t.ray_to_object(ray);
                let mut hit = self.shape.intersect_any(&local, t_max - dt, coherence)?;
                hit.t += dt;
                Some(hit)
            }
        })
    }

    /// World bounds; for a moving object, of everywhere it goes while the shutter is open.
    pub fn world_bounds(&self) -> Option<Bounds3> {
        let b = self.shape.bounds()?;
        Some(match (&self.motion, &self.to_world) {
            (Some(m), _) => m.bounds(&b),
            (None, None) => b,
            (None, Some(t)) => Bounds3::from_points(b.corners().map(|c| t.point(c))),
        })
    }
}
