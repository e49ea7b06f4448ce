//! Sharded rendering is exact: parts of a render (ranges of samples, bands
//! of rows) merged give the very image one render gives, bit for bit, for
//! any split, because each sample's random stream is keyed by (seed, pixel,
//! sample number) and the accumulator's sums are exact integers.

use airlight::film::partial::{Partial, PartialHeader, merge, piece};
use airlight::integrator::IntegratorDesc;
use airlight::prelude::*;
use airlight::render::{RenderObserver, accumulate, render};

/// Spheres on a floor under a spot light in height fog (scenes/
/// spheres_spot_fog.toml), small.
fn scene() -> SceneFile {
    let mut file = SceneFile::from_toml_str(include_str!("../../../scenes/spheres_spot_fog.toml"), None).unwrap();
    let s = file.scene.settings_mut();
    (s.film.width, s.film.height, s.spp) = (20, 14, 7);
    file.integrator.raymarch.steps = 16;
    file
}

fn header(scene: &Scene, samples: std::ops::Range<u64>, rows: std::ops::Range<u32>) -> PartialHeader {
    let s = scene.settings();
    PartialHeader {
        version: "test".into(),
        scene: "0".into(),
        seed: s.seed,
        width: s.film.width,
        height: s.film.height,
        spp: s.spp,
        samples,
        rows,
        frame: None,
        exposure: s.film.exposure,
        tonemap: s.film.tonemap,
    }
}

#[test]
fn any_split_into_shards_and_tiles_merges_to_the_single_render_bit_for_bit() {
    let file = scene();
    let scene = &file.scene;
    let (spp, height) = (scene.settings().spp as u64, scene.settings().film.height as u64);
    for kind in [IntegratorKind::Path, IntegratorKind::Stochastic, IntegratorKind::Raymarch] {
        let integrator = IntegratorDesc { kind, ..file.integrator }.build(scene).unwrap();
        let whole = render(scene, integrator.as_ref(), &RenderObserver::none());
        assert!(whole.mean().max_element() > 0.0);
        for shards in [1u64, 2, 3, 4, 7] {
            for tiles in [1u64, 3] {
                let mut parts = Vec::new();
                for k in 0..shards {
                    for t in 0..tiles {
                        let (samples, rows) = (piece(spp, k, shards), piece(height, t, tiles));
                        let rows = rows.start as u32..rows.end as u32;
                        let sums =
                            accumulate(scene, integrator.as_ref(), samples.clone(), rows.clone(), &Default::default());
                        parts.push((format!("{k}/{t}"), Partial { header: header(scene, samples, rows), sums }));
                    }
                }
                let (_, merged) = merge(&parts).unwrap();
                assert!(merged.image() == whole, "{kind}: {shards} shards × {tiles} tiles differ from one render");
            }
        }
    }
}

#[test]
fn parts_survive_their_files_exactly() {
    let file = scene();
    let scene = &file.scene;
    let integrator = file.integrator.build(scene).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut parts = Vec::new();
    for k in 0..3 {
        let samples = piece(scene.settings().spp as u64, k, 3);
        let rows = 0..scene.settings().film.height;
        let sums = accumulate(scene, integrator.as_ref(), samples.clone(), rows.clone(), &Default::default());
        let path = dir.path().join(format!("part{k}.exr"));
        Partial { header: header(scene, samples, rows), sums }.write(&path).unwrap();
        parts.push((path.display().to_string(), Partial::read(&path).unwrap()));
    }
    let (_, merged) = merge(&parts).unwrap();
    assert!(merged.image() == render(scene, integrator.as_ref(), &Default::default()));
}
