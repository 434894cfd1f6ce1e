//! Bidirectional path tracing (Veach and Guibas 1995; Veach's thesis, ch. 10): per pixel
//! sample a camera subpath and a light subpath, joined by every connection strategy (s, t) —
//! s vertices from the light, t from the camera — and weighed by multiple importance
//! sampling with the power heuristic. The bookkeeping is pbrt's (3rd ed. §16.3): each vertex
//! keeps the area density of being reached forward along its own subpath and in reverse, so
//! that a strategy's weight is a sum of ratios of densities computed in one sweep per side.
//!
//! Strategies: s = 0, a camera subpath that finds an emitter; s = 1, next-event estimation
//! (a fresh light sample); t = 1, the light subpath joined to a fresh lens point and splatted
//! (light tracing); the rest join a light vertex to a camera vertex. Depth as elsewhere:
//! `max_depth` D allows up to D + 1 surface vertices, the path tracer's longest paths.
//!
//! The power heuristic's ratios are squared and clamped to 10^±150, so deep paths neither
//! overflow nor lose their weight (a clamped ratio stands for a strategy whose weight is
//! below 10⁻³⁰⁰). Russian roulette after `rr_depth` shortens both subpaths; it divides the
//! throughput by the survival probability, so weights stay a partition of unity.
//!
//! Light carried from the lights scatters by the adjoint BSDF with Veach's shading-normal
//! correction (§5.3, [`super::light_tracing`]); emission that no light represents (the
//! background, a Phong material's k_e) is found by s = 0 alone and so takes weight 1.

use super::light_path::{adjoint_cosine_of, leave_light, start_light_path, LightStart};
use super::{
    rgb, weight_rgb, IntegratorConfig, RayCounts, RayKind, RayNode, RayTree, Stop, Strategy,
};
use crate::accel::Coherence;
use crate::bxdf::{Bsdf, TransportMode};
use crate::camera::Camera;
use crate::color::Color;
use crate::film::SplatBuffer;
use crate::light::AREA_SHADOW_END;
use crate::material::rgb_radiance;
use crate::math::{offset_ray_origin, Ray, Vec3};
use crate::sampling::SampleStream;
use crate::scene::Scene;
use plenum_spectrum::{ColorMode, SampledSpectrum, SampledWavelengths};
use std::cell::RefCell;
use std::f64::consts::PI;

/// Images of each strategy (s, t), weighted by MIS and not, as Veach's thesis shows them
/// (fig. 10.3): summed in fixed point like the film's splats.
pub struct StrategyImages {
    /// The longest path in vertices, s + t.
    pub max_vertices: usize,
    /// (weighted, unweighted) per (s, t), at index [`StrategyImages::index`].
    pub images: Vec<(SplatBuffer, SplatBuffer)>,
}

impl StrategyImages {
    pub fn new(width: u32, height: u32, scale: f64, max_depth: u32) -> StrategyImages {
        let max_vertices = max_depth as usize + 3;
        let n = (max_vertices + 1) * (max_vertices + 1);
        StrategyImages {
            max_vertices,
            images: (0..n)
                .map(|_| {
                    (
                        SplatBuffer::new(width, height, scale),
                        SplatBuffer::new(width, height, scale),
                    )
                })
                .collect(),
        }
    }

    pub fn index(&self, s: usize, t: usize) -> usize {
        s * (self.max_vertices + 1) + t
    }

    /// The strategies a render of depth `max_depth` uses: every (s, t) with t ≥ 1,
    /// 2 ≤ s + t ≤ max_depth + 3, but (1, 1).
    pub fn strategies(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (2..=self.max_vertices).flat_map(|n| {
            (0..n)
                .map(move |s| (s, n - s))
                .filter(|&(s, t)| !(s == 1 && t == 1))
        })
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Camera,
    Light,
    Surface,
}

/// One vertex of a subpath.
#[derive(Clone, Copy, Debug)]
struct Vertex {
    kind: Kind,
    p: Vec3,
    p_error: Vec3,
    /// Geometric normal; zero where the vertex is not on a surface (the lens of a pinhole,
    /// point lights).
    n: Vec3,
    /// Shading normal.
    ns: Vec3,
    /// Unit direction toward the previous vertex of its subpath.
    wo: Vec3,
    bsdf: Option<Bsdf>,
    /// The light this vertex is on (a light vertex, or a surface that emits).
    light: Option<u32>,
    /// A light at infinity, in the direction `toward_light`.
    infinite: bool,
    toward_light: Vec3,
    /// The subpath's throughput up to and including this vertex.
    beta: SampledSpectrum,
    /// Reached by a delta lobe (a mirror, smooth glass).
    delta: bool,
    /// Area densities of reaching this vertex forward along its subpath and in reverse.
    pdf_fwd: f64,
    pdf_rev: f64,
    /// What a camera path's surface emits: the radiance of the area light it is on
    /// (`light`), or a Phong k_e no light stands for.
    le: SampledSpectrum,
    time: f64,
    /// The primitive a surface vertex lies on, for the ray tree.
    primitive: Option<u32>,
}

impl Vertex {
    fn endpoint(kind: Kind, p: Vec3, beta: SampledSpectrum) -> Vertex {
        Vertex {
            kind,
            p,
            p_error: Vec3::ZERO,
            n: Vec3::ZERO,
            ns: Vec3::ZERO,
            wo: Vec3::ZERO,
            bsdf: None,
            light: None,
            infinite: false,
            toward_light: Vec3::ZERO,
            beta,
            delta: false,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            le: SampledSpectrum::ZERO,
            time: 0.0,
            primitive: None,
        }
    }

