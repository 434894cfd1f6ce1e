//! Every NFF file of the Standard Procedural Databases in ../shared/data/nff loads with the
//! record counts its SOURCES.md lists, and renders a plausible picture.

mod common;
use common::shared_data_present;
use plenum_core::geometry::Shape;
use plenum_core::render::{render, RenderSettings};
use plenum_core::sampling::PixelSampler;
use plenum_scene::load_scene;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

fn shared(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/nff")
        .join(name)
}

/// (file, lights, spheres, cones, polygons, patches, surfaces) from SOURCES.md.
const FILES: [(&str, usize, usize, usize, usize, usize, usize); 14] = [
    ("balls3.nff", 3, 820, 0, 1, 0, 2),
    ("balls4.nff", 3, 7381, 0, 1, 0, 2),
    ("gears.nff", 5, 0, 0, 9345, 0, 65),
    ("mount.nff", 1, 4, 0, 8192, 0, 2),
    ("rings.nff", 3, 4200, 4200, 1, 0, 841),
    ("tetra.nff", 1, 0, 0, 4096, 0, 1),
    ("tree.nff", 7, 4095, 4095, 1, 0, 2),
    ("teapot.nff", 2, 0, 0, 36, 2256, 3),
    ("teapot12.nff", 2, 0, 0, 144, 9120, 3),
    ("lattice.nff", 6, 2197, 6084, 0, 0, 8281),
    ("shells.nff", 1, 5761, 0, 0, 0, 1),
    ("jacks.nff", 1, 6, 3, 0, 0, 1),
    ("jacks4.nff", 1, 3510, 1755, 0, 0, 1),
    ("sombrero.nff", 1, 0, 0, 1922, 0, 1),
];

#[test]
fn every_spd_file_loads_with_its_counts_and_renders() {
    if !shared_data_present() {
        return;
    }
    for (file, lights, spheres, cones, polygons, patches, surfaces) in FILES {
        let loaded = load_scene(&shared(file)).unwrap_or_else(|e| panic!("{e}"));
        let scene = &loaded.scene;
        let count = |f: fn(&Shape) -> usize| {
            scene
                .geometry
                .primitives
                .iter()
                .map(|p| f(&p.shape))
                .sum::<usize>()
        };
        // The file's lights; the background is one more, for the physically based methods.
        let given = scene.lights.len() - usize::from(scene.lights.background.is_some());
        assert_eq!(given, lights, "{file}: lights");
        assert_eq!(
            count(|s| matches!(s, Shape::Sphere(_)) as usize),
            spheres,
            "{file}: spheres"
        );
        assert_eq!(
            count(|s| matches!(s, Shape::Cone(_)) as usize),
            cones,
            "{file}: cones"
        );
        assert_eq!(
            count(|s| matches!(s, Shape::Polygon(_)) as usize),
            polygons,
            "{file}: polygons"
        );
        let triangles = count(|s| match s {
            Shape::Mesh(m) => m.triangle_count(),
            _ => 0,
        });
        assert_eq!(
            triangles, patches,
            "{file}: patches (all triangles in the SPD)"
        );
        assert_eq!(scene.materials.len(), surfaces, "{file}: surfaces");
        let b = scene.geometry.bounds();
        assert!(
            !b.is_empty() && b.min.is_finite() && b.max.is_finite(),
            "{file}: bounds {b:?}"
        );
        let settings = RenderSettings {
            width: 48,
            height: 48,
            sampler: PixelSampler::grid_for(1),
            ..Default::default()
        };
        let film = render(scene, &settings, &AtomicBool::new(false), &|_, _| {}).film;
        let pixels = film.pixels();
        assert!(
            pixels.iter().flatten().all(|v| v.is_finite()),
            "{file}: NaN"
        );
        let mean = pixels.iter().flatten().sum::<f32>() / (pixels.len() * 3) as f32;
        assert!(mean > 0.02 && mean < 2.0, "{file}: mean {mean}");
    }
}

#[test]
fn corner_rays_average_to_the_pixel() {
    if !shared_data_present() {
        return;
    }
    let mut loaded = load_scene(&shared("jacks.nff")).unwrap();
    loaded.scene.camera.fov_degrees = loaded.defaults.nff_angle.unwrap();
    let mut settings = RenderSettings {
        width: 16,
        height: 16,
        corners: true,
        ..Default::default()
    };
    let output = render(
        &loaded.scene,
        &settings,
        &AtomicBool::new(false),
        &|_, _| {},
    );
    // (W+1)·(H+1) eye rays, as the SPD procedure counts them.
    assert_eq!(output.counts.camera, 17 * 17);
    assert_eq!((output.film.width, output.film.height), (16, 16));
    // The same pixel traced on its own: the mean of its four corner rays.
    let (_, alone) = plenum_core::render::trace_pixel(&loaded.scene, &settings, 7, 9);
    let shared = output.film.get(7, 9);
    assert!((alone.r - shared.r).abs() < 1e-6 && (alone.b - shared.b).abs() < 1e-6);
    settings.corners = false;
    let centres = render(
        &loaded.scene,
        &settings,
        &AtomicBool::new(false),
        &|_, _| {},
    );
    assert_eq!(centres.counts.camera, 16 * 16);
}

/// The acceleration structure changes the time, never the picture: scenes of spheres,
/// cones, polygons and meshes render bit for bit the same with a grid, an octree and brute
/// force as with the BVH.
#[test]
fn every_accelerator_renders_the_same_image() {
    if !shared_data_present() {
        return;
    }
    use plenum_core::accel::AccelKind;
    let settings = RenderSettings {
        width: 40,
        height: 40,
        sampler: PixelSampler::grid_for(1),
        ..Default::default()
    };
    for file in [
        "balls3.nff",
        "rings.nff",
        "jacks.nff",
        "teapot.nff",
        "mount.nff",
    ] {
        let images: Vec<Vec<[f32; 3]>> = AccelKind::ALL
            .into_iter()
            .map(|kind| {
                let scene = load_scene(&shared(file))
                    .unwrap_or_else(|e| panic!("{e}"))
                    .scene
                    .with_accel(kind);
                assert_eq!(scene.geometry.accel_kind(), kind);
                render(&scene, &settings, &AtomicBool::new(false), &|_, _| {})
                    .film
                    .pixels()
                    .to_vec()
            })
            .collect();
        for (kind, image) in AccelKind::ALL.iter().zip(&images).skip(1) {
            assert!(image == &images[0], "{file}: {kind} differs from bvh");
        }
    }
}
