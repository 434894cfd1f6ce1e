//! The physically based materials, as pbrt-v4 names them: each evaluates its textures at a
//! hit and returns a [`Bxdf`] for the sample's wavelengths. Parameters, defaults and units
//! are documented for users in docs/materials.md.

use super::param::{FloatTexture, SpectralTexture, SpectrumValue};
use crate::bxdf::{
    Bxdf, CoatedDiffuseBxdf, ConductorBxdf, DielectricBxdf, DiffuseBxdf, DiffuseTransmissionBxdf,
    ThinDielectricBxdf, TrowbridgeReitz,
};
use crate::texture::TextureCoords;
use plenum_spectrum::{SampledSpectrum, SampledWavelengths};

/// Microfacet roughness along u and v (equal: isotropic), as α or, with `remap`, as pbrt's
/// perceptual roughness (α = √r).
#[derive(Clone, Debug)]
pub struct Roughness {
    pub u: FloatTexture,
    pub v: FloatTexture,
    pub remap: bool,
}

impl Roughness {
    /// A perfectly smooth surface.
    pub const SMOOTH: Roughness = Roughness {
        u: FloatTexture::Constant(0.0),
        v: FloatTexture::Constant(0.0),
        remap: false,
    };

    pub fn distribution(&self, at: &TextureCoords) -> TrowbridgeReitz {
        let (mut u, mut v) = (self.u.evaluate(at).max(0.0), self.v.evaluate(at).max(0.0));
        if self.remap {
            u = TrowbridgeReitz::roughness_to_alpha(u);
            v = TrowbridgeReitz::roughness_to_alpha(v);
        }
        TrowbridgeReitz::new(u, v)
    }

    pub fn needs_uv(&self) -> bool {
        self.u.needs_uv() || self.v.needs_uv()
    }
}

/// Lambertian reflection.
#[derive(Clone, Debug)]
pub struct DiffuseMaterial {
    pub reflectance: SpectralTexture,
}

/// How a conductor's optical constants are given.
#[derive(Clone, Debug)]
pub enum ConductorSpec {
    /// The complex index η + ik, relative to the outside (vacuum).
    EtaK {
        eta: SpectralTexture,
        k: SpectralTexture,
    },
    /// A reflectance at normal incidence, turned into η = 1, k = 2√r / √(1 − r) as pbrt-v4
    /// does (exact at normal incidence).
    Reflectance(SpectralTexture),
}

#[derive(Clone, Debug)]
pub struct ConductorMaterial {
    pub spec: ConductorSpec,
    pub roughness: Roughness,
}

/// A dielectric interface: glass, water, diamond. η may vary with wavelength (dispersion).
#[derive(Clone, Debug)]
pub struct DielectricMaterial {
    pub eta: SpectrumValue,
    pub roughness: Roughness,
}

/// A pane of zero thickness with the interreflection inside it summed (pbrt-v4's
/// `ThinDielectricBxDF`): windows, soap films, bubbles.
#[derive(Clone, Debug)]
pub struct ThinDielectricMaterial {
    pub eta: SpectrumValue,
}

/// Lambertian reflection and Lambertian transmission: paper, leaves, lamp shades.
#[derive(Clone, Debug)]
pub struct DiffuseTransmissionMaterial {
    pub reflectance: SpectralTexture,
    pub transmittance: SpectralTexture,
    pub scale: f64,
}

/// A dielectric coat over a diffuse base with an optional absorbing medium between them
/// (pbrt-v4's `CoatedDiffuseMaterial`, by a stochastic random walk between the layers).
#[derive(Clone, Debug)]
pub struct CoatedDiffuseMaterial {
    pub reflectance: SpectralTexture,
    pub roughness: Roughness,
    pub thickness: f64,
    pub eta: SpectrumValue,
    /// Single-scattering albedo of the medium between the layers; 0: none.
    pub albedo: SpectralTexture,
    /// Henyey–Greenstein asymmetry of that medium.
    pub g: f64,
    pub max_depth: u32,
    pub samples: u32,
}

/// η at the sample's wavelengths: the hero wavelength's, after which a dispersive η leaves
/// only the hero wavelength alive (pbrt-v4's `TerminateSecondary`). In RGB mode: η at the
/// sodium D line.
fn eta_at(eta: &SpectrumValue, wl: &mut SampledWavelengths) -> f64 {
    let e = eta.spectrum().eval(wl.lambda()[0]);
    if !eta.spectrum().is_constant() {
        wl.terminate_secondary();
    }
    e
}

impl DiffuseMaterial {
    pub fn bxdf(&self, at: &TextureCoords, wl: &SampledWavelengths) -> Bxdf {
        let r = self.reflectance.evaluate(at, wl).map(|v| v.clamp(0.0, 1.0));
        Bxdf::Diffuse(DiffuseBxdf::new(r))
    }
}

impl ConductorMaterial {
    pub fn bxdf(&self, at: &TextureCoords, wl: &SampledWavelengths) -> Bxdf {
        let (eta, k) = match &self.spec {
            ConductorSpec::EtaK { eta, k } => (eta.evaluate(at, wl), k.evaluate(at, wl)),
            ConductorSpec::Reflectance(r) => {
                // Just below 1, so that a white reflectance stays finite.
                let r = r.evaluate(at, wl).map(|v| v.clamp(0.0, 0.9999));
                let k = r.zip(r, |r, _| 2.0 * r.sqrt() / (1.0 - r).sqrt());
                (SampledSpectrum::ONE, k)
            }
        };
        Bxdf::Conductor(ConductorBxdf::new(self.roughness.distribution(at), eta, k))
    }
}

impl DielectricMaterial {
    pub fn bxdf(&self, at: &TextureCoords, wl: &mut SampledWavelengths) -> Bxdf {
        let eta = eta_at(&self.eta, wl);
        Bxdf::Dielectric(DielectricBxdf::new(eta, self.roughness.distribution(at)))
    }
}

impl ThinDielectricMaterial {
    pub fn bxdf(&self, wl: &mut SampledWavelengths) -> Bxdf {
        Bxdf::ThinDielectric(ThinDielectricBxdf::new(eta_at(&self.eta, wl)))
    }
}

impl DiffuseTransmissionMaterial {
    pub fn bxdf(&self, at: &TextureCoords, wl: &SampledWavelengths) -> Bxdf {
        let clamp = |s: SampledSpectrum| (s * self.scale).map(|v| v.clamp(0.0, 1.0));
        let r = clamp(self.reflectance.evaluate(at, wl));
        let t = clamp(self.transmittance.evaluate(at, wl));
        Bxdf::DiffuseTransmission(DiffuseTransmissionBxdf::new(r, t))
    }
}

impl CoatedDiffuseMaterial {
    pub fn bxdf(&self, at: &TextureCoords, wl: &mut SampledWavelengths) -> Bxdf {
        let r = self.reflectance.evaluate(at, wl).map(|v| v.clamp(0.0, 1.0));
        let albedo = self.albedo.evaluate(at, wl).map(|v| v.clamp(0.0, 1.0));
        let eta = eta_at(&self.eta, wl);
        Bxdf::CoatedDiffuse(CoatedDiffuseBxdf {
            top: DielectricBxdf::new(eta, self.roughness.distribution(at)),
            bottom: DiffuseBxdf::new(r),
            thickness: self.thickness,
            albedo,
            g: self.g,
            max_depth: self.max_depth,
            samples: self.samples,
        })
    }
}
