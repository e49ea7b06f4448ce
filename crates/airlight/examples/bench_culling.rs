//! Light culling: 1,000 short-range lights over a floor, rendered with and
//! without culling, side by side.
//!
//! `cargo run --release --example bench_culling`

use airlight::integrator::Direct;
use airlight::light::{Attenuation, AttenuationModel};
use airlight::prelude::*;
use airlight::render::render;
use airlight::sampling::Sampler;
use std::time::Instant;

fn scene(cull: bool) -> Scene {
    let mut b = SceneBuilder::new()
        .size(320, 240)
        .with_settings(|s| {
            s.spp = 4;
            s.cull_lights = cull;
        })
        .camera(Camera::look_at(vec3(0.0, 14.0, -14.0), Vec3::ZERO, Vec3::Y, 55.0))
        .material("floor", Material::diffuse(Rgb::splat(0.7)))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "floor")
        .object(Shape::sphere(vec3(0.0, 1.0, 0.0), 1.0), "floor");
    let mut s = Sampler::for_pixel(1, 0, 0);
    for _ in 0..1000 {
        let p = vec3(20.0 * s.next() - 10.0, 0.3 + 0.7 * s.next(), 20.0 * s.next() - 10.0);
        let intensity = Rgb::new(s.next(), s.next(), s.next()) * 2.0;
        let a =
            Attenuation::new(AttenuationModel::WindowRational, 0.05, intensity.max_element() / 0.0025, Some(0.5), None)
                .unwrap();
        b = b.light(Light::point(p, intensity).with_attenuation(a));
    }
    b.build().unwrap()
}

fn main() {
    let (culled, full) = (scene(true), scene(false));
    let mut reach = 0;
    culled.for_each_emitter_at(Vec3::ZERO, |_, _| reach += 1);
    println!("1000 point lights, range {:.2}; {reach} reach the origin", culled.lights()[0].reach().unwrap().1);
    for round in 0..2 {
        let t = Instant::now();
        let a = render(&culled, &Direct, &RenderObserver::none());
        let with = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let b = render(&full, &Direct, &RenderObserver::none());
        let without = t.elapsed().as_secs_f64();
        assert!(a == b, "culling changed the image");
        println!("round {round}: with culling {with:.3} s, without {without:.3} s: {:.1}× faster", without / with);
    }
}
