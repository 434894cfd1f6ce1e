//! Physically based BSDFs: what fraction of the light arriving from one direction a surface
//! sends into another, per wavelength lane of a [`SampledSpectrum`].
//!
//! The models and their maths follow pbrt-v4 (Pharr, Jakob & Humphreys, *Physically Based
//! Rendering*, 4th ed., chapters 9–10 and 14): Lambert, Torrance–Sparrow microfacets with
//! the Trowbridge–Reitz (GGX) distribution sampled by visible normals (Heitz 2018), smooth
//! and rough dielectrics (Walter et al. 2007), thin dielectric sheets, diffuse transmission,
//! a coated diffuse surface by a stochastic random walk between layers (Guo et al. 2018, as
//! pbrt-v4's `LayeredBxDF`), and the Phong material read as a normalised BSDF.
//!
//! **The one direction convention.** `wo` and `wi` point *away* from the surface and are
//! given in the shading frame: z is the shading normal, pointing up (out of the surface),
//! x and y span the tangent plane. cos θ of a direction is its z component. `wo` is the
//! direction light leaves towards (the camera side in a path tracer), `wi` the one it
//! arrives from. A [`Bxdf`] works in this frame only; a [`Bsdf`] carries world directions
//! into it and back.
//!
//! Values: `f` is the BSDF in 1/sr; `pdf` a density per steradian of `wi`; delta lobes
//! (mirrors, smooth interfaces) have `f = 0` and `pdf = 0` and are reached only through
//! `sample_f`, which returns their weight as `f` with `pdf` the discrete probability of the
//! lobe (so that f·|cos θi|/pdf is the throughput weight either way).

mod conductor;
mod dielectric;
mod diffuse;
mod diffuse_transmission;
pub mod fresnel;
mod layered;
pub mod microfacet;
mod phong;
mod thin_dielectric;

#[cfg(test)]
mod test_support;

pub use conductor::ConductorBxdf;
pub use dielectric::DielectricBxdf;
pub use diffuse::DiffuseBxdf;
pub use diffuse_transmission::DiffuseTransmissionBxdf;
pub use layered::CoatedDiffuseBxdf;
pub use microfacet::TrowbridgeReitz;
pub use phong::PhongBxdf;
pub use thin_dielectric::ThinDielectricBxdf;

use std::ops::BitOr;

use plenum_spectrum::SampledSpectrum;

use crate::math::Vec3;
use crate::sampling::Frame;

/// Which quantity a path carries, so that non-symmetric BSDFs scale correctly.
///
/// Refraction compresses radiance by 1/η² (the solid angle narrows) but not importance:
/// camera paths carry `Radiance`; light paths (light tracing, photon mapping, the light
/// half of BDPT) carry `Importance`, the adjoint, without that factor.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum TransportMode {
    Radiance,
    Importance,
}

/// The kinds of lobe a BSDF has or a sample came from.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub struct BxdfFlags(u8);

impl BxdfFlags {
    pub const UNSET: BxdfFlags = BxdfFlags(0);
    pub const REFLECTION: BxdfFlags = BxdfFlags(1);
    pub const TRANSMISSION: BxdfFlags = BxdfFlags(2);
    pub const DIFFUSE: BxdfFlags = BxdfFlags(4);
    pub const GLOSSY: BxdfFlags = BxdfFlags(8);
    pub const SPECULAR: BxdfFlags = BxdfFlags(16);

    pub const DIFFUSE_REFLECTION: BxdfFlags = BxdfFlags(1 | 4);
    pub const DIFFUSE_TRANSMISSION: BxdfFlags = BxdfFlags(2 | 4);
    pub const GLOSSY_REFLECTION: BxdfFlags = BxdfFlags(1 | 8);
    pub const GLOSSY_TRANSMISSION: BxdfFlags = BxdfFlags(2 | 8);
    pub const SPECULAR_REFLECTION: BxdfFlags = BxdfFlags(1 | 16);
    pub const SPECULAR_TRANSMISSION: BxdfFlags = BxdfFlags(2 | 16);

