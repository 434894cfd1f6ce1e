//! Intel Embree 3 as a reference intersector for `plenum bench --accel embree`, built only
//! with the `embree` feature (it links Debian's libembree-dev: `apt-get install
//! libembree-dev`, then `cargo build --release --features embree`). Embree builds its BVH
//! with its high-quality builder and traces with rtcIntersect1 / rtcOccluded1, one ray at a
//! time, from the same threads as Plenum's structures, so the two are measured alike.

use plenum_core::accel::Coherence;
use plenum_core::geometry::TriangleMesh;
use plenum_core::math::Ray;
use std::ffi::{c_char, c_void, CString};

type Device = *mut c_void;
type RtcScene = *mut c_void;
type Geometry = *mut c_void;

const GEOMETRY_TYPE_TRIANGLE: u32 = 0;
const BUFFER_TYPE_INDEX: u32 = 0;
const BUFFER_TYPE_VERTEX: u32 = 1;
const FORMAT_UINT3: u32 = 0x5003;
const FORMAT_FLOAT3: u32 = 0x9003;
const BUILD_QUALITY_HIGH: u32 = 2;
const INVALID_GEOMETRY_ID: u32 = u32::MAX;

/// `struct RTCIntersectContext` with RTC_MAX_INSTANCE_LEVEL_COUNT = 1 (Debian's build).
#[repr(C)]
struct IntersectContext {
    flags: u32,
    filter: *const c_void,
    inst_id: [u32; 1],
}

/// `struct RTCRay`.
#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcRay {
    org: [f32; 3],
    tnear: f32,
    dir: [f32; 3],
    time: f32,
    tfar: f32,
    mask: u32,
    id: u32,
    flags: u32,
}

/// `struct RTCHit`.
#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcHit {
    ng: [f32; 3],
    u: f32,
    v: f32,
    prim_id: u32,
    geom_id: u32,
    inst_id: [u32; 1],
}

/// `struct RTCRayHit`.
#[repr(C, align(16))]
struct RayHit {
    ray: RtcRay,
    hit: RtcHit,
}

#[link(name = "embree3")]
extern "C" {
    fn rtcNewDevice(config: *const c_char) -> Device;
    fn rtcReleaseDevice(device: Device);
    fn rtcNewScene(device: Device) -> RtcScene;
    fn rtcSetSceneBuildQuality(scene: RtcScene, quality: u32);
    fn rtcCommitScene(scene: RtcScene);
    fn rtcReleaseScene(scene: RtcScene);
    fn rtcNewGeometry(device: Device, kind: u32) -> Geometry;
    fn rtcSetNewGeometryBuffer(
        geometry: Geometry,
        kind: u32,
        slot: u32,
        format: u32,
        stride: usize,
        count: usize,
    ) -> *mut c_void;
    fn rtcCommitGeometry(geometry: Geometry);
    fn rtcAttachGeometry(scene: RtcScene, geometry: Geometry) -> u32;
    fn rtcReleaseGeometry(geometry: Geometry);
    fn rtcIntersect1(scene: RtcScene, context: *mut IntersectContext, rayhit: *mut RayHit);
    fn rtcOccluded1(scene: RtcScene, context: *mut IntersectContext, ray: *mut RtcRay);
}

/// A committed Embree scene of one triangle mesh.
pub struct EmbreeMesh {
    device: Device,
    scene: RtcScene,
    triangles: usize,
}

// Embree's committed scenes are safe to trace from many threads at once.
unsafe impl Send for EmbreeMesh {}
unsafe impl Sync for EmbreeMesh {}