    fn on_surface(&self) -> bool {
        self.n != Vec3::ZERO
    }

    fn is_light(&self) -> bool {
        self.kind == Kind::Light || (self.kind == Kind::Surface && self.light.is_some())
    }

    /// Unit direction from this vertex toward `other`.
    fn toward(&self, other: &Vertex) -> Vec3 {
        if other.infinite {
            other.toward_light
        } else {
            (other.p - self.p).normalized()
        }
    }

    /// The BSDF toward `next` times the cosine there: |ωi·n_s| for radiance, the adjoint's
    /// corrected cosine for importance.
    fn f_cos(&self, next: &Vertex, mode: TransportMode) -> SampledSpectrum {
        let Some(bsdf) = &self.bsdf else {
            return SampledSpectrum::ZERO;
        };
        let wi = self.toward(next);
        let cos = match mode {
            TransportMode::Radiance => wi.dot(self.ns).abs(),
            TransportMode::Importance => adjoint_cosine_of(self.n, self.ns, self.wo, wi),
        };
        bsdf.f(self.wo, wi, mode) * cos
    }

    /// A density per steradian at this vertex turned into one per unit area at `next`.
    fn convert_density(&self, pdf: f64, next: &Vertex) -> f64 {
        if next.infinite {
            return pdf;
        }
        let w = next.p - self.p;
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let mut pdf = pdf / d2;
        if next.on_surface() {
            pdf *= next.n.dot(w).abs() / d2.sqrt();
        }
        pdf
    }
}

pub struct BidirectionalPathTracer<'a> {
    scene: &'a Scene,
    camera: &'a Camera,
    splats: &'a SplatBuffer,
    strategies: Option<&'a StrategyImages>,
    max_depth: u32,
    rr_depth: u32,
    pub(super) color: ColorMode,
    center: Vec3,
    radius: f64,
}

/// Each render thread's subpaths and pending splats, reused from sample to sample.
#[derive(Default)]
struct Scratch {
    camera: Vec<Vertex>,
    light: Vec<Vertex>,
    splats: Vec<([f64; 2], SampledSpectrum, usize, f64)>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// The squared ratio of two densities for the power heuristic, a zero density (a delta
/// lobe's) standing as 1, clamped so products cannot overflow.
fn ratio(rev: f64, fwd: f64) -> f64 {
    let remap = |x: f64| if x != 0.0 { x } else { 1.0 };
    let r = remap(rev) / remap(fwd);
    (r * r).clamp(1e-300, 1e300)
}

impl<'a> BidirectionalPathTracer<'a> {
    pub fn new(
        scene: &'a Scene,
        config: &IntegratorConfig,
        camera: &'a Camera,
        splats: &'a SplatBuffer,
        strategies: Option<&'a StrategyImages>,
    ) -> Self {
        let (center, radius) = scene.geometry.entry_sphere(camera);
        BidirectionalPathTracer {
            scene,
            camera,
            splats,
            strategies,
            max_depth: config.max_depth,
            rr_depth: config.rr_depth,
            color: config.color,
            center,
            radius,
        }
    }

    /// The pixel's estimate from every strategy with t ≥ 2, at the wavelengths `wl` (which
    /// a dispersive bounce may reduce to the hero wavelength); the t = 1 strategies splat.
    pub(super) fn li(
        &self,
        ray: &Ray,
        wl: &mut SampledWavelengths,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
        tree: Option<&mut RayTree>,
    ) -> SampledSpectrum {
        SCRATCH.with(|s| {
            let mut s = s.borrow_mut();
            self.sample(ray, wl, stream, counts, tree, &mut s)
        })
    }

