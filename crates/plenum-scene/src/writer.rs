//! Writes a scene in the native TOML format, for `plenum convert`: any format Plenum reads
//! becomes a file a user can edit. Shapes keep their own coordinates and carry their placement
//! as a 4×4 `matrix` step, so the written scene renders exactly as the one read. Meshes shared
//! by several objects are written once, as `[meshes.NAME]`.

use crate::RenderDefaults;
use plenum_core::color::Color;
use plenum_core::geometry::{Shape, UvMap};
use plenum_core::light::{Attenuation, Emitter, Light};
use plenum_core::material::{ConductorSpec, FloatTexture, Material, Roughness, SpectralTexture};
use plenum_core::math::{Transform, Vec3};
use plenum_core::scene::Scene;
use plenum_core::texture::{Mapping, Noise, Texture};
use plenum_spectrum::Spectrum;
use std::collections::HashMap;
use std::fmt::Write;

/// The scene as native TOML. Image textures, whose files the core does not keep, are written
/// as their average colour, with a comment saying so.
pub fn to_toml(scene: &Scene, defaults: &RenderDefaults) -> String {
    let mut out = String::new();
    let w = &mut out;
    let _ = writeln!(w, "# Written by `plenum convert`.\n");
    let _ = writeln!(w, "background = {}\n", color(scene.background));
    let _ = writeln!(
        w,
        "[render]\nspp = {}\nsampler = \"{}\"\nfilter = \"{}\"\nmax_depth = {}\nmin_weight = {:?}\nexposure = {:?}",
        defaults.spp,
        if defaults.adaptive {
            "adaptive"
        } else {
            defaults.sampler.name()
        },
        defaults.filter.name(),
        defaults.max_depth,
        defaults.min_weight,
        defaults.exposure
    );
    if let Some(r) = defaults.filter_radius {
        let _ = writeln!(w, "filter_radius = {r:?}");
    }
    if let Some(k) = defaults.integrator {
        let _ = writeln!(w, "integrator = \"{}\"", k.name());
    }
    if let Some(c) = defaults.color {
        let mode = match c {
            plenum_core::integrator::ColorMode::Spectral => "spectral",
            plenum_core::integrator::ColorMode::Rgb => "rgb",
        };
        let _ = writeln!(w, "color = \"{mode}\"");
    }
    let sampler = match defaults.light_sampler {
        plenum_core::light_sampler::LightSamplerKind::Power => "power",
        plenum_core::light_sampler::LightSamplerKind::Uniform => "uniform",
    };
    let _ = writeln!(
        w,
        "rr_depth = {}\nlight_sampler = \"{sampler}\"",
        defaults.rr_depth
    );
    // The photon methods' settings, where they differ from the defaults.
    let (p, base) = (
        &defaults.photon,
        plenum_core::integrator::PhotonConfig::default(),
    );
    for (key, value, default) in [
        ("photons", p.photons, base.photons),
        ("caustic_photons", p.caustic_photons, base.caustic_photons),
        ("photon_nearest", p.nearest as u64, base.nearest as u64),
        ("gather_rays", p.gather_rays as u64, base.gather_rays as u64),
        ("sppm_photons", p.sppm_photons, base.sppm_photons),
    ] {
        if value != default {
            let _ = writeln!(w, "{key} = {value}");
        }
    }
    if p.radius != base.radius {
        let _ = writeln!(w, "photon_radius = {:?}", p.radius);
    }
    if p.alpha != base.alpha {
        let _ = writeln!(w, "sppm_alpha = {:?}", p.alpha);
    }
    let _ = writeln!(w);
    let c = &scene.camera;
    let _ = writeln!(
        w,
        "[camera]\nposition = {}\nlook_at = {}\nup = {}\nresolution = [{}, {}]",
        vec(c.position),
        vec(c.look_at),
        vec(c.up),
        defaults.width,
        defaults.height
    );
    match c.orthographic {
        Some(h) => {
            let _ = writeln!(w, "orthographic = {h:?}");
        }
        None => {
            let _ = writeln!(w, "fov = {:?}", c.fov_degrees);
        }
    }
    let _ = writeln!(w, "shutter = [{:?}, {:?}]", c.shutter[0], c.shutter[1]);
    if c.lens.radius > 0.0 && c.orthographic.is_none() {
        let _ = writeln!(
            w,
            "aperture = {:?}\nfocus_distance = {:?}\nblades = {}\nblade_rotation = {:?}",
            c.lens.radius, c.lens.focus_distance, c.lens.blades, c.lens.rotation_degrees
        );
    }
    if let Some((p, l)) = c.motion {
        let _ = writeln!(w, "position_close = {}\nlook_at_close = {}", vec(p), vec(l));
    }
    if c.left_handed {
        let _ = writeln!(w, "left_handed = true");
    }
    let _ = writeln!(w);
    let keys = unique_keys(&scene.materials.names, "material");
    let written = written_materials(scene);
    for (i, (key, m)) in keys.iter().zip(&scene.materials).enumerate() {
        if !written[i] {
            continue;
        }
        let _ = writeln!(w, "[materials.{}]", quote(key));
        let m = match m {
            Material::Phong(m) => m,
            other => {
                let _ = writeln!(w, "{}", physical_material(other, &keys));
                if scene.materials.is_one_sided(i as u32) {
                    let _ = writeln!(w, "two_sided = false\n");
                }
                continue;
            }
        };
        for (name, t) in [
            ("emissive", &m.emissive),
            ("ambient", &m.ambient),
            ("diffuse", &m.diffuse),
            ("specular", &m.specular),
            ("reflective", &m.reflective),
            ("transmissive", &m.transmissive),
        ] {
            let _ = writeln!(w, "{name} = {}", texture(t));
        }
        let _ = writeln!(
            w,
            "shininess = {:?}\nior = {:?}\nfresnel = {}",
            m.shininess, m.ior, m.fresnel
        );
        if let Some(g) = m.gloss {
            let _ = writeln!(w, "gloss = {g:?}");
        }
        let _ = writeln!(w);
    }
    // Meshes used more than once are written once.
    let mut uses: HashMap<*const (), usize> = HashMap::new();
    for p in &scene.geometry.primitives {
        if let Shape::Mesh(m) = &p.shape {
            *uses
                .entry(std::sync::Arc::as_ptr(m) as *const ())
                .or_default() += 1;
        }
    }
    let mut mesh_names: HashMap<*const (), String> = HashMap::new();
    for p in &scene.geometry.primitives {
        if let Shape::Mesh(m) = &p.shape {
            let ptr = std::sync::Arc::as_ptr(m) as *const ();
            if uses[&ptr] > 1 && !mesh_names.contains_key(&ptr) {
                let name = format!("mesh{}", mesh_names.len() + 1);
                let _ = writeln!(w, "[meshes.{name}]\n{}", mesh_arrays(m));
                mesh_names.insert(ptr, name);
            }
        }
    }
    if !scene.ambient.is_black() {
        let _ = writeln!(
            w,
            "[[lights]]\ntype = \"ambient\"\ncolor = {}\n",
            color(scene.ambient)
        );
    }
    // Per light: the object that shows it, for area lights.
    let mut surface = vec![None; scene.lights.len()];
    for (i, p) in scene.geometry.primitives.iter().enumerate() {
        if let Some(l) = p.light {
            surface[l as usize] = Some(i);
        }
    }
    for (i, (light, name)) in scene.lights.iter().zip(&scene.lights.names).enumerate() {
        // The background is written as `background`, not as a light.
        if Some(i as u32) == scene.lights.background {
            continue;
        }
        if surface[i].is_some_and(|p| written_with_object(scene, p)) {
            // Written as its object, with `emission`.
            continue;
        }
        let _ = writeln!(w, "[[lights]]\nname = {}", quote(name));
        match light {
            Light::Area {
                shape,
                radiance,
                samples,
                ..
            } => {
                let _ = match shape {
                    Emitter::Rectangle {
                        corner,
                        edge_u,
                        edge_v,
                    } => writeln!(
                        w,
                        "type = \"rectangle\"\ncorner = {}\nedge_u = {}\nedge_v = {}",
                        vec(*corner),
                        vec(*edge_u),
                        vec(*edge_v)
                    ),
                    Emitter::Disk {
                        center,
                        normal,
                        radius,
                    } => writeln!(
                        w,
                        "type = \"disk\"\ncenter = {}\nnormal = {}\nradius = {:?}",
                        vec(*center),
                        vec(*normal),
                        radius
                    ),
                    Emitter::Sphere { center, radius } => writeln!(
                        w,
                        "type = \"sphere\"\ncenter = {}\nradius = {:?}",
                        vec(*center),
                        radius
                    ),
                    Emitter::Triangles { .. } => Ok(()),
                };
                let _ = writeln!(
                    w,
                    "{}\nsamples = {samples}\n",
                    emission(scene, i, *radiance, "color")
                );
            }
            Light::Environment { map, .. } => {
                let frame = map.map.frame();
                let layout = match map.map.layout() {
                    plenum_core::environment::EnvironmentLayout::LatLong => "latlong",
                    plenum_core::environment::EnvironmentLayout::LatLongPoles => "latlong-poles",
                    plenum_core::environment::EnvironmentLayout::EqualArea => "equalarea",
                };
                let _ = writeln!(
                    w,
                    "type = \"infinite\"\nfile = {}\nlayout = \"{layout}\"\naxes = [{}, {}, {}]\nintensity = {:?}\n",
                    quote(&map.file),
                    vec(frame.x),
                    vec(frame.y),
                    vec(frame.z),
                    map.scale
                );
            }
            Light::Infinite { radiance } => {
                let _ = writeln!(
                    w,
                    "type = \"infinite\"\n{}\n",
                    emission(scene, i, *radiance, "color")
                );
            }
            Light::Point {
                position,
                intensity,
                attenuation,
            } => {
                let _ = writeln!(
                    w,
                    "type = \"point\"\nposition = {}\n{}\nattenuation = {}\n",
                    vec(*position),
                    emission(scene, i, *intensity, "color"),
                    atten(attenuation)
                );
            }
            Light::Profiled {
                position,
                intensity,
                profile,
            } => {
                // The native format has no profiles: the mean intensity, from the point.
                let _ = writeln!(
                    w,
                    "# a goniometric or projection light, written as a point light of its mean intensity\ntype = \"point\"\nposition = {}\n{}\nintensity = {:?}\n",
                    vec(*position),
                    emission(scene, i, *intensity, "color"),
                    profile.mean_luminance()
                );
            }
            Light::Directional {
                direction,
                intensity,
            } => {
                let _ = writeln!(
                    w,
                    "type = \"directional\"\ndirection = {}\n{}\n",
                    vec(*direction),
                    emission(scene, i, *intensity, "color")
                );
            }
            Light::Spot {
                position,
                direction,
                cos_inner,
                cos_outer,
                intensity,
                attenuation,
            } => {
                let _ = writeln!(
                    w,
                    "type = \"spot\"\nposition = {}\ndirection = {}\ninner_angle = {:?}\nouter_angle = {:?}\n{}\nattenuation = {}\n",
                    vec(*position),
                    vec(*direction),
                    cos_inner.clamp(-1.0, 1.0).acos().to_degrees(),
                    cos_outer.clamp(-1.0, 1.0).acos().to_degrees(),
                    emission(scene, i, *intensity, "color"),
                    atten(attenuation)
                );
            }
        }
    }
    for (index, (p, name)) in scene
        .geometry
        .primitives
        .iter()
        .zip(&scene.geometry.names)
        .enumerate()
    {
        // An object that shows an area light is written with its light.
        let _ = match p.light.map(|i| (i as usize, &scene.lights[i as usize])) {
            Some((
                i,
                Light::Area {
                    radiance,
                    samples,
                    two_sided,
                    texture: emitted,
                    ..
                },
            )) if written_with_object(scene, index) => {
                let m = &scene.materials[p.material as usize];
                let material = if m.reflects_nothing() {
                    String::new()
                } else {
                    format!("\nmaterial = {}", quote(&keys[p.material as usize]))
                };
                writeln!(
                    w,
                    "[[objects]]\nname = {}{material}\n{}\ntwo_sided = {two_sided}\nlight_samples = {samples}",
                    quote(name),
                    match emitted {
                        // A texture that is not white is scaled by the radiance.
                        Some(t) => format!(
                            "emission = {}",
                            texture(&match *radiance == Color::WHITE {
                                true => t.texture.clone(),
                                false => Texture::Scale(std::sync::Arc::new([
                                    Texture::Constant(*radiance),
                                    t.texture.clone(),
                                ])),
                            })
                        ),
                        None => emission(scene, i, *radiance, "emission"),
                    }
                )
            }
            Some(_) => continue,
            None => writeln!(
                w,
                "[[objects]]\nname = {}\nmaterial = {}",
                quote(name),
                quote(&keys[p.material as usize])
            ),
        };
        let _ = match &p.shape {
            Shape::Sphere(s) => writeln!(w, "type = \"sphere\"\ncenter = {}\nradius = {:?}\ninside_only = {}{}{}", vec(s.center), s.radius, s.inside_only, partial(s.partial), uv_map(s.uv_map)),
            Shape::Plane(s) => writeln!(w, "type = \"plane\"\npoint = {}\nnormal = {}", vec(s.point), vec(s.normal)),
            Shape::Disk(s) => writeln!(w, "type = \"disk\"\ncenter = {}\nnormal = {}\nradius = {:?}{}{}", vec(s.center), vec(s.normal), s.radius, partial(s.partial), uv_map(s.uv_map)),
            Shape::Cuboid(s) => writeln!(w, "type = \"box\"\nmin = {}\nmax = {}", vec(s.min), vec(s.max)),
            Shape::Cylinder(s) => writeln!(w, "type = \"cylinder\"\nbase = [0.0, 0.0, 0.0]\ntop = [0.0, 0.0, {:?}]\nradius = {:?}\ncapped = {}{}{}", s.height(), s.radius(), s.is_capped(), partial(s.partial()), uv_map(s.uv_map())),
            Shape::Cone(s) => writeln!(
                w,
                "type = \"cone\"\nbase = [0.0, 0.0, 0.0]\ntop = [0.0, 0.0, {:?}]\nradius = {:?}\ntop_radius = {:?}\ncapped = {}\ninside_only = {}{}",
                s.height, s.radius0, s.radius1, s.capped, s.inside_only, partial(s.partial)
            ),
            Shape::Polygon(s) => writeln!(w, "type = \"polygon\"\nvertices = {}", points(s.vertices())),
            Shape::Polyhedron(s) => {
                // Faces as loops into one vertex list, shared corners written once.
                let mut vertices: Vec<Vec3> = Vec::new();
                let mut faces = Vec::new();
                for face in s.faces() {
                    let ids: Vec<String> = face
                        .vertices()
                        .iter()
                        .map(|v| {
                            let i = vertices.iter().position(|u| u == v).unwrap_or_else(|| {
                                vertices.push(*v);
                                vertices.len() - 1
                            });
                            i.to_string()
                        })
                        .collect();
                    faces.push(format!("[{}]", ids.join(", ")));
                }
                writeln!(w, "type = \"polyhedron\"\nvertices = {}\nfaces = [{}]", points(&vertices), faces.join(", "))
            }
            Shape::Mesh(m) => match mesh_names.get(&(std::sync::Arc::as_ptr(m) as *const ())) {
                Some(n) => writeln!(w, "type = \"mesh\"\nmesh = {}", quote(n)),
                None => writeln!(w, "type = \"mesh\"\n{}", mesh_arrays(m)),
            },
        };
        if let Some(ids) = &p.vertex_materials {
            let names: Vec<String> = ids.iter().map(|&m| quote(&keys[m as usize])).collect();
            let _ = writeln!(w, "vertex_materials = [{}]", names.join(", "));
        }
        if let Some(t) = &p.to_world {
            let _ = writeln!(w, "transform = [{{ matrix = {} }}]", matrix(t));
        }
        if let Some(m) = &p.motion {
            let _ = writeln!(
                w,
                "transform_close = [{{ matrix = {} }}]",
                matrix(&m.at(1.0))
            );
        }
        if let Some(a) = &p.alpha {
            let _ = match &a.texture {
                FloatTexture::Constant(v) => writeln!(w, "alpha = {v:?}"),
                FloatTexture::Texture(t) => writeln!(w, "alpha = {}", texture(t)),
            };
            // An image is written as its average: a cutoff would then cut all or nothing,
            // so the average stays a coverage.
            let image = matches!(a.texture, FloatTexture::Texture(Texture::Image(_)));
            if let (Some(c), false) = (a.cutoff, image) {
                let _ = writeln!(w, "alpha_cutoff = {c:?}");
            }
        }
        if p.bump.is_some() {
            // The image a map was read from is not kept, so it cannot be named here.
            let _ = writeln!(
                w,
                "# its material's normal or bump map is not written: add `normal_map` or `bump` to the material"
            );
        }
        let _ = writeln!(w);
    }
    out
}

