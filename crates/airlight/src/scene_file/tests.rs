use super::*;
use crate::prelude::*;
use crate::render::{RenderObserver, render};
use glam::{Affine3A, Vec2};

const SCENE: &str = r#"
[render]
width = 24
height = 16
spp = 2
integrator = "direct"

[camera]
position = [0, 2, -6]
look_at = [0, 1, 0]
fov = 40

[materials.floor]
type = "checker"
albedo = 0.8
albedo2 = 0.2
scale = 1

[materials.ball]
type = "phong"
albedo = [0.2, 0.4, 0.9]
specular = 0.1
exponent = 20

[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
translate = [0, 1, 0]
material = "ball"

[[lights]]
type = "spot"
position = [0, 5, 0]
look_at = [0, 0, 0]
intensity = 40
cone_angle = 30
falloff_start = 25
"#;

#[test]
fn file_and_builder_make_the_same_scene() {
    let from_file = SceneFile::from_toml_str(SCENE, None).unwrap();
    let built = SceneBuilder::new()
        .size(24, 16)
        .with_settings(|s| s.spp = 2)
        .camera(Camera::look_at(vec3(0.0, 2.0, -6.0), vec3(0.0, 1.0, 0.0), Vec3::Y, 40.0))
        .material("floor", Material::checker(Rgb::splat(0.8), Rgb::splat(0.2), 1.0))
        .material("ball", Material::phong(Rgb::new(0.2, 0.4, 0.9), Rgb::splat(0.1), 20.0))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "floor")
        .object_transformed(Shape::sphere(Vec3::ZERO, 1.0), Affine3A::from_translation(Vec3::Y), "ball")
        .light(Light::spot(vec3(0.0, 5.0, 0.0), Vec3::ZERO, Rgb::splat(40.0), 30.0, 25.0))
        .build()
        .unwrap();
    assert_eq!(from_file.integrator, IntegratorDesc::new(IntegratorKind::Direct));
    let from_file = from_file.scene;
    assert_eq!(from_file.settings(), built.settings());
    assert_eq!(from_file.lights(), built.lights());
    let integrator = IntegratorDesc::default().build(&built).unwrap();
    let a = render(&from_file, integrator.as_ref(), &RenderObserver::none());
    let b = render(&built, integrator.as_ref(), &RenderObserver::none());
    assert!(a == b, "file and builder render differently");
    assert!(a.mean().z > 0.0);
}

#[test]
fn fog_without_an_integrator_named_is_ray_marched() {
    let file = SceneFile::from_toml_str("[medium]\nsigma_s = 0.1\n", None).unwrap();
    assert_eq!(file.integrator.kind, IntegratorKind::Raymarch);
    assert_eq!(SceneFile::from_toml_str("", None).unwrap().integrator.kind, IntegratorKind::Direct);
}

#[test]
fn the_fingerprint_follows_every_value_that_changes_the_image() {
    let file = || SceneFile::from_toml_str(SCENE, None).unwrap();
    let a = file();
    let print = |f: &SceneFile| super::fingerprint(&f.scene, &f.integrator);
    assert_eq!(print(&a), print(&file()), "the same scene, the same fingerprint");
    assert_eq!(print(&a).len(), 16);
    let mut spp = file();
    spp.scene.settings_mut().spp = 3;
    let mut light = file();
    let moved: Vec<Light> = light.scene.lights().iter().map(|l| l.moved_to(vec3(0.0, 5.0, 0.001))).collect();
    light.scene.set_lights(&moved);
    let mut steps = file();
    steps.integrator.raymarch.steps += 1;
    for (what, other) in [("spp", spp), ("a light", light), ("an option", steps)] {
        assert_ne!(print(&a), print(&other), "{what} changed");
    }
}

#[test]
fn the_fingerprint_follows_every_number_of_a_mesh() {
    // A mesh's numbers enter the fingerprint as a checksum of their bits
    // (not as formatted text): each change below, down to the sign of a
    // zero, must change it.
    let positions = vec![vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 1.0, 0.0)];
    let mesh = |positions: Vec<Vec3>, triangles: Vec<[u32; 3]>, uvs: Vec<Vec2>| {
        let scene = SceneBuilder::new()
            .material("grey", Material::diffuse(Rgb::splat(0.5)))
            .object(Shape::Mesh { positions, triangles, uvs, normals: Vec::new() }, "grey")
            .build()
            .unwrap();
        super::fingerprint(&scene, &IntegratorDesc::default())
    };
    let triangles = vec![[0, 1, 2], [1, 3, 2]];
    let a = mesh(positions.clone(), triangles.clone(), Vec::new());
    assert_eq!(a, mesh(positions.clone(), triangles.clone(), Vec::new()), "the same mesh, the same fingerprint");
    let mut signed_zero = positions.clone();
    signed_zero[0].z = -0.0;
    let mut nudged = positions.clone();
    nudged[3].y = f32::from_bits(1.0f32.to_bits() + 1);
    let swapped = vec![[1, 3, 2], [0, 1, 2]];
    let uvs = |v: f32| vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::new(1.0, v)];
    // Each print differs from every other one.
    let prints = [
        ("the mesh", a),
        ("a zero's sign", mesh(signed_zero, triangles.clone(), Vec::new())),
        ("a position by one ulp", mesh(nudged, triangles.clone(), Vec::new())),
        ("the triangles' order", mesh(positions.clone(), swapped, Vec::new())),
        ("texture coordinates added", mesh(positions.clone(), triangles.clone(), uvs(1.0))),
        ("a texture coordinate", mesh(positions.clone(), triangles.clone(), uvs(0.5))),
    ];
    for (i, (what, print)) in prints.iter().enumerate() {
        for (other, other_print) in &prints[..i] {
            assert_ne!(print, other_print, "{what} against {other}");
        }
    }
}

