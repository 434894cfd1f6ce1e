//! `--aov`: images beside the render, each to NAME.VIEW.EXT beside NAME.EXT (or, for an EXR,
//! in it as its layers). Where the
//! work goes (`rays`, `spp`, `depth`, and `cost`: the acceleration structures' node visits,
//! primitive tests and their sum as red, green and blue), what the camera's rays first meet
//! (`normal`, `albedo`, `position`), and how noisy each pixel is (`variance`). Float formats
//! keep the values (an EXR's layers are named NAME.CHANNEL); a PNG shows them
//! (counts scaled so that the largest is white, the cost in false colour, normals as
//! (n + 1)/2, positions across their bounding box).

use crate::FILM_EXTENSION;
use plenum_core::aov::first_hits;
use plenum_core::integrator::IntegratorKind;
use plenum_core::raw_film::RawFilm;
use plenum_core::render::{Adaptive, RenderOutput, RenderSettings};
use plenum_core::scene::Scene;
use plenum_image::ExrLayer;
use std::path::{Path, PathBuf};

/// One view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aov {
    Variance,
    Rays,
    Spp,
    Depth,
    Cost,
    Normal,
    Albedo,
    Position,
}

impl Aov {
    const ALL: [Aov; 8] = [
        Aov::Variance,
        Aov::Rays,
        Aov::Spp,
        Aov::Depth,
        Aov::Cost,
        Aov::Normal,
        Aov::Albedo,
        Aov::Position,
    ];

    fn name(self) -> &'static str {
        match self {
            Aov::Variance => "variance",
            Aov::Rays => "rays",
            Aov::Spp => "spp",
            Aov::Depth => "depth",
            Aov::Cost => "cost",
            Aov::Normal => "normal",
            Aov::Albedo => "albedo",
            Aov::Position => "position",
        }
    }
}

/// `--aov a,b,…`: the views asked for, each once, in the order of [`Aov::ALL`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AovList(Vec<Aov>);

impl std::str::FromStr for AovList {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let mut asked = Vec::new();
        for name in s.split(',').map(str::trim) {
            let Some(aov) = Aov::ALL.into_iter().find(|a| a.name() == name) else {
                let names: Vec<&str> = Aov::ALL.iter().map(|a| a.name()).collect();
                return Err(format!(
                    "unknown view `{name}`: expected a comma-separated list of {}",
                    names.join(", ")
                ));
            };
            asked.push(aov);
        }
        Ok(AovList(
            Aov::ALL.into_iter().filter(|a| asked.contains(a)).collect(),
        ))
    }
}

impl AovList {
    fn has(&self, aov: Aov) -> bool {
        self.0.contains(&aov)
    }

    /// Whether the render must keep each pixel's rays.
    pub fn needs_pixel_rays(&self) -> bool {
        [Aov::Rays, Aov::Spp, Aov::Depth, Aov::Cost]
            .iter()
            .any(|&a| self.has(a))
    }

    /// Why these views cannot go with `settings`, if they cannot: `keeps_film` (checkpoints,
    /// a time limit, sample ranges) and `film_output` as the render is asked.
    pub fn check(
        &self,
        settings: &RenderSettings,
        keeps_film: bool,
        film_output: bool,
    ) -> Result<(), String> {
        if self.0.is_empty() {
            return Ok(());
        }
        let kind = settings.integrator.kind;
        if film_output {
            return Err(format!("--aov writes an image beside the output: the raw film (.{FILM_EXTENSION}) holds no views (render the image itself, or `plenum merge` the parts into one)"));
        }
        if self.has(Aov::Variance) {
            if kind.splats() || kind == IntegratorKind::Sppm {
                return Err(format!("--aov variance is not available with integrator `{}`: its pixels are not the mean of their own samples (light paths land anywhere; SPPM's iterations share their radii)", kind.name()));
            }
            if settings.corners || matches!(settings.adaptive, Some(Adaptive::Subdivide { .. })) {
                return Err("--aov variance needs pixels made of samples: adaptive subdivision and the SPD corners compute each pixel whole".to_string());
            }
        }
        if self.needs_pixel_rays() {
            if kind == IntegratorKind::Sppm {
                return Err("--aov rays, spp, depth and cost are not available with integrator `sppm`: its photon passes belong to no pixel".to_string());
            }
            if settings.corners {
                return Err("--aov rays, spp, depth and cost are not available with the SPD corners: each corner ray belongs to four pixels".to_string());
            }
            if keeps_film {
                return Err("--aov rays, spp, depth and cost cannot be combined with checkpoints, --time-limit or --samples: the rays of each pixel are not kept in the film".to_string());
            }
        }
        Ok(())
    }

