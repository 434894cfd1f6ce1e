//! The physically based side of the native format: `[materials.NAME]` tables with a `type`
//! (`diffuse`, `conductor`, `dielectric`, `thindielectric`, `diffusetransmission`,
//! `coateddiffuse`, `mix`), and spectra wherever a colour or an index goes. Documented key by
//! key in docs/materials.md.

use super::Reader;
use crate::diagnostics::did_you_mean;
use crate::reader::{Fields, Result, Value};
use plenum_core::material::{
    CoatedDiffuseMaterial, ConductorMaterial, ConductorSpec, DielectricMaterial, DiffuseMaterial,
    DiffuseTransmissionMaterial, FloatTexture, Material, Roughness, SpectralTexture, SpectrumKind,
    SpectrumValue, ThinDielectricMaterial,
};
use plenum_core::texture::Texture;
use plenum_spectrum::Spectrum;
use toml::de::DeValue;

/// The material types besides the Phong model (which has no `type`).
pub const MATERIAL_TYPES: &[&str] = &[
    "phong",
    "diffuse",
    "conductor",
    "dielectric",
    "thindielectric",
    "diffusetransmission",
    "coateddiffuse",
    "mix",
];

/// The metals `metal = "…"` names, each with its measured η and k.
const METALS: &[&str] = &["Ag", "Al", "Au", "Cr", "Cu", "CuZn", "Ti"];