    /// Every bit of `other` is set here.
    pub fn contains(self, other: BxdfFlags) -> bool {
        self.0 & other.0 == other.0
    }

    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    pub fn is_specular(self) -> bool {
        self.0 & Self::SPECULAR.0 != 0
    }

    /// Has a diffuse or glossy lobe, one that `f` and `pdf` can see.
    pub fn is_non_specular(self) -> bool {
        self.0 & (Self::DIFFUSE.0 | Self::GLOSSY.0) != 0
    }

    pub fn is_reflective(self) -> bool {
        self.0 & Self::REFLECTION.0 != 0
    }

    pub fn is_transmissive(self) -> bool {
        self.0 & Self::TRANSMISSION.0 != 0
    }
}

impl BitOr for BxdfFlags {
    type Output = BxdfFlags;
    fn bitor(self, o: BxdfFlags) -> BxdfFlags {
        BxdfFlags(self.0 | o.0)
    }
}

/// Which hemispheres, relative to `wo`, `sample_f` may return and `pdf` accounts for
/// (pbrt-v4's `BxDFReflTransFlags`); the layered model asks for one side at a time.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum SampleFlags {
    All,
    Reflection,
    Transmission,
}

impl SampleFlags {
    pub fn reflection(self) -> bool {
        self != SampleFlags::Transmission
    }

    pub fn transmission(self) -> bool {
        self != SampleFlags::Reflection
    }
}

/// One sampled scattering event.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// The BSDF value for (wo, wi), 1/sr; for a delta lobe its weight divided by |cos θi|.
    pub f: SampledSpectrum,
    /// The sampled incident direction, unit length, pointing away from the surface.
    pub wi: Vec3,
    /// Per steradian for a continuous lobe; the discrete probability for a delta lobe.
    pub pdf: f64,
    pub flags: BxdfFlags,
    /// The relative index of refraction across the event, η_transmitted/η_incident as
    /// seen from wo's side; 1 for reflection.
    pub eta: f64,
    /// `pdf` is only proportional to the true density (a stochastic estimate, as in the
    /// layered model): use it for weights f/pdf, not in MIS heuristics.
    pub pdf_is_proportional: bool,
}

impl BsdfSample {
    fn new(f: SampledSpectrum, wi: Vec3, pdf: f64, flags: BxdfFlags) -> BsdfSample {
        BsdfSample {
            f,
            wi,
            pdf,
            flags,
            eta: 1.0,
            pdf_is_proportional: false,
        }
    }

    fn with_eta(self, eta: f64) -> BsdfSample {
        BsdfSample { eta, ..self }
    }

    pub fn is_specular(&self) -> bool {
        self.flags.is_specular()
    }

    pub fn is_reflection(&self) -> bool {
        self.flags.is_reflective()
    }

    pub fn is_transmission(&self) -> bool {
        self.flags.is_transmissive()
    }
}

/// Every BSDF model, a small value built per hit; dispatch is by `match`.
#[derive(Clone, Copy, Debug)]
pub enum Bxdf {
    Diffuse(DiffuseBxdf),
    Conductor(ConductorBxdf),
    Dielectric(DielectricBxdf),
    ThinDielectric(ThinDielectricBxdf),
    DiffuseTransmission(DiffuseTransmissionBxdf),
    CoatedDiffuse(CoatedDiffuseBxdf),
    Phong(PhongBxdf),
}