/// Per material: whether it is written. A black material that no written object or mix
/// names (the surface of an area light, written as its light) is left out.
fn written_materials(scene: &Scene) -> Vec<bool> {
    let mut named = vec![false; scene.materials.len()];
    for p in &scene.geometry.primitives {
        if p.light.is_some() && scene.materials[p.material as usize].reflects_nothing() {
            continue;
        }
        named[p.material as usize] = true;
        for &m in p.vertex_materials.iter().flat_map(|ids| ids.iter()) {
            named[m as usize] = true;
        }
    }
    for m in &scene.materials {
        if let Material::Mix { materials, .. } = m {
            for &id in materials {
                named[id as usize] = true;
            }
        }
    }
    scene
        .materials
        .iter()
        .zip(named)
        .map(|(m, named)| {
            named
                || !m
                    .phong()
                    .is_some_and(|p| p.reflects_nothing() && p.emissive.is_black())
        })
        .collect()
}

/// Whether primitive `prim`, an area light's surface, is written as an object with an
/// `emission`: a mesh light, or any object with a material of its own; the lights of
/// docs/scene-format.md's rectangle, disk and sphere kind are written as lights.
fn written_with_object(scene: &Scene, prim: usize) -> bool {
    let p = &scene.geometry.primitives[prim];
    matches!(p.shape, Shape::Mesh(_)) || !scene.materials[p.material as usize].reflects_nothing()
}

