//! A differential test across integrators: random scenes (boxes, spheres,
//! quads, planes and meshes placed at random, some enclosing the lights or
//! the camera; point, spot, sphere, quad and distant lights; homogeneous and
//! height fog with random coefficients) rendered by every integrator that
//! takes them, which must agree within the noise of the stochastic ones:
//!
//! - single scattering: `analytic`, `stochastic` and `path` at
//!   `max_depth = 1` against `raymarch` (256 jittered steps);
//! - without a medium, `radiosity` with 2 bounces against `path` at
//!   `max_depth = 3`, within the patches' discretisation error: 12% of the
//!   pixels' value, or 1% of the brightest patch's radiance.
//!
//! Agreement is judged on the image mean and on each quarter of the image:
//! |a − b| ≤ 5·√(se_a² + se_b²) + tol·max(a, b), with se the standard error
//! of the mean from the accumulator's per-pixel variances (the camera rays
//! go through pixel centres, so only the integrators' own randomness is
//! there), and tol the deterministic error allowed (the march's steps: 1%;
//! the analytic integrator's sphere lights as points: σt·R more;
//! radiosity's patches: 12%).
//!
//! `cargo test --test differential` runs `DEFAULT_SCENES` scenes; the
//! ignored `many_random_scenes` runs 5,000. `AIRLIGHT_DIFF_SEED=S` replays
//! one scene, `AIRLIGHT_DIFF_SCENES=N` sets the count, and
//! `AIRLIGHT_DIFF_RENDER_SEED=R` renders with other random numbers (a
//! disagreement that another seed does not repeat is noise: the allowance is
//! 5 standard errors estimated from few samples, and path-traced pixels
//! have heavy tails, so among 75,000 comparisons a few pass 5; so a scene
//! that disagrees is rendered once more with another seed and fails only
//! if that disagrees too);
//! `AIRLIGHT_DIFF_REFERENCE_SPP=N` renders the raymarch reference at N
//! samples, `AIRLIGHT_DIFF_LIGHT=k` keeps only light k, and
//! `AIRLIGHT_DIFF_DEBUG=1` prints each block's means, and
//! `AIRLIGHT_DIFF_INDEPENDENT=1` draws the path tracer's samples
//! independently rather than stratified. A disagreement prints
//! the seed. Cases it found are kept below as named tests.

use airlight::film::Accumulator;
use airlight::film::PixelFilter;
use airlight::geometry::Shape;
use airlight::integrator::{IntegratorDesc, IntegratorKind, RadiosityIntegrator, RadiosityOptions};
use airlight::light::Light;
use airlight::material::Material;
use airlight::medium::Medium;
use airlight::prelude::*;
use airlight::render::accumulate;

const DEFAULT_SCENES: u64 = 60;
const SIZE: u32 = 6;
/// Radiosity's patches: coarse, for speed (rooms of 8 units, objects of 0.2
/// to 2).
const PATCH_SIZE: f32 = 0.5;

/// SplitMix64: a small, fixed generator for the scenes (not for rendering).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.next()
    }
    fn point(&mut self, r: f32) -> Vec3 {
        vec3(self.range(-r, r), self.range(-r, r), self.range(-r, r))
    }
    fn pick(&mut self, n: usize) -> usize {
        ((self.next() * n as f32) as usize).min(n - 1)
    }
}

/// A closed cube of twelve triangles, wound outward.
fn mesh_cube(center: Vec3, half: f32) -> Shape {
    let positions: Vec<Vec3> = (0..8)
        .map(|i| {
            center
                + half
                    * vec3(
                        if i & 1 == 0 { -1.0 } else { 1.0 },
                        if i & 2 == 0 { -1.0 } else { 1.0 },
                        if i & 4 == 0 { -1.0 } else { 1.0 },
                    )
        })
        .collect();
    let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
    let triangles = faces.iter().flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]]).collect();
    Shape::Mesh { positions, triangles, uvs: Vec::new(), normals: Vec::new() }
}

/// AIRLIGHT_DIFF_RENDER_SEED: the render seed of every scene, to replay
/// one with other random numbers.
fn render_seed_override() -> Option<u64> {
    std::env::var("AIRLIGHT_DIFF_RENDER_SEED").ok().and_then(|v| v.parse().ok())
}