impl Bxdf {
    /// The BSDF for light arriving from `wi` and leaving to `wo`, 1/sr; 0 for delta lobes.
    pub fn f(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> SampledSpectrum {
        match self {
            Bxdf::Diffuse(b) => b.f(wo, wi, mode),
            Bxdf::Conductor(b) => b.f(wo, wi, mode),
            Bxdf::Dielectric(b) => b.f(wo, wi, mode),
            Bxdf::ThinDielectric(b) => b.f(wo, wi, mode),
            Bxdf::DiffuseTransmission(b) => b.f(wo, wi, mode),
            Bxdf::CoatedDiffuse(b) => b.f(wo, wi, mode),
            Bxdf::Phong(b) => b.f(wo, wi, mode),
        }
    }

    /// Draws wi given wo from `uc` (chooses a lobe) and `u` (the direction), all in [0, 1).
    pub fn sample_f(
        &self,
        wo: Vec3,
        uc: f64,
        u: [f64; 2],
        mode: TransportMode,
        which: SampleFlags,
    ) -> Option<BsdfSample> {
        match self {
            Bxdf::Diffuse(b) => b.sample_f(wo, uc, u, mode, which),
            Bxdf::Conductor(b) => b.sample_f(wo, uc, u, mode, which),
            Bxdf::Dielectric(b) => b.sample_f(wo, uc, u, mode, which),
            Bxdf::ThinDielectric(b) => b.sample_f(wo, uc, u, mode, which),
            Bxdf::DiffuseTransmission(b) => b.sample_f(wo, uc, u, mode, which),
            Bxdf::CoatedDiffuse(b) => b.sample_f(wo, uc, u, mode, which),
            Bxdf::Phong(b) => b.sample_f(wo, uc, u, mode, which),
        }
    }

    /// The density per steradian with which `sample_f` returns `wi`, continuous lobes only.
    pub fn pdf(&self, wo: Vec3, wi: Vec3, mode: TransportMode, which: SampleFlags) -> f64 {
        match self {
            Bxdf::Diffuse(b) => b.pdf(wo, wi, mode, which),
            Bxdf::Conductor(b) => b.pdf(wo, wi, mode, which),
            Bxdf::Dielectric(b) => b.pdf(wo, wi, mode, which),
            Bxdf::ThinDielectric(b) => b.pdf(wo, wi, mode, which),
            Bxdf::DiffuseTransmission(b) => b.pdf(wo, wi, mode, which),
            Bxdf::CoatedDiffuse(b) => b.pdf(wo, wi, mode, which),
            Bxdf::Phong(b) => b.pdf(wo, wi, mode, which),
        }
    }

    /// The BSDF as two: its diffuse lobes, and the rest (glossy and specular), each a BSDF
    /// of its own, whose values and delta lobes add up to this one's; `None` for a part it
    /// lacks. A Phong material splits into k_d and the other lobes; a coat over a diffuse
    /// base keeps the base (and a rough coat's reflection) and gives its smooth coat's
    /// mirror reflection, F(θ) by Fresnel, to the rest. SPPM leaves visible points on the
    /// diffuse part and traces the rest, as pbrt-v4 does for glossy surfaces: a sharp
    /// glossy lobe times a photon's flux is an estimate of enormous variance.
    pub fn split_diffuse(&self) -> (Option<Bxdf>, Option<Bxdf>) {
        match *self {
            Bxdf::Phong(b) => {
                let zero = SampledSpectrum::ZERO;
                let diffuse = (!b.kd.is_black()).then_some(Bxdf::Phong(PhongBxdf {
                    ks: zero,
                    kr: zero,
                    kt: zero,
                    ..b
                }));
                let others = !(b.ks.is_black() && b.kr.is_black() && b.kt.is_black());
                let rest = others.then_some(Bxdf::Phong(PhongBxdf { kd: zero, ..b }));
                (diffuse, rest)
            }
            Bxdf::CoatedDiffuse(b) if b.top.flags().is_specular() => {
                let mirror = PhongBxdf {
                    kd: SampledSpectrum::ZERO,
                    ks: SampledSpectrum::ZERO,
                    exponent: 1.0,
                    kr: SampledSpectrum::ONE,
                    kt: SampledSpectrum::ZERO,
                    eta: b.top.eta,
                    thin: true,
                    fresnel: true,
                };
                (Some(*self), Some(Bxdf::Phong(mirror)))
            }
            Bxdf::Diffuse(_) | Bxdf::DiffuseTransmission(_) | Bxdf::CoatedDiffuse(_) => {
                (Some(*self), None)
            }
            Bxdf::Conductor(_) | Bxdf::Dielectric(_) | Bxdf::ThinDielectric(_) => {
                (None, Some(*self))
            }
        }
    }

    /// Roughly the share of the light leaving toward `wo` that [`split_diffuse`]'s diffuse
    /// part carries, in [0, 1]. A method that must choose between the parts at one vertex
    /// (SPPM keeps one visible point per pixel) chooses by it; any value strictly between 0
    /// and 1 keeps its estimate unbiased, a good one keeps the variance low.
    ///
    /// [`split_diffuse`]: Bxdf::split_diffuse
    pub fn diffuse_fraction(&self, wo: Vec3) -> f64 {
        match self {
            Bxdf::Phong(b) => b.diffuse_fraction(wo),
            Bxdf::CoatedDiffuse(b) if b.top.flags().is_specular() => b.diffuse_fraction(wo),
            Bxdf::Diffuse(_) | Bxdf::DiffuseTransmission(_) | Bxdf::CoatedDiffuse(_) => 1.0,
            Bxdf::Conductor(_) | Bxdf::Dielectric(_) | Bxdf::ThinDielectric(_) => 0.0,
        }
    }

    pub fn flags(&self) -> BxdfFlags {
        match self {
            Bxdf::Diffuse(b) => b.flags(),
            Bxdf::Conductor(b) => b.flags(),
            Bxdf::Dielectric(b) => b.flags(),
            Bxdf::ThinDielectric(b) => b.flags(),
            Bxdf::DiffuseTransmission(b) => b.flags(),
            Bxdf::CoatedDiffuse(b) => b.flags(),
            Bxdf::Phong(b) => b.flags(),
        }
    }
}

/// A [`Bxdf`] placed in a shading frame: the interface integrators use, in world space.
#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    frame: Frame,
    bxdf: Bxdf,
    /// `bxdf.flags()`, asked several times per vertex.
    flags: BxdfFlags,
}