/// A physically based material's keys (after its `[materials.NAME]` line).
fn physical_material(m: &Material, keys: &[String]) -> String {
    let rough = |r: &Roughness| {
        let f = |t: &FloatTexture| match t {
            FloatTexture::Constant(v) => format!("{v:?}"),
            FloatTexture::Texture(t) => texture(t),
        };
        format!(
            "roughness = [{}, {}]\nremap_roughness = {}",
            f(&r.u),
            f(&r.v),
            r.remap
        )
    };
    match m {
        Material::Phong(_) => String::new(),
        Material::Diffuse(m) => format!(
            "type = \"diffuse\"\nreflectance = {}\n",
            spectral(&m.reflectance)
        ),
        Material::Conductor(m) => {
            let spec = match &m.spec {
                ConductorSpec::EtaK { eta, k } => {
                    format!("eta = {}\nk = {}", spectral(eta), spectral(k))
                }
                ConductorSpec::Reflectance(r) => format!("reflectance = {}", spectral(r)),
            };
            format!("type = \"conductor\"\n{spec}\n{}\n", rough(&m.roughness))
        }
        Material::Dielectric(m) => format!(
            "type = \"dielectric\"\neta = {}\n{}\n",
            spectrum(m.eta.spectrum()),
            rough(&m.roughness)
        ),
        Material::ThinDielectric(m) => format!(
            "type = \"thindielectric\"\neta = {}\n",
            spectrum(m.eta.spectrum())
        ),
        Material::DiffuseTransmission(m) => format!(
            "type = \"diffusetransmission\"\nreflectance = {}\ntransmittance = {}\nscale = {:?}\n",
            spectral(&m.reflectance),
            spectral(&m.transmittance),
            m.scale
        ),
        Material::CoatedDiffuse(m) => format!(
            "type = \"coateddiffuse\"\nreflectance = {}\n{}\neta = {}\nthickness = {:?}\nalbedo = {}\ng = {:?}\nmax_depth = {}\nsamples = {}\n",
            spectral(&m.reflectance),
            rough(&m.roughness),
            spectrum(m.eta.spectrum()),
            m.thickness,
            spectral(&m.albedo),
            m.g,
            m.max_depth,
            m.samples
        ),
        Material::Mix { materials, amount } => format!(
            "type = \"mix\"\nmaterials = [{}, {}]\namount = {}\n",
            quote(&keys[materials[0] as usize]),
            quote(&keys[materials[1] as usize]),
            match amount {
                FloatTexture::Constant(v) => format!("{v:?}"),
                FloatTexture::Texture(t) => texture(t),
            }
        ),
    }
}