    fn sample(
        &self,
        ray: &Ray,
        wl: &mut SampledWavelengths,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
        mut tree: Option<&mut RayTree>,
        scratch: &mut Scratch,
    ) -> SampledSpectrum {
        let Scratch {
            camera: camera_path,
            light: light_path,
            splats,
        } = scratch;
        camera_path.clear();
        light_path.clear();
        splats.clear();
        let raster = self.camera.we(ray).map(|(_, r)| r);
        let max_surface = self.max_depth as usize + 1;
        self.camera_subpath(ray, max_surface + 2, wl, stream, counts, camera_path);
        let escaped = self.light_subpath(ray.time, max_surface, wl, stream, counts, light_path);
        record_subpath(&mut tree, self.scene, camera_path, RayKind::Camera, wl);
        record_subpath(&mut tree, self.scene, light_path, RayKind::Light, wl);
        // A light subpath whose first ray met nothing is that ray alone.
        if let (Some(t), Some(d), [light]) = (tree.as_deref_mut(), escaped, &light_path[..]) {
            let mut node = RayNode::new(
                None,
                RayKind::Light,
                0,
                light.p,
                d,
                weight_rgb(light.beta, wl),
            );
            node.stops.push(Stop::Miss);
            t.push(node);
        }

        let mut l = SampledSpectrum::ZERO;
        // Emission no light stands for, Phong k_e, by s = 0 alone (the background is a
        // light at infinity, found by every strategy).
        for v in camera_path
            .iter()
            .skip(1)
            .filter(|v| !v.infinite && v.light.is_none())
        {
            l += v.beta * v.le;
        }
        let max_vertices = self.max_depth as usize + 3;
        // s = 1 samples a light afresh: it counts even where no light subpath began (a
        // direction the light sends nothing along, which its weight still expects).
        for t in 1..=camera_path.len() {
            for s in 0..=light_path.len().max(1) {
                if s + t < 2 || s + t > max_vertices || (s == 1 && t == 1) {
                    continue;
                }
                let Some((c, weight, splat_at)) =
                    self.connect(light_path, camera_path, s, t, wl, ray.time, stream, counts)
                else {
                    continue;
                };
                let index = self.strategies.map_or(0, |si| si.index(s, t));
                match splat_at {
                    Some(r) => splats.push((r, c, index, weight)),
                    None => {
                        l += c * weight;
                        if let (Some(si), Some(r)) = (self.strategies, raster) {
                            let (weighted, plain) = &si.images[index];
                            weighted.add(r, rgb(c * weight, wl));
                            plain.add(r, rgb(c, wl));
                        }
                    }
                }
                if let Some(tr) = tree.as_deref_mut() {
                    let end = &camera_path[t - 1];
                    // s = 0: the camera path found a light itself, along its last ray.
                    let (from, direction) = match s {
                        0 => {
                            let v = &camera_path[t - 2];
                            (v.p, v.toward(end))
                        }
                        _ => (light_path[s - 1].p, end.p - light_path[s - 1].p),
                    };
                    let mut node = RayNode::new(
                        None,
                        RayKind::Connection,
                        (s + t - 2) as u32,
                        from,
                        direction,
                        Color::gray(weight),
                    );
                    node.strategy = Some(Strategy {
                        s: s as u32,
                        t: t as u32,
                        mis_weight: weight,
                        unweighted: rgb(c, wl),
                        splat: splat_at,
                    });
                    node.color = rgb(c * weight, wl);
                    tr.push(node);
                }
            }
        }
        // The wavelengths are final only now (a dispersive bounce on either subpath may
        // have kept the hero alone), so splats are turned into colour here.
        for &(r, c, index, weight) in splats.iter() {
            let v = rgb(c * weight, wl);
            if !(v.r.is_finite() && v.g.is_finite() && v.b.is_finite()) {
                counts.invalid += 1;
                continue;
            }
            self.splats.add(r, v);
            if let Some(si) = self.strategies {
                let (weighted, plain) = &si.images[index];
                weighted.add(r, v);
                plain.add(r, rgb(c, wl));
            }
        }
        l
    }

    /// The camera subpath: the lens point, then up to `max_vertices` − 1 more.
    #[allow(clippy::too_many_arguments)]
    fn camera_subpath(
        &self,
        ray: &Ray,
        max_vertices: usize,
        wl: &mut SampledWavelengths,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
        path: &mut Vec<Vertex>,
    ) {
        let (_, pdf_dir) = self.camera.pdf_we(ray);
        let mut camera = Vertex::endpoint(Kind::Camera, ray.origin, SampledSpectrum::ONE);
        camera.time = ray.time;
        path.push(camera);
        if pdf_dir == 0.0 {
            return;
        }
        self.random_walk(
            *ray,
            SampledSpectrum::ONE,
            pdf_dir,
            max_vertices - 1,
            TransportMode::Radiance,
            wl,
            stream,
            counts,
            path,
        );
    }

    /// The light subpath: a point on a light chosen by power, then up to `max_vertices`
    /// surface vertices; the direction of its first ray, for the ray tree.
    #[allow(clippy::too_many_arguments)]
    fn light_subpath(
        &self,
        time: f64,
        max_vertices: usize,
        wl: &mut SampledWavelengths,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
        path: &mut Vec<Vertex>,
    ) -> Option<Vec3> {
        let scene = self.scene;
        let Some(LightStart {
            index,
            pmf,
            es,
            le,
            beta,
        }) = start_light_path(scene, (self.center, self.radius), wl, stream)
        else {
            return None;
        };
        let light = &scene.lights[index as usize];
        let mut v = Vertex::endpoint(Kind::Light, es.ray.origin, le);
        v.light = Some(index);
        if let Some(n) = es.n {
            v.n = n;
            v.ns = n;
        }
        if light.is_infinite() || light.is_delta_direction() {
            v.infinite = true;
            v.toward_light = -es.ray.direction;
            v.pdf_fwd = self.infinite_light_density(v.toward_light);
        } else {
            v.pdf_fwd = pmf * es.pdf.pos;
        }
        path.push(v);
        let ray = leave_light(&es).at_time(time);
        self.random_walk(
            ray,
            beta,
            es.pdf.dir,
            max_vertices,
            TransportMode::Importance,
            wl,
            stream,
            counts,
            path,
        );
        // From a light at infinity the first hit's density is the entry disk's, by area
        // across the beam.
        if v.infinite && path.len() > 1 {
            let first = &mut path[1];
            first.pdf_fwd = es.pdf.pos;
            if first.on_surface() {
                first.pdf_fwd *= es.ray.direction.dot(first.n).abs();
            }
        }
        Some(es.ray.direction)
    }