impl Bsdf {
    /// The frame has z = `shading_normal` (unit length) and, when `dpdu_hint` is given and
    /// not parallel to it, x along the hint projected onto the tangent plane, which orients
    /// anisotropic lobes; otherwise any tangent.
    pub fn new(shading_normal: Vec3, dpdu_hint: Option<Vec3>, bxdf: Bxdf) -> Bsdf {
        let n = shading_normal;
        let tangent = dpdu_hint
            .map(|t| t - n * n.dot(t))
            .filter(|t| t.length_squared() > 1e-12 * n.length_squared());
        let frame = match tangent {
            Some(t) => {
                let x = t.normalized();
                Frame {
                    x,
                    y: n.cross(x),
                    z: n,
                }
            }
            None => Frame::from_z(n),
        };
        Bsdf::placed(frame, bxdf)
    }

    fn placed(frame: Frame, bxdf: Bxdf) -> Bsdf {
        Bsdf {
            frame,
            flags: bxdf.flags(),
            bxdf,
        }
    }

    pub fn bxdf(&self) -> &Bxdf {
        &self.bxdf
    }

    pub fn to_local(&self, v: Vec3) -> Vec3 {
        self.frame.to_local(v)
    }

    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.frame.to_world(v)
    }

    pub fn flags(&self) -> BxdfFlags {
        self.flags
    }

    /// [`Bxdf::split_diffuse`], each part in this BSDF's frame.
    pub fn split_diffuse(&self) -> (Option<Bsdf>, Option<Bsdf>) {
        let (diffuse, rest) = self.bxdf.split_diffuse();
        let frame = self.frame;
        let place = |bxdf| Bsdf::placed(frame, bxdf);
        (diffuse.map(place), rest.map(place))
    }

    /// [`Bxdf::diffuse_fraction`] toward the world direction `wo`.
    pub fn diffuse_fraction(&self, wo_world: Vec3) -> f64 {
        self.bxdf.diffuse_fraction(self.to_local(wo_world))
    }

    pub fn f(&self, wo_world: Vec3, wi_world: Vec3, mode: TransportMode) -> SampledSpectrum {
        let wo = self.to_local(wo_world);
        if wo.z == 0.0 {
            return SampledSpectrum::ZERO;
        }
        self.bxdf.f(wo, self.to_local(wi_world), mode)
    }

    /// As [`Bxdf::sample_f`], with wo and the returned wi in world space; `None` also for
    /// samples that carry nothing (f black, pdf 0, wi in the tangent plane).
    pub fn sample_f(
        &self,
        wo_world: Vec3,
        uc: f64,
        u: [f64; 2],
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        let wo = self.to_local(wo_world);
        if wo.z == 0.0 || self.flags().is_empty() {
            return None;
        }
        let sample = self.bxdf.sample_f(wo, uc, u, mode, SampleFlags::All)?;
        if sample.f.is_black() || sample.pdf == 0.0 || sample.wi.z == 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi: self.to_world(sample.wi),
            ..sample
        })
    }

    pub fn pdf(&self, wo_world: Vec3, wi_world: Vec3, mode: TransportMode) -> f64 {
        let wo = self.to_local(wo_world);
        if wo.z == 0.0 {
            return 0.0;
        }
        self.bxdf
            .pdf(wo, self.to_local(wi_world), mode, SampleFlags::All)
    }
}