fn spectral(t: &SpectralTexture) -> String {
    match t {
        SpectralTexture::Constant(v) => spectrum(v.spectrum()),
        SpectralTexture::Rgb { texture: t, .. } => texture(t),
    }
}

/// A spectrum: a constant as a number, an uplifted RGB value as its colour, a dispersion
/// formula by its coefficients, a table by its own points, a blackbody tabulated every
/// nanometre over 360–830 nm (names are not kept).
fn spectrum(s: &Spectrum) -> String {
    if let Some(rgb) = plenum_core::material::source_rgb(s) {
        return color(Color::new(rgb[0], rgb[1], rgb[2]));
    }
    let list = |v: &[f64]| {
        let items: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
        format!("[{}]", items.join(", "))
    };
    match s {
        Spectrum::Constant(c) => return format!("{c:?}"),
        Spectrum::Sellmeier { b, c } => {
            return format!("{{ sellmeier = [{}, {}] }}", list(b), list(c))
        }
        Spectrum::Sellmeier4 { b, c } => {
            return format!("{{ sellmeier = [{}, {}] }}", list(b), list(c))
        }
        Spectrum::Cauchy { a, b } => return format!("{{ cauchy = [{a:?}, {b:?}] }}"),
        Spectrum::CiddorAir => return "\"air\"".to_string(),
        _ => {}
    }
    let pairs: Vec<String> = match s {
        Spectrum::PiecewiseLinear(p) => p
            .wavelengths()
            .iter()
            .zip(p.values())
            .map(|(l, v)| format!("[{l:?}, {v:?}]"))
            .collect(),
        _ => (360..=830)
            .map(|l| format!("[{:?}, {:?}]", l as f64, s.eval(l as f64)))
            .collect(),
    };
    format!("{{ spectrum = [{}] }}", pairs.join(", "))
}