    /// Extends `path` by up to `max_vertices` vertices from `ray`, scattering by the BSDFs
    /// sampled in `mode`; `pdf_dir` is the density of the ray's direction per steradian.
    #[allow(clippy::too_many_arguments)]
    fn random_walk(
        &self,
        mut ray: Ray,
        mut beta: SampledSpectrum,
        pdf_dir: f64,
        max_vertices: usize,
        mode: TransportMode,
        wl: &mut SampledWavelengths,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
        path: &mut Vec<Vertex>,
    ) {
        let scene = self.scene;
        let mut pdf_fwd = pdf_dir;
        let mut eta_scale = 1.0;
        let mut added = 0;
        while added < max_vertices {
            let Some((prim, hit)) = scene.geometry.intersect(&ray, f64::INFINITY) else {
                // A camera path that leaves the scene ends on the lights at infinity.
                if mode == TransportMode::Radiance {
                    let mut v = Vertex::endpoint(Kind::Light, ray.origin, beta);
                    v.infinite = true;
                    v.toward_light = ray.direction.normalized();
                    v.pdf_fwd = pdf_fwd;
                    path.push(v);
                }
                return;
            };
            let it = scene.geometry.interaction(&ray, prim, &hit);
            let wo = -ray.direction.normalized();
            let bsdf = scene.bsdf(&it, wo, wl);
            let prev = *path.last().expect("a walk starts from an endpoint");
            let mut v = Vertex {
                kind: Kind::Surface,
                p: it.p,
                p_error: it.p_error,
                n: it.n,
                ns: it.shading_n,
                wo,
                bsdf,
                light: scene.area_light(prim),
                infinite: false,
                toward_light: Vec3::ZERO,
                beta,
                delta: false,
                pdf_fwd: 0.0,
                pdf_rev: 0.0,
                le: SampledSpectrum::ZERO,
                time: ray.time,
                primitive: Some(prim),
            };
            if mode == TransportMode::Radiance {
                v.le = match v.light {
                    Some(light) => scene.lights.emitted(light, &it.texture(), wl),
                    None => scene
                        .phong_emission(&it, wl)
                        .unwrap_or(SampledSpectrum::ZERO),
                };
            }
            v.pdf_fwd = prev.convert_density(pdf_fwd, &v);
            path.push(v);
            added += 1;
            if added >= max_vertices {
                return;
            }
            let Some(bsdf) = bsdf else {
                return;
            };
            let uc = stream.next_1d();
            let Some(bs) = bsdf.sample_f(wo, uc, stream.next_2d(), mode) else {
                return;
            };
            let cos = match mode {
                TransportMode::Radiance => bs.wi.dot(it.shading_n).abs(),
                TransportMode::Importance => adjoint_cosine_of(it.n, it.shading_n, wo, bs.wi),
            };
            beta *= bs.f * (cos / bs.pdf);
            pdf_fwd = if bs.pdf_is_proportional {
                bsdf.pdf(wo, bs.wi, mode)
            } else {
                bs.pdf
            };
            let mut pdf_rev = bsdf.pdf(bs.wi, wo, mode);
            let n = path.len();
            if bs.is_specular() {
                path[n - 1].delta = true;
                pdf_fwd = 0.0;
                pdf_rev = 0.0;
            }
            let this = path[n - 1];
            path[n - 2].pdf_rev = this.convert_density(pdf_rev, &path[n - 2]);
            match (mode, bs.is_transmission()) {
                (TransportMode::Importance, _) => counts.light += 1,
                (_, true) => {
                    eta_scale *= bs.eta * bs.eta;
                    counts.refraction += 1;
                }
                (_, false) => counts.reflection += 1,
            }
            // The ray past `max_depth` only looks for an emitter to end the path on, as the
            // path tracer's last BSDF sample does: not a bounce.
            let depth = n as u32 - 1;
            if mode == TransportMode::Radiance && depth <= self.max_depth {
                counts.bounce(depth);
            }
            if beta.is_black() {
                return;
            }
            ray =
                Ray::new(offset_ray_origin(it.p, it.p_error, it.n, bs.wi), bs.wi).at_time(ray.time);
            let rr = (beta * eta_scale).max_value();
            if added > self.rr_depth as usize && rr < 1.0 {
                let q = (1.0 - rr).max(0.0);
                if stream.next_1d() < q {
                    return;
                }
                beta /= 1.0 - q;
            }
        }
    }

