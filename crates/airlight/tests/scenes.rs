//! Every example scene in scenes/ loads and renders (small, few samples).

use airlight::prelude::*;
use airlight::render::try_render;

#[test]
fn every_example_scene_renders() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let mut scene = airlight::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let s = &mut scene.settings;
        (s.width, s.height, s.spp, s.steps) = (40, 30, 1, 16);
        let image = try_render(&scene, &RenderObserver::none()).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mean = image.mean();
        assert!(mean.is_finite() && mean.max_element() > 0.0, "{}: mean {mean}", path.display());
        count += 1;
    }
    assert!(count >= 7, "only {count} scenes");
}