/// A light's `color`, or its `spectrum` when it was given one.
fn emission(scene: &Scene, light: usize, rgb: Color, key: &str) -> String {
    let s = scene.lights.emission(light as u32).spectrum();
    if plenum_core::material::source_rgb(s).is_some() {
        format!("{key} = {}", color(rgb))
    } else {
        let key = if key == "color" { "spectrum" } else { key };
        format!("{key} = {}", spectrum(s))
    }
}

/// A partial shape's cut as native keys, each on a line of its own after a newline.
fn partial(p: Option<plenum_core::geometry::Partial>) -> String {
    let Some(p) = p else {
        return String::new();
    };
    let mut out = String::new();
    if p.z_min > f64::NEG_INFINITY {
        let _ = write!(out, "\nz_min = {:?}", p.z_min);
    }
    if p.z_max < f64::INFINITY {
        let _ = write!(out, "\nz_max = {:?}", p.z_max);
    }
    if p.inner_radius > 0.0 {
        let _ = write!(out, "\ninner_radius = {:?}", p.inner_radius);
    }
    if p.phi_max < std::f64::consts::TAU {
        let _ = write!(out, "\nphi_max = {:?}", p.phi_max.to_degrees());
    }
    out
}

fn vec(v: Vec3) -> String {
    format!("[{:?}, {:?}, {:?}]", v.x, v.y, v.z)
}