#[test]
fn a_medium_from_command_line_options_follows_the_scene_file_rules() {
    let m = medium_from_options("sigma_s=0.05,sigma_a=0.01,g=0.3").unwrap();
    assert_eq!(m, Medium::homogeneous(Vec3::splat(0.01), Vec3::splat(0.05), 0.3));
    let m = medium_from_options(r#"type = "height", sigma_s = [0.1, 0.2, 0.3], falloff = 2"#).unwrap();
    assert_eq!(m, Medium::height(Vec3::ZERO, Vec3::new(0.1, 0.2, 0.3), 0.0, 0.0, 2.0));
    // The same text in a scene file's [medium] gives the same medium.
    let desc = parse("[medium]\nsigma_s = 0.05\nsigma_a = 0.01\ng = 0.3\n").unwrap();
    let scene =
        build(&desc, "[medium]\nsigma_s = 0.05\nsigma_a = 0.01\ng = 0.3\n", &AssetPath::new(None, &[])).unwrap();
    assert_eq!(scene.medium(), Some(&medium_from_options("sigma_s=0.05,sigma_a=0.01,g=0.3").unwrap()));
    for (options, message) in [
        ("g = 1", "medium.g must lie strictly between -1 and 1, got 1"),
        ("sigma_s = -1", "medium.sigma_s must be finite and ≥ 0, got [-1, -1, -1]"),
        ("falloff = 1", "`falloff` is a key of height or noise media, not of homogeneous media"),
        ("density = 1", "`density` is not a key of homogeneous media; they take sigma_a, sigma_s, g"),
        ("type = \"grid\", file = \"a.vol\", density_scael = 2", "did you mean `density_scale`?"),
    ] {
        let e = medium_from_options(options).unwrap_err();
        assert!(e.contains(message), "{options}: {e}");
    }
}

/// The text of docs/scene-format.md from the heading `## {heading}` to
/// the next `## `.
fn format_section(heading: &str) -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/scene-format.md");
    let text = std::fs::read_to_string(path).expect("docs/scene-format.md");
    let start = text.find(&format!("\n## {heading}\n")).unwrap_or_else(|| panic!("no section {heading}"));
    let rest = &text[start + 1..];
    let end = rest[3..].find("\n## ").map_or(rest.len(), |i| i + 3);
    rest[..end].to_string()
}

/// Every type of a family and every key its struct declares is named in
/// the family's section of the scene format: a key added to a type is
/// documented where users look for it.
fn documented<T: tables::Tagged>(heading: &str) -> Vec<String> {
    let section = format_section(heading);
    let named = |word: &str| section.contains(&format!("`{word}`")) || section.contains(&format!("`{word} = "));
    let mut missing = Vec::new();
    let shared = tables::keys_of::<T::Shared>();
    for name in T::TYPES {
        if !named(name) {
            missing.push(format!("{heading}: type `{name}`"));
        }
        for key in T::keys(name).iter().chain(shared) {
            if !named(key) && !missing.iter().any(|m| m.ends_with(&format!("key `{key}`"))) {
                missing.push(format!("{heading}: key `{key}`"));
            }
        }
    }
    missing
}

#[test]
fn the_scene_format_names_every_type_and_key() {
    let missing: Vec<String> = [
        documented::<desc::CameraDesc>("`[camera]`"),
        documented::<desc::MediumDesc>("`[medium]`"),
        documented::<desc::MaterialDesc>("`[materials.NAME]`"),
        documented::<desc::ObjectDesc>("`[[objects]]`"),
        documented::<desc::SdfNodeDesc>("`[[objects]]`"),
        documented::<desc::LightDesc>("`[[lights]]`"),
    ]
    .concat();
    assert!(missing.is_empty(), "not in docs/scene-format.md:\n{}", missing.join("\n"));
}