    /// Writes each view beside `output`; the lines that say what a PNG's white stands for
    /// (`most`, where given, for the counts; else each view's largest).
    pub fn write(
        &self,
        output: &Path,
        film: &RawFilm,
        rendered: &RenderOutput,
        scene: &Scene,
        settings: &RenderSettings,
        most: Option<u64>,
    ) -> Result<Vec<String>, String> {
        let is = |ext: &str| {
            output
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case(ext))
        };
        let (png, exr) = (is("png"), is("exr"));
        let mut layers = Vec::new();
        let hits = [Aov::Normal, Aov::Albedo, Aov::Position]
            .iter()
            .any(|&a| self.has(a))
            .then(|| first_hits(scene, settings));
        let (w, h) = settings.image_size();
        let mut notes = Vec::new();
        for &aov in &self.0 {
            let path = aov_path(output, aov.name());
            let counts = |f: fn(&plenum_core::render::PixelRays) -> u64| -> Vec<[f32; 3]> {
                rendered
                    .pixel_rays
                    .iter()
                    .map(|r| [f(r) as f32; 3])
                    .collect()
            };
            let pixels: Vec<[f32; 3]> = match aov {
                Aov::Variance => match film.variance_image() {
                    Some(v) => v.pixels().to_vec(),
                    None => continue,
                },
                Aov::Rays => counts(|r| r.total),
                Aov::Spp => counts(|r| r.camera),
                Aov::Depth => counts(|r| r.deepest),
                Aov::Cost => rendered
                    .pixel_rays
                    .iter()
                    .map(|r| {
                        let (n, t) = (r.cost.nodes as f32, r.cost.tests as f32);
                        [n, t, n + t]
                    })
                    .collect(),
                Aov::Normal => hits.as_ref().map_or(Vec::new(), |h| h.normal.clone()),
                Aov::Albedo => hits.as_ref().map_or(Vec::new(), |h| h.albedo.clone()),
                Aov::Position => hits.as_ref().map_or(Vec::new(), |h| h.position.clone()),
            };
            if exr {
                layers.push(exr_layer(aov, &pixels));
                continue;
            }
            let pixels = if png {
                let (shown, note) = for_png(aov, pixels, most.map(|m| m as f32));
                if let Some(n) = note {
                    notes.push(format!("{}: {n}", path.display()));
                }
                shown
            } else {
                pixels
            };
            plenum_image::write_image(&path, w, h, &pixels, 0.0).map_err(|e| e.to_string())?;
        }
        if !layers.is_empty() {
            // The image again, with the views as its layers.
            let f = &rendered.film;
            plenum_image::write_exr_layers(output, f.width, f.height, f.pixels(), &layers)
                .map_err(|e| e.to_string())?;
            let names: Vec<String> = layers
                .iter()
                .map(|l| {
                    let channels: Vec<&str> = l.channels.iter().map(|c| c.0).collect();
                    format!("{}.{}", l.name, channels.join("/"))
                })
                .collect();
            notes.push(format!(
                "{}: the views are its layers {}",
                output.display(),
                names.join(", ")
            ));
        }
        Ok(notes)
    }
}