/// A quadric's `uv_map` line, where it is not Plenum's own.
fn uv_map(m: UvMap) -> &'static str {
    match m {
        UvMap::Plenum => "",
        UvMap::Pbrt => "\nuv_map = \"pbrt\"",
        UvMap::Mitsuba => "\nuv_map = \"mitsuba\"",
    }
}

fn color(c: Color) -> String {
    format!("[{:?}, {:?}, {:?}]", c.r, c.g, c.b)
}

fn points(p: &[Vec3]) -> String {
    format!(
        "[{}]",
        p.iter().map(|v| vec(*v)).collect::<Vec<_>>().join(", ")
    )
}

fn atten(a: &Attenuation) -> String {
    format!("[{:?}, {:?}, {:?}]", a.constant, a.linear, a.quadratic)
}

fn matrix(t: &Transform) -> String {
    let rows: Vec<String> = t
        .matrix
        .0
        .iter()
        .map(|r| format!("[{:?}, {:?}, {:?}, {:?}]", r[0], r[1], r[2], r[3]))
        .collect();
    format!("[{}]", rows.join(", "))
}

fn texture(t: &Texture) -> String {
    match t {
        Texture::Image(img) => format!(
            "{}  # an image texture, written as its average colour",
            color(img.average())
        ),
        t => inline_texture(t),
    }
}

