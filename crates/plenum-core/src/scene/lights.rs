//! The scene's lights: each light, its name and its emission as a spectrum, the lights at
//! infinity, and how next-event estimation picks one. An area light's surface is a primitive
//! that names it ([`super::Primitive::light`]).

use crate::color::Color;
use crate::light::Light;
use crate::light_sampler::{LightSampler, LightSamplerKind};
use crate::material::{rgb_radiance, scaled, SpectrumKind, SpectrumValue};
use crate::math::Vec3;
use crate::texture::TextureCoords;
use plenum_spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

#[derive(Clone, Debug, Default)]
pub struct Lights {
    all: Vec<Light>,
    pub names: Vec<String>,
    /// Per light: its emission as a spectrum (an RGB light's uplifted as an illuminant).
    spectra: Vec<SpectrumValue>,
    /// The lights at infinity, which rays that hit nothing see.
    pub infinite: Vec<u32>,
    /// The lights of Whitted's model, which it sums over at every hit: all but those at
    /// infinity (a background light among them would cost every hit a light for nothing).
    pub whitted: Vec<u32>,
    /// Chooses a light for next-event estimation.
    pub sampler: LightSampler,
    /// The scene's background as a light (a uniform infinite light), where it is not black.
    pub background: Option<u32>,
}

impl Lights {
    /// The lights `all`, named by `names`, with a spectrum and scale in place of the RGB
    /// value of some (`spectra`: their RGB value becomes that spectrum's, for Whitted's
    /// model and RGB mode). The light `background` is the background's.
    pub(super) fn new(
        mut all: Vec<Light>,
        names: Vec<String>,
        spectra: &[Option<(Spectrum, f64)>],
        background: Option<u32>,
    ) -> Lights {
        for (light, spectrum) in all.iter_mut().zip(spectra) {
            if let Some((s, scale)) = spectrum {
                let [r, g, b] = s.to_rgb_illuminant();
                light.set_rgb(Color::new(r, g, b) * *scale);
            }
        }
        let spectra = all
            .iter()
            .zip(spectra)
            .map(|(l, s)| match s {
                Some((s, scale)) => SpectrumValue::new(scaled(s, *scale), SpectrumKind::Illuminant),
                None => SpectrumValue::from_rgb(l.rgb(), SpectrumKind::Illuminant),
            })
            .collect();
        let (infinite, whitted) =
            (0..all.len() as u32).partition(|&i| all[i as usize].is_infinite());
        Lights {
            all,
            names,
            spectra,
            infinite,
            whitted,
            sampler: LightSampler::default(),
            background,
        }
    }

    pub fn len(&self) -> usize {
        self.all.len()
    }

    pub fn is_empty(&self) -> bool {
        self.all.is_empty()
    }

    pub fn iter(&self) -> std::slice::Iter<'_, Light> {
        self.all.iter()
    }

    /// Chooses how next-event estimation picks lights; `radius` is the scene's, which
    /// bounds the power of lights at infinity.
    pub fn set_sampler(&mut self, kind: LightSamplerKind, radius: f64) {
        self.sampler = match kind {
            LightSamplerKind::Uniform => LightSampler::uniform(self.all.len()),
            LightSamplerKind::Power => {
                let powers: Vec<f64> = self.all.iter().map(|l| l.power(radius)).collect();
                LightSampler::new(&powers)
            }
        };
    }

    /// Light `light`'s emission as a spectrum (with its RGB value).
    pub fn emission(&self, light: u32) -> &SpectrumValue {
        &self.spectra[light as usize]
    }

    /// Light `light`'s radiance (or intensity) at the sample's wavelengths.
    #[inline]
    pub fn spectrum(&self, light: u32, wl: &SampledWavelengths) -> SampledSpectrum {
        self.spectra[light as usize].sample(wl)
    }

    /// What area light `light` sends from the point of its surface a ray met, whose texture
    /// coordinates are `at`.
    #[inline]
    pub fn emitted(
        &self,
        light: u32,
        at: &TextureCoords,
        wl: &SampledWavelengths,
    ) -> SampledSpectrum {
        match self.all[light as usize].textured_radiance_at(at) {
            Some(c) => rgb_radiance(c, wl),
            None => self.spectrum(light, wl),
        }
    }

    /// What light `light`, one at infinity, sends along -`d` toward the scene.
    pub fn radiance_from_infinity(
        &self,
        light: u32,
        d: Vec3,
        wl: &SampledWavelengths,
    ) -> SampledSpectrum {
        match &self.all[light as usize] {
            Light::Environment { map, .. } => {
                let [r, g, b] = map.map.radiance(d);
                rgb_radiance(Color::new(r, g, b), wl)
            }
            _ => self.spectrum(light, wl),
        }
    }
}

impl std::ops::Index<usize> for Lights {
    type Output = Light;

    fn index(&self, light: usize) -> &Light {
        &self.all[light]
    }
}

impl<'a> IntoIterator for &'a Lights {
    type Item = &'a Light;
    type IntoIter = std::slice::Iter<'a, Light>;

    fn into_iter(self) -> Self::IntoIter {
        self.all.iter()
    }
}
