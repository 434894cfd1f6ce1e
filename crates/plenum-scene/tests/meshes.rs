//! The shared meshes load with the vertex and triangle counts their SOURCES.md lists, and
//! render on their own, framed by the default camera.

mod common;
use common::shared_data_present;
use plenum_core::geometry::Shape;
use plenum_core::render::{render, RenderSettings};
use plenum_scene::{load_scene, LoadedScene};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

fn meshes() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/meshes")
}

/// (vertices, triangles) over every mesh of a loaded scene.
fn counts(loaded: &LoadedScene) -> (usize, usize) {
    loaded
        .scene
        .geometry
        .primitives
        .iter()
        .fold((0, 0), |(v, t), p| match &p.shape {
            Shape::Mesh(m) => (v + m.vertex_count(), t + m.triangle_count()),
            _ => (v, t),
        })
}

fn renders_something(loaded: &LoadedScene) -> bool {
    let settings = RenderSettings {
        width: 40,
        height: 30,
        ..Default::default()
    };
    let film = render(
        &loaded.scene,
        &settings,
        &AtomicBool::new(false),
        &|_, _| {},
    )
    .film;
    let centre = film.get(20, 15);
    film.pixels().iter().flatten().all(|v| v.is_finite()) && centre != loaded.scene.background
}

#[test]
fn obj_models_load_with_their_counts() {
    if !shared_data_present() {
        return;
    }
    for (file, vertices, triangles) in [
        ("stanford-bunny.obj", 35_947, 69_451),
        ("dragon-100k.obj", 50_000, 100_000),
    ] {
        let loaded = load_scene(&meshes().join(file)).unwrap_or_else(|e| panic!("{e}"));
        // The OBJ reader keeps only vertices that faces use (the bunny has 1,113 unused).
        let (used, tris) = counts(&loaded);
        assert_eq!(tris, triangles, "{file}");
        assert!(
            used <= vertices && used * 10 > vertices * 9,
            "{file}: {used} vertices"
        );
        assert!(
            renders_something(&loaded),
            "{file}: the framed model is not in view"
        );
    }
}

#[test]
fn breakfast_room_ply_meshes_load() {
    if !shared_data_present() {
        return;
    }
    let dir = meshes().join("breakfast-room/models");
    let (mut vertices, mut triangles) = (0, 0);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert_eq!(files.len(), 52);
    for file in &files {
        let loaded = load_scene(file).unwrap_or_else(|e| panic!("{e}"));
        let (v, t) = counts(&loaded);
        vertices += v;
        triangles += t;
    }
    assert_eq!((vertices, triangles), (142_716, 269_536));
    let first = load_scene(&files[1]).unwrap();
    assert!(renders_something(&first));
}

/// A scene is read with the structures its render asks for, each built once: the scene's
/// and every mesh's are of that kind, and instances of one mesh still share it.
#[test]
fn scenes_are_read_with_the_structures_asked_for() {
    use plenum_core::accel::AccelKind;
    use std::sync::Arc;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/instances.toml");
    for kind in [
        AccelKind::Bvh,
        AccelKind::Grid,
        AccelKind::Octree,
        AccelKind::None,
    ] {
        let scene = plenum_scene::load_scene_with(&path, kind)
            .unwrap_or_else(|e| panic!("{e}"))
            .scene;
        assert_eq!(scene.geometry.accel_kind(), kind);
        let meshes: Vec<_> = scene
            .geometry
            .primitives
            .iter()
            .filter_map(|p| match &p.shape {
                Shape::Mesh(m) => Some(m.clone()),
                _ => None,
            })
            .collect();
        assert!(
            meshes.len() > 1,
            "{kind}: the scene places its gem more than once"
        );
        for m in &meshes {
            assert_eq!(m.accel_kind(), kind);
            assert!(Arc::ptr_eq(m, &meshes[0]), "{kind}: an instance was copied");
        }
    }
}
