//! Lights with a finite range are culled without changing the image.

use airlight::integrator::Direct;
use airlight::light::{Attenuation, AttenuationModel};
use airlight::prelude::*;
use airlight::render::render;
use airlight::sampling::Sampler;

/// A floor with 1,000 small lights of short range above it (and one light
/// that reaches everywhere, so culled and unculled points mix).
pub fn many_lights(cull: bool) -> Scene {
    let mut b = SceneBuilder::new()
        .size(48, 36)
        .with_settings(|s| {
            s.spp = 1;
            s.cull_lights = cull;
        })
        .camera(Camera::look_at(vec3(0.0, 14.0, -14.0), Vec3::ZERO, Vec3::Y, 55.0))
        .material("floor", Material::diffuse(Rgb::splat(0.7)))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "floor")
        .object(Shape::sphere(vec3(0.0, 1.0, 0.0), 1.0), "floor")
        .light(Light::sphere(vec3(5.0, 6.0, 5.0), 0.5, Rgb::splat(2.0)));
    let mut s = Sampler::for_pixel(1, 0, 0);
    for i in 0..1000 {
        let p = vec3(20.0 * s.next() - 10.0, 0.3 + 0.7 * s.next(), 20.0 * s.next() - 10.0);
        let model = [
            AttenuationModel::Cutoff,
            AttenuationModel::WindowTan,
            AttenuationModel::WindowRational,
            AttenuationModel::WindowUe4,
        ][i % 4];
        let intensity = Rgb::new(s.next(), s.next(), s.next()) * 2.0;
        let a = Attenuation::new(model, 0.05, intensity.max_element() / 0.0025, Some(0.5), None).unwrap();
        let light = if i % 5 == 0 {
            Light::sphere(p, 0.05, intensity / (std::f32::consts::PI * 0.0025))
        } else {
            Light::point(p, intensity)
        };
        b = b.light(light.with_attenuation(a));
    }
    b.build().unwrap()
}

#[test]
fn culling_lights_out_of_range_leaves_the_image_unchanged() {
    let culled = render(&many_lights(true), &Direct, &RenderObserver::none());
    let full = render(&many_lights(false), &Direct, &RenderObserver::none());
    let worst =
        culled.pixels.iter().zip(&full.pixels).map(|(a, b)| (*a - *b).abs().max_element()).fold(0.0f32, f32::max);
    assert!(worst <= 1e-6, "largest difference {worst}");
    assert!(culled.mean().x > 0.0);
    // The lights have a short reach: most are out of range of any one point.
    let scene = many_lights(true);
    let mut reached = 0;
    scene.for_each_emitter_at(Vec3::ZERO, |_, _| reached += 1);
    assert!(reached < 50, "{reached} lights reach the origin");
}

/// An emitting mesh is one emitter with culling as without it: a point is
/// visited by its first triangle alone, beside the lights in range.
#[test]
fn an_emitting_mesh_is_visited_once_with_culling_as_without() {
    let positions = [vec3(-1.0, 3.0, -1.0), vec3(1.0, 3.0, -1.0), vec3(1.0, 3.0, 1.0), vec3(-1.0, 3.0, 1.0)];
    let mesh = Light::triangles_of(&positions, &[[0, 2, 1], [0, 3, 2], [0, 1, 3]], Rgb::ONE);
    assert_eq!(mesh.len(), 3);
    let near = Attenuation::new(AttenuationModel::WindowRational, 0.05, 100.0, None, Some(2.0)).unwrap();
    for cull in [true, false] {
        let mut b = SceneBuilder::new()
            .with_settings(|s| s.cull_lights = cull)
            .material("floor", Material::diffuse(Rgb::ONE))
            .object(Shape::plane(Vec3::ZERO, Vec3::Y), "floor")
            .light(Light::point(vec3(0.0, 0.5, 0.0), Rgb::ONE).with_attenuation(near))
            .light(Light::point(vec3(9.0, 0.5, 0.0), Rgb::ONE).with_attenuation(near));
        for light in &mesh {
            b = b.light(*light);
        }
        let scene = b.build().unwrap();
        assert!(scene.light_culling().has_ranges());
        let mut visited = Vec::new();
        scene.for_each_emitter_at(Vec3::ZERO, |index, _| visited.push(index));
        // The near light, the far one unless culled, and the mesh at its first triangle.
        let expected = if cull { vec![0, 2] } else { vec![0, 1, 2] };
        assert_eq!(visited, expected, "cull_lights = {cull}");
    }
}
