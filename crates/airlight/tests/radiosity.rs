//! Radiosity against independent answers, and its scene-file side
//! (settings, keyframes).

use airlight::geometry::{Ray, Shape};
use airlight::integrator::{Direct, RadiosityIntegrator, RadiosityOptions, RaymarchOptions};
use airlight::prelude::*;
use airlight::radiosity::Radiosity;
use airlight::render::render;
use airlight::sampling::Sampler;
use std::f32::consts::PI;

const CORNELL: &str = include_str!("../../../scenes/cornell_box.toml");
const ROOM: &str = include_str!("../../../scenes/room_moving_lights.toml");

fn cornell() -> Scene {
    SceneFile::from_toml_str(CORNELL, None).unwrap().scene
}

/// One bounce with patches of `patch_size`.
fn options(patch_size: f32) -> RadiosityOptions {
    RadiosityOptions { patch_size: Some(patch_size), bounces: 1, ..RadiosityOptions::default() }
}

fn integrator(scene: &Scene, patch_size: f32) -> RadiosityIntegrator {
    RadiosityIntegrator::new(scene, options(patch_size), RaymarchOptions::default()).unwrap()
}

/// Direct irradiance at `y` on the side facing along `n` from the quad light,
/// by uniform sampling of the light's area with shadow rays:
/// E = (A/K) Σ L cos θ_y cos θ_l V / r². Written here, apart from the
/// library's light sampling, as the independent estimator.
fn quad_light_irradiance(scene: &Scene, y: Vec3, n: Vec3, k: usize, s: &mut Sampler) -> Rgb {
    let Light::Quad { corner, edge_u, edge_v, radiance } = scene.lights()[0] else {
        panic!("the Cornell box has one quad light");
    };
    let cross = edge_u.cross(edge_v);
    let (area, n_l) = (cross.length(), cross.normalize());
    let mut sum = Rgb::ZERO;
    for _ in 0..k {
        let (a, b) = (s.next(), s.next());
        let l = corner + edge_u * a + edge_v * b;
        let d = l - y;
        let r2 = d.length_squared();
        let w = d / r2.sqrt();
        let (cos_y, cos_l) = (n.dot(w), -n_l.dot(w));
        if cos_l <= 0.0 || cos_y <= 0.0 {
            continue;
        }
        let origin = y + n * 1e-4;
        if scene.geometry().occluded(origin, w, r2.sqrt() * (1.0 - 1e-3)) {
            continue;
        }
        sum += radiance * (cos_y * cos_l / r2);
    }
    sum * (area / k as f32)
}

/// One-bounce indirect irradiance averaged over a wall's inner side: from
/// uniform points x on the wall, a cosine-distributed direction (pdf cos/π)
/// finds the surface y it sees; the light y reflects once is ρ_y E_y / π,
/// so E_ind(x) = ∫ L cos dω ≈ mean(ρ_y E_y). Light-surface hits are direct
/// light and count zero.
fn monte_carlo_wall(scene: &Scene, corner: Vec3, u: Vec3, v: Vec3, inward: Vec3, n: usize) -> Rgb {
    let mut s = Sampler::for_pixel(7, corner.x.to_bits() as u64, u.length().to_bits() as u64);
    let (t, b) = airlight::sampling::basis(inward);
    let mut sum = Rgb::ZERO;
    for _ in 0..n {
        let x = corner + u * s.next() + v * s.next();
        // Cosine-weighted direction by Malley's method, written out.
        let (r, phi) = (s.next().sqrt(), 2.0 * PI * s.next());
        let z = (1.0 - r * r).max(0.0).sqrt();
        let w = t * (r * phi.cos()) + b * (r * phi.sin()) + inward * z;
        let ray = Ray::new(x + inward * 1e-4, w);
        let Some(hit) = scene.geometry().intersect(&ray, f32::INFINITY) else {
            continue;
        };
        let surf = scene.geometry().surface(&ray, hit);
        if surf.emitter.is_some() {
            continue;
        }
        let albedo = scene.materials()[surf.material as usize].albedo(surf.p, surf.n);
        let n_y = if surf.n.dot(w) < 0.0 { surf.n } else { -surf.n };
        sum += albedo * quad_light_irradiance(scene, surf.p, n_y, 4, &mut s);
    }
    sum / n as f32
}