/// The random scene of `seed`, rendered with random numbers `render_seed`.
fn random_scene(seed: u64, render_seed: u64) -> Scene {
    let mut r = Rng(seed.wrapping_mul(0x2545_f491_4f6c_dd1d) ^ 0x1234_5678);
    let mut b = SceneBuilder::new().size(SIZE, SIZE).with_settings(|s| {
        s.film.filter = PixelFilter::Point;
        s.max_distance = 40.0;
        s.seed = render_seed;
    });
    for (i, albedo) in [0.7f32, 0.45, 0.25].into_iter().enumerate() {
        b = b.material(&format!("m{i}"), Material::diffuse(Rgb::splat(albedo * r.range(0.8, 1.2))));
    }
    let camera = r.point(2.0);
    let target = camera + (r.point(1.0) - camera * 0.3).normalize_or(Vec3::Z) * 3.0;
    let up = if (target - camera).normalize().dot(Vec3::Y).abs() > 0.95 { Vec3::X } else { Vec3::Y };
    b = b.camera(Camera::look_at(camera, target, up, r.range(40.0, 90.0)));
    // An enclosure around the camera and the lights: a room, a dome, a mesh
    // room; or an open scene.
    match r.pick(4) {
        0 => b = b.object(Shape::cuboid(Vec3::splat(-4.0), Vec3::splat(4.0)), "m0"),
        1 => b = b.object(Shape::sphere(Vec3::ZERO, 5.0), "m0"),
        2 => b = b.object(mesh_cube(Vec3::ZERO, 4.2), "m1"),
        _ => {}
    }
    for _ in 0..1 + r.pick(3) {
        let at = r.point(2.5);
        let m = format!("m{}", r.pick(3));
        b = match r.pick(5) {
            0 => b.object(Shape::sphere(at, r.range(0.2, 1.0)), &m),
            1 => {
                let h = vec3(r.range(0.1, 0.9), r.range(0.1, 0.9), r.range(0.1, 0.9));
                b.object(Shape::cuboid(at - h, at + h), &m)
            }
            2 => b.object(Shape::quad(at, r.point(1.5), r.point(1.5)), &m),
            3 => b.object(Shape::plane(vec3(0.0, r.range(-3.0, -1.5), 0.0), (Vec3::Y + r.point(0.3)).normalize()), &m),
            _ => b.object(mesh_cube(at, r.range(0.2, 0.7)), &m),
        };
    }
    for _ in 0..1 + r.pick(2) {
        let at = r.point(2.8);
        let power = r.range(2.0, 20.0);
        let light = match r.pick(5) {
            0 => Light::point(at, Rgb::new(power, 0.8 * power, 0.6 * power)),
            1 => {
                let cone = r.range(15.0, 70.0);
                Light::spot(at, at + r.point(1.0) - Vec3::Y, Rgb::splat(power), cone, cone * r.range(0.3, 1.0))
            }
            2 => Light::sphere(at, r.range(0.05, 0.4), Rgb::splat(power / 4.0)),
            3 => Light::quad(at, r.point(0.8), r.point(0.8), Rgb::splat(power / 3.0)),
            _ => Light::distant((r.point(1.0) - Vec3::Y * 2.0).normalize(), Rgb::splat(r.range(0.5, 3.0))),
        };
        b = b.light(light);
    }
    let (sigma_a, sigma_s, g) = (r.range(0.0, 0.08), r.range(0.02, 0.3), r.range(-0.5, 0.7));
    b = match r.pick(10) {
        0 | 1 => b,
        2..=6 => b.medium(Medium::homogeneous(Rgb::splat(sigma_a), Rgb::new(sigma_s, 0.9 * sigma_s, 1.1 * sigma_s), g)),
        _ => {
            b.medium(Medium::height(Rgb::splat(sigma_a), Rgb::splat(sigma_s), g, r.range(-2.0, 1.0), r.range(0.2, 1.5)))
        }
    };
    b.build().unwrap()
}

/// The blocks agreement is judged on: the whole image and its quarters.
fn blocks() -> [(std::ops::Range<u32>, std::ops::Range<u32>); 5] {
    let h = SIZE / 2;
    [(0..SIZE, 0..SIZE), (0..h, 0..h), (h..SIZE, 0..h), (0..h, h..SIZE), (h..SIZE, h..SIZE)]
}

/// Mean and squared standard error of the mean over a block of pixels.
fn block(acc: &Accumulator, xs: std::ops::Range<u32>, ys: std::ops::Range<u32>) -> (f64, f64) {
    let (mut mean, mut var, mut n) = (0.0, 0.0, 0.0);
    for y in ys {
        for x in xs.clone() {
            let p = acc.pixel(x, y).unwrap();
            mean += p.mean().as_dvec3().element_sum() / 3.0;
            let v = p.variance_of_mean().element_sum() / 9.0;
            var += if v.is_finite() { v } else { 0.0 };
            n += 1.0;
        }
    }
    (mean / n, var / (n * n))
}

