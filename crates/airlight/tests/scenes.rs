//! Every example scene in scenes/ loads and renders (small, few samples).

use airlight::prelude::*;

#[test]
fn every_example_scene_renders() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let SceneFile { mut scene, mut integrator } = SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let s = scene.settings_mut();
        (s.film.width, s.film.height, s.spp) = (40, 30, 1);
        integrator.raymarch.steps = 16;
        let integrator = integrator.build(&scene).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let image = airlight::render(&scene, integrator.as_ref(), &RenderObserver::none());
        let mean = image.mean();
        assert!(mean.is_finite() && mean.max_element() > 0.0, "{}: mean {mean}", path.display());
        count += 1;
    }
    assert!(count >= 7, "only {count} scenes");
}
