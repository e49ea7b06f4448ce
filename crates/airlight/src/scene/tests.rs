use super::*;
use crate::render::{RenderObserver, render};
use glam::vec3;

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
    let from_file = from_toml_str(SCENE, None).unwrap();
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
    assert_eq!(from_file.settings, built.settings);
    assert_eq!(from_file.lights, built.lights);
    let a = render(&from_file, &RenderObserver::none());
    let b = render(&built, &RenderObserver::none());
    assert!(a == b, "file and builder render differently");
    assert!(a.mean().z > 0.0);
}

#[test]
fn builder_rejects_unknown_materials_and_empty_images() {
    let unknown = SceneBuilder::new().object(Shape::sphere(Vec3::ZERO, 1.0), "nope").build();
    assert!(unknown.unwrap_err().message.contains("unknown material `nope`"));
    let empty = SceneBuilder::new().size(0, 10).build();
    assert!(empty.unwrap_err().message.contains("at least 1×1"));
}

#[test]
fn fog_without_an_integrator_named_is_ray_marched() {
    let scene = from_toml_str("[medium]\nsigma_s = 0.1\n", None).unwrap();
    assert_eq!(scene.settings.integrator, IntegratorKind::Raymarch);
    assert_eq!(from_toml_str("", None).unwrap().settings.integrator, IntegratorKind::Direct);
}