/// Renders `kind` (with `max_depth` `depth` for path) at
/// `spp`, or the integrator's refusal.
fn render(scene: &mut Scene, kind: IntegratorKind, spp: u32, depth: u32) -> Result<Accumulator, String> {
    let mut desc = IntegratorDesc::new(kind);
    desc.path.max_depth = depth;
    desc.raymarch.steps = std::env::var("AIRLIGHT_DIFF_STEPS").ok().and_then(|s| s.parse().ok()).unwrap_or(256);
    desc.analytic.shadows = true;
    desc.path.stratify = std::env::var_os("AIRLIGHT_DIFF_INDEPENDENT").is_none();
    let integrator = desc.build(scene).map_err(|e| e.to_string())?;
    scene.settings_mut().spp = spp;
    Ok(accumulate(scene, integrator.as_ref(), 0..spp as u64, 0..SIZE, &Default::default()))
}

/// The largest radiance any patch of the scene's radiosity solution leaves
/// (direct and indirect light times its albedo, over π).
fn brightest_patch(scene: &Scene, r: &RadiosityIntegrator) -> f64 {
    let s = &r.solution;
    s.patches()
        .iter()
        .zip(s.direct_irradiance().iter().zip(s.indirect_irradiance()))
        .map(|(p, (d, i))| ((*d + *i) * scene.material(p.material).albedo(p.center, p.normal)).max_element() as f64)
        .fold(0.0, f64::max)
        / std::f64::consts::PI
}

/// Whether `a` and `b` agree within `absolute` (plus their noise) in the
/// image mean and each quarter; the worst disagreement as a multiple of
/// what is allowed.
fn agreement_within(a: &Accumulator, b: &Accumulator, scale: f64) -> f64 {
    blocks()
        .into_iter()
        .map(|(xs, ys)| {
            let ((ma, va), (mb, vb)) = (block(a, xs.clone(), ys.clone()), block(b, xs, ys));
            (ma - mb).abs() / (5.0 * (va + vb).sqrt() + 0.01 * scale + 1e-6)
        })
        .fold(0.0, f64::max)
}

/// Whether `a` and `b` agree (image mean and each quarter); the worst
/// disagreement as a multiple of what is allowed.
fn agreement(a: &Accumulator, b: &Accumulator, tol: f64) -> f64 {
    blocks()
        .into_iter()
        .map(|(xs, ys)| {
            let ((ma, va), (mb, vb)) = (block(a, xs.clone(), ys.clone()), block(b, xs, ys));
            let allowed = 5.0 * (va + vb).sqrt() + tol * ma.abs().max(mb.abs()) + 1e-6;
            (ma - mb).abs() / allowed
        })
        .fold(0.0, f64::max)
}

/// Prints the blocks' means and standard errors of `a` and `b`
/// (`AIRLIGHT_DIFF_DEBUG`).
fn print_blocks(name: &str, a: &Accumulator, b: &Accumulator) {
    for (xs, ys) in blocks() {
        let ((ma, va), (mb, vb)) = (block(a, xs.clone(), ys.clone()), block(b, xs.clone(), ys.clone()));
        eprintln!("{name} {xs:?}×{ys:?}: {ma:.6} ± {:.6} against {mb:.6} ± {:.6}", va.sqrt(), vb.sqrt());
    }
}

/// Renders scene `seed` with every integrator that takes it; returns the
/// comparisons made (name, worst ratio), or the description of a failure.
/// [`check_with`] the render seed the environment gives, else the scene's.
fn check(seed: u64) -> Result<Vec<(&'static str, f64)>, String> {
    check_with(seed, render_seed_override().unwrap_or(seed))
}

