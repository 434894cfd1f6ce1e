//! Whitted's recursive ray tracing (Whitted 1980), as the lecture's pseudocode states it:
//!
//! I = k_e + k_a·I_a + Σ_L S_L·f(d)·I_L·(k_d·max(0, N·L) + k_s·max(0, R·V)^n)
//!     + k_r·I(reflected ray) + k_t·I(refracted ray)
//!
//! S_L comes from a shadow ray to every light: 1 when nothing is in the way, the product of
//! the occluders' k_t when they are transmissive, 0 behind an opaque one. Recursion stops at
//! the maximum depth and when a ray's weight in the pixel drops below a threshold (Hall and
//! Greenberg 1983). On total internal reflection the refracted weight goes to reflection.
//!
//! It becomes distribution ray tracing (Cook, Porter and Carpenter 1984) where the scene asks
//! for it: an area light's S_L·I_L is averaged over shadow rays to points stratified over its
//! area, and a glossy material's reflected and refracted rays are drawn from a Phong lobe
//! around the mirror and Snell directions (the lobe is normalised, so the weight stays k_r or
//! k_t; a direction drawn below the surface carries nothing). Their random numbers come from
//! the pixel sample's stream, so the sampler stratifies them across the pixel's samples.

use super::{
    IntegratorConfig, IntegratorKind, MediumStack, Optics, RayCounts, RayKind, RayNode, RayTree,
    ShadowInfo, Stop,
};
use crate::accel::Coherence;
use crate::color::Color;
use crate::light::Incident;
use crate::math::{offset_ray_origin, Ray, Vec3};
use crate::optics::{fresnel_dielectric, reflect, refract};
use crate::sampling::{phong_lobe, Frame, SampleStream};
use crate::scene::{Interaction, Scene};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WhittedConfig {
    /// Bounces of reflection and refraction after the camera ray (0: direct light only);
    /// at most [`crate::settings::MAX_DEPTH`].
    pub max_depth: u32,
    /// Rays whose weight in the pixel (largest RGB component) falls below this are not traced.
    pub min_weight: f64,
    /// Shadow rays decide S_L; without them every light is seen (local illumination).
    pub shadows: bool,
    /// Whitted's method recurses; local illumination and Appel's stop at the first hit.
    pub recursive: bool,
}

impl Default for WhittedConfig {
    fn default() -> Self {
        IntegratorConfig::default().whitted()
    }
}

impl IntegratorConfig {
    /// Whitted's settings; local illumination and Appel's method are Whitted's without
    /// recursion, local illumination also without shadow rays.
    pub fn whitted(&self) -> WhittedConfig {
        let recursive = self.kind == IntegratorKind::Whitted;
        WhittedConfig {
            max_depth: if recursive { self.max_depth } else { 0 },
            min_weight: self.min_weight,
            shadows: self.kind != IntegratorKind::Local,
            recursive,
        }
    }
}

pub struct Whitted<'a> {
    scene: &'a Scene,
    config: WhittedConfig,
}

/// One ray to trace, with where it sits in the tree.
struct Branch<'t, 'm> {
    kind: RayKind,
    depth: u32,
    weight: Color,
    media: &'m MediumStack,
    tree: Option<&'t mut RayTree>,
    parent: Option<usize>,
}

impl<'a> Whitted<'a> {
    pub fn new(scene: &'a Scene, config: WhittedConfig) -> Self {
        Whitted { scene, config }
    }

    /// Radiance along a camera ray; `stream` gives the random numbers of its pixel sample.
    /// With `tree`, every ray traced is recorded in it.
    pub fn camera_ray(
        &self,
        ray: &Ray,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
        tree: Option<&mut RayTree>,
    ) -> Color {
        let branch = Branch {
            kind: RayKind::Camera,
            depth: 0,
            weight: Color::WHITE,
            media: &MediumStack::default(),
            tree,
            parent: None,
        };
        self.trace(ray, branch, stream, counts)
    }

