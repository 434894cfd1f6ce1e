//! One bounce of an eye path, written once for the methods that walk from the camera: the
//! path tracer and the eye passes of photon mapping and SPPM. A bounce traces the path's
//! ray, takes the light that ray finds (the sky where it escapes, an emitter where it hits
//! one), weighed by MIS against the light sample taken at the vertex it left, and goes on by
//! a BSDF sample. What a method does at a vertex (light sampling, a final gather, a visible
//! point, Russian roulette) stays the method's own.

use super::{
    direct, record, record_hit, rgb, weight_rgb, RayCounts, RayKind, RayNode, RayTree, Stop,
};
use crate::bxdf::{Bsdf, BsdfSample, TransportMode};
use crate::math::{offset_ray_origin, Ray, Vec3};
use crate::scene::{Interaction, Scene};
use plenum_spectrum::{SampledSpectrum, SampledWavelengths};

/// An eye path between bounces.
pub(super) struct EyePath {
    /// The ray traced next.
    pub ray: Ray,
    /// The throughput: the product of f·|cos θ|/pdf over the bounces so far.
    pub beta: SampledSpectrum,
    /// The bounces so far: 0 while the camera ray is traced.
    pub depth: u32,
    /// The length of the path so far, to the last vertex found.
    pub distance: f64,
    /// For MIS on the light the next ray finds: the pdf of its direction under the BSDF
    /// that sampled it, and the point it left from. The camera ray and specular bounces find
    /// light that no light sample finds: their infinite pdf takes it in full.
    pdf_bsdf: f64,
    previous: Vec3,
    /// The next ray's kind and parent in the ray tree.
    kind: RayKind,
    parent: Option<usize>,
}

/// Where an eye path's ray hit.
pub(super) struct EyeVertex {
    pub it: Interaction,
    /// The direction back along the ray, unit length.
    pub wo: Vec3,
    /// The ray's node in the ray tree.
    pub node: Option<usize>,
}

impl EyePath {
    pub fn new(camera_ray: &Ray) -> Self {
        EyePath {
            ray: *camera_ray,
            beta: SampledSpectrum::ONE,
            depth: 0,
            distance: 0.0,
            pdf_bsdf: f64::INFINITY,
            previous: camera_ray.origin,
            kind: RayKind::Camera,
            parent: None,
        }
    }

    /// Traces the path's ray and adds to `l` the light it finds, times the throughput.
    /// Returns the vertex it hits, or `None` where it escapes. The ray's tree node names
    /// what it hit and, where it escaped, the light it brought.
    pub fn trace(
        &mut self,
        scene: &Scene,
        wl: &SampledWavelengths,
        l: &mut SampledSpectrum,
        tree: &mut Option<&mut RayTree>,
    ) -> Option<EyeVertex> {
        let ray = &self.ray;
        let node = tree.as_deref_mut().map(|t| {
            t.push(RayNode::new(
                self.parent,
                self.kind,
                self.depth,
                ray.origin,
                ray.direction,
                weight_rgb(self.beta, wl),
            ))
        });
        let Some((prim, hit)) = scene.geometry.intersect(ray, f64::INFINITY) else {
            let d = ray.direction.normalized();
            let le = self.beta * direct::infinite_mis(scene, d, wl, self.pdf_bsdf, 1.0);
            *l += le;
            record(tree, node, |n| {
                n.stops.push(Stop::Miss);
                n.color = rgb(le, wl);
            });
            return None;
        };
        let t = hit.t * ray.direction.length();
        self.distance += t;
        record_hit(tree, node, scene, prim, t);
        let it = scene.geometry.interaction(ray, prim, &hit);
        let wo = -ray.direction.normalized();
        if let Some(light) = scene.area_light(prim) {
            let le =
                direct::emitted_mis(scene, light, &it, wo, wl, self.pdf_bsdf, self.previous, 1.0);
            *l += self.beta * le;
        } else if let Some(ke) = scene.phong_emission(&it, wl) {
            // A Phong surface's k_e: seen, but no light to sample.
            *l += self.beta * ke;
        }
        Some(EyeVertex { it, wo, node })
    }

    /// Goes on from `v` by a sample of `bsdf` (the vertex's BSDF, or the part of it the
    /// method traces) drawn with `uc` and `u`. Returns the sample, or `None` where the path
    /// ends: no direction sampled, or no throughput left.
    pub fn bounce(
        &mut self,
        v: &EyeVertex,
        bsdf: &Bsdf,
        uc: f64,
        u: [f64; 2],
        counts: &mut RayCounts,
        tree: &mut Option<&mut RayTree>,
    ) -> Option<BsdfSample> {
        let Some(bs) = bsdf.sample_f(v.wo, uc, u, TransportMode::Radiance) else {
            record(tree, v.node, |n| n.stops.push(Stop::Opaque));
            return None;
        };
        self.beta *= bs.f * (bs.wi.dot(v.it.shading_n).abs() / bs.pdf);
        self.pdf_bsdf = match bs.is_specular() {
            true => f64::INFINITY,
            false => direct::bsdf_pdf(bsdf, v.wo, &bs),
        };
        if bs.is_transmission() {
            counts.refraction += 1;
            self.kind = RayKind::Refracted;
        } else {
            counts.reflection += 1;
            self.kind = RayKind::Reflected;
        }
        counts.bounce(self.depth + 1);
        if self.beta.is_black() {
            return None;
        }
        let it = &v.it;
        self.previous = it.p;
        let origin = offset_ray_origin(it.p, it.p_error, it.n, bs.wi);
        self.ray = Ray::new(origin, bs.wi).at_time(self.ray.time);
        self.parent = v.node;
        self.depth += 1;
        Some(bs)
    }
}
