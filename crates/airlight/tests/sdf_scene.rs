//! Scene files with SDF objects, volume lights and the stochastic settings:
//! what they build, and the errors bad ones give (line and column).

use airlight::SceneFile;
use airlight::geometry::{Ray, Sdf, Shape};
use airlight::integrator::{IntegratorKind, Sampling};
use airlight::light::{Light, LightVolume};
use airlight::prelude::*;

const HEAD: &str = r#"
[render]
integrator = "stochastic"
sampling = "mis"
stratify = false

[materials.m]
albedo = 0.5
"#;

#[test]
fn sdf_objects_and_volume_lights_build_what_they_say() {
    let text = format!(
        "{HEAD}{}",
        r#"
[[objects]]
type = "sdf"
material = "m"
shape = "smooth_union"
blend = 0.2
children = [
  { shape = "box", min = [-1, 0, -1], max = [1, 1, 1] },
  { shape = "sphere", radius = 0.5, translate = [0, 1.2, 0] },
]
translate = [0, 0, 5]

[[lights]]
type = "box"
min = [-1, 3, -1]
max = [1, 4, 1]
intensity = 5

[[lights]]
type = "sphere"
volume = true
center = [0, 2, 0]
radius = 0.5
intensity = [1, 2, 3]
"#
    );
    let SceneFile { scene, integrator } = SceneFile::from_toml_str(&text, None).unwrap();
    assert_eq!(integrator.kind, IntegratorKind::Stochastic);
    assert_eq!(integrator.stochastic.sampling, Sampling::Mis);
    assert!(!integrator.stochastic.stratify);
    assert_eq!(
        scene.lights()[0],
        Light::Volume {
            shape: LightVolume::Box { min: vec3(-1.0, 3.0, -1.0), max: vec3(1.0, 4.0, 1.0) },
            intensity: Rgb::splat(5.0)
        }
    );
    assert_eq!(scene.lights()[1], Light::volume_sphere(vec3(0.0, 2.0, 0.0), 0.5, Rgb::new(1.0, 2.0, 3.0)));
    // The same field built in Rust: every ray hits both at the same place.
    let sdf = Sdf::SmoothUnion {
        children: vec![
            Sdf::Box { min: vec3(-1.0, 0.0, -1.0), max: vec3(1.0, 1.0, 1.0) },
            Sdf::Sphere { center: Vec3::ZERO, radius: 0.5 }
                .transformed(glam::Affine3A::from_translation(vec3(0.0, 1.2, 0.0))),
        ],
        blend: 0.2,
    }
    .transformed(glam::Affine3A::from_translation(vec3(0.0, 0.0, 5.0)));
    let built = SceneBuilder::new()
        .material("m", Material::diffuse(Rgb::splat(0.5)))
        .object(Shape::sdf(sdf.clone()), "m")
        .build()
        .unwrap();
    let mut hits = 0;
    for i in 0..200 {
        let (x, y) = ((i % 20) as f32 * 0.15 - 1.5, (i / 20) as f32 * 0.2 - 0.2);
        let ray = Ray::new(vec3(x, y, 0.0), Vec3::Z);
        let a = scene.geometry().intersect(&ray, f32::INFINITY).map(|h| h.t);
        let b = built.geometry().intersect(&ray, f32::INFINITY).map(|h| h.t);
        assert_eq!(a, b);
        if let Some(t) = a {
            hits += 1;
            assert!(sdf.distance(ray.at(t)).abs() < 1e-3);
        }
    }
    assert!(hits > 50);
}

#[test]
fn the_isometric_scene_renders_its_fog() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/sdf_isometric.toml");
    let SceneFile { mut scene, integrator } = SceneFile::load(&path).unwrap();
    assert_eq!(integrator.kind, IntegratorKind::Stochastic);
    assert!(matches!(scene.lights()[0], Light::Volume { shape: LightVolume::Box { .. }, .. }));
    let s = scene.settings_mut();
    (s.film.width, s.film.height, s.spp) = (32, 24, 4);
    let image = airlight::render(&scene, integrator.build(&scene).unwrap().as_ref(), &RenderObserver::none());
    // Every pixel sees the floor or a block through lit fog.
    assert!(image.pixels.iter().all(|p| p.min_element() > 0.0 && p.is_finite()));
}