    fn trace(
        &self,
        ray: &Ray,
        mut b: Branch,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
    ) -> Color {
        let node = b.tree.as_deref_mut().map(|t| {
            t.push(RayNode::new(
                b.parent,
                b.kind,
                b.depth,
                ray.origin,
                ray.direction,
                b.weight,
            ))
        });
        let Some((prim, hit)) = self.scene.geometry.intersect(ray, f64::INFINITY) else {
            if let (Some(t), Some(i)) = (b.tree.as_deref_mut(), node) {
                t.nodes[i].stops.push(Stop::Miss);
                t.nodes[i].color = self.scene.background;
            }
            return self.scene.background;
        };
        let it = self.scene.geometry.interaction(ray, prim, &hit);
        let k = self.scene.coefficients(&it);
        if let (Some(t), Some(i)) = (b.tree.as_deref_mut(), node) {
            let n = &mut t.nodes[i];
            n.object = Some(self.scene.geometry.names[prim as usize].clone());
            let m = self.scene.geometry.primitives[prim as usize].material as usize;
            n.material = Some(self.scene.materials.names[m].clone());
            n.distance = Some(hit.t * ray.direction.length());
        }

        let d = ray.direction.normalized();
        let v = -d;
        let entering = d.dot(it.n) < 0.0;
        // Normals on the side the ray arrives from.
        let n = if entering { it.n } else { -it.n };
        let ns = it.shading_n.face_forward(n);
        if b.tree.is_some() {
            // The angle at every hit; where the ray splits, the rest is added below.
            let optics = Optics {
                incidence: degrees(v.dot(ns)),
                eta: None,
                refraction: None,
                critical: None,
                fresnel: None,
            };
            record(&mut b, node, |n| n.optics = Some(optics));
        }

        // Local illumination: emission, ambient, and Phong from every light. An area light's
        // surface shows its light's radiance on the side it emits to, in place of any k_e
        // (as under the physically based methods).
        let mut color = k.ambient * self.scene.ambient;
        match self.scene.area_light(prim) {
            Some(l) => {
                let light = &self.scene.lights[l as usize];
                if light.emits_toward(it.n, v) {
                    color += light
                        .textured_radiance_at(&it.texture())
                        .unwrap_or(light.rgb());
                }
            }
            None => color += k.emissive,
        }
        // A surface that neither diffuses nor highlights (an emitter, a mirror, clear
        // glass) needs no shadow rays.
        let lit = !(k.diffuse.is_black() && k.specular.is_black());
        for &li in self.scene.lights.whitted.iter().filter(|_| lit) {
            let light = &self.scene.lights[li as usize];
            // An area light's m × m shadow rays share one offset from the stream, each in
            // its own cell: stratified within the shading point, and the offset stratified
            // across the pixel's samples.
            let count = light.samples();
            let offset = if light.is_area() {
                stream.next_2d()
            } else {
                [0.5; 2]
            };
            let m = (count as f64).sqrt().round() as u32;
            let mut sum = Color::BLACK;
            for cell in 0..count {
                let u = [
                    ((cell % m) as f64 + offset[0]) / m as f64,
                    ((cell / m) as f64 + offset[1]) / m as f64,
                ];
                let Some(inc) = light.incident(it.p, u) else {
                    continue;
                };
                let cos = ns.dot(inc.wi);
                if cos <= 0.0 || n.dot(inc.wi) <= 0.0 {
                    // Said once per light, not per shadow-ray cell.
                    let name = &self.scene.lights.names[li as usize];
                    record(&mut b, node, |n| {
                        if !n.lights_behind.contains(name) {
                            n.lights_behind.push(name.clone());
                        }
                    });
                    continue;
                }
                let s = if self.config.shadows {
                    self.shadow(ray, &it, n, &inc, li as usize, &mut b, node, counts)
                } else {
                    Color::WHITE
                };
                if s.is_black() {
                    continue;
                }
                let mut response = k.diffuse * cos;
                if !k.specular.is_black() {
                    let r = reflect(-inc.wi, ns);
                    response += k.specular * r.dot(v).max(0.0).powf(k.shininess);
                }
                sum += s * inc.intensity * response;
            }
            color += sum / count as f64;
        }

        // Global illumination: the reflected and refracted rays.
        let (mut kr, mut kt) = (k.reflective, k.transmissive);
        if kr.is_black() && kt.is_black() {
            record(&mut b, node, |n| n.stops.push(Stop::Opaque));
            record(&mut b, node, |n| n.color = color);
            return color;
        }
        // Closed solids (and the half-space under a plane) are media the ray enters and
        // leaves. Thin sheets (polygons, disks, open shells) have no inside: light crosses them
        // unbent, as through a pane of zero thickness, and the medium stays the same.
        let solid = self.scene.geometry.primitives[prim as usize]
            .shape
            .is_closed();
        // Whitted's model is RGB: indices at the sodium D line.
        let ior = |m| self.scene.materials[m as usize].ior_at(589.3);
        let media_t = if kt.is_black() || !solid {
            *b.media
        } else if entering {
            b.media
                .entered(prim, self.scene.geometry.primitives[prim as usize].material)
        } else {
            b.media.left(prim)
        };
        let (eta_i, eta_t) = if entering || !solid {
            (b.media.ior(ior), k.ior)
        } else {
            (k.ior, media_t.ior(ior))
        };
        // Mirror and lens directions follow the shading normal, so smooth meshes look
        // smooth; a direction that would cross to the wrong side of the true surface falls
        // back to the geometric normal.
        let reflected = Some(reflect(d, ns))
            .filter(|r| r.dot(n) > 0.0)
            .unwrap_or_else(|| reflect(d, n));
        let refracted = if kt.is_black() {
            None
        } else if !solid {
            Some(d)
        } else {
            let eta = eta_i / eta_t;
            match refract(d, ns, eta) {
                Some(t) if t.dot(n) < 0.0 => Some(t),
                Some(_) => refract(d, n, eta),
                None => None,
            }
        };
        let total_internal_reflection = !kt.is_black() && refracted.is_none();
        if total_internal_reflection {
            record(&mut b, node, |n| n.total_internal_reflection = true);
        }
        let mut fresnel = None;
        if k.fresnel {
            // F = 1 under total internal reflection: everything goes to the reflected ray.
            let f = fresnel_dielectric(v.dot(ns).max(0.0), eta_i, eta_t);
            fresnel = Some(f);
            kr = kr * f;
            kt = kt * (1.0 - f);
        } else if total_internal_reflection {
            kr += kt;
            kt = Color::BLACK;
        }
        if b.tree.is_some() {
            let transmits = !k.transmissive.is_black() && solid;
            let optics = Optics {
                incidence: degrees(v.dot(ns)),
                eta: transmits.then_some((eta_i, eta_t)),
                refraction: refracted.filter(|_| transmits).map(|t| degrees(t.dot(-ns))),
                critical: (transmits && eta_i > eta_t).then(|| (eta_t / eta_i).asin().to_degrees()),
                fresnel,
            };
            record(&mut b, node, |n| n.optics = Some(optics));
        }
        let secondary = [
            (RayKind::Reflected, kr, Some(reflected), b.media),
            (RayKind::Refracted, kt, refracted, &media_t),
        ];
        for (kind, coefficient, direction, media) in secondary {
            let Some(mut direction) = direction.filter(|_| !coefficient.is_black()) else {
                continue;
            };
            if let Some(exponent) = k.gloss {
                let lobe =
                    Frame::from_z(direction).to_world(phong_lobe(stream.next_2d(), exponent));
                // Reflected rays stay above the surface, refracted ones go below.
                let above = lobe.dot(n) > 0.0;
                if above != (kind == RayKind::Reflected) {
                    continue;
                }
                direction = lobe;
            }
            if b.depth >= self.config.max_depth {
                let stop = if self.config.recursive {
                    Stop::SkippedAtDepth(kind)
                } else {
                    Stop::NoRecursion
                };
                record(&mut b, node, |n| {
                    if !n.stops.contains(&stop) {
                        n.stops.push(stop)
                    }
                });
                continue;
            }
            let weight = b.weight * coefficient;
            if weight.max_component() < self.config.min_weight {
                record(&mut b, node, |n| n.stops.push(Stop::SkippedForWeight(kind)));
                continue;
            }
            match kind {
                RayKind::Reflected => counts.reflection += 1,
                _ => counts.refraction += 1,
            }
            counts.bounce(b.depth + 1);
            let origin = offset_ray_origin(it.p, it.p_error, n, direction);
            let child = Branch {
                kind,
                depth: b.depth + 1,
                weight,
                media,
                tree: b.tree.as_deref_mut(),
                parent: node,
            };
            let next = Ray::new(origin, direction).at_time(ray.time);
            color += coefficient * self.trace(&next, child, stream, counts);
        }
        record(&mut b, node, |n| n.color = color);
        color
    }

