//! The ray tree of one pixel, as drawn in the lecture: every ray the integrator traced, with
//! what it hit, what it returned, and why its branch ended.

use crate::color::Color;
use crate::math::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    Camera,
    Shadow,
    Reflected,
    Refracted,
    /// A ray of a light path: leaving a light, or scattered along the path.
    Light,
    /// A ray joining a path's vertex to the camera or to another path's vertex.
    Connection,
    /// A photon's flight (photon mapping).
    Photon,
}

impl RayKind {
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Camera => "camera",
            RayKind::Shadow => "shadow",
            RayKind::Reflected => "reflected",
            RayKind::Refracted => "refracted",
            RayKind::Light => "light",
            RayKind::Connection => "connection",
            RayKind::Photon => "photon",
        }
    }
}

/// Why the recursion ended at a node, or skipped one of its branches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// The ray left the scene; it returned the background.
    Miss,
    /// A secondary ray was due but the maximum depth was reached.
    Depth,
    /// A secondary ray's weight in the pixel fell below the threshold.
    Weight,
    /// The surface neither reflects nor transmits: a leaf of the tree.
    Opaque,
    /// Local illumination and Appel's method end at the first hit: they do not recurse.
    NoRecursion,
    /// One secondary ray of Whitted's (reflected or refracted) was due but not traced, as
    /// the maximum depth was reached; the other may go on.
    SkippedAtDepth(RayKind),
    /// One secondary ray of Whitted's was not traced, its weight in the pixel being below
    /// the threshold; the other may go on.
    SkippedForWeight(RayKind),
}

impl Stop {
    pub fn name(self) -> &'static str {
        match self {
            Stop::Miss => "miss",
            Stop::Depth => "depth",
            Stop::Weight => "weight",
            Stop::Opaque => "no reflection or transmission",
            Stop::NoRecursion => "no recursion (this method stops at the first hit)",
            Stop::SkippedAtDepth(RayKind::Refracted) => "refracted ray not traced: depth",
            Stop::SkippedAtDepth(_) => "reflected ray not traced: depth",
            Stop::SkippedForWeight(RayKind::Refracted) => "refracted ray not traced: weight",
            Stop::SkippedForWeight(_) => "reflected ray not traced: weight",
        }
    }
}

/// The optics at a hit of Whitted's: what the ray met and how it splits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Optics {
    /// Angle of incidence to the shading normal, degrees.
    pub incidence: f64,
    /// Indices of refraction on the ray's side and beyond, where the surface transmits.
    pub eta: Option<(f64, f64)>,
    /// Angle of refraction, degrees; `None` under total internal reflection or where the
    /// surface does not transmit.
    pub refraction: Option<f64>,
    /// The critical angle, degrees, where light goes from denser to thinner.
    pub critical: Option<f64>,
    /// Fresnel reflectance at this angle, where the material uses it.
    pub fresnel: Option<f64>,
}

/// What a shadow ray found on its way to a light.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowInfo {
    pub light: String,
    /// Objects between the point and the light, nearest first.
    pub occluders: Vec<String>,
    /// An opaque occluder stopped the light.
    pub blocked: bool,
    /// S_L: the product of the transmissive occluders' k_t (zero when blocked).
    pub transmittance: Color,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RayNode {
    pub parent: Option<usize>,
    pub kind: RayKind,
    pub depth: u32,
    pub origin: Vec3,
    /// Unit direction.
    pub direction: Vec3,
    /// The ray's weight in the pixel: the product of the coefficients along its path.
    pub weight: Color,
    /// Object and material hit, for camera, reflected and refracted rays.
    pub object: Option<String>,
    pub material: Option<String>,
    /// Distance to the hit (to the light for shadow rays).
    pub distance: Option<f64>,
    /// Radiance the ray returned.
    pub color: Color,
    pub stops: Vec<Stop>,
    /// At this hit the refracted ray was totally internally reflected.
    pub total_internal_reflection: bool,
    pub shadow: Option<ShadowInfo>,
    /// For a bidirectional connection: which strategy it is and how it was weighed.
    pub strategy: Option<Strategy>,
    /// For photon mapping and SPPM: the photons a density estimate at this hit found.
    pub photons: Option<PhotonGather>,
    /// Whitted's: the angles and Fresnel reflectance at this hit.
    pub optics: Option<Optics>,
    /// Whitted's: lights behind the surface at this hit, which get no shadow ray.
    pub lights_behind: Vec<String>,
}

/// The photons found around one point by a density estimate, and what they give.
#[derive(Clone, Debug, PartialEq)]
pub struct PhotonGather {
    /// Where they come from: "caustic map", "global map", or "SPPM photon pass".
    pub source: &'static str,
    /// The radius they were gathered in.
    pub radius: f64,
    pub photons: Vec<FoundPhoton>,
    /// The radiance toward the eye they give, linear sRGB.
    pub estimate: Color,
}

/// One photon of a [`PhotonGather`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FoundPhoton {
    pub position: Vec3,
    /// Unit direction it arrived from (toward where it came from).
    pub wi: Vec3,
    /// Its flux, linear sRGB.
    pub power: Color,
    pub distance: f64,
}

/// One connection strategy of bidirectional path tracing: s vertices from the light, t from
/// the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strategy {
    pub s: u32,
    pub t: u32,
    /// Its multiple importance sampling weight.
    pub mis_weight: f64,
    /// Its contribution before weighting, linear sRGB.
    pub unweighted: Color,
    /// Where a strategy of one camera vertex (t = 1) lands: a raster point, often in
    /// another pixel; `None`: this pixel's own sample.
    pub splat: Option<[f64; 2]>,
}

impl RayNode {
    pub fn new(
        parent: Option<usize>,
        kind: RayKind,
        depth: u32,
        origin: Vec3,
        direction: Vec3,
        weight: Color,
    ) -> Self {
        RayNode {
            parent,
            kind,
            depth,
            origin,
            direction: direction.normalized(),
            weight,
            object: None,
            material: None,
            distance: None,
            color: Color::BLACK,
            stops: Vec::new(),
            total_internal_reflection: false,
            shadow: None,
            strategy: None,
            photons: None,
            optics: None,
            lights_behind: Vec::new(),
        }
    }
}

/// Nodes in the order they were traced; children point to their parent.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RayTree {
    pub nodes: Vec<RayNode>,
    /// In spectral mode, the wavelengths (nm) of each camera sample traced, in order.
    pub wavelengths: Vec<[f64; 4]>,
}

impl RayTree {
    pub fn push(&mut self, node: RayNode) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    pub fn children(&self, parent: usize) -> impl Iterator<Item = usize> + '_ {
        self.nodes
            .iter()
            .enumerate()
            .filter(move |(_, n)| n.parent == Some(parent))
            .map(|(i, _)| i)
    }
}