fn check_with(seed: u64, render_seed: u64) -> Result<Vec<(&'static str, f64)>, String> {
    let mut scene = random_scene(seed, render_seed);
    // AIRLIGHT_DIFF_LIGHT=k: only the scene's light k, to find which light
    // a disagreement comes from.
    if let Some(k) = std::env::var("AIRLIGHT_DIFF_LIGHT").ok().and_then(|k| k.parse::<usize>().ok()) {
        let only: Vec<Light> = scene.lights().get(k).cloned().into_iter().collect();
        scene.set_lights(&only);
    }
    let mut results = Vec::new();
    let mut fail = Vec::new();
    let reference = render(
        &mut scene,
        IntegratorKind::Raymarch,
        std::env::var("AIRLIGHT_DIFF_REFERENCE_SPP").ok().and_then(|s| s.parse().ok()).unwrap_or(16),
        1,
    )?;
    // The closed form takes a sphere light as a point at its centre of
    // intensity πR²L: exact without extinction and with isotropic
    // scattering, off by O(σt·R) otherwise (its documented approximation).
    let sigma_t = scene.medium().map_or(0.0, |m| m.sigma_t().max_element());
    let sphere = scene
        .lights()
        .iter()
        .map(|l| if let Light::Sphere { radius, .. } = l { *radius } else { 0.0 })
        .fold(0.0, f32::max);
    let analytic_tol = 0.01 + (sigma_t * sphere) as f64;
    for (name, kind, spp, tol) in [
        // Deterministic in the medium, but area lights' light on surfaces
        // is sampled: as many samples as the reference, so that the
        // variance estimate is as good as its (with 4, seed 440's dim
        // room read 1.07× the allowance on a variance from 4 samples).
        ("analytic", IntegratorKind::Analytic, 16, analytic_tol),
        ("stochastic", IntegratorKind::Stochastic, 256, 0.01),
        ("path max_depth 1", IntegratorKind::Path, 512, 0.01),
    ] {
        match render(&mut scene, kind, spp, 1) {
            Ok(image) => {
                let worst = agreement(&image, &reference, tol);
                results.push((name, worst));
                if std::env::var_os("AIRLIGHT_DIFF_DEBUG").is_some() {
                    print_blocks(name, &image, &reference);
                }
                if worst > 1.0 {
                    let (a, b) = (block(&image, 0..SIZE, 0..SIZE).0, block(&reference, 0..SIZE, 0..SIZE).0);
                    fail.push(format!("{name} {a:.5} vs raymarch {b:.5} ({worst:.2}× the allowance)"));
                }
            }
            // The analytic integrator refuses what it has no closed form for.
            Err(_) if kind == IntegratorKind::Analytic => {}
            Err(e) => fail.push(format!("{name} refused: {e}")),
        }
    }
    if scene.medium().is_none() {
        let path = render(&mut scene, IntegratorKind::Path, 512, 3)?;
        let patch_size =
            std::env::var("AIRLIGHT_DIFF_PATCH_SIZE").ok().and_then(|s| s.parse().ok()).unwrap_or(PATCH_SIZE);
        let options = RadiosityOptions { bounces: 2, patch_size: Some(patch_size), ..Default::default() };
        let solved = RadiosityIntegrator::new(&scene, options, Default::default()).map_err(|e| e.to_string())?;
        scene.settings_mut().spp = 16;
        let radiosity = accumulate(&scene, &solved, 0..16, 0..SIZE, &Default::default());
        // The patches' error is a share of the light around, not of the
        // pixels' own (a dark room beside a sunlit floor that runs under
        // its wall: patches straddling the wall pass a little light in).
        let worst = agreement(&radiosity, &path, 0.12).min(agreement_within(
            &radiosity,
            &path,
            brightest_patch(&scene, &solved),
        ));
        results.push(("radiosity 2 bounces", worst));
        if std::env::var_os("AIRLIGHT_DIFF_DEBUG").is_some() {
            for y in 0..SIZE {
                for x in 0..SIZE {
                    let (r, p) = (radiosity.pixel(x, y).unwrap().mean(), path.pixel(x, y).unwrap().mean());
                    eprintln!("pixel {x},{y}: radiosity {r} path {p}");
                }
            }
        }
        if worst > 1.0 {
            let (a, b) = (block(&radiosity, 0..SIZE, 0..SIZE).0, block(&path, 0..SIZE, 0..SIZE).0);
            fail.push(format!("radiosity {a:.5} vs path max_depth 3 {b:.5} ({worst:.2}×)"));
        }
    }
    if fail.is_empty() { Ok(results) } else { Err(fail.join("; ")) }
}

/// XORed into a scene's seed for its second render (see [`run`]).
const RETRY_SEED: u64 = 0x5_eed0_fa11;