    /// Strategy (s, t): its unweighted contribution, MIS weight, and the raster point for a
    /// t = 1 splat; `None` when it contributes nothing.
    #[allow(clippy::too_many_arguments)]
    fn connect(
        &self,
        light_path: &[Vertex],
        camera_path: &[Vertex],
        s: usize,
        t: usize,
        wl: &SampledWavelengths,
        time: f64,
        stream: &mut SampleStream,
        counts: &mut RayCounts,
    ) -> Option<(SampledSpectrum, f64, Option<[f64; 2]>)> {
        let scene = self.scene;
        if t > 1 && s != 0 && camera_path[t - 1].kind == Kind::Light {
            return None;
        }
        let mut sampled = None;
        let mut raster = None;
        let l = if s == 0 {
            let pt = &camera_path[t - 1];
            if !pt.is_light() {
                return None;
            }
            pt.beta * self.le(pt, &camera_path[t - 2], wl)
        } else if t == 1 {
            let qs = &light_path[s - 1];
            if !self.connectible(qs) {
                return None;
            }
            let c = self.camera.sample_wi(qs.p, stream.next_2d(), time)?;
            let mut cam = Vertex::endpoint(
                Kind::Camera,
                c.lens_point,
                SampledSpectrum::splat(c.we / c.pdf),
            );
            cam.time = time;
            let l = qs.beta * qs.f_cos(&cam, TransportMode::Importance) * cam.beta;
            if l.is_black() {
                return None;
            }
            counts.connection += 1;
            if !self.visible(qs, &cam, time) {
                return None;
            }
            raster = Some(c.raster);
            sampled = Some(cam);
            l
        } else if s == 1 {
            let pt = &camera_path[t - 1];
            if !self.connectible(pt) {
                return None;
            }
            let ul = stream.next_1d();
            let u = stream.next_2d();
            let (index, pmf) = scene.lights.sampler.sample(ul)?;
            let light = &scene.lights[index as usize];
            let ls = light.sample_li(pt.p, u)?;
            if ls.scale == 0.0 || ls.pdf == 0.0 {
                return None;
            }
            let le = match ls.radiance {
                Some(c) => rgb_radiance(c, wl),
                None => scene.lights.spectrum(index, wl) * ls.scale,
            };
            let mut lv = Vertex::endpoint(
                Kind::Light,
                ls.position.unwrap_or(pt.p + ls.wi),
                le / (ls.pdf * pmf),
            );
            lv.light = Some(index);
            if let Some(n) = ls.normal {
                lv.n = n;
                lv.ns = n;
            }
            if ls.position.is_none() {
                lv.infinite = true;
                lv.toward_light = ls.wi;
            }
            lv.pdf_fwd = self.pdf_light_origin(&lv, pt);
            let l = pt.beta * pt.f_cos(&lv, TransportMode::Radiance) * lv.beta;
            if l.is_black() {
                return None;
            }
            counts.shadow += 1;
            let origin = offset_ray_origin(pt.p, pt.p_error, pt.n, ls.wi);
            let (shadow, t_max) = match ls.position {
                Some(q) => (Ray::new(origin, q - origin), ls.shadow_end),
                None => (Ray::new(origin, ls.wi), f64::INFINITY),
            };
            if scene
                .geometry
                .occluded(&shadow.at_time(time), t_max, Coherence::Incoherent)
            {
                return None;
            }
            sampled = Some(lv);
            l
        } else {
            let (qs, pt) = (&light_path[s - 1], &camera_path[t - 1]);
            if !(self.connectible(qs) && self.connectible(pt)) {
                return None;
            }
            let d2 = (qs.p - pt.p).length_squared();
            if d2 == 0.0 {
                return None;
            }
            let l = qs.beta
                * qs.f_cos(pt, TransportMode::Importance)
                * pt.f_cos(qs, TransportMode::Radiance)
                * pt.beta
                / d2;
            if l.is_black() {
                return None;
            }
            counts.connection += 1;
            if !self.visible(qs, pt, time) {
                return None;
            }
            l
        };
        if l.is_black() {
            return None;
        }
        let w = self.mis_weight(light_path, camera_path, sampled.as_ref(), s, t);
        Some((l, w, raster))
    }

    /// Nothing lies between two vertices (each a surface point or a lens point).
    fn visible(&self, a: &Vertex, b: &Vertex, time: f64) -> bool {
        let lift = |v: &Vertex, toward: Vec3| {
            if v.kind == Kind::Surface {
                offset_ray_origin(v.p, v.p_error, v.n, toward - v.p)
            } else {
                v.p
            }
        };
        let from = lift(a, b.p);
        let to = lift(b, a.p);
        let ray = Ray::new(from, to - from).at_time(time);
        // A surface at the far end (a mesh's, tested in f32) may be met a hair before it.
        let t_max = match b.kind {
            Kind::Surface => AREA_SHADOW_END,
            _ => 1.0 - 1e-9,
        };
        !self
            .scene
            .geometry
            .occluded(&ray, t_max, Coherence::Incoherent)
    }

    fn connectible(&self, v: &Vertex) -> bool {
        match v.kind {
            Kind::Camera => true,
            Kind::Light => v
                .light
                .is_some_and(|l| !self.scene.lights[l as usize].is_delta_direction()),
            Kind::Surface => v.bsdf.is_some_and(|b| b.flags().is_non_specular()),
        }
    }

    fn is_delta_light(&self, v: &Vertex) -> bool {
        v.kind == Kind::Light
            && v.light.is_some_and(|l| {
                let light = &self.scene.lights[l as usize];
                light.is_delta_position() || light.is_delta_direction()
            })
    }

    /// Radiance an emitting vertex of the camera path sends toward `toward`.
    fn le(&self, v: &Vertex, toward: &Vertex, wl: &SampledWavelengths) -> SampledSpectrum {
        let scene = self.scene;
        if v.infinite {
            let mut l = SampledSpectrum::ZERO;
            for &i in &scene.lights.infinite {
                l += scene.lights.radiance_from_infinity(i, v.toward_light, wl);
            }
            return l;
        }
        let Some(i) = v.light else {
            return SampledSpectrum::ZERO;
        };
        let w = v.toward(toward);
        if scene.lights[i as usize].emits_toward(v.n, w) {
            v.le
        } else {
            SampledSpectrum::ZERO
        }
    }

