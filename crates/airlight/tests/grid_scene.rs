//! `type = "grid"` media in scene files: a `.vol` file read, scaled and
//! placed; bad files and misplaced keys refused with the scene's line and
//! what is wrong; integrators that cannot render a grid say so.

use airlight::SceneFile;
use airlight::assets::vol::{self, VolGrid};
use airlight::integrator::{IntegratorDesc, IntegratorKind};
use glam::Vec3;
use std::path::Path;

const TAIL: &str = r#"
[[lights]]
type = "point"
position = [0, 4, 0]
intensity = 10
"#;

/// Two voxels along x, densities 1 and 3, in the box [0, 2]×[0, 1]×[0, 1].
fn two_voxels() -> VolGrid {
    VolGrid { resolution: [2, 1, 1], min: Vec3::ZERO, max: Vec3::new(2.0, 1.0, 1.0), values: vec![1.0, 3.0] }
}

fn scene_with(dir: &Path, medium: &str) -> Result<SceneFile, airlight::scene::SceneError> {
    SceneFile::from_toml_str(&format!("[medium]\n{medium}\n{TAIL}"), Some(dir))
}

#[test]
fn a_grid_is_read_scaled_and_placed() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("cloud.vol"), vol::write(&two_voxels())).unwrap();
    let file = scene_with(
        dir.path(),
        "type = \"grid\"\nfile = \"cloud.vol\"\nsigma_s = 0.5\ndensity_scale = 2\ntranslate = [10, 0, 0]",
    )
    .unwrap();
    let m = file.scene.medium().expect("a medium");
    // Voxel centres at x = 10.5 and 11.5 after the translation, doubled.
    assert_eq!(m.density_at(Vec3::new(10.5, 0.5, 0.5)), 2.0);
    assert_eq!(m.density_at(Vec3::new(11.0, 0.5, 0.5)), 4.0);
    assert_eq!(m.density_at(Vec3::new(11.9, 0.5, 0.5)), 6.0);
    assert_eq!(m.density_at(Vec3::new(0.5, 0.5, 0.5)), 0.0, "the box moved away");
    assert!(file.scene.files().iter().any(|f| f.ends_with("cloud.vol")), "the grid is listed among the files read");
    let e = IntegratorDesc::new(IntegratorKind::Analytic).build(&file.scene).err().expect("analytic refuses");
    assert!(e.to_string().contains("this scene's is a density grid: use raymarch"), "{e}");
    for kind in [IntegratorKind::Raymarch, IntegratorKind::Stochastic, IntegratorKind::Path] {
        assert!(IntegratorDesc::new(kind).build(&file.scene).is_ok(), "{kind}");
    }
}