/// wo and wi on the same side of the surface.
fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

/// The mirror image of `wo` about the normal `n` (both pointing away from the surface).
fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    n * (2.0 * wo.dot(n)) - wo
}

/// The direction `wi` refracts into through a surface of normal `n` and relative index
/// `eta` (inside over outside, the inside being opposite `n`), with the relative index
/// actually crossed; `None` under total internal reflection. `wi` may arrive from either
/// side: from the side opposite `n`, the interface is seen with 1/eta.
fn refract(wi: Vec3, n: Vec3, eta: f64) -> Option<(Vec3, f64)> {
    let (mut n, mut eta, mut cos_i) = (n, eta, n.dot(wi));
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    Some((-wi / eta + n * (cos_i / eta - cos_t), eta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn flags_combine_and_query() {
        let f = BxdfFlags::GLOSSY_REFLECTION | BxdfFlags::SPECULAR_TRANSMISSION;
        assert!(f.contains(BxdfFlags::REFLECTION) && f.contains(BxdfFlags::TRANSMISSION));
        assert!(f.is_specular() && f.is_non_specular() && f.is_reflective() && f.is_transmissive());
        assert!(!BxdfFlags::DIFFUSE_REFLECTION.is_specular());
        assert!(!BxdfFlags::SPECULAR_REFLECTION.is_non_specular());
        assert!(BxdfFlags::UNSET.is_empty());
    }

    #[test]
    fn bsdf_frame_follows_the_normal_and_the_tangent_hint() {
        // z = n, x = the hint projected onto the tangent plane, to 1e-12; the anisotropic
        // conductor's value in world space equals the local one in that frame.
        let n = Vec3::new(0.2, -0.4, 0.9).normalized();
        let hint = Vec3::new(1.0, 0.3, 0.0);
        let bxdf = Bxdf::Conductor(ConductorBxdf::new(
            TrowbridgeReitz::new(0.5, 0.1),
            SampledSpectrum::splat(2.0),
            SampledSpectrum::splat(4.0),
        ));
        let bsdf = Bsdf::new(n, Some(hint), bxdf);
        let x = (hint - n * n.dot(hint)).normalized();
        assert!((bsdf.to_world(Vec3::Z) - n).length() < 1e-12);
        assert!((bsdf.to_world(Vec3::X) - x).length() < 1e-12);
        let mut rng = Rng::new(11, 0);
        let mode = TransportMode::Radiance;
        for _ in 0..100 {
            let u = [rng.uniform(), rng.uniform()];
            let wo_local = crate::sampling::cosine_hemisphere([rng.uniform(), rng.uniform()]);
            let wo = bsdf.to_world(wo_local);
            // A microfacet may reflect below the horizon: no sample then.
            let Some(s) = bsdf.sample_f(wo, rng.uniform(), u, mode) else {
                continue;
            };
            let wi_local = bsdf.to_local(s.wi);
            let local = bxdf.f(wo_local, wi_local, mode)[0];
            assert!((bsdf.f(wo, s.wi, mode)[0] - local).abs() <= 1e-9 * local);
            assert!((bsdf.f(wo, s.wi, mode)[0] - s.f[0]).abs() <= 1e-9 * local);
            let pdf = bsdf.pdf(wo, s.wi, mode);
            assert!((pdf - s.pdf).abs() <= 1e-9 * pdf);
        }
        // A hint along the normal falls back to some tangent frame.
        let b = Bsdf::new(n, Some(n * 3.0), bxdf);
        assert!((b.to_world(Vec3::Z) - n).length() < 1e-12);
        assert!(b.to_world(Vec3::X).dot(n).abs() < 1e-12);
    }

    /// The specular lobes' total weight toward wo: the mean of f·|cos|/pdf over samples that
    /// came from a specular lobe (each lobe's probability is in its pdf).
    fn specular_albedo(bxdf: &Bxdf, wo: Vec3, rng: &mut Rng) -> f64 {
        let n = 200_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let u = [rng.uniform(), rng.uniform()];
            let s = bxdf.sample_f(
                wo,
                rng.uniform(),
                u,
                TransportMode::Radiance,
                SampleFlags::All,
            );
            if let Some(s) = s.filter(|s| s.is_specular() && s.pdf > 0.0) {
                sum += s.f[0] * s.wi.z.abs() / s.pdf;
            }
        }
        sum / n as f64
    }

    /// `split_diffuse`: the parts' values add up to the whole's (to 1e-12), their specular
    /// lobes carry the whole's weight (Monte Carlo, 2·10⁵ samples each, seed 21, within
    /// 0.01), the diffuse part has no glossy or specular lobe, for a Phong material with
    /// every lobe (Fresnel-weighted glass with k_d and k_s) and a smooth coat; a diffuse
    /// surface is all diffuse, a conductor all the rest.
    #[test]
    fn split_diffuse_parts_add_up_to_the_bsdf() {
        let g = |v: f64| SampledSpectrum::splat(v);
        let phong = Bxdf::Phong(PhongBxdf {
            kd: g(0.2),
            ks: g(0.3),
            exponent: 40.0,
            kr: g(0.2),
            kt: g(0.5),
            eta: 1.5,
            thin: false,
            fresnel: true,
        });
        let coat = Bxdf::CoatedDiffuse(CoatedDiffuseBxdf::new(
            DielectricBxdf::smooth(1.5),
            DiffuseBxdf::new(g(0.6)),
        ));
        let mut rng = Rng::new(21, 0);
        let mode = TransportMode::Radiance;
        for whole in [phong, coat] {
            let (Some(d), Some(r)) = whole.split_diffuse() else {
                panic!("{whole:?}: both parts")
            };
            assert!(!d.flags().contains(BxdfFlags::GLOSSY));
            for _ in 0..200 {
                let u = [rng.uniform(), rng.uniform()];
                let wo = crate::sampling::cosine_hemisphere(u);
                let wi = crate::sampling::cosine_hemisphere([rng.uniform(), rng.uniform()]);
                let (f, parts) = (
                    whole.f(wo, wi, mode)[0],
                    d.f(wo, wi, mode)[0] + r.f(wo, wi, mode)[0],
                );
                assert!((f - parts).abs() <= 1e-12 * f.max(1.0), "{f} vs {parts}");
            }
            for cos in [0.9f64, 0.5, 0.15] {
                let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
                let a = specular_albedo(&whole, wo, &mut rng);
                let b = specular_albedo(&r, wo, &mut rng);
                assert!((a - b).abs() < 0.01, "{whole:?} at cos {cos}: {a} vs {b}");
                assert!(
                    specular_albedo(&d, wo, &mut rng) == 0.0 || matches!(d, Bxdf::CoatedDiffuse(_))
                );
            }
        }
        let diffuse = Bxdf::Diffuse(DiffuseBxdf::new(g(0.5)));
        assert!(matches!(diffuse.split_diffuse(), (Some(_), None)));
        assert_eq!(diffuse.diffuse_fraction(Vec3::Z), 1.0);
        let metal = Bxdf::Conductor(ConductorBxdf::new(
            TrowbridgeReitz::new(0.3, 0.3),
            g(0.2),
            g(3.0),
        ));
        assert!(matches!(metal.split_diffuse(), (None, Some(_))));
        assert_eq!(metal.diffuse_fraction(Vec3::Z), 0.0);
    }
}