impl<'s> Reader<'s> {
    /// A physically based material of type `kind`; `None` for `phong`, which the caller reads.
    pub(super) fn physical_material(
        &mut self,
        name: &str,
        kind: &str,
        v: &Value<'s>,
    ) -> Result<Option<Material>> {
        let what = format!("{kind} material `{name}`");
        let rough_keys = ["roughness", "remap_roughness"];
        let src = self.src;
        let table = |keys: &[&'static str]| {
            let all: Vec<&'static str> = [
                "type",
                "two_sided",
                "normal_map",
                "normal_scale",
                "bump",
                "bump_scale",
            ]
            .iter()
            .chain(keys)
            .copied()
            .collect();
            src.table(v, &what, &all)
        };
        Ok(Some(match kind {
            "diffuse" => {
                let f = table(&["reflectance"])?;
                Material::Diffuse(DiffuseMaterial {
                    reflectance: self.spectral_or(&f, "reflectance", 0.5, SpectrumKind::Albedo)?,
                })
            }
            "conductor" => {
                let f = table(&[
                    "metal",
                    "eta",
                    "k",
                    "reflectance",
                    rough_keys[0],
                    rough_keys[1],
                ])?;
                let spec = match (f.get("metal"), f.get("reflectance")) {
                    (Some(m), _) => {
                        if f.get("eta").is_some() || f.get("k").is_some() {
                            return Err(self.src.error(
                                m.span(),
                                "give either `metal` or `eta` and `k`, not both",
                            ));
                        }
                        let metal = self.src.string(m)?;
                        if !METALS.contains(&metal) {
                            let e = self.src.error(m.span(), format!("unknown metal `{metal}`"));
                            return Err(match did_you_mean(metal, METALS.iter().copied()) {
                                Some(s) => e.with_help(format!("did you mean `{s}`?")),
                                None => {
                                    e.with_help(format!("expected one of: {}", METALS.join(", ")))
                                }
                            });
                        }
                        self.metal(metal)
                    }
                    (None, Some(r)) => {
                        ConductorSpec::Reflectance(self.spectral(r, SpectrumKind::Albedo)?)
                    }
                    // pbrt-v4's default conductor is copper.
                    (None, None) => match (f.get("eta"), f.get("k")) {
                        (None, None) => self.metal("Cu"),
                        (eta, k) => ConductorSpec::EtaK {
                            eta: match eta {
                                Some(e) => self.optical_constant(e, "η")?,
                                None => self.metal_part("Cu", "eta"),
                            },
                            k: match k {
                                Some(k) => self.optical_constant(k, "k")?,
                                None => self.metal_part("Cu", "k"),
                            },
                        },
                    },
                };
                Material::Conductor(ConductorMaterial {
                    spec,
                    roughness: self.roughness(&f)?,
                })
            }
            "dielectric" => {
                let f = table(&["eta", rough_keys[0], rough_keys[1]])?;
                Material::Dielectric(DielectricMaterial {
                    eta: self.eta(&f)?,
                    roughness: self.roughness(&f)?,
                })
            }
            "thindielectric" => {
                let f = table(&["eta"])?;
                Material::ThinDielectric(ThinDielectricMaterial { eta: self.eta(&f)? })
            }
            "diffusetransmission" => {
                let f = table(&["reflectance", "transmittance", "scale"])?;
                Material::DiffuseTransmission(DiffuseTransmissionMaterial {
                    reflectance: self.spectral_or(&f, "reflectance", 0.25, SpectrumKind::Albedo)?,
                    transmittance: self.spectral_or(
                        &f,
                        "transmittance",
                        0.25,
                        SpectrumKind::Albedo,
                    )?,
                    scale: f.non_negative_or("scale", 1.0)?,
                })
            }
            "coateddiffuse" => {
                let f = table(&[
                    "reflectance",
                    "eta",
                    "thickness",
                    "albedo",
                    "g",
                    "max_depth",
                    "samples",
                    rough_keys[0],
                    rough_keys[1],
                ])?;
                let g = f.number_or("g", 0.0)?;
                if !(-1.0..=1.0).contains(&g) {
                    return Err(self.src.error(
                        f.required("g")?.span(),
                        format!("expected an asymmetry g between -1 and 1, found {g}"),
                    ));
                }
                let count = |key: &str, default: u32| -> Result<u32> {
                    match f.count(key)? {
                        None => Ok(default),
                        Some(n) if (1..=100).contains(&n) => Ok(n),
                        Some(n) => Err(self.src.error(
                            f.required(key)?.span(),
                            format!("expected `{key}` between 1 and 100, found {n}"),
                        )),
                    }
                };
                Material::CoatedDiffuse(CoatedDiffuseMaterial {
                    reflectance: self.spectral_or(&f, "reflectance", 0.5, SpectrumKind::Albedo)?,
                    roughness: self.roughness(&f)?,
                    thickness: f.positive("thickness", Some(0.01))?,
                    eta: self.eta(&f)?,
                    albedo: self.spectral_or(&f, "albedo", 0.0, SpectrumKind::Albedo)?,
                    g,
                    max_depth: count("max_depth", 10)?,
                    samples: count("samples", 1)?,
                })
            }
            "mix" => {
                let f = table(&["materials", "amount"])?;
                let list = f.required("materials")?;
                let items = self.src.array(list, "two material names")?;
                if items.len() != 2 {
                    return Err(self.src.error(
                        list.span(),
                        format!("expected two materials, found {}", items.len()),
                    ));
                }
                // Materials must be defined before the mix that uses them, so mixes cannot
                // form a cycle.
                let a = self.defined_material(&items[0])?;
                let b = self.defined_material(&items[1])?;
                let amount = match f.get("amount") {
                    None => FloatTexture::Constant(0.5),
                    Some(v) => self.fraction(v, "an amount")?,
                };
                Material::Mix {
                    materials: [a, b],
                    amount,
                }
            }
            _ => return Ok(None),
        }))
    }

    fn defined_material(&mut self, v: &Value<'s>) -> Result<plenum_core::scene::MaterialId> {
        let name = self.src.string(v)?;
        if !self.materials.contains_key(name) {
            return Err(self
                .src
                .error(
                    v.span(),
                    format!("no material named `{name}` is defined before this mix"),
                )
                .with_help("define the mixed materials above the mix"));
        }
        self.material_ref(Some(v))
    }

    fn metal_part(&self, metal: &str, part: &str) -> SpectralTexture {
        let s = plenum_spectrum::named(&format!("metal-{metal}-{part}"))
            .unwrap_or(Spectrum::Constant(1.0));
        SpectralTexture::Constant(SpectrumValue::new(s, SpectrumKind::Unbounded))
    }

    fn metal(&self, metal: &str) -> ConductorSpec {
        ConductorSpec::EtaK {
            eta: self.metal_part(metal, "eta"),
            k: self.metal_part(metal, "k"),
        }
    }

    /// `eta`: a number, a named spectrum (`"glass-BK7"`, `"water"`), or a spectrum table;
    /// 1.5 when not given.
    fn eta(&self, f: &Fields<'_, 's>) -> Result<SpectrumValue> {
        let Some(v) = f.get("eta") else {
            return Ok(SpectrumValue::new(
                Spectrum::Constant(1.5),
                SpectrumKind::Unbounded,
            ));
        };
        let s = match v.get_ref() {
            DeValue::Integer(_) | DeValue::Float(_) => {
                let e = self.src.number(v)?;
                if e <= 0.0 {
                    return Err(self
                        .src
                        .error(v.span(), format!("expected an index η > 0, found {e}")));
                }
                Spectrum::Constant(e)
            }
            _ => self.spectrum(v)?,
        };
        self.positive_over_visible(v, &s, "an index η")?;
        Ok(SpectrumValue::new(s, SpectrumKind::Unbounded))
    }

    /// Checks that `s` is finite and positive at every 5 nm of 360–830 nm (an index of
    /// refraction with a pole in the visible, or a negative table, is refused where it is
    /// written).
    fn positive_over_visible(&self, v: &Value<'s>, s: &Spectrum, what: &str) -> Result<()> {
        for i in 0..=94 {
            let l = 360.0 + 5.0 * i as f64;
            let x = s.eval(l);
            if !(x.is_finite() && x > 0.0) {
                return Err(self.src.error(
                    v.span(),
                    format!("expected {what} > 0 over 360–830 nm, found {x} at {l} nm"),
                ));
            }
        }
        Ok(())
    }

    /// `roughness` (one number, [u, v] for anisotropy, or a texture) with
    /// `remap_roughness` (default true: α = √roughness, as pbrt-v4).
    fn roughness(&self, f: &Fields<'_, 's>) -> Result<Roughness> {
        let remap = f.bool_or("remap_roughness", true)?;
        let Some(v) = f.get("roughness") else {
            return Ok(Roughness::SMOOTH);
        };
        let scalar = |t: Texture| match t {
            Texture::Constant(c) => FloatTexture::Constant((c.r + c.g + c.b) / 3.0),
            t => FloatTexture::Texture(t),
        };
        let (u, v) = match v.get_ref() {
            // [u, v]: numbers or textures.
            DeValue::Array(_) if self.src.array(v, "[u, v] roughness")?.len() == 2 => {
                let a = self.src.array(v, "[u, v] roughness")?;
                let one = |x: &Value<'s>| -> Result<FloatTexture> {
                    let t = scalar(self.texture(x)?);
                    match t {
                        FloatTexture::Constant(r) if r < 0.0 => {
                            Err(self.src.error(x.span(), "expected roughness ≥ 0"))
                        }
                        t => Ok(t),
                    }
                };
                (one(&a[0])?, one(&a[1])?)
            }
            _ => {
                let t = scalar(self.texture(v)?);
                (t.clone(), t)
            }
        };
        Ok(Roughness { u, v, remap })
    }

    /// A conductor's η or k: a colour, texture or spectrum; a spectrum must be positive over
    /// the visible range (k may be 0).
    fn optical_constant(&self, v: &Value<'s>, what: &str) -> Result<SpectralTexture> {
        let t = self.spectral(v, SpectrumKind::Unbounded)?;
        if let SpectralTexture::Constant(c) = &t {
            if what == "k" {
                let s = c.spectrum();
                for i in 0..=94 {
                    let l = 360.0 + 5.0 * i as f64;
                    let x = s.eval(l);
                    if !(x.is_finite() && x >= 0.0) {
                        return Err(self.src.error(
                            v.span(),
                            format!("expected k ≥ 0 over 360–830 nm, found {x} at {l} nm"),
                        ));
                    }
                }
            } else {
                self.positive_over_visible(v, c.spectrum(), "η")?;
            }
        }
        Ok(t)
    }

    /// A parameter that may be an RGB colour or texture (uplifted as `kind`) or a spectrum.
    pub(super) fn spectral(&self, v: &Value<'s>, kind: SpectrumKind) -> Result<SpectralTexture> {
        let is_spectrum = match v.get_ref() {
            DeValue::String(_) => true,
            DeValue::Table(t) => t.get("blackbody").is_some() || t.get("spectrum").is_some(),
            _ => false,
        };
        if is_spectrum {
            return Ok(SpectralTexture::Constant(SpectrumValue::new(
                self.spectrum(v)?,
                kind,
            )));
        }
        Ok(SpectralTexture::from_texture(self.texture(v)?, kind))
    }

    fn spectral_or(
        &self,
        f: &Fields<'_, 's>,
        key: &str,
        default: f64,
        kind: SpectrumKind,
    ) -> Result<SpectralTexture> {
        match f.get(key) {
            Some(v) => self.spectral(v, kind),
            None => Ok(SpectralTexture::constant(
                plenum_core::color::Color::gray(default),
                kind,
            )),
        }
    }

    /// A spectrum: a named one (`"metal-Au-eta"`, `"stdillum-D65"`, `"water"`), a blackbody
    /// (`{ blackbody = 6500 }`, kelvin, normalised to peak 1), a piecewise-linear list
    /// (`{ spectrum = [[400, 0.2], [700, 0.9]] }`, nm and value), or an index by a
    /// dispersion formula, λ in µm: `{ sellmeier = [[B₁, B₂, B₃], [C₁, C₂, C₃]] }` (three or
    /// four terms) or `{ cauchy = [A, B] }` (n = A + B/λ²).
    pub(super) fn spectrum(&self, v: &Value<'s>) -> Result<Spectrum> {
        match v.get_ref() {
            DeValue::String(_) => {
                let name = self.src.string(v)?;
                plenum_spectrum::named(name).ok_or_else(|| {
                    let e = self
                        .src
                        .error(v.span(), format!("unknown spectrum `{name}`"));
                    match did_you_mean(name, plenum_spectrum::names().iter().copied()) {
                        Some(s) => e.with_help(format!("did you mean `{s}`?")),
                        None => e.with_help("see docs/spectra.md for the named spectra"),
                    }
                })
            }
            DeValue::Table(_) => {
                let f = self.src.table(
                    v,
                    "a spectrum",
                    &["blackbody", "spectrum", "sellmeier", "cauchy"],
                )?;
                if f.get("blackbody").is_some() {
                    let t = f.positive("blackbody", None)?;
                    return Ok(Spectrum::blackbody(t, 1.0));
                }
                if let Some(c) = f.get("cauchy") {
                    let [a, b] = self.src.numbers::<2>(c, "Cauchy's [A, B in µm²]")?;
                    return Ok(Spectrum::Cauchy { a, b });
                }
                if let Some(list) = f.get("sellmeier") {
                    let what = "Sellmeier's [[B₁, …], [C₁, … in µm²]], three or four terms";
                    let rows = self.src.array(list, what)?;
                    if rows.len() != 2 {
                        return Err(self.src.error(list.span(), format!("expected {what}")));
                    }
                    let terms = |r: &Value<'s>| -> Result<Vec<f64>> {
                        self.src
                            .array(r, what)?
                            .iter()
                            .map(|x| self.src.number(x))
                            .collect()
                    };
                    let (b, c) = (terms(&rows[0])?, terms(&rows[1])?);
                    return match (b.len(), c.len()) {
                        (3, 3) => Ok(Spectrum::Sellmeier {
                            b: [b[0], b[1], b[2]],
                            c: [c[0], c[1], c[2]],
                        }),
                        (4, 4) => Ok(Spectrum::Sellmeier4 {
                            b: [b[0], b[1], b[2], b[3]],
                            c: [c[0], c[1], c[2], c[3]],
                        }),
                        _ => Err(self.src.error(list.span(), format!("expected {what}"))),
                    };
                }
                let list = f.required("spectrum")?;
                let items = self.src.array(list, "[wavelength in nm, value] pairs")?;
                let mut pairs = Vec::with_capacity(items.len());
                for item in items {
                    let [l, x] = self
                        .src
                        .numbers::<2>(item, "a [wavelength in nm, value] pair")?;
                    pairs.push((l, x));
                }
                Spectrum::piecewise(&pairs).map_err(|e| self.src.error(list.span(), e))
            }
            _ => Err(self.src.error(
                v.span(),
                "expected a spectrum: a name, { blackbody = K } or { spectrum = [[nm, value], …] }",
            )),
        }
    }
}