    /// The density per steradian with which the light sampler and the lights at infinity
    /// send light from the direction `toward_light`.
    fn infinite_light_density(&self, toward_light: Vec3) -> f64 {
        let scene = self.scene;
        scene
            .lights
            .infinite
            .iter()
            .map(|&i| {
                scene.lights.sampler.pmf(i) * scene.lights[i as usize].pdf_direction(toward_light)
            })
            .sum()
    }

    /// The area density of `v` (a light's point or direction) as a light subpath's origin.
    fn pdf_light_origin(&self, v: &Vertex, next: &Vertex) -> f64 {
        if v.infinite {
            return self.infinite_light_density(v.toward_light);
        }
        let Some(i) = v.light else {
            return 0.0;
        };
        let w = v.toward(next);
        let e = self.scene.lights[i as usize].pdf_le(v.n, w, self.radius);
        self.scene.lights.sampler.pmf(i) * e.pos
    }

    /// The area density at `next` of light leaving the light vertex `v` toward it.
    fn pdf_light(&self, v: &Vertex, next: &Vertex) -> f64 {
        if v.infinite {
            // Light from infinity enters through the entry disk (started beyond the
            // unbounded primitives behind it, `Geometry::from_infinity`): a point outside
            // that beam (on an infinite plane, far out) no light path reaches. Its density
            // is the least positive number, not 0, which the weights would read as a delta
            // lobe's and remap to 1.
            let w = v.toward_light;
            let q = next.p - self.center;
            let along = q.dot(w);
            if (q - w * along).length_squared() > self.radius * self.radius {
                return f64::MIN_POSITIVE;
            }
            let mut pdf = 1.0 / (PI * self.radius * self.radius);
            if next.on_surface() {
                pdf *= next.n.dot(v.toward_light).abs();
            }
            return pdf;
        }
        let Some(i) = v.light else {
            return 0.0;
        };
        let w = next.p - v.p;
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let w = w / d2.sqrt();
        let e = self.scene.lights[i as usize].pdf_le(v.n, w, self.radius);
        let mut pdf = e.dir / d2;
        if next.on_surface() {
            pdf *= next.n.dot(w).abs();
        }
        pdf
    }

    /// The area density at `next` of the subpath through `prev` and `v` going on to `next`.
    fn pdf(&self, v: &Vertex, prev: Option<&Vertex>, next: &Vertex) -> f64 {
        match v.kind {
            Kind::Light => self.pdf_light(v, next),
            Kind::Camera => {
                let w = v.toward(next);
                let (_, dir) = self.camera.pdf_we(&Ray::new(v.p, w).at_time(v.time));
                v.convert_density(dir, next)
            }
            Kind::Surface => {
                let (Some(bsdf), Some(prev)) = (&v.bsdf, prev) else {
                    return 0.0;
                };
                let pdf = bsdf.pdf(v.toward(prev), v.toward(next), TransportMode::Radiance);
                v.convert_density(pdf, next)
            }
        }
    }

