//! The scene's material table, indexed by [`MaterialId`]: each material, its name, and
//! whether it scatters on one side only.

use crate::bxdf::Bxdf;
use crate::material::{Coefficients, Material, MaterialId, Scattering};
use crate::sampling::Rng;
use crate::texture::TextureCoords;
use plenum_spectrum::SampledWavelengths;

#[derive(Clone, Debug, Default)]
pub struct Materials {
    all: Vec<Material>,
    pub names: Vec<String>,
    /// Per material: it scatters only on the side its surface's normal points to (Mitsuba's
    /// convention; pbrt's, the default, scatters on both).
    one_sided: Vec<bool>,
}

/// Mixes nest at most this deep; a deeper one (or a cycle, which the scene reader refuses)
/// ends the walk.
const MIX_DEPTH: u32 = 16;

impl Materials {
    /// The table of `all`, named by `names`; the materials `one_sided` scatter on their
    /// normals' side only (transmissive ones stay two-sided).
    pub(super) fn new(all: Vec<Material>, names: Vec<String>, one_sided: &[MaterialId]) -> Self {
        let mut sided = vec![false; all.len()];
        for &id in one_sided {
            if let Some(o) = sided.get_mut(id as usize) {
                *o = !all[id as usize].is_transmissive();
            }
        }
        Materials {
            all,
            names,
            one_sided: sided,
        }
    }

    pub fn len(&self) -> usize {
        self.all.len()
    }

    pub fn is_empty(&self) -> bool {
        self.all.is_empty()
    }

    pub fn iter(&self) -> std::slice::Iter<'_, Material> {
        self.all.iter()
    }

    /// Whether material `id` scatters only on its normals' side.
    pub fn is_one_sided(&self, id: MaterialId) -> bool {
        self.one_sided[id as usize]
    }

    /// Material `id`'s coefficients; a mix blends its two materials' by its amount (a few
    /// mixes deep; a deeper one gives its first material's).
    pub fn coefficients(&self, id: MaterialId, at: &TextureCoords) -> Coefficients {
        self.coefficients_of(id, at, 0)
    }

    fn coefficients_of(&self, id: MaterialId, at: &TextureCoords, depth: u32) -> Coefficients {
        match &self.all[id as usize] {
            Material::Mix { materials, amount } if depth < MIX_DEPTH => {
                let a = amount.evaluate(at).clamp(0.0, 1.0);
                Coefficients::blend(&[
                    (1.0 - a, self.coefficients_of(materials[0], at, depth + 1)),
                    (a, self.coefficients_of(materials[1], at, depth + 1)),
                ])
            }
            m => m.coefficients(at),
        }
    }

    /// The BxDF of material `id` at `at` (`solid`: on a closed surface); a mix chooses one
    /// of its materials by a number drawn from `seed()`, so that the choice can be the same
    /// for any thread. `None` where it does not scatter (an emitter's surface).
    pub fn bxdf(
        &self,
        mut id: MaterialId,
        at: &TextureCoords,
        wl: &mut SampledWavelengths,
        solid: bool,
        seed: impl FnOnce() -> u64,
    ) -> Option<Bxdf> {
        let mut seed = Some(seed);
        let mut rng = None;
        for _ in 0..MIX_DEPTH {
            let m = &self.all[id as usize];
            let u = match m {
                Material::Mix { .. } => rng
                    .get_or_insert_with(|| Rng::new(seed.take().map_or(0, |s| s()), 0))
                    .uniform(),
                _ => 0.5,
            };
            match m.scattering(at, wl, solid, u) {
                Scattering::Bxdf(b) => return Some(b),
                Scattering::Other(next) => id = next,
            }
        }
        None
    }

    /// What in the scene varies with wavelength beyond what RGB can carry (a dispersive
    /// index, a measured spectrum), named for a warning; `None` if nothing does.
    pub fn needs_wavelengths(&self) -> Option<String> {
        for (m, name) in self.all.iter().zip(&self.names) {
            if let Some(what) = m.wavelength_dependence() {
                return Some(format!("material `{name}` ({what})"));
            }
        }
        None
    }
}

impl std::ops::Index<usize> for Materials {
    type Output = Material;

    fn index(&self, id: usize) -> &Material {
        &self.all[id]
    }
}

impl<'a> IntoIterator for &'a Materials {
    type Item = &'a Material;
    type IntoIter = std::slice::Iter<'a, Material>;

    fn into_iter(self) -> Self::IntoIter {
        self.all.iter()
    }
}
