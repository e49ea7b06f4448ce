use super::*;
use crate::scene::from_toml_str;

const CORNELL: &str = include_str!("../../../../scenes/cornell_box.toml");

fn cornell(patch_size: f32) -> Scene {
    let mut scene = from_toml_str(CORNELL, None).unwrap();
    scene.settings.patch_size = Some(patch_size);
    scene.settings.bounces = 1;
    scene
}

/// Mean over patches of |E_h − E_full| / E_full (green channel) for
/// patches with E_full above 1% of the mean.
fn hierarchical_error(scene: &Scene, full: &Radiosity, threshold: f32) -> (f64, usize) {
    let mut params = CompileParams::for_scene(scene);
    params.link_threshold = threshold;
    let mut h = Radiosity::compile_with(scene, params);
    h.update(scene);
    assert_eq!(h.patches(), full.patches());
    let e_full = full.indirect_irradiance();
    let mean: f64 = e_full.iter().map(|e| e.y as f64).sum::<f64>() / e_full.len() as f64;
    let mut sum = 0.0;
    let mut count = 0;
    for (a, b) in h.indirect_irradiance().iter().zip(e_full) {
        if b.y as f64 > 0.01 * mean {
            sum += ((a.y - b.y) as f64 / b.y as f64).abs();
            count += 1;
        }
    }
    (sum / count as f64, h.stats().links)
}

#[test]
#[ignore]
fn explore_thresholds() {
    let scene = cornell(0.3);
    let mut params = CompileParams::for_scene(&scene);
    params.link_threshold = 0.0;
    let mut full = Radiosity::compile_with(&scene, params);
    full.update(&scene);
    eprintln!(
        "patches {} full links {}",
        full.stats().patches,
        full.stats().links
    );
    for t in [0.002, 0.005, 0.01, 0.02, 0.05, 0.1] {
        let (err, links) = hierarchical_error(&scene, &full, t);
        eprintln!("threshold {t}: mean rel err {err:.4}, links {links}");
    }
}