    /// The power heuristic's weight of strategy (s, t) against every other strategy that
    /// could have made the same path (Veach's thesis §10.2; pbrt's `MISWeight`).
    fn mis_weight(
        &self,
        light_path: &[Vertex],
        camera_path: &[Vertex],
        sampled: Option<&Vertex>,
        s: usize,
        t: usize,
    ) -> f64 {
        if s + t == 2 {
            return 1.0;
        }
        // The connection's two ends, with a fresh sample standing in where there is one.
        let pt = if t == 1 {
            sampled.expect("t = 1 samples the lens")
        } else {
            &camera_path[t - 1]
        };
        let qs = match s {
            0 => None,
            1 => Some(sampled.expect("s = 1 samples a light")),
            _ => Some(&light_path[s - 1]),
        };
        let pt_minus = (t >= 2).then(|| &camera_path[t - 2]);
        let qs_minus = (s >= 2).then(|| &light_path[s - 2]);
        // Reverse densities of the four vertices at the connection, for this strategy.
        let pt_rev = match qs {
            Some(q) => self.pdf(q, qs_minus, pt),
            None => self.pdf_light_origin(pt, pt_minus.expect("s = 0 has t ≥ 2")),
        };
        let pt_minus_rev = pt_minus.map(|pm| match qs {
            Some(q) => self.pdf(pt, Some(q), pm),
            None => self.pdf_light(pt, pm),
        });
        let qs_rev = qs.map(|q| self.pdf(pt, pt_minus, q));
        let qs_minus_rev = qs_minus.map(|qm| self.pdf(qs.expect("s ≥ 2"), Some(pt), qm));

        let mut sum = 0.0;
        let mut r = 1.0;
        for i in (1..t).rev() {
            let (v, rev, delta) = if i == t - 1 {
                (pt, pt_rev, false)
            } else if i + 2 == t {
                let v = &camera_path[i];
                (v, pt_minus_rev.unwrap_or(v.pdf_rev), v.delta)
            } else {
                let v = &camera_path[i];
                (v, v.pdf_rev, v.delta)
            };
            r = (r * ratio(rev, v.pdf_fwd)).clamp(1e-300, 1e300);
            if !delta && !camera_path[i - 1].delta {
                sum += r;
            }
        }
        let mut r = 1.0;
        for i in (0..s).rev() {
            let (v, rev, delta) = if i == s - 1 {
                (qs.expect("s ≥ 1"), qs_rev.unwrap_or(0.0), false)
            } else if i + 2 == s {
                let v = &light_path[i];
                (v, qs_minus_rev.unwrap_or(v.pdf_rev), v.delta)
            } else {
                let v = &light_path[i];
                (v, v.pdf_rev, v.delta)
            };
            r = (r * ratio(rev, v.pdf_fwd)).clamp(1e-300, 1e300);
            let delta_before = if i > 0 {
                light_path[i - 1].delta
            } else {
                self.is_delta_light(v)
            };
            if !delta && !delta_before {
                sum += r;
            }
        }
        1.0 / (1.0 + sum)
    }
}

/// The subpath's rays in the ray tree, each with its throughput and what it hit.
fn record_subpath(
    tree: &mut Option<&mut RayTree>,
    scene: &Scene,
    path: &[Vertex],
    kind: RayKind,
    wl: &SampledWavelengths,
) {
    let Some(t) = tree.as_deref_mut() else {
        return;
    };
    let mut parent = None;
    for (i, pair) in path.windows(2).enumerate() {
        let (a, b) = (&pair[0], &pair[1]);
        let d = a.toward(b);
        // The camera subpath's later rays are its bounces, reflected or refracted as they
        // leave on the side they came from or the other; the light subpath's are all light.
        let k = match kind {
            RayKind::Camera if i > 0 && a.n.dot(d) * a.n.dot(a.wo) < 0.0 => RayKind::Refracted,
            RayKind::Camera if i > 0 => RayKind::Reflected,
            _ => kind,
        };
        let mut node = RayNode::new(parent, k, i as u32, a.p, d, weight_rgb(b.beta, wl));
        node.distance = (!b.infinite).then(|| (b.p - a.p).length());
        if let Some(prim) = b.primitive {
            node.object = Some(scene.geometry.names[prim as usize].clone());
            let m = scene.geometry.primitives[prim as usize].material as usize;
            node.material = Some(scene.materials.names[m].clone());
        } else if b.infinite {
            node.stops.push(Stop::Miss);
        }
        parent = Some(t.push(node));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit;
    use crate::sampling::Rng;
    use crate::settings::IntegratorKind;

    const SIZE: u32 = 16;

    /// Runs `test` on BDPT (`max_depth` 4, no Russian roulette) in the kit's Cornell box,
    /// diffuse and with a rough metal wall.
    fn in_both_boxes(test: impl Fn(&BidirectionalPathTracer)) {
        for glossy in [false, true] {
            let scene = kit::cornell_box(glossy);
            let camera = Camera::new(&scene.camera, SIZE, SIZE);
            let splats = SplatBuffer::new(SIZE, SIZE, 1.0);
            let config = IntegratorConfig {
                kind: IntegratorKind::Bdpt,
                max_depth: 4,
                rr_depth: 100,
                color: ColorMode::Rgb,
                ..Default::default()
            };
            test(&BidirectionalPathTracer::new(
                &scene, &config, &camera, &splats, None,
            ));
        }
    }

    /// Four camera and light subpaths per pixel, from seed 7.
    fn subpaths(b: &BidirectionalPathTracer) -> Vec<(Vec<Vertex>, Vec<Vertex>)> {
        let mut all = Vec::new();
        for (x, y, i) in
            (0..SIZE * SIZE * 4).map(|k| (k % SIZE, (k / SIZE) % SIZE, k / (SIZE * SIZE)))
        {
            let mut stream = SampleStream::random(Rng::for_sample(7, x, y, i));
            let ray = b
                .camera
                .sample_ray(x as f64 + 0.5, y as f64 + 0.5, [0.5; 2], 0.0);
            let mut wl = SampledWavelengths::rgb();
            let mut counts = RayCounts::default();
            let (mut camera, mut light) = (Vec::new(), Vec::new());
            b.camera_subpath(&ray, 7, &mut wl, &mut stream, &mut counts, &mut camera);
            b.light_subpath(ray.time, 6, &mut wl, &mut stream, &mut counts, &mut light);
            all.push((camera, light));
        }
        all
    }

    /// Equal to 10⁻⁴: a walk's ray leaves from an offset origin, which at the lamp's 0.01
    /// from the ceiling moves a density by 2·10⁻⁵. A wrong density is off by far more.
    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-4 * a.abs().max(b.abs()) + 1e-12
    }

    /// The walks store at each vertex the area densities that the one-step density
    /// (`pdf`, which the weights use) gives for its neighbours: forward from the previous
    /// vertex, and in reverse from the next.
    #[test]
    fn subpaths_store_the_densities_of_their_steps() {
        in_both_boxes(|b| {
            let mut checked = 0;
            for (cam, light) in subpaths(b) {
                for path in [&cam, &light] {
                    // Directions between nearly coincident points (a corner) are noise.
                    let far = |a: usize, b: usize| (path[a].p - path[b].p).length() > 1e-3;
                    for j in 1..path.len() {
                        if path[j].infinite || !far(j - 1, j) || (j >= 2 && !far(j - 2, j - 1)) {
                            continue;
                        }
                        let fwd = match j {
                            1 if path[0].kind == Kind::Light => b.pdf_light(&path[0], &path[1]),
                            1 => b.pdf(&path[0], None, &path[1]),
                            _ => b.pdf(&path[j - 1], Some(&path[j - 2]), &path[j]),
                        };
                        assert!(
                            close(path[j].pdf_fwd, fwd),
                            "vertex {j} forward: stored {} ≠ {fwd}",
                            path[j].pdf_fwd
                        );
                        if j + 2 < path.len()
                            && !path[j + 2].infinite
                            && far(j, j + 1)
                            && far(j + 1, j + 2)
                        {
                            let rev = b.pdf(&path[j + 1], Some(&path[j + 2]), &path[j]);
                            assert!(
                                close(path[j].pdf_rev, rev),
                                "vertex {j} reverse: stored {} ≠ {rev}",
                                path[j].pdf_rev
                            );
                        }
                        checked += 1;
                    }
                }
                if let Some(origin) = light.first() {
                    if light.len() > 1 {
                        let pos = b.pdf_light_origin(origin, &light[1]);
                        assert!(
                            close(origin.pdf_fwd, pos),
                            "light origin: {} ≠ {pos}",
                            origin.pdf_fwd
                        );
                    }
                }
            }
            assert!(checked > 1000, "{checked} vertices checked");
        });
    }

    /// Veach's power heuristic, computed from its definition: a path x₀ (on the lamp) …
    /// x_{n−1} (the lens) that strategy s samples with density
    /// p_s = Π_{i<s} p→(x_i) · Π_{i≥s} p←(x_i) weighs p_s² / Σ_j p_j². The weights of all
    /// strategies of the path then add up to 1. The paths are camera subpaths that reached
    /// the lamp; each strategy gets the subpaths it would have sampled.
    #[test]
    fn every_strategy_of_a_path_weighs_as_the_power_heuristic() {
        in_both_boxes(|b| {
            let mut paths = 0;
            for (cam, _) in subpaths(b) {
                let Some(last) = cam.last() else { continue };
                if cam.len() < 3 || last.kind != Kind::Surface || last.light.is_none() {
                    continue;
                }
                // x₀ … x_{n−1}: the camera subpath reversed.
                let x: Vec<Vertex> = cam.iter().rev().copied().collect();
                let n = x.len();
                let mut origin = Vertex::endpoint(Kind::Light, x[0].p, SampledSpectrum::ONE);
                origin.light = x[0].light;
                origin.n = x[0].n;
                origin.ns = x[0].n;
                // p→(x_i), from the light; p←(x_i), from the camera (the lens point's own
                // density is every strategy's, and left out).
                let mut fwd = vec![
                    b.pdf_light_origin(&origin, &x[1]),
                    b.pdf_light(&origin, &x[1]),
                ];
                for i in 2..n - 1 {
                    fwd.push(b.pdf(&x[i - 1], Some(&x[i - 2]), &x[i]));
                }
                let mut rev = vec![0.0; n - 1];
                rev[n - 2] = b.pdf(&x[n - 1], None, &x[n - 2]);
                for i in (0..n - 2).rev() {
                    rev[i] = b.pdf(&x[i + 1], Some(&x[i + 2]), &x[i]);
                }
                let density = |s: usize| -> f64 {
                    fwd[..s].iter().product::<f64>() * rev[s..].iter().product::<f64>()
                };
                let squares: f64 = (0..n).map(|s| density(s).powi(2)).sum();
                let mut total = 0.0;
                for s in 0..n {
                    let t = n - s;
                    let mut light_path: Vec<Vertex> = x[..s].to_vec();
                    if s > 0 {
                        light_path[0] = origin;
                    }
                    // The reverse densities of the two vertices at each end of the
                    // connection came from the subpath's own next vertex, not from the
                    // other side: the weight must compute them anew, so here they are wrong.
                    const STALE: f64 = 12345.0;
                    for (i, v) in light_path.iter_mut().enumerate() {
                        v.pdf_fwd = fwd[i];
                        v.pdf_rev = if i + 2 >= s { STALE } else { rev[i] };
                    }
                    let mut camera_path: Vec<Vertex> = x[s..].iter().rev().copied().collect();
                    for (j, v) in camera_path.iter_mut().enumerate().skip(1) {
                        v.pdf_fwd = rev[n - 1 - j];
                        v.pdf_rev = if j + 2 >= t { STALE } else { fwd[n - 1 - j] };
                    }
                    let sampled = match (s, t) {
                        (1, _) => Some(light_path[0]),
                        (_, 1) => Some(camera_path[0]),
                        _ => None,
                    };
                    let w = b.mis_weight(&light_path, &camera_path, sampled.as_ref(), s, t);
                    let expected = density(s).powi(2) / squares;
                    assert!(
                        (w - expected).abs() < 1e-9,
                        "path of {n} vertices, strategy s = {s}: weight {w}, power heuristic {expected}"
                    );
                    total += w;
                }
                assert!((total - 1.0).abs() < 1e-9, "weights add up to {total}");
                paths += 1;
            }
            assert!(paths > 20, "{paths} paths reached the lamp");
        });
    }
}