/// A texture as one TOML value, without a comment (it may sit inside another); an image as
/// its average colour.
fn inline_texture(t: &Texture) -> String {
    match t {
        Texture::Constant(c) => color(*c),
        Texture::Checker2d { even, odd, scale } => format!(
            "{{ texture = \"checker\", even = {}, odd = {}, scale = {scale:?} }}",
            color(*even),
            color(*odd)
        ),
        Texture::Checker3d { even, odd, scale } => format!(
            "{{ texture = \"checker3d\", even = {}, odd = {}, scale = {scale:?} }}",
            color(*even),
            color(*odd)
        ),
        Texture::Image(img) => color(img.average()),
        Texture::Bilerp(b) => {
            let (corners, scale) = &**b;
            let corners: Vec<String> = corners.iter().map(|c| color(*c)).collect();
            format!(
                "{{ texture = \"bilerp\", corners = [{}], scale = [{:?}, {:?}] }}",
                corners.join(", "),
                scale[0],
                scale[1]
            )
        }
        Texture::Scale(t) => format!(
            "{{ texture = \"scale\", textures = [{}, {}] }}",
            inline_texture(&t[0]),
            inline_texture(&t[1])
        ),
        Texture::Mix(t) => format!(
            "{{ texture = \"mix\", textures = [{}, {}], amount = {} }}",
            inline_texture(&t[0]),
            inline_texture(&t[1]),
            inline_texture(&t[2])
        ),
        Texture::DirectionMix(m) => format!(
            "{{ texture = \"directionmix\", textures = [{}, {}], direction = {} }}",
            inline_texture(&m.1[0]),
            inline_texture(&m.1[1]),
            vec(m.0)
        ),
        Texture::Noise(n) => match **n {
            Noise::Fbm { omega, octaves } => {
                format!("{{ texture = \"fbm\", omega = {omega:?}, octaves = {octaves} }}")
            }
            Noise::Wrinkled { omega, octaves } => {
                format!("{{ texture = \"wrinkled\", omega = {omega:?}, octaves = {octaves} }}")
            }
            Noise::Windy => "{ texture = \"windy\" }".to_string(),
            Noise::Marble {
                omega,
                octaves,
                scale,
                variation,
            } => format!(
                "{{ texture = \"marble\", omega = {omega:?}, octaves = {octaves}, scale = {scale:?}, variation = {variation:?} }}"
            ),
        },
        Texture::Dots => "{ texture = \"dots\" }".to_string(),
        Texture::Mapped(m) => {
            let of = inline_texture(&m.1);
            let placed = |to_texture: &Transform| {
                format!("transform = {{ matrix = {} }}", matrix(&to_texture.inverted()))
            };
            let pair = |p: [f64; 2]| format!("[{:?}, {:?}]", p[0], p[1]);
            let mapping = match &m.0 {
                Mapping::Uv { scale, delta } => format!(
                    "mapping = \"uv\", scale = {}, delta = {}",
                    pair(*scale),
                    pair(*delta)
                ),
                Mapping::Spherical(t) => format!("mapping = \"spherical\", {}", placed(t)),
                Mapping::Cylindrical(t) => format!("mapping = \"cylindrical\", {}", placed(t)),
                Mapping::Solid(t) => format!("mapping = \"solid\", {}", placed(t)),
                Mapping::Planar {
                    to_texture,
                    axes,
                    delta,
                } => format!(
                    "mapping = \"planar\", {}, axes = {}, delta = {}",
                    placed(to_texture),
                    points(axes),
                    pair(*delta)
                ),
            };
            format!("{{ texture = \"mapped\", {mapping}, of = {of} }}")
        }
    }
}