#[test]
fn bad_grid_files_and_keys_are_scene_errors() {
    let dir = tempfile::tempdir().unwrap();
    let good = vol::write(&two_voxels());
    let mut nan = good.clone();
    nan[52..56].copy_from_slice(&f32::NAN.to_le_bytes());
    let mut negative = good.clone();
    negative[48..52].copy_from_slice(&(-1.0f32).to_le_bytes());
    let mut magic = good.clone();
    magic[..3].copy_from_slice(b"VOX");
    let mut huge = good.clone();
    for at in [8, 12, 16] {
        huge[at..at + 4].copy_from_slice(&100_000i32.to_le_bytes());
    }
    let mut big = good.clone();
    for at in [8, 12, 16] {
        big[at..at + 4].copy_from_slice(&1500i32.to_le_bytes());
    }
    for (name, bytes) in [
        ("nan.vol", nan),
        ("negative.vol", negative),
        ("magic.vol", magic),
        ("truncated.vol", good[..50].to_vec()),
        ("huge.vol", huge),
        ("big.vol", big),
        ("cloud.vdb", good.clone()),
    ] {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    let grid = |file: &str| format!("type = \"grid\"\nsigma_s = 1\nfile = \"{file}\"");
    let cases = [
        (grid("nan.vol"), 4, "voxel (1, 0, 0) holds NaN"),
        (grid("negative.vol"), 4, "voxel (0, 0, 0) holds -1"),
        (grid("magic.vol"), 4, "not a Mitsuba volume"),
        (grid("truncated.vol"), 4, "truncated: 50 bytes, where a 2×1×1 float32 grid takes 56"),
        (grid("huge.vol"), 4, "voxels, more than the 4294967296 read"),
        // 1500³ voxels fit the count but not the file (or memory).
        (grid("big.vol"), 4, "truncated"),
        (grid("missing.vol"), 4, "no file `missing.vol` in the scene's folder"),
        (grid("../x.vol"), 4, "must be a relative path"),
        (grid("cloud.vdb"), 4, "must be a Mitsuba volume ending in .vol"),
        ("type = \"grid\"\nsigma_s = 1".into(), 1, "medium (grid): a grid medium needs `file`"),
        (format!("{}\nbase = 2", grid("nan.vol")), 5, "`base` is a key of height or noise media, not of grid media"),
        ("sigma_s = 1\nfile = \"a.vol\"".into(), 3, "`file` is a key of grid media, not of homogeneous media"),
        (
            "type = \"height\"\nsigma_s = 1\ndensity_scale = 2".into(),
            4,
            "`density_scale` is a key of grid media, not of height media",
        ),
        (format!("{}\ndensity_scale = -1", grid("nan.vol")), 5, "medium.density_scale must be a finite number ≥ 0"),
        (format!("{}\nscale = 0", grid("nan.vol")), 5, "medium.scale must not be zero"),
        (
            "type = \"gird\"".into(),
            2,
            "unknown type `gird`; did you mean `grid`? media are homogeneous, height, grid or noise",
        ),
    ];
    for (medium, line, phrase) in cases {
        let e = match scene_with(dir.path(), &medium) {
            Ok(_) => panic!("accepted:\n{medium}"),
            Err(e) => e,
        };
        assert!(e.message.contains(phrase), "{medium}\n→ {e}\n(expected `{phrase}`)");
        assert_eq!(e.location.map(|l| l.0), Some(line), "{medium}\n→ {e}");
    }
}

#[test]
fn noise_fog_is_read_and_its_bad_keys_refused() {
    let dir = tempfile::tempdir().unwrap();
    let file = scene_with(
        dir.path(),
        "type = \"noise\"\nsigma_s = 0.5\nscale = [2, 1, 2]\noctaves = 5\ngain = 0.6\noffset = -0.1\nseed = 3\n\
         min = [-5, 0, -5]\nmax = [5, 3, 5]\nfalloff = 0.4",
    )
    .unwrap();
    let m = file.scene.medium().expect("a medium");
    assert_eq!(m.density_at(Vec3::new(0.0, 3.5, 0.0)), 0.0, "outside the box");
    let inside = (0..200).filter(|i| m.density_at(Vec3::new(*i as f32 * 0.05 - 5.0, 1.0, 0.3)) > 0.0).count();
    assert!(inside > 10 && inside < 190, "patchy: {inside} of 200 points have fog");
    let e = IntegratorDesc::new(IntegratorKind::Analytic).build(&file.scene).err().expect("analytic refuses");
    assert!(e.to_string().contains("noise fog"), "{e}");
    let noise = |extra: &str| format!("type = \"noise\"\nsigma_s = 1\n{extra}");
    let cases = [
        (noise("octaves = 0"), 4, "medium.octaves must be an integer from 1 to 12"),
        (noise("gain = 1.5"), 4, "medium.gain must lie in [0, 1]"),
        (noise("scale = [1, 0, 1]"), 4, "medium.scale must be finite and > 0"),
        (noise("seed = -1"), 4, "medium.seed must be an integer from 0"),
        (noise("min = [0, 0, 0]"), 4, "needs both min and max"),
        (noise("min = [0, 0, 0]\nmax = [1, 0, 1]"), 5, "must exceed medium.min"),
        (noise("base = 1"), 4, "medium.base needs a falloff"),
        (noise("file = \"a.vol\""), 4, "`file` is a key of grid media, not of noise media"),
        ("sigma_s = 1\noctaves = 3".into(), 3, "`octaves` is a key of noise media, not of homogeneous media"),
    ];
    for (medium, line, phrase) in cases {
        let e = match scene_with(dir.path(), &medium) {
            Ok(_) => panic!("accepted:\n{medium}"),
            Err(e) => e,
        };
        assert!(e.message.contains(phrase), "{medium}\n→ {e}\n(expected `{phrase}`)");
        assert_eq!(e.location.map(|l| l.0), Some(line), "{medium}\n→ {e}");
    }
}