#[test]
fn cornell_box_one_bounce_matches_monte_carlo() {
    // Each wall's mean one-bounce radiance (ρ/π · mean indirect irradiance)
    // from radiosity within 5% of the Monte Carlo estimate. At 20,000
    // samples two seeds' estimates of the red wall lay 3.5% apart; 80,000
    // halve that noise.
    let scene = cornell();
    let r = Radiosity::compile(&scene, &options(0.2)).unwrap();
    let middle = Vec3::new(2.78, 2.74, 2.8);
    for (object, (shape, material)) in scene.objects().iter().enumerate().take(5) {
        let Shape::Quad { corner, edge_u, edge_v } = shape else {
            panic!("walls are quads");
        };
        let mut inward = edge_u.cross(*edge_v).normalize();
        if inward.dot(middle - *corner) < 0.0 {
            inward = -inward;
        }
        let (mut e, mut area) = (Rgb::ZERO, 0.0);
        for (p, ind) in r.patches().iter().zip(r.indirect_irradiance()) {
            if p.object as usize == object && p.normal.dot(inward) > 0.0 {
                e += *ind * p.area;
                area += p.area;
            }
        }
        let albedo = scene.materials()[*material as usize].albedo(*corner, inward);
        let radiosity = albedo * (e / area) / PI;
        let reference = albedo * monte_carlo_wall(&scene, *corner, *edge_u, *edge_v, inward, 80_000) / PI;
        let (a, b) = (radiosity.element_sum(), reference.element_sum());
        eprintln!("wall {object}: radiosity {radiosity}, Monte Carlo {reference}");
        assert!((a / b - 1.0).abs() < 0.05, "wall {object}: {a} vs {b}");
    }
}

#[test]
fn radiosity_image_is_the_direct_image_plus_indirect_light() {
    // Without a medium the integrator draws the same samples as `direct`,
    // so every pixel differs by the indirect light alone: never negative,
    // and positive on the walls.
    let scene = cornell();
    let with_fog = |fog: &str| {
        let mut scene = SceneFile::from_toml_str(&format!("{CORNELL}\n{fog}"), None).unwrap().scene;
        let s = scene.settings_mut();
        (s.film.width, s.film.height, s.spp) = (32, 32, 2);
        scene
    };
    let scene = {
        drop(scene);
        with_fog("")
    };
    let radiosity = integrator(&scene, 0.4);
    let a = render(&scene, &radiosity, &RenderObserver::none());
    let b = render(&scene, &Direct, &RenderObserver::none());
    for (x, y) in a.pixels.iter().zip(&b.pixels) {
        assert!((*x - *y).min_element() >= -1e-6, "{x} < {y}");
    }
    let brighter =
        a.pixels.iter().zip(&b.pixels).filter(|(x, y)| x.element_sum() > 1.1 * y.element_sum() + 1e-4).count();
    assert!(brighter * 2 > a.pixels.len(), "{brighter} of {}", a.pixels.len());
    // In fog the result is finite and dimmer with more fog.
    let foggy = with_fog("[medium]\nsigma_a = 0.2\nsigma_s = 0.05\n");
    let fog = render(&foggy, &radiosity, &RenderObserver::none());
    assert!(fog.pixels.iter().all(|p| p.is_finite()));
    assert!(fog.mean().element_sum() < a.mean().element_sum());
}

#[test]
fn the_moving_lights_room_renders_a_frame() {
    // Relit at mid-animation with no recompile; the frame is finite, and
    // the bounce light adds to what the lights reach directly.
    let mut scene = SceneFile::from_toml_str(ROOM, None).unwrap().scene;
    let s = scene.settings_mut();
    (s.film.width, s.film.height, s.spp) = (24, 16, 1);
    let mut integrator = integrator(&scene, 0.5);
    let compiled = Radiosity::compile_count();
    airlight::render::set_time(&mut scene, &mut integrator, 0.5).unwrap();
    assert_eq!(Radiosity::compile_count(), compiled, "relit, not recompiled");
    let image = render(&scene, &integrator, &RenderObserver::none());
    let direct = render(&scene, &Direct, &RenderObserver::none());
    assert!(image.pixels.iter().all(|p| p.is_finite()));
    assert!(image.mean().element_sum() > 1.1 * direct.mean().element_sum());
}