/// A view as an EXR layer: counts as one channel, Y; the cost as node visits, tests and
/// their sum in R, G and B (as in a file of its own); the rest as R, G, B.
fn exr_layer(aov: Aov, pixels: &[[f32; 3]]) -> ExrLayer {
    let channel = |k: usize| pixels.iter().map(|p| p[k]).collect::<Vec<f32>>();
    let channels = match aov {
        Aov::Rays | Aov::Spp | Aov::Depth => vec![("Y", channel(0))],
        _ => vec![("R", channel(0)), ("G", channel(1)), ("B", channel(2))],
    };
    ExrLayer {
        name: aov.name().to_string(),
        channels,
    }
}

/// NAME.VIEW.EXT beside the output NAME.EXT.
pub fn aov_path(output: &Path, view: &str) -> PathBuf {
    let stem = output.file_stem().unwrap_or_default().to_string_lossy();
    let ext = output
        .extension()
        .map_or(String::new(), |e| format!(".{}", e.to_string_lossy()));
    output.with_file_name(format!("{stem}.{view}{ext}"))
}

/// A view as a PNG shows it (linear values, which the PNG encodes as sRGB), and what its
/// white stands for where that is not 1.
fn for_png(
    aov: Aov,
    mut pixels: Vec<[f32; 3]>,
    most: Option<f32>,
) -> (Vec<[f32; 3]>, Option<String>) {
    // The full scale: as asked, else the largest of channel `k`.
    let full = |pixels: &[[f32; 3]], k: usize| {
        most.unwrap_or_else(|| pixels.iter().map(|p| p[k]).fold(0.0f32, f32::max))
    };
    match aov {
        Aov::Rays | Aov::Spp | Aov::Depth => {
            let most = full(&pixels, 0);
            if most > 0.0 {
                for p in &mut pixels {
                    *p = p.map(|c| (c / most).min(1.0));
                }
            }
            let what = match aov {
                Aov::Rays => "rays",
                Aov::Spp => "camera rays (samples)",
                _ => "bounces (the deepest reflected or refracted ray)",
            };
            (
                pixels,
                Some(format!("black 0, white {most} {what} per pixel")),
            )
        }
        Aov::Normal => {
            for p in &mut pixels {
                *p = p.map(|c| 0.5 * (c + 1.0));
            }
            (pixels, Some("(n + 1)/2 of the unit normal".to_string()))
        }
        Aov::Position => {
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for p in &pixels {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            for p in &mut pixels {
                for k in 0..3 {
                    let span = hi[k] - lo[k];
                    p[k] = if span > 0.0 {
                        (p[k] - lo[k]) / span
                    } else {
                        0.0
                    };
                }
            }
            (
                pixels,
                Some(format!("x, y, z from {lo:?} (black) to {hi:?} (full)")),
            )
        }
        Aov::Cost => {
            let most = full(&pixels, 2);
            for p in &mut pixels {
                *p = heat(if most > 0.0 { p[2] / most } else { 0.0 });
            }
            (
                pixels,
                Some(format!(
                    "false colour from black (0) through blue, red and yellow to white ({most} node visits and primitive tests per pixel)"
                )),
            )
        }
        Aov::Variance | Aov::Albedo => (pixels, None),
    }
}

/// The colour of `t` in 0..=1 on a heat scale, black, blue, red, yellow, white (as linear
/// values: the PNG encodes them as sRGB, which shows the scale's own colours).
fn heat(t: f32) -> [f32; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 1.0, 1.0],
    ];
    let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (x as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    std::array::from_fn(|k| {
        let srgb = STOPS[i][k] + (STOPS[i + 1][k] - STOPS[i][k]) * f;
        if srgb <= 0.04045 {
            srgb / 12.92
        } else {
            ((srgb + 0.055) / 1.055).powf(2.4)
        }
    })
}
