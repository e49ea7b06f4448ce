//! The analytic integrator's images against independent answers: the
//! ray-marching integrator converged (4096 steps), and for line and quad
//! lights a 4096-point superposition.

use airlight::film::{self, Image};
use airlight::integrator::RaymarchOptions;
use airlight::integrator::analytic::{Analytic, AnalyticOptions, LightQuadrature};
use airlight::integrator::{Integrator, Raymarch};
use airlight::prelude::*;
use airlight::render::render;
use airlight::sampling::Sampler;
use glam::Vec2;
use rayon::prelude::*;
use std::path::PathBuf;

mod common;

fn file(name: &str) -> SceneFile {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn scene_file(name: &str) -> Scene {
    file(name).scene
}

/// The integrator a scene file names, or why it cannot be had.
fn build(file: &SceneFile) -> Result<Box<dyn Integrator>, String> {
    file.integrator.build(&file.scene).map_err(|e| e.to_string())
}

fn analytic(scene: &Scene, shadows: bool, light_steps: u32, quadrature: LightQuadrature) -> Analytic {
    Analytic::new(scene, AnalyticOptions { shadows, light_steps, quadrature }).unwrap()
}

/// Renders with `per_side`² rays per pixel on a fixed stratified grid, the
/// same rays whatever the integrator, each with its own random stream; so
/// two integrators' images differ only by what they compute along a ray.
fn same_rays(scene: &Scene, integrator: &dyn Integrator, per_side: u32) -> Image {
    let (w, h) = (scene.settings().film.width, scene.settings().film.height);
    let rows: Vec<Vec<Rgb>> = (0..h)
        .into_par_iter()
        .map(|y| {
            (0..w)
                .map(|x| {
                    let mut sum = Rgb::ZERO;
                    for k in 0..per_side * per_side {
                        let (i, j) = (k % per_side, k / per_side);
                        let film = Vec2::new(
                            x as f32 + (i as f32 + 0.5) / per_side as f32,
                            y as f32 + (j as f32 + 0.5) / per_side as f32,
                        );
                        let ray = scene.camera().ray(film, w, h, Vec2::splat(0.5));
                        let mut sampler = Sampler::for_pixel(7, (y * w + x) as u64, k as u64);
                        sum += integrator.radiance(scene, &ray, &mut sampler);
                    }
                    sum / (per_side * per_side) as f32
                })
                .collect()
        })
        .collect();
    Image { width: w, height: h, pixels: rows.concat() }
}

fn small(mut scene: Scene, w: u32, h: u32) -> Scene {
    scene.settings_mut().film.width = w;
    scene.settings_mut().film.height = h;
    scene.settings_mut().spp = 1;
    scene
}

#[test]
fn glow_scene_matches_raymarch_at_4096_steps() {
    // One sample per pixel: both integrators trace the same camera ray (the
    // first two numbers of each pixel's stream), and without jitter the
    // march is deterministic, so the images differ only by the integrals.
    let scene = small(scene_file("glow.toml"), 64, 48);
    let an = render(&scene, &analytic(&scene, false, 16, LightQuadrature::Gauss), &RenderObserver::none());
    let rm = render(&scene, &Raymarch::new(RaymarchOptions { steps: 4096, jitter: false }), &RenderObserver::none());
    let e = film::compare(&an, &rm).unwrap();
    println!("glow: analytic vs raymarch 4096: rel_rmse {:.3e}", e.rel_rmse);
    assert!(e.rel_rmse <= 0.005, "{e:?}");
    assert!(an.mean().min_element() > 0.0);
}

#[test]
fn spot_light_with_soft_edge_anisotropic_phase_and_coloured_medium_matches_raymarch() {
    // Henyey–Greenstein g = 0.6, a smoothstep edge 25°–40° and σt different
    // per channel: every approximation of the analytic integrator at once.
    for (g, profile) in [(0.6, "smoothstep"), (-0.3, "linear")] {
        let text = format!(
            r#"
            [render]
            width = 48
            height = 36
            spp = 1
            jitter = false
            max_distance = 30
            [camera]
            position = [0, 2, -7]
            look_at = [0, 1.5, 0]
            fov = 50
            [medium]
            sigma_a = [0.02, 0.01, 0.0]
            sigma_s = [0.05, 0.08, 0.15]
            g = {g}
            [materials.floor]
            albedo = 0.5
            [[objects]]
            type = "plane"
            point = [0, 0, 0]
            normal = [0, 1, 0]
            material = "floor"
            [[lights]]
            type = "spot"
            position = [0.5, 5, 1]
            look_at = [-0.5, 0, 0]
            intensity = 80
            cone_angle = 40
            falloff_start = 25
            profile = "{profile}"
            "#
        );
        let scene = SceneFile::from_toml_str(&text, None).unwrap().scene;
        let an = same_rays(&scene, &analytic(&scene, false, 16, LightQuadrature::Gauss), 1);
        let rm = same_rays(&scene, &Raymarch::new(RaymarchOptions { steps: 32768, jitter: false }), 1);
        let e = film::compare(&an, &rm).unwrap();
        println!("spot g={g} {profile}: analytic vs raymarch 32768: rel_rmse {:.3e}", e.rel_rmse);
        assert!(e.rel_rmse <= 0.005, "g={g}: {e:?}");
    }
}

fn area_scene(light: &str) -> Scene {
    let text = format!(
        r#"
        [render]
        width = 24
        height = 18
        spp = 1
        max_distance = 20
        [camera]
        position = [0, 1.5, -6]
        look_at = [0, 1.5, 0]
        fov = 50
        [medium]
        sigma_a = 0.02
        sigma_s = 0.1
        [materials.floor]
        albedo = 0.5
        [[objects]]
        type = "plane"
        point = [0, 0, 0]
        normal = [0, 1, 0]
        material = "floor"
        {light}
        "#
    );
    SceneFile::from_toml_str(&text, None).unwrap().scene
}

#[test]
fn line_and_quad_lights_with_16_gauss_points_are_within_a_tenth_of_a_percent_of_4096() {
    let lights = [
        ("line", "[[lights]]\ntype = \"line\"\nstart = [-1.5, 1, 1]\nend = [1.5, 2.5, 0]\nintensity = 30", 4096),
        (
            "quad",
            "[[lights]]\ntype = \"quad\"\ncorner = [-1, 3, -0.5]\nedge_u = [2, 0, 0]\nedge_v = [0, 0, 2]\nradiance = 10",
            64, // 64 × 64 = 4096 points
        ),
    ];
    for (name, light, reference_steps) in lights {
        let scene = area_scene(light);
        let full = |steps: u32, q: LightQuadrature| same_rays(&scene, &analytic(&scene, false, steps, q), 1);
        // The image's surface term samples the area light with the same
        // random numbers whatever the rule: only the in-scattered light differs.
        let reference = full(reference_steps, LightQuadrature::Uniform);
        let mut errors = Vec::new();
        for q in [LightQuadrature::Gauss, LightQuadrature::Uniform] {
            let e = film::compare(&full(16, q), &reference).unwrap().rel_rmse;
            println!(
                "{name} light, 16 points per side, {q:?}: rel_rmse {e:.2e} \
                 against {reference_steps} uniform"
            );
            errors.push(e);
        }
        assert!(errors[0] <= 1e-3, "{name}: {errors:?}");
        assert!(reference.mean().min_element() > 0.0);
    }
}

#[test]
fn line_quad_and_sphere_lights_match_raymarch() {
    // The whole image, surface term included, against marching with a
    // sampled light at every step. The lights hang just above the view, so
    // that no ray passes within a few centimetres of them: there one random
    // point of the light per step gives the march a huge variance.
    let lights = [
        "[[lights]]\ntype = \"line\"\nstart = [-1.5, 5.0, 1]\nend = [1.5, 6.0, 0]\nintensity = 30",
        "[[lights]]\ntype = \"quad\"\ncorner = [-1, 6.5, -0.5]\nedge_u = [2, 0, 0]\nedge_v = [0, 0, 2]\nradiance = 10",
        "[[lights]]\ntype = \"sphere\"\ncenter = [0.3, 5.2, 0.5]\nradius = 0.3\nradiance = 40",
    ];
    for light in lights {
        let scene = area_scene(light);
        let an = same_rays(&scene, &analytic(&scene, false, 16, LightQuadrature::Gauss), 2);
        let rm = same_rays(&scene, &Raymarch::new(RaymarchOptions { steps: 4096, jitter: true }), 2);
        let e = film::compare(&an, &rm).unwrap();
        println!("{}: analytic vs raymarch: rel_rmse {:.3e}", light.lines().nth(1).unwrap(), e.rel_rmse);
        assert!(e.rel_rmse <= 0.01, "{light}: {e:?}");
    }
}

#[test]
fn volumetric_shadows_match_raymarch_with_jitter() {
    assert!(file("shadow_spheres.toml").integrator.analytic.shadows);
    let scene = small(scene_file("shadow_spheres.toml"), 48, 36);
    let an = same_rays(&scene, &analytic(&scene, true, 16, LightQuadrature::Gauss), 2);
    let rm = same_rays(&scene, &Raymarch::new(RaymarchOptions { steps: 4096, jitter: true }), 2);
    let e = film::compare(&an, &rm).unwrap();
    println!("shadows: analytic vs raymarch 4096 jittered: rel_rmse {:.3e}", e.rel_rmse);
    assert!(e.rel_rmse <= 0.01, "{e:?}");
    // Without shadows the same scene is visibly brighter: the test can fail.
    let unshadowed = same_rays(&scene, &analytic(&scene, false, 16, LightQuadrature::Gauss), 2);
    let e = film::compare(&unshadowed, &rm).unwrap();
    assert!(e.rel_rmse > 0.003, "{e:?}");
}

#[test]
fn mesh_shadows_match_raymarch() {
    // A cube as twelve triangles, and a tilted box instance, under a point light.
    let cube = |c: Vec3, s: f32| {
        let positions: Vec<Vec3> = (0..8)
            .map(|i| {
                c + s * vec3(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                )
            })
            .collect();
        let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
        let triangles = faces.iter().flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]]).collect();
        Shape::Mesh { positions, triangles, uvs: Vec::new(), normals: Vec::new() }
    };
    let rotated = glam::Affine3A::from_rotation_translation(
        glam::Quat::from_rotation_y(0.6) * glam::Quat::from_rotation_x(0.3),
        vec3(1.6, 0.7, 0.0),
    );
    let scene = SceneBuilder::new()
        .size(40, 30)
        .camera(Camera::look_at(vec3(0.0, 2.0, -7.0), vec3(0.0, 1.0, 0.0), Vec3::Y, 45.0))
        .medium(Medium::homogeneous(Rgb::splat(0.01), Rgb::splat(0.1), 0.0))
        .material("m", Material::diffuse(Rgb::splat(0.5)))
        .object(Shape::plane(Vec3::ZERO, Vec3::Y), "m")
        .object(cube(vec3(-1.0, 0.8, 0.3), 0.6), "m")
        .object_transformed(Shape::cuboid(Vec3::splat(-0.5), Vec3::splat(0.5)), rotated, "m")
        .light(Light::point(vec3(0.0, 4.5, 0.5), Rgb::splat(50.0)))
        .with_settings(|s| s.max_distance = 30.0)
        .build()
        .unwrap();
    let an = same_rays(&scene, &analytic(&scene, true, 16, LightQuadrature::Gauss), 2);
    let rm = same_rays(&scene, &Raymarch::new(RaymarchOptions { steps: 4096, jitter: true }), 2);
    let e = film::compare(&an, &rm).unwrap();
    println!("mesh shadows: analytic vs raymarch: rel_rmse {:.3e}", e.rel_rmse);
    assert!(e.rel_rmse <= 0.01, "{e:?}");
}