impl EmbreeMesh {
    /// Builds Embree's BVH over the mesh's triangles, in the order the mesh was made from (so
    /// hits name triangles as the mesh file does), with `threads` build threads.
    pub fn build(mesh: &TriangleMesh, threads: usize) -> Result<EmbreeMesh, String> {
        // PLENUM_EMBREE_CONFIG adds to Embree's device configuration: ",verbose=2" prints
        // its builder's statistics, whose SAH cost `plenum bench` gives for Plenum's BVH.
        let extra = std::env::var("PLENUM_EMBREE_CONFIG").unwrap_or_default();
        let config =
            CString::new(format!("threads={threads}{extra}")).map_err(|e| e.to_string())?;
        // SAFETY: plain calls into the Embree C API with the buffers it hands out, sized as
        // asked; every handle is checked before use and released once.
        unsafe {
            let device = rtcNewDevice(config.as_ptr());
            if device.is_null() {
                return Err("Embree could not create a device".into());
            }
            let scene = rtcNewScene(device);
            rtcSetSceneBuildQuality(scene, BUILD_QUALITY_HIGH);
            let geometry = rtcNewGeometry(device, GEOMETRY_TYPE_TRIANGLE);
            // In the order the mesh was made from: hits then name triangles as its file does.
            let (positions, triangles) = mesh.indexed();
            let vertices = rtcSetNewGeometryBuffer(
                geometry,
                BUFFER_TYPE_VERTEX,
                0,
                FORMAT_FLOAT3,
                12,
                positions.len(),
            ) as *mut f32;
            let indices = rtcSetNewGeometryBuffer(
                geometry,
                BUFFER_TYPE_INDEX,
                0,
                FORMAT_UINT3,
                12,
                triangles.len(),
            ) as *mut u32;
            if vertices.is_null() || indices.is_null() {
                rtcReleaseGeometry(geometry);
                rtcReleaseScene(scene);
                rtcReleaseDevice(device);
                return Err("Embree could not allocate the mesh's buffers".into());
            }
            for (i, p) in positions.iter().enumerate() {
                for a in 0..3 {
                    *vertices.add(3 * i + a) = p[a] as f32;
                }
            }
            for (i, t) in triangles.iter().enumerate() {
                for (a, &v) in t.iter().enumerate() {
                    *indices.add(3 * i + a) = v;
                }
            }
            rtcCommitGeometry(geometry);
            rtcAttachGeometry(scene, geometry);
            rtcReleaseGeometry(geometry);
            rtcCommitScene(scene);
            Ok(EmbreeMesh {
                device,
                scene,
                triangles: triangles.len(),
            })
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles
    }

    fn ray(ray: &Ray, t_max: f64) -> RtcRay {
        RtcRay {
            org: [0, 1, 2].map(|a| ray.origin[a] as f32),
            tnear: 0.0,
            dir: [0, 1, 2].map(|a| ray.direction[a] as f32),
            time: 0.0,
            tfar: t_max.min(f32::MAX as f64) as f32,
            mask: u32::MAX,
            id: 0,
            flags: 0,
        }
    }

    /// A context hinting at `coherence` (RTC_INTERSECT_CONTEXT_FLAG_COHERENT or its
    /// absence, INCOHERENT), as Plenum's any-hit walk is given.
    fn context(coherence: Coherence) -> IntersectContext {
        IntersectContext {
            flags: match coherence {
                Coherence::Coherent => 1,
                Coherence::Incoherent => 0,
            },
            filter: std::ptr::null(),
            inst_id: [INVALID_GEOMETRY_ID],
        }
    }

    /// The nearest hit in (0, t_max): distance and triangle.
    pub fn closest(&self, ray: &Ray, t_max: f64) -> Option<(f64, u32)> {
        let mut rh = RayHit {
            ray: EmbreeMesh::ray(ray, t_max),
            hit: RtcHit {
                ng: [0.0; 3],
                u: 0.0,
                v: 0.0,
                prim_id: INVALID_GEOMETRY_ID,
                geom_id: INVALID_GEOMETRY_ID,
                inst_id: [INVALID_GEOMETRY_ID],
            },
        };
        let mut context = EmbreeMesh::context(Coherence::Incoherent);
        // SAFETY: a committed scene, and a ray-hit laid out and aligned as Embree's.
        unsafe { rtcIntersect1(self.scene, &mut context, &mut rh) };
        (rh.hit.geom_id != INVALID_GEOMETRY_ID).then_some((rh.ray.tfar as f64, rh.hit.prim_id))
    }

    /// Whether anything is hit in (0, t_max), for one of `coherence` rays.
    pub fn occluded(&self, ray: &Ray, t_max: f64, coherence: Coherence) -> bool {
        let mut r = EmbreeMesh::ray(ray, t_max);
        let mut context = EmbreeMesh::context(coherence);
        // SAFETY: as for `closest`; Embree sets tfar to −∞ on a hit.
        unsafe { rtcOccluded1(self.scene, &mut context, &mut r) };
        r.tfar == f32::NEG_INFINITY
    }
}

impl Drop for EmbreeMesh {
    fn drop(&mut self) {
        // SAFETY: the handles were made in `build` and are released once, here.
        unsafe {
            rtcReleaseScene(self.scene);
            rtcReleaseDevice(self.device);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plenum_core::sampling::{uniform_sphere, Rng};

    /// Embree and Plenum's BVH agree on the bunny, ray by ray: 20,000 rays between random
    /// points of its bounding sphere (seed 0x5EED0004) hit the same triangle at the same
    /// distance (within 1e-4 relative, Embree's single precision), or both miss, or differ
    /// only where a ray grazes an edge that one of them counts (at most 1 in 2,000).
    #[test]
    fn embree_agrees_with_the_bvh_on_the_bunny() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../../shared/data/meshes/stanford-bunny.obj");
        let mesh = plenum_scene::load_mesh(&path)
            .unwrap()
            .with_accel(plenum_core::accel::AccelKind::Bvh);
        let embree = EmbreeMesh::build(&mesh, 2).unwrap();
        let (centre, radius) = mesh.bounds().bounding_sphere();
        let mut rng = Rng::new(0x5EED0004, 0);
        let mut disagree = 0;
        let n = 20_000;
        for _ in 0..n {
            let mut point = || centre + uniform_sphere([rng.uniform(), rng.uniform()]) * radius;
            let (from, to) = (point(), point());
            let ray = Ray::new(from, to - from);
            let ours = mesh
                .intersect(&ray, 1.0)
                .map(|h| (h.t, mesh.source_triangle(h.part)));
            let theirs = embree.closest(&ray, 1.0);
            let same = match (ours, theirs) {
                (None, None) => true,
                (Some((t0, p0)), Some((t1, p1))) => {
                    p0 == p1 || (t0 - t1).abs() <= 1e-4 * t0.max(t1)
                }
                _ => false,
            };
            disagree += usize::from(!same);
            assert_eq!(
                embree.occluded(&ray, 1.0, Coherence::Incoherent),
                theirs.is_some(),
                "Embree's any-hit and closest-hit differ"
            );
        }
        assert!(disagree * 2000 <= n, "{disagree} of {n} rays disagree");
    }
}
