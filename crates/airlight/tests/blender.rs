//! A scene built in Blender and exported by Blender's own glTF exporter
//! (tools/blender_export_scene.py → scenes/models/blender_room.glb: a
//! camera, a point light, an emissive quad, a textured floor, a diffuse
//! box) renders like the same scene written by hand in TOML
//! (scenes/blender_room.toml), direct light only, within noise: Blender's
//! axes, light units, emission strength, texture and its coordinates, and
//! camera all arrive where the hand-written file puts them.

use airlight::SceneFile;
use airlight::film::Accumulator;
use airlight::integrator::{IntegratorDesc, IntegratorKind};
use airlight::light::Light;
use airlight::render::accumulate;
use std::path::PathBuf;

const WIDTH: u32 = 40;
const HEIGHT: u32 = 30;

fn scenes() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn render(file: &mut SceneFile) -> Accumulator {
    let s = file.scene.settings_mut();
    (s.film.width, s.film.height) = (WIDTH, HEIGHT);
    let integrator = IntegratorDesc::new(IntegratorKind::Direct).build(&file.scene).unwrap();
    accumulate(&file.scene, integrator.as_ref(), 0..256, 0..HEIGHT, &Default::default())
}

/// Mean over a block (channel by channel) and the variance of that mean.
fn block(acc: &Accumulator, xs: std::ops::Range<u32>, ys: std::ops::Range<u32>) -> ([f64; 3], [f64; 3]) {
    let (mut mean, mut var, mut n) = ([0.0; 3], [0.0; 3], 0.0);
    for y in ys {
        for x in xs.clone() {
            let p = acc.pixel(x, y).unwrap();
            let (m, v) = (p.mean().as_dvec3(), p.variance_of_mean());
            for c in 0..3 {
                mean[c] += m[c];
                var[c] += v[c];
            }
            n += 1.0;
        }
    }
    (mean.map(|m| m / n), var.map(|v| v / (n * n)))
}

#[test]
fn the_blender_export_renders_as_the_scene_written_by_hand() {
    let mut by_hand = SceneFile::load(&scenes().join("blender_room.toml")).unwrap();
    let mut exported = SceneFile::load(&scenes().join("models/blender_room.glb")).unwrap();
    // What the exporter wrote: 200 W → 200/(4π)·683 cd → 200/(4π) W/sr; the
    // emissive square as two triangle lights; the 4:3 camera.
    let point = exported.scene.lights().iter().find_map(|l| match l {
        Light::Point { position, intensity, .. } => Some((*position, *intensity)),
        _ => None,
    });
    let (position, intensity) = point.expect("a point light");
    assert!((position - glam::Vec3::new(1.5, 3.0, 1.0)).length() < 1e-5, "{position}");
    assert!((intensity.x - 200.0 / (4.0 * std::f32::consts::PI)).abs() < 1e-3, "{intensity}");
    assert_eq!(exported.scene.lights().iter().filter(|l| matches!(l, Light::Triangle { .. })).count(), 2);
    let s = exported.scene.settings();
    assert_eq!(s.film.height * 4, s.film.width * 3);

    let (a, b) = (render(&mut by_hand), render(&mut exported));
    // Blocks of 5×5 pixels: the floor's texture, the box, the lamp's
    // light on the floor, each where the other file has it.
    let mut lit = 0;
    for bx in 0..WIDTH / 5 {
        for by in 0..HEIGHT / 5 {
            let (xs, ys) = (bx * 5..bx * 5 + 5, by * 5..by * 5 + 5);
            let ((ma, va), (mb, vb)) = (block(&a, xs.clone(), ys.clone()), block(&b, xs.clone(), ys.clone()));
            for c in 0..3 {
                let allowed = 5.0 * (va[c] + vb[c]).sqrt() + 0.005 * ma[c].max(mb[c]);
                assert!(
                    (ma[c] - mb[c]).abs() <= allowed,
                    "pixels {xs:?}×{ys:?}, channel {c}: by hand {}, Blender's export {}, allowed ±{allowed}",
                    ma[c],
                    mb[c]
                );
            }
            lit += (ma[0] > 0.05) as usize;
        }
    }
    assert!(lit >= 24, "only {lit} of 48 blocks are lit");
}