#[test]
fn images_do_not_depend_on_the_thread_count() {
    let mut file = file("shadow_spheres.toml");
    let s = file.scene.settings_mut();
    (s.film.width, s.film.height, s.spp) = (32, 24, 1);
    let integrator = build(&file).unwrap();
    let scene = file.scene;
    let render = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(&scene, integrator.as_ref(), &RenderObserver::none()))
    };
    assert_eq!(render(1), render(2));
}

#[test]
fn scenes_the_analytic_integrator_cannot_render_say_why() {
    let base = |medium: &str, light: &str| {
        format!(
            "[render]\nintegrator = \"analytic\"\n{medium}\n[materials.m]\nalbedo = 0.5\n\
             [[objects]]\ntype = \"sphere\"\ncenter = [0, 1, 0]\nradius = 1\nmaterial = \"m\"\n{light}"
        )
    };
    let point = "[[lights]]\ntype = \"point\"\nposition = [0, 4, 0]\nintensity = 10";
    let sun = "[[lights]]\ntype = \"distant\"\ndirection = [0, -1, 0]\nirradiance = 1";
    let height = "[medium]\ntype = \"height\"\nsigma_s = 0.1";
    let fog = "[medium]\nsigma_s = 0.1";
    let scene = SceneFile::from_toml_str(&base(height, point), None).unwrap();
    let err = build(&scene).err().unwrap();
    assert!(err.contains("homogeneous"), "{err}");
    let scene = SceneFile::from_toml_str(&base(fog, sun), None).unwrap();
    let err = build(&scene).err().unwrap();
    assert!(err.contains("distant"), "{err}");
    // A sun without a medium lights surfaces only: fine.
    let scene = SceneFile::from_toml_str(&base("", sun), None).unwrap();
    assert!(build(&scene).is_ok());
    // A volume light.
    let volume = "[[lights]]\ntype = \"box\"\nmin = [-0.4, 2.6, -0.4]\nmax = [0.4, 3.4, 0.4]\nintensity = 30.0";
    let scene = SceneFile::from_toml_str(&base(fog, volume), None).unwrap();
    let err = build(&scene).err().unwrap();
    assert!(err.contains("volume light"), "{err}");
    // A real-time attenuation window: the closed form is for 1/r² only.
    let windowed = format!("{point}\nattenuation = \"window_ue4\"\nrange = 5.0");
    let scene = SceneFile::from_toml_str(&base(fog, &windowed), None).unwrap();
    let err = build(&scene).err().unwrap();
    assert!(err.contains("attenuation"), "{err}");
    // SDF objects with shadows (without shadows they only end rays: fine).
    let sdf = "[[objects]]\ntype = \"sdf\"\nmaterial = \"m\"\nshape = \"box\"\nmin = [2, 0, 2]\nmax = [3, 1, 3]";
    let with_sdf = |shadows: bool| {
        let text = base(fog, point).replacen("[render]\n", &format!("[render]\nshadows = {shadows}\n"), 1);
        SceneFile::from_toml_str(&format!("{text}\n{sdf}"), None).unwrap()
    };
    let err = build(&with_sdf(true)).err().unwrap();
    assert!(err.contains("SDF"), "{err}");
    assert!(build(&with_sdf(false)).is_ok());
}

