//! Every `.ray` file in ../shared/data/ray loads (both dialects), places one object for each
//! primitive the file writes, and renders a plausible picture.

mod common;
use common::shared_data_present;
use plenum_core::render::{render, RenderSettings};
use plenum_core::sampling::PixelSampler;
use plenum_scene::load_scene;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn ray_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            ray_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "ray") {
            out.push(path);
        }
    }
}

/// Primitives written in the file: shape keywords followed by `{`, outside comments.
fn primitives_written(text: &str) -> usize {
    let mut clean = String::new();
    let mut rest = text;
    while let Some(i) = rest.find('/') {
        clean.push_str(&rest[..i]);
        let tail = &rest[i..];
        if let Some(after) = tail.strip_prefix("//") {
            rest = after.find('\n').map_or("", |j| &after[j..]);
        } else if let Some(after) = tail.strip_prefix("/*") {
            rest = after.find("*/").map_or("", |j| &after[j + 2..]);
        } else {
            clean.push('/');
            rest = &tail[1..];
        }
    }
    clean.push_str(rest);
    let shapes = [
        "sphere", "box", "square", "cylinder", "cone", "trimesh", "polymesh",
    ];
    let spaced: String = clean
        .chars()
        .map(|c| if "(),;=".contains(c) { ' ' } else { c })
        .collect::<String>()
        .replace('{', " { ");
    let tokens: Vec<&str> = spaced.split_whitespace().collect();
    tokens
        .windows(2)
        .filter(|w| shapes.contains(&w[0]) && w[1] == "{")
        .count()
}

#[test]
fn every_course_file_loads_and_renders() {
    if !shared_data_present() {
        return;
    }
    let mut files = Vec::new();
    ray_files(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/ray"),
        &mut files,
    );
    files.sort();
    assert!(files.len() >= 70, "found {} files", files.len());
    for file in &files {
        let loaded = load_scene(file).unwrap_or_else(|e| panic!("{e}"));
        let scene = &loaded.scene;
        let text = std::fs::read_to_string(file).unwrap();
        let objects: HashSet<&String> = scene.geometry.names.iter().collect();
        assert_eq!(
            objects.len(),
            primitives_written(&text),
            "{}",
            file.display()
        );
        let b = scene.geometry.bounds();
        assert!(
            !b.is_empty() && b.min.is_finite() && b.max.is_finite(),
            "{}: {b:?}",
            file.display()
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
            "{}: NaN",
            file.display()
        );
        // Some course scenes are dim by design: require a lit pixel and no blow-out.
        let mean = pixels.iter().flatten().sum::<f32>() / (pixels.len() * 3) as f32;
        let brightest = pixels.iter().flatten().fold(0.0f32, |a, &b| a.max(b));
        assert!(
            brightest > 0.05 && mean < 5.0,
            "{}: mean {mean}, max {brightest}",
            file.display()
        );
    }
}