    /// S_L for one light: 1, the product of the transmissive occluders' k_t, or 0. Each
    /// occluding object counts once, with k_t where the shadow ray first meets it; the
    /// product does not depend on order, so one any-hit pass finds it, stopping at the first
    /// opaque occluder.
    #[allow(clippy::too_many_arguments)]
    fn shadow(
        &self,
        from: &Ray,
        it: &Interaction,
        n: Vec3,
        inc: &Incident,
        light: usize,
        b: &mut Branch,
        parent: Option<usize>,
        counts: &mut RayCounts,
    ) -> Color {
        counts.shadow += 1;
        let origin = offset_ray_origin(it.p, it.p_error, n, inc.wi);
        let ray = match inc.position {
            Some(light_at) => Ray::new(origin, light_at - origin),
            None => Ray::new(origin, inc.wi),
        }
        .at_time(from.time);
        let t_max = inc.shadow_end;
        let recording = b.tree.is_some();
        let mut occluders: Vec<(f64, u32)> = Vec::new();
        let mut s = Color::WHITE;
        // Incoherent: between a pixel's camera, reflected and refracted rays, its shadow
        // rays do not follow the last pixel's closely enough for the branch predictor
        // (walked as coherent, a bunny lit by two point lights rendered 9 % slower).
        let walk = Coherence::Incoherent;
        self.scene
            .geometry
            .for_each_hit(&ray, t_max, walk, |prim, hit| {
                if recording {
                    occluders.push((hit.t, prim));
                }
                if self.scene.geometry.is_transmissive(prim) {
                    s *= self.scene.transmissive(&ray, prim, hit);
                } else {
                    s = Color::BLACK;
                }
                // Once black, nothing further can let light through.
                !s.is_black() || recording
            });
        if let Some(t) = b.tree.as_deref_mut() {
            occluders.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut node = RayNode::new(
                parent,
                RayKind::Shadow,
                b.depth + 1,
                origin,
                inc.wi,
                b.weight,
            );
            node.distance = Some(inc.distance);
            node.color = s * inc.intensity;
            node.shadow = Some(ShadowInfo {
                light: self.scene.lights.names[light].clone(),
                occluders: occluders
                    .iter()
                    .map(|&(_, p)| self.scene.geometry.names[p as usize].clone())
                    .collect(),
                blocked: s.is_black(),
                transmittance: s,
            });
            t.push(node);
        }
        s
    }
}

/// The angle, in degrees, whose cosine is `cos` (clamped to [−1, 1]).
fn degrees(cos: f64) -> f64 {
    cos.clamp(-1.0, 1.0).acos().to_degrees()
}

fn record(b: &mut Branch<'_, '_>, node: Option<usize>, f: impl FnOnce(&mut RayNode)) {
    if let (Some(t), Some(i)) = (b.tree.as_deref_mut(), node) {
        f(&mut t.nodes[i]);
    }
}