#[test]
fn anisotropic_phase_along_rays_matches_numeric_integration() {
    // A point light in fog with Henyey–Greenstein g: the analytic in-scatter
    // along rays against adaptive quadrature of σs·HG·I·e^{−σt (t + r)}/r².
    let (sigma_s, sigma_a, intensity) = (0.1f32, 0.03f32, 20.0f32);
    let light = vec3(0.4, 2.0, 3.0);
    for (g, bound) in [(0.3f32, 1e-4), (0.6, 1e-4), (-0.7, 1e-4), (0.9, 1e-4)] {
        let scene = SceneBuilder::new()
            .medium(Medium::homogeneous(Rgb::splat(sigma_a), Rgb::splat(sigma_s), g))
            .light(Light::point(light, Rgb::splat(intensity)))
            .build()
            .unwrap();
        let medium = scene.medium().unwrap();
        let integrator = analytic(&scene, false, 16, LightQuadrature::Gauss);
        let mut worst = 0.0f64;
        for i in 0..200 {
            let a = i as f32 * 0.7;
            let dir = vec3(a.cos() * 0.5, (a * 1.3).sin() * 0.4, 1.0).normalize();
            let origin = vec3(0.0, 1.5, -4.0 + (i % 7) as f32);
            let t_end = 3.0 + (i % 11) as f32 * 2.0;
            let ray = airlight::geometry::Ray::new(origin, dir);
            let got = integrator.in_scattered(&scene, medium, &ray, t_end).x as f64;
            let (o, d, p) = (origin.as_dvec3(), dir.as_dvec3(), light.as_dvec3());
            let st = (sigma_a + sigma_s) as f64;
            let f = |t: f64| {
                let to = p - (o + d * t);
                let r = to.length();
                let cos = -d.dot(to / r);
                let hg = (1.0 - (g * g) as f64)
                    / (4.0 * std::f64::consts::PI * (1.0 + (g * g) as f64 + 2.0 * g as f64 * cos).powf(1.5));
                sigma_s as f64 * intensity as f64 * hg * (-st * (t + r)).exp() / (r * r)
            };
            let foot = d.dot(p - o);
            let expected = common::integrate(&f, 0.0, t_end as f64, &[foot], 1e-10);
            worst = worst.max((got / expected - 1.0).abs());
        }
        println!("HG g = {g}: worst relative error {worst:.2e} over 200 rays");
        assert!(worst <= bound, "g = {g}: {worst:e}");
    }
}
