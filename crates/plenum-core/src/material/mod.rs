//! Materials: what a surface is made of. A material evaluates its textures at a hit; the
//! physically based ones return a BSDF for the sample's wavelengths ([`Material::bxdf`]), and
//! every material, the Phong model first, also gives Whitted's coefficients
//! ([`Material::coefficients`]), so that any scene renders under every integrator.
//!
//! `Material` is a closed enum dispatched by `match`, one file per model: `phong.rs` for the
//! lecture's model, `physical.rs` for pbrt-v4's set, `param.rs` for their parameters.

mod param;
pub(crate) use param::scaled_sigmoid;
mod phong;
mod physical;

pub use param::{
    rgb_radiance, scaled, source_rgb, uplift, uplift_illuminant, FloatTexture, SpectralTexture,
    SpectrumKind, SpectrumValue,
};
pub use phong::{Coefficients, PhongMaterial};
pub use physical::{
    CoatedDiffuseMaterial, ConductorMaterial, ConductorSpec, DielectricMaterial, DiffuseMaterial,
    DiffuseTransmissionMaterial, Roughness, ThinDielectricMaterial,
};

use crate::bxdf::{Bxdf, PhongBxdf};
use crate::color::Color;
use crate::texture::{Texture, TextureCoords};
use plenum_spectrum::{SampledSpectrum, SampledWavelengths};

/// Index of a material in a scene's table (`Scene::materials`).
pub type MaterialId = u32;

#[derive(Clone, Debug)]
pub enum Material {
    /// The lecture's Phong model with Whitted's k_r and k_t.
    Phong(PhongMaterial),
    Diffuse(DiffuseMaterial),
    Conductor(ConductorMaterial),
    Dielectric(DielectricMaterial),
    ThinDielectric(ThinDielectricMaterial),
    DiffuseTransmission(DiffuseTransmissionMaterial),
    CoatedDiffuse(CoatedDiffuseMaterial),
    /// One of two materials, the second with probability `amount`, chosen per hit by a hash
    /// of the hit (pbrt-v4's `MixMaterial`: a stochastic blend, so it costs one BSDF).
    Mix {
        materials: [MaterialId; 2],
        amount: FloatTexture,
    },
}

impl From<PhongMaterial> for Material {
    fn from(m: PhongMaterial) -> Material {
        Material::Phong(m)
    }
}

impl Default for Material {
    fn default() -> Self {
        Material::Phong(PhongMaterial::default())
    }
}

/// What a material gives the physically based integrators at a hit.
pub enum Scattering {
    Bxdf(Bxdf),
    /// Resolve this material instead (a mix chose it).
    Other(MaterialId),
}

impl Material {
    /// The Phong model's parameters, if this is one.
    pub fn phong(&self) -> Option<&PhongMaterial> {
        match self {
            Material::Phong(m) => Some(m),
            _ => None,
        }
    }

    /// A Phong material that scatters no light (an area light's surface, or k_e alone).
    pub fn reflects_nothing(&self) -> bool {
        match self {
            Material::Phong(m) => m.reflects_nothing(),
            _ => false,
        }
    }