fn run(count: u64) {
    let seeds: Vec<u64> = match std::env::var("AIRLIGHT_DIFF_SEED").ok().and_then(|s| s.parse().ok()) {
        Some(seed) => vec![seed],
        None => (0..std::env::var("AIRLIGHT_DIFF_SCENES").ok().and_then(|s| s.parse().ok()).unwrap_or(count)).collect(),
    };
    let mut worst: std::collections::BTreeMap<&str, (f64, u64, usize)> = Default::default();
    let mut failures = Vec::new();
    let mut noise = Vec::new();
    let start = std::time::Instant::now();
    let verbose = std::env::var_os("AIRLIGHT_DIFF_VERBOSE").is_some();
    for &seed in &seeds {
        let t = std::time::Instant::now();
        let mut result = check(seed);
        // A disagreement that other random numbers do not repeat is noise
        // (module notes): path-traced pixels have heavy tails, and a render
        // that drew none of the rare bright samples reads low with a small
        // variance estimate. So a failing scene is rendered once more with
        // another seed, and fails only if that fails too; a bias above the
        // allowance repeats. (Not when a render seed is given: a replay
        // shows that seed's result.)
        if let Err(first) = &result
            && render_seed_override().is_none()
        {
            let again = check_with(seed, seed ^ RETRY_SEED);
            eprintln!("seed {seed}: {first}; with render seed {}: {again:?}", seed ^ RETRY_SEED);
            if again.is_ok() {
                noise.push(seed);
            }
            result = again.map_err(|second| format!("{first}; again with render seed {}: {second}", seed ^ RETRY_SEED));
        }
        if verbose {
            eprintln!("seed {seed}: {:.2} s {result:?}", t.elapsed().as_secs_f64());
            if seeds.len() == 1 {
                let scene = random_scene(seed, seed);
                eprintln!(
                    "camera {:?}\nobjects {:?}\nlights {:?}\nmedium {:?}",
                    scene.camera(),
                    scene.objects(),
                    scene.lights(),
                    scene.medium()
                );
            }
        }
        match result {
            Ok(results) => {
                for (name, ratio) in results {
                    let w = worst.entry(name).or_insert((0.0, 0, 0));
                    w.2 += 1;
                    if ratio > w.0 {
                        (w.0, w.1) = (ratio, seed);
                    }
                }
            }
            Err(why) => {
                eprintln!("DIFFERENTIAL FAILURE: AIRLIGHT_DIFF_SEED={seed}: {why}");
                failures.push(seed);
            }
        }
    }
    eprintln!("{} scenes in {:.1} s", seeds.len(), start.elapsed().as_secs_f64());
    if !noise.is_empty() {
        eprintln!("  disagreements that another render seed did not repeat (noise): {noise:?}");
    }
    for (name, (ratio, seed, n)) in &worst {
        eprintln!("  {name}: {n} scenes, largest disagreement {ratio:.3} of the allowance (seed {seed})");
    }
    assert!(failures.is_empty(), "scenes that disagree (replay with AIRLIGHT_DIFF_SEED): {failures:?}");
}

#[test]
fn random_scenes_agree_across_integrators() {
    run(DEFAULT_SCENES);
}

#[test]
#[ignore = "5,000 scenes: minutes; run by hand"]
fn many_random_scenes() {
    run(5000);
}

// Cases the random scenes found, kept by name.

/// A sun outside a dome lit the dome's inside: diffuse surfaces reflected
/// light that reached them from behind (fixed in `Material::brdf`).
#[test]
fn seed_9_a_sun_outside_a_dome_lights_nothing_inside() {
    check(9).unwrap();
}

/// A floor under a sunlit room's wall, and a thin box: radiosity's lookup
/// blended the light of patches on a wall's other side into a dark room
/// (fixed by `Radiosity::irradiance_seen_at`).
#[test]
fn seed_59_and_81_radiosity_does_not_blend_light_through_walls() {
    check(59).unwrap();
    check(81).unwrap();
}

/// A sphere light in thick anisotropic fog: the analytic integrator's
/// point-at-the-centre approximation is off by 1.7%, within its stated
/// O(σt·R).
#[test]
fn seed_128_a_sphere_light_in_thick_fog_is_within_the_stated_approximation() {
    check(128).unwrap();
}

/// Sphere lights 1 to 3 radii from a ball, a box or a mesh: the analytic
/// integrator shadowed them as a point at the centre, whose hard shadows
/// misplaced the wide penumbrae (a quarter of the image 36% dark in seed
/// 3374); now such lights are points on their surface.
#[test]
fn seeds_606_2402_3374_3912_sphere_lights_near_occluders_cast_penumbrae() {
    for seed in [606, 2402, 3374, 3912] {
        check(seed).unwrap();
    }
}

/// Open scenes under a sun with an infinite floor: radiosity cut the floor
/// only in a square around the objects, so the bounce light from the rest
/// of the sunlit floor was missing (seed 3122: a box's side got a fifth of
/// the path tracer's light); now coarse rings extend it 64 times further.
#[test]
fn seeds_1271_1465_3122_4432_a_sunlit_floor_bounces_light_from_beyond_the_objects() {
    for seed in [1271, 1465, 3122, 4432] {
        check(seed).unwrap();
    }
}