/// (the object or light tables after HEAD, expected line (of the whole
/// text), a phrase the message must contain)
fn bad_cases() -> Vec<(&'static str, usize, &'static str)> {
    vec![
        (
            "[[objects]]\ntype = \"sdf\"\nmaterial = \"m\"\nradius = 1\n",
            10,
            "objects[0] (sdf) needs `shape`: sphere, box",
        ),
        (
            "[[objects]]\ntype = \"sdf\"\nmaterial = \"m\"\nshape = \"blob\"\n",
            13,
            "unknown shape `blob`; did you mean `box`?",
        ),
        ("[[objects]]\ntype = \"sdf\"\nmaterial = \"m\"\nshape = \"sphere\"\n", 10, "a sphere node needs `radius`"),
        (
            "[[objects]]\ntype = \"sdf\"\nmaterial = \"m\"\nshape = \"sphere\"\nradius = -2\n",
            14,
            "radius must be a positive",
        ),
        (
            "[[objects]]\ntype = \"sdf\"\nmaterial = \"m\"\nshape = \"box\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\nradius = 1\n",
            16,
            "`radius` is a key of sphere, capsule or cylinder nodes, not of box nodes",
        ),
        (
            "[[objects]]\ntype = \"sdf\"\nmaterial = \"m\"\nshape = \"union\"\nchildren = [\n  { shape = \"sphere\", radius = 1 },\n  { shape = \"torus\", major_radius = 1, minor_radius = 0 },\n]\n",
            16,
            "minor_radius must be a positive",
        ),
        (
            "[[objects]]\ntype = \"sdf\"\nmaterial = \"m\"\nshape = \"smooth_union\"\nchildren = [{ shape = \"sphere\", radius = 1 }]\n",
            10,
            "a smooth_union node needs `blend`",
        ),
        ("[[objects]]\ntype = \"sdf\"\nmaterial = \"m\"\nshape = \"union\"\nchildren = []\n", 14, "must not be empty"),
        (
            "[[objects]]\ntype = \"sdf\"\nmaterial = \"m\"\nshape = \"round_box\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\nrounding = 0.7\n",
            16,
            "rounding must lie in [0, 0.5]",
        ),
        (
            "[[objects]]\ntype = \"sphere\"\nmaterial = \"m\"\ncenter = [0, 0, 0]\nradius = 1\nblend = 1\n",
            15,
            "`blend` is a key of sdf objects, not of sphere objects",
        ),
        (
            "[[lights]]\ntype = \"box\"\nmin = [0, 0, 0]\nmax = [1, 0, 1]\nintensity = 1\n",
            13,
            "min must be less than max",
        ),
        ("[[lights]]\ntype = \"box\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n", 10, "a box light needs `intensity`"),
        (
            "[[lights]]\ntype = \"sphere\"\nvolume = true\ncenter = [0, 0, 0]\nradius = 1\nradiance = 1\n",
            15,
            "a volume sphere (volume = true) glows with `intensity` and takes no `radiance`",
        ),
        (
            "[[lights]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = 1\nvolume = true\n",
            14,
            "`volume` is a key of sphere lights, not of point lights",
        ),
    ]
}

#[test]
fn bad_sdf_and_light_tables_name_line_and_column() {
    // The render table has `sampling` at line 4: a bad value is caught there too.
    let bad_sampling = HEAD.replace("\"mis\"", "\"importance\"");
    let e = SceneFile::from_toml_str(&bad_sampling, None).unwrap_err();
    assert_eq!(e.location.map(|l| l.0), Some(4), "{e}");
    assert!(
        e.message.contains("render.sampling must be uniform, equiangular or mis, got the text \"importance\""),
        "{e}"
    );
    for (tables, line, phrase) in bad_cases() {
        let text = format!("{HEAD}\n{tables}");
        let e = match SceneFile::from_toml_str(&text, None) {
            Ok(_) => panic!("accepted:\n{text}"),
            Err(e) => e,
        };
        assert!(e.message.contains(phrase), "{text}\n→ {e}\n(expected `{phrase}`)");
        assert_eq!(e.location.map(|l| l.0), Some(line), "{text}\n→ {e}");
    }
}

#[test]
fn inline_child_errors_point_at_the_field() {
    let text = format!(
        "{HEAD}\n{}",
        "[[objects]]\ntype = \"sdf\"\nmaterial = \"m\"\nshape = \"union\"\nchildren = [{ shape = \"capsule\", a = [0, 0, 0], b = [0, 1, 0], radius = -1 }]\n"
    );
    let e = SceneFile::from_toml_str(&text, None).unwrap_err();
    let line = text.lines().nth(e.location.unwrap().0 - 1).unwrap();
    let col = e.location.unwrap().1;
    assert!(line[col - 1..].starts_with("-1"), "{e}: column {col} of `{line}`");
}