fn mesh_arrays(m: &plenum_core::geometry::TriangleMesh) -> String {
    let (positions, triangles) = m.indexed();
    let mut s = format!(
        "positions = {}\nindices = [{}]",
        points(&positions),
        triangles
            .iter()
            .map(|t| format!("[{}, {}, {}]", t[0], t[1], t[2]))
            .collect::<Vec<_>>()
            .join(", ")
    );
    if !m.normals().is_empty() {
        s += &format!("\nnormals = {}", points(m.normals()));
    }
    if !m.uvs().is_empty() {
        s += &format!(
            "\nuvs = [{}]",
            m.uvs()
                .iter()
                .map(|u| format!("[{:?}, {:?}]", u[0], u[1]))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    s
}

/// A TOML basic string.
fn quote(s: &str) -> String {
    format!("{s:?}")
}

/// Names made distinct: a repeated name gets " (2)", " (3)", … appended.
fn unique_keys(names: &[String], fallback: &str) -> Vec<String> {
    let mut seen: HashMap<String, usize> = HashMap::new();
    names
        .iter()
        .map(|n| {
            let base = if n.is_empty() {
                fallback.to_string()
            } else {
                n.clone()
            };
            let count = seen.entry(base.clone()).or_default();
            *count += 1;
            if *count == 1 {
                base
            } else {
                format!("{base} ({count})")
            }
        })
        .collect()
}