    /// What about the material RGB rendering cannot carry: a dispersive index of refraction.
    pub fn wavelength_dependence(&self) -> Option<&'static str> {
        let dispersive = |e: &SpectrumValue| !e.spectrum().is_constant();
        match self {
            Material::Dielectric(m) if dispersive(&m.eta) => Some("a dispersive η"),
            Material::ThinDielectric(m) if dispersive(&m.eta) => Some("a dispersive η"),
            Material::CoatedDiffuse(m) if dispersive(&m.eta) => Some("a dispersive η"),
            _ => None,
        }
    }

    /// Physically based: the model and its parameters are the physics, with no Phong terms.
    pub fn is_physical(&self) -> bool {
        !matches!(self, Material::Phong(_))
    }

    /// The BSDF at a hit, for the sample's wavelengths (a dispersive η may terminate all but
    /// the hero wavelength). `solid`: the shape has an inside (Phong's k_t refracts into it;
    /// on a thin sheet it passes straight through). `u`: a number for a mix's choice.
    pub fn scattering(
        &self,
        at: &TextureCoords,
        wl: &mut SampledWavelengths,
        solid: bool,
        u: f64,
    ) -> Scattering {
        Scattering::Bxdf(match self {
            Material::Phong(m) => {
                let k = m.evaluate(at);
                let s = |c: Color| spectrum_of(c, wl);
                Bxdf::Phong(PhongBxdf {
                    kd: s(k.diffuse),
                    ks: s(k.specular),
                    exponent: k.shininess,
                    kr: s(k.reflective),
                    kt: s(k.transmissive),
                    eta: k.ior,
                    thin: !solid,
                    fresnel: k.fresnel,
                })
            }
            Material::Diffuse(m) => m.bxdf(at, wl),
            Material::Conductor(m) => m.bxdf(at, wl),
            Material::Dielectric(m) => m.bxdf(at, wl),
            Material::ThinDielectric(m) => m.bxdf(wl),
            Material::DiffuseTransmission(m) => m.bxdf(at, wl),
            Material::CoatedDiffuse(m) => m.bxdf(at, wl),
            Material::Mix { materials, amount } => {
                let pick = u < amount.evaluate(at).clamp(0.0, 1.0);
                return Scattering::Other(materials[usize::from(pick)]);
            }
        })
    }

    /// Whitted's coefficients at a point, for the `whitted` integrator. The physically based
    /// materials give their nearest Phong reading (docs/materials.md): diffuse as k_d, a
    /// conductor as a mirror of its normal-incidence reflectance, glass with Fresnel
    /// weighting, roughness as a Phong gloss exponent 2/α² − 2. A mix gives none of its own:
    /// the scene blends its two materials' ([`crate::scene::Scene::coefficients`]).
    pub fn coefficients(&self, at: &TextureCoords) -> Coefficients {
        let black = Color::BLACK;
        let base = Coefficients {
            emissive: black,
            ambient: black,
            diffuse: black,
            specular: black,
            shininess: 1.0,
            reflective: black,
            transmissive: black,
            ior: 1.0,
            fresnel: false,
            gloss: None,
        };
        let gloss = |r: &Roughness| {
            let d = r.distribution(at);
            let alpha = d.alpha_x.max(d.alpha_y);
            (!d.effectively_smooth()).then(|| (2.0 / (alpha * alpha) - 2.0).max(1.0))
        };
        let eta = |e: &SpectrumValue| e.spectrum().eval(589.3);
        match self {
            Material::Phong(m) => m.evaluate(at),
            Material::Diffuse(m) => {
                let kd = m.reflectance.rgb(at);
                Coefficients {
                    diffuse: kd,
                    ambient: kd,
                    ..base
                }
            }
            Material::Conductor(m) => {
                let f0 = match &m.spec {
                    ConductorSpec::Reflectance(r) => r.rgb(at),
                    ConductorSpec::EtaK { eta, k } => {
                        let (n, k) = (eta.rgb(at), k.rgb(at));
                        let f = |n: f64, k: f64| {
                            ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
                        };
                        Color::new(f(n.r, k.r), f(n.g, k.g), f(n.b, k.b))
                    }
                };
                Coefficients {
                    reflective: f0,
                    gloss: gloss(&m.roughness),
                    ..base
                }
            }
            Material::Dielectric(m) => Coefficients {
                reflective: Color::WHITE,
                transmissive: Color::WHITE,
                ior: eta(&m.eta),
                fresnel: true,
                gloss: gloss(&m.roughness),
                ..base
            },
            Material::ThinDielectric(m) => Coefficients {
                reflective: Color::WHITE,
                transmissive: Color::WHITE,
                ior: eta(&m.eta),
                fresnel: true,
                ..base
            },
            Material::DiffuseTransmission(m) => Coefficients {
                diffuse: m.reflectance.rgb(at) * m.scale,
                ambient: m.reflectance.rgb(at) * m.scale,
                transmissive: m.transmittance.rgb(at) * m.scale,
                ..base
            },
            Material::CoatedDiffuse(m) => Coefficients {
                diffuse: m.reflectance.rgb(at),
                ambient: m.reflectance.rgb(at),
                reflective: Color::WHITE,
                ior: eta(&m.eta),
                fresnel: true,
                gloss: gloss(&m.roughness),
                ..base
            },
            Material::Mix { .. } => base,
        }
    }

    /// The k_t of [`coefficients`](Self::coefficients) where it is the same at every point
    /// (what a shadow ray keeps passing through), so that no hit need be worked out for it;
    /// `None` where it varies or the scene blends it (a mix).
    pub fn uniform_transmissive(&self) -> Option<Color> {
        match self {
            Material::Phong(m) => match m.transmissive {
                Texture::Constant(c) => Some(c),
                _ => None,
            },
            Material::Diffuse(_) | Material::Conductor(_) | Material::CoatedDiffuse(_) => {
                Some(Color::BLACK)
            }
            Material::Dielectric(_) | Material::ThinDielectric(_) => Some(Color::WHITE),
            Material::DiffuseTransmission(_) | Material::Mix { .. } => None,
        }
    }

    /// The index of refraction of a solid of this material at `lambda` nm (1 for those
    /// that do not refract).
    pub fn ior_at(&self, lambda: f64) -> f64 {
        match self {
            Material::Phong(m) => m.ior,
            Material::Dielectric(m) => m.eta.spectrum().eval(lambda),
            Material::ThinDielectric(m) => m.eta.spectrum().eval(lambda),
            Material::CoatedDiffuse(m) => m.eta.spectrum().eval(lambda),
            _ => 1.0,
        }
    }

    /// Some parameter is looked up by texture coordinates.
    pub fn needs_uv(&self) -> bool {
        match self {
            Material::Phong(m) => m.needs_uv(),
            Material::Diffuse(m) => m.reflectance.needs_uv(),
            Material::Conductor(m) => {
                m.roughness.needs_uv()
                    || match &m.spec {
                        ConductorSpec::EtaK { eta, k } => eta.needs_uv() || k.needs_uv(),
                        ConductorSpec::Reflectance(r) => r.needs_uv(),
                    }
            }
            Material::Dielectric(m) => m.roughness.needs_uv(),
            Material::ThinDielectric(_) => false,
            Material::DiffuseTransmission(m) => {
                m.reflectance.needs_uv() || m.transmittance.needs_uv()
            }
            Material::CoatedDiffuse(m) => m.reflectance.needs_uv() || m.roughness.needs_uv(),
            Material::Mix { amount, .. } => amount.needs_uv(),
        }
    }

    /// Light can pass through: shadow rays continue and rays may start inside.
    pub fn is_transmissive(&self) -> bool {
        match self {
            Material::Phong(m) => m.is_transmissive(),
            Material::Diffuse(_) | Material::Conductor(_) | Material::CoatedDiffuse(_) => false,
            Material::Dielectric(_)
            | Material::ThinDielectric(_)
            | Material::DiffuseTransmission(_)
            | Material::Mix { .. } => true,
        }
    }
}

/// An RGB coefficient at the sample's wavelengths (an albedo, bounded by 1 per channel).
fn spectrum_of(c: Color, wl: &SampledWavelengths) -> SampledSpectrum {
    if c.is_black() {
        SampledSpectrum::ZERO
    } else if wl.is_rgb() {
        SampledSpectrum([c.r, c.g, c.b, 0.0])
    } else {
        let clamp = |v: f64| v.clamp(0.0, 1.0);
        param::uplift_at(
            Color::new(clamp(c.r), clamp(c.g), clamp(c.b)),
            SpectrumKind::Albedo,
            wl,
        )
    }
}
