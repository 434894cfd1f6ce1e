//! The lecture's Phong material for Whitted ray tracing, with Whitted's k_r and k_t. Every
//! coefficient may be textured. Under the physically based integrators it is read as a
//! normalised BSDF ([`crate::bxdf::PhongBxdf`]).

use crate::color::Color;
use crate::texture::{Texture, TextureCoords};

#[derive(Clone, Debug)]
pub struct PhongMaterial {
    /// k_e: light the surface emits on its own.
    pub emissive: Texture,
    /// k_a: response to the scene's ambient light.
    pub ambient: Texture,
    /// k_d: Lambertian diffuse reflectance.
    pub diffuse: Texture,
    /// k_s: Phong specular reflectance.
    pub specular: Texture,
    /// n: the Phong exponent.
    pub shininess: f64,
    /// k_r: mirror reflectance.
    pub reflective: Texture,
    /// k_t: transmittance of refracted light.
    pub transmissive: Texture,
    /// η: index of refraction of the solid's interior.
    pub ior: f64,
    /// Scale k_r and k_t by the dielectric Fresnel reflectance F and 1 − F.
    pub fresnel: bool,
    /// Glossy reflection and refraction: reflected and refracted rays spread around the
    /// mirror and Snell directions in a Phong lobe cos^n α of this exponent n (the smaller,
    /// the blurrier); `None`: perfectly sharp.
    pub gloss: Option<f64>,
}

impl Default for PhongMaterial {
    /// A matte grey, lit by ambient light in its own colour.
    fn default() -> Self {
        PhongMaterial {
            emissive: Texture::Constant(Color::BLACK),
            ambient: Texture::Constant(Color::gray(0.8)),
            diffuse: Texture::Constant(Color::gray(0.8)),
            specular: Texture::Constant(Color::BLACK),
            shininess: 32.0,
            reflective: Texture::Constant(Color::BLACK),
            transmissive: Texture::Constant(Color::BLACK),
            ior: 1.0,
            fresnel: false,
            gloss: None,
        }
    }
}

/// A material's coefficients evaluated at one point.
#[derive(Clone, Copy, Debug)]
pub struct Coefficients {
    pub emissive: Color,
    pub ambient: Color,
    pub diffuse: Color,
    pub specular: Color,
    pub shininess: f64,
    pub reflective: Color,
    pub transmissive: Color,
    pub ior: f64,
    pub fresnel: bool,
    pub gloss: Option<f64>,
}

impl Coefficients {
    /// The weighted sum of several materials' coefficients (weights summing to one); Fresnel
    /// weighting applies if any part asks for it.
    pub fn blend(parts: &[(f64, Coefficients)]) -> Coefficients {
        let sum = |f: fn(&Coefficients) -> Color| {
            parts
                .iter()
                .fold(Color::BLACK, |acc, (w, c)| acc + f(c) * *w)
        };
        let mean = |f: fn(&Coefficients) -> f64| parts.iter().map(|(w, c)| w * f(c)).sum::<f64>();
        Coefficients {
            emissive: sum(|c| c.emissive),
            ambient: sum(|c| c.ambient),
            diffuse: sum(|c| c.diffuse),
            specular: sum(|c| c.specular),
            shininess: mean(|c| c.shininess),
            reflective: sum(|c| c.reflective),
            transmissive: sum(|c| c.transmissive),
            ior: mean(|c| c.ior),
            fresnel: parts.iter().any(|(_, c)| c.fresnel),
            // Exponents do not average meaningfully; the blurriest part wins.
            gloss: parts
                .iter()
                .filter_map(|(_, c)| c.gloss)
                .min_by(f64::total_cmp),
        }
    }
}

impl PhongMaterial {
    /// A surface that reflects, transmits and emits nothing: an area light's surface shows
    /// its light's emission on it.
    pub fn black() -> PhongMaterial {
        let black = Texture::Constant(Color::BLACK);
        PhongMaterial {
            emissive: black.clone(),
            ambient: black.clone(),
            diffuse: black.clone(),
            specular: black,
            ..PhongMaterial::default()
        }
    }

    /// The material whose coefficients are these, everywhere.
    pub fn constant(k: &Coefficients) -> PhongMaterial {
        let t = Texture::Constant;
        PhongMaterial {
            emissive: t(k.emissive),
            ambient: t(k.ambient),
            diffuse: t(k.diffuse),
            specular: t(k.specular),
            shininess: k.shininess,
            reflective: t(k.reflective),
            transmissive: t(k.transmissive),
            ior: k.ior,
            fresnel: k.fresnel,
            gloss: k.gloss,
        }
    }

    pub fn evaluate(&self, at: &TextureCoords) -> Coefficients {
        Coefficients {
            emissive: self.emissive.evaluate(at),
            ambient: self.ambient.evaluate(at),
            diffuse: self.diffuse.evaluate(at),
            specular: self.specular.evaluate(at),
            shininess: self.shininess,
            reflective: self.reflective.evaluate(at),
            transmissive: self.transmissive.evaluate(at),
            ior: self.ior,
            fresnel: self.fresnel,
            gloss: self.gloss,
        }
    }

    /// Everything but the emission is black: the surface shows light (its own k_e, or an
    /// area light's) and scatters none.
    pub fn reflects_nothing(&self) -> bool {
        [
            &self.ambient,
            &self.diffuse,
            &self.specular,
            &self.reflective,
            &self.transmissive,
        ]
        .iter()
        .all(|t| t.is_black())
    }

    /// Some coefficient is looked up by texture coordinates.
    pub fn needs_uv(&self) -> bool {
        [
            &self.emissive,
            &self.ambient,
            &self.diffuse,
            &self.specular,
            &self.reflective,
            &self.transmissive,
        ]
        .iter()
        .any(|t| t.needs_uv())
    }

    /// Light can pass through: shadow rays continue and rays may start inside.
    pub fn is_transmissive(&self) -> bool {
        !self.transmissive.is_black()
    }
}