#[test]
fn keyframes_move_lights_linearly() {
    let scene = SceneFile::from_toml_str(ROOM, None).unwrap().scene;
    assert!(scene.is_animated());
    let path = scene.light_paths().iter().flatten().next().unwrap();
    let keys = path.keys().to_vec();
    let (i, _) = scene.light_paths().iter().enumerate().find(|(_, p)| p.is_some()).unwrap();
    for w in keys.windows(2) {
        let ((t0, p0), (t1, p1)) = (w[0], w[1]);
        let mid = scene.lights_at(0.5 * (t0 + t1))[i].position().unwrap();
        assert!((mid - 0.5 * (p0 + p1)).length() < 1e-5);
        assert!((scene.lights_at(t0)[i].position().unwrap() - p0).length() < 1e-5);
    }
}

fn error_of(text: &str) -> airlight::scene::SceneError {
    match SceneFile::from_toml_str(text, None) {
        Ok(_) => panic!("should be rejected:\n{text}"),
        Err(e) => e,
    }
}

#[test]
fn bad_keyframes_and_settings_name_their_place() {
    let light = |keys: &str| {
        format!("[[lights]]\ntype = \"point\"\nposition = [0, 4, 0]\nintensity = 10\nkeyframes = [\n  {keys}\n]\n")
    };
    let cases: Vec<(String, usize, &str)> = vec![
        (
            light("{ time = 0.0, position = [0, 1, 0] },\n  { time = 1.5, position = [1, 1, 0] }"),
            7,
            "time must lie in [0, 1]",
        ),
        (
            light("{ time = 0.5, position = [0, 1, 0] },\n  { time = 0.5, position = [1, 1, 0] }"),
            7,
            "greater than the previous key",
        ),
        (
            light("{ time = 0.0, position = [0, 1] }"),
            6,
            "three",
        ),
        (
            light("{ time = 0.0, position = [0, 1, 0], color = 1 }"),
            6,
            "unknown field `color`",
        ),
        (
            "[[lights]]\ntype = \"distant\"\ndirection = [0, -1, 0]\nirradiance = 1\nkeyframes = [{ time = 0.0, position = [0, 1, 0] }]\n".into(),
            5,
            "distant light has no position",
        ),
        (
            "[render]\nbounces = 0\n".into(),
            2,
            "render.bounces must be an integer from 1 to 1024",
        ),
        (
            "[render]\npatch_size = -1.0\n".into(),
            2,
            "render.patch_size must be a positive",
        ),
        (
            "[render]\nlink_threshold = -0.5\n".into(),
            2,
            "render.link_threshold must be a finite number ≥ 0",
        ),
    ];
    for (text, line, phrase) in cases {
        let e = error_of(&text);
        assert!(e.message.contains(phrase), "`{}` lacks `{phrase}`:\n{text}", e.message);
        assert_eq!(e.location.map(|l| l.0), Some(line), "{e}\n{text}");
    }
}

#[test]
fn a_quad_light_does_not_shadow_points_far_from_the_origin() {
    // A point 70 units from the origin, 1 below a small quad light: the
    // shadow ray's lift off the floor (which grows with |p|) must not make it
    // reach the light's own surface. Small source: E ≈ L·A/d², so the
    // radiance is ρ/π · L·A/d² to within (side/d)².
    let p = Vec3::new(50.0, 0.0, 50.0);
    let (side, radiance, albedo) = (0.05, 10.0, 0.5);
    let scene = SceneBuilder::new()
        .material("m", Material::diffuse(Rgb::splat(albedo)))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
        .light(Light::quad(
            p + Vec3::new(-side / 2.0, 1.0, -side / 2.0),
            Vec3::X * side,
            Vec3::Z * side,
            Rgb::splat(radiance),
        ))
        .build()
        .unwrap();
    let eye = p + Vec3::new(0.0, 0.5, -0.5);
    let ray = Ray::new(eye, (p - eye).normalize());
    let got = airlight::integrator::Integrator::radiance(&Direct, &scene, &ray, &mut Sampler::for_pixel(0, 0, 0));
    let want = albedo / PI * radiance * side * side;
    assert!((got.x / want - 1.0).abs() < 0.01, "{} vs {want}", got.x);
}
