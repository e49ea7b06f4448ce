use super::*;
use crate::SceneFile;
use crate::geometry::Shape;
use crate::integrator::RadiosityOptions;
use crate::light::Light;
use crate::scene::SceneBuilder;
use glam::vec3;

const CORNELL: &str = include_str!("../../../../scenes/cornell_box.toml");

fn cornell() -> Scene {
    SceneFile::from_toml_str(CORNELL, None).unwrap().scene
}

/// One bounce with patches of `patch_size`.
fn options(patch_size: f32) -> RadiosityOptions {
    RadiosityOptions { patch_size: Some(patch_size), bounces: 1, ..RadiosityOptions::default() }
}

fn quads(shapes: &[Shape]) -> Scene {
    let mut b = SceneBuilder::new().material("m", Material::diffuse(Rgb::splat(0.5)));
    for s in shapes {
        b = b.object(s.clone(), "m");
    }
    b.build().unwrap()
}

fn compile(scene: &Scene, patch_size: f32, threshold: f32) -> Radiosity {
    Radiosity::compile_with(
        scene,
        CompileParams { patch_size, link_threshold: threshold, receiver_share: 0.0, seed: 1 },
    )
    .unwrap()
}

/// F from object `from` (its side facing `toward`) to object `to`:
/// Σ_i A_i Σ_{j ∈ to} F_ij / Σ_i A_i over the patches with full links.
fn object_factor(r: &Radiosity, from: u32, toward: Vec3, to: u32) -> f64 {
    let patches = r.patches();
    let (mut num, mut area) = (0.0f64, 0.0f64);
    for (i, p) in patches.iter().enumerate() {
        if p.object != from || p.normal.dot(toward - p.center) <= 0.0 {
            continue;
        }
        area += p.area as f64;
        for l in r.links().of(i) {
            let s = l.source as usize;
            assert!(s < patches.len(), "threshold 0 links patches only");
            if patches[s].object == to {
                num += p.area as f64 * l.factor as f64;
            }
        }
    }
    num / area
}

/// Howell's catalogue C-11: identical parallel, directly opposed rectangles
/// a × b at distance c; X = a/c, Y = b/c.
fn parallel_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x1, y1) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    2.0 / (std::f64::consts::PI * x * y)
        * ((x1 * x1 * y1 * y1 / (1.0 + x * x + y * y)).sqrt().ln()
            + x * y1 * (x / y1).atan()
            + y * x1 * (y / x1).atan()
            - x * x.atan()
            - y * y.atan())
}

/// Howell's catalogue C-14: from a rectangle l × w to a perpendicular one
/// l × h sharing the edge of length l; H = h/l, W = w/l.
fn perpendicular_rectangles(l: f64, w: f64, h: f64) -> f64 {
    let (hh, ww) = (h / l, w / l);
    let (h2, w2) = (hh * hh, ww * ww);
    let a = (1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2);
    let b = (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).powf(w2);
    let c = (h2 * (1.0 + h2 + w2) / ((1.0 + h2) * (h2 + w2))).powf(h2);
    1.0 / (std::f64::consts::PI * ww)
        * (ww * (1.0 / ww).atan() + hh * (1.0 / hh).atan() - (h2 + w2).sqrt() * (1.0 / (h2 + w2).sqrt()).atan()
            + 0.25 * (a * b * c).ln())
}

#[test]
fn closed_forms_are_the_catalogue_values() {
    // Guards the transcription: the tabulated values for unit squares.
    assert!((parallel_rectangles(1.0, 1.0, 1.0) - 0.19982).abs() < 1e-4);
    assert!((perpendicular_rectangles(1.0, 1.0, 1.0) - 0.20004).abs() < 1e-4);
}

#[test]
fn parallel_rectangles_match_the_closed_form() {
    for (a, b, c) in [(1.0f32, 1.0f32, 1.0f32), (2.0, 1.0, 0.5)] {
        let scene = quads(&[
            Shape::quad(Vec3::ZERO, Vec3::X * a, Vec3::Z * b),
            Shape::quad(Vec3::Y * c, Vec3::X * a, Vec3::Z * b),
        ]);
        let r = compile(&scene, b / 16.0, 0.0);
        let got = object_factor(&r, 0, Vec3::Y * c, 1);
        let want = parallel_rectangles(a as f64, b as f64, c as f64);
        assert!((got / want - 1.0).abs() < 0.01, "{a}×{b} at {c}: {got} vs {want}");
    }
}

#[test]
fn perpendicular_rectangles_match_the_closed_form() {
    for (l, w, h) in [(1.0f32, 1.0f32, 1.0f32), (1.0, 2.0, 0.5)] {
        // From the floor l (along z) × w (along x) to the wall l × h at x = 0.
        let scene = quads(&[
            Shape::quad(Vec3::ZERO, Vec3::X * w, Vec3::Z * l),
            Shape::quad(Vec3::ZERO, Vec3::Y * h, Vec3::Z * l),
        ]);
        let r = compile(&scene, 1.0 / 16.0, 0.0);
        let got = object_factor(&r, 0, vec3(w / 2.0, 1.0, l / 2.0), 1);
        let want = perpendicular_rectangles(l as f64, w as f64, h as f64);
        assert!((got / want - 1.0).abs() < 0.01, "{l}, {w}, {h}: {got} vs {want}");
    }
}

#[test]
fn form_factors_are_reciprocal() {
    // A_i F_ij = A_j F_ji with visibility, on random pairs of the Cornell
    // box's patches (the blocks occlude some of them).
    let scene = cornell();
    let r = compile(&scene, 0.3, DEFAULT_THRESHOLD);
    let p = r.patches();
    let mut state = 12345u64;
    let mut checked = 0;
    for _ in 0..20000 {
        state = hierarchy::mix(state);
        let (i, j) = ((state % p.len() as u64) as usize, ((state >> 32) % p.len() as u64) as usize);
        if i == j {
            continue;
        }
        let fij = factors::form_factor(&p[i], &p[j]) * factors::visibility(scene.geometry(), p, i, j, 3);
        let fji = factors::form_factor(&p[j], &p[i]) * factors::visibility(scene.geometry(), p, j, i, 3);
        let (a, b) = (p[i].area * fij, p[j].area * fji);
        // Far pairs use the symmetric point formula; near ones integrate
        // over the receiver only, to within the quadrature's error.
        let tol = if factors::is_near(&p[i], &p[j]) { 0.02 } else { 1e-4 };
        assert!((a - b).abs() <= tol * a.max(b) + 1e-4 * p[i].area.min(p[j].area), "{i} {j}: {a} vs {b}");
        checked += (fij > 0.0) as u32;
    }
    assert!(checked > 500, "too few pairs see each other: {checked}");
}

const DEFAULT_THRESHOLD: f32 = crate::integrator::DEFAULT_LINK_THRESHOLD;

/// Inside a closed cube every patch sees all the rest: Σ_j F_ij = 1.
#[test]
fn form_factors_in_a_closed_box_sum_to_one() {
    let (o, x, y, z) = (Vec3::ZERO, Vec3::X * 2.0, Vec3::Y * 2.0, Vec3::Z * 2.0);
    let scene = quads(&[
        Shape::quad(o, x, z),
        Shape::quad(o + y, x, z),
        Shape::quad(o, x, y),
        Shape::quad(o + z, x, y),
        Shape::quad(o, y, z),
        Shape::quad(o + x, y, z),
    ]);
    for threshold in [0.0, DEFAULT_THRESHOLD] {
        let r = compile(&scene, 0.2, threshold);
        let n = r.patches().len();
        assert_eq!(n, 600, "the outer sides see nothing and are dropped");
        let mut mean = 0.0;
        for i in 0..n {
            let sum: f32 = r.links().of(i).map(|l| l.factor).sum();
            assert!((sum - 1.0).abs() < 0.05, "patch {i}: Σ F = {sum}");
            mean += sum as f64 / n as f64;
        }
        assert!((mean - 1.0).abs() < 0.01, "threshold {threshold}: mean Σ F = {mean}");
    }
}

/// Mean over patches of |E_h − E_full| / E_full (all channels), over
/// patches whose E_full exceeds 1% of the mean.
fn relative_error(a: &[Rgb], full: &[Rgb]) -> f64 {
    let mean: f64 = full.iter().map(|e| e.element_sum() as f64).sum::<f64>() / full.len() as f64;
    let (mut sum, mut count) = (0.0, 0);
    for (a, b) in a.iter().zip(full) {
        if b.element_sum() as f64 > 0.01 * mean {
            sum += ((a.element_sum() - b.element_sum()) / b.element_sum()).abs() as f64;
            count += 1;
        }
    }
    sum / count as f64
}

#[test]
fn hierarchy_matches_the_full_solution() {
    let scene = cornell();
    let mut full = compile(&scene, 0.3, 0.0);
    full.update(&scene, 2);
    let mut h = compile(&scene, 0.3, DEFAULT_THRESHOLD);
    h.update(&scene, 2);
    assert_eq!(h.patches(), full.patches());
    assert!(h.stats().links * 3 < full.stats().links, "clusters save links");
    let err = relative_error(h.indirect_irradiance(), full.indirect_irradiance());
    eprintln!("hierarchy: mean relative error {err}, links {} of {}", h.stats().links, full.stats().links);
    assert!(err <= 0.02, "mean relative error {err}");
}

#[test]
fn receiver_clusters_keep_energy() {
    // With clusters receiving too, each patch's total form factor (what it
    // and its ancestors gather per unit radiosity) stays near that of the
    // patch-only solution.
    let mut scene = cornell();
    for m in scene.materials_mut() {
        *m = Material::diffuse(Rgb::ONE);
    }
    let params = CompileParams { receiver_share: 0.5, ..CompileParams::for_scene(&scene, &options(0.3)) };
    let mut with = Radiosity::compile_with(&scene, params).unwrap();
    with.update(&scene, 1);
    let mut without = compile(&scene, 0.3, DEFAULT_THRESHOLD);
    without.update(&scene, 1);
    let cluster_receivers =
        (with.patches().len()..with.links().offsets.len() - 1).filter(|&r| with.links().of(r).len() > 0).count();
    assert!(cluster_receivers > 0);
    let total = |r: &Radiosity| -> f64 {
        r.indirect_irradiance().iter().zip(r.patches()).map(|(e, p)| (e.element_sum() * p.area) as f64).sum()
    };
    let (a, b) = (total(&with), total(&without));
    assert!((a / b - 1.0).abs() < 0.03, "{a} vs {b}");
}

#[test]
fn large_scenes_let_clusters_receive_and_stay_near_the_patch_only_solution() {
    // The default: patches alone receive at the Cornell box's 7k patches,
    // flat clusters too past RECEIVER_CLUSTERS_FROM.
    let scene = cornell();
    assert_eq!(CompileParams::for_scene(&scene, &options(0.165)).receiver_share, 0.0);
    assert_eq!(CompileParams::for_scene(&scene, &options(0.044)).receiver_share, LARGE_RECEIVER_SHARE);
    // At 12k patches the large-scene share keeps the one-bounce light within
    // a few per cent of the patch-only solution on the same patches (2.5%
    // area-weighted at 100k and 300k patches, docs/radiosity-bench.md),
    // with fewer links.
    let mut without = compile(&scene, 0.125, DEFAULT_THRESHOLD);
    without.update(&scene, 1);
    let params = CompileParams { receiver_share: LARGE_RECEIVER_SHARE, ..without.params() };
    let mut with = Radiosity::compile_with(&scene, params).unwrap();
    with.update(&scene, 1);
    assert_eq!(with.patches(), without.patches());
    assert!(with.stats().links * 4 < without.stats().links * 3, "{} vs {}", with.stats().links, without.stats().links);
    let area_weighted = |r: &Radiosity| -> (f64, f64) {
        let pairs = r.indirect_irradiance().iter().zip(without.indirect_irradiance()).zip(r.patches());
        pairs.fold((0.0, 0.0), |(d, t), ((a, b), p)| {
            let (a, b, w) = (a.element_sum() as f64, b.element_sum() as f64, p.area as f64);
            (d + (a - b).abs() * w, t + b * w)
        })
    };
    let (difference, total) = area_weighted(&with);
    eprintln!(
        "receiver share {LARGE_RECEIVER_SHARE}: {} links of {}, area-weighted difference {:.2}%",
        with.stats().links,
        without.stats().links,
        100.0 * difference / total
    );
    assert!(difference < 0.03 * total, "{:.2}%", 100.0 * difference / total);
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let scene = cornell();
    // Patches alone receiving, and clusters too (the large-scene default).
    for share in [0.0, LARGE_RECEIVER_SHARE] {
        let run = |threads| {
            rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
                let params = CompileParams {
                    patch_size: 0.4,
                    link_threshold: DEFAULT_THRESHOLD,
                    receiver_share: share,
                    seed: 1,
                };
                let mut r = Radiosity::compile_with(&scene, params).unwrap();
                r.update(&scene, 1);
                (r.links().clone(), r.indirect_irradiance().to_vec())
            })
        };
        assert_eq!(run(1), run(3), "receiver share {share}");
    }
}

/// The largest change of the interpolated irradiance between points `step`
/// apart along a line across the floor, over the mean.
fn largest_step(r: &Radiosity, step: f32) -> f32 {
    let mut values = Vec::new();
    let mut x = 0.3;
    while x < 5.3 {
        let e = r.irradiance_at(vec3(x, 0.0, 0.8), Vec3::Y).unwrap();
        values.push(e.element_sum());
        x += step;
    }
    let mean = values.iter().sum::<f32>() / values.len() as f32;
    values.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f32::max) / mean
}

#[test]
fn shading_is_continuous_across_patches() {
    // Continuous shading changes by less when the step shrinks (about in
    // proportion); a jump at a patch edge would not shrink at all. Nearest-
    // patch lookup fails this.
    let scene = cornell();
    let r = Radiosity::compile(&scene, &options(0.3)).unwrap();
    let h = r.params().patch_size;
    let coarse = largest_step(&r, h / 10.0);
    let fine = largest_step(&r, h / 80.0);
    assert!(fine > 0.0 && coarse > 4.0 * fine, "{coarse} vs {fine}");
}

#[test]
fn a_moved_light_needs_no_recompile() {
    // Updating with moved lights gives what compiling anew with those lights
    // gives; so does a changed albedo. (A point light, whose moving leaves
    // the geometry the links were made against as it was.)
    let mut scene = cornell();
    let quad_centre = scene.lights()[0].position().unwrap();
    scene.set_lights(&[Light::point(quad_centre - Vec3::Y * 0.1, Rgb::splat(30.0))]);
    let mut r = Radiosity::compile(&scene, &options(0.4)).unwrap();
    let before = r.indirect_irradiance().to_vec();
    let moved: Vec<Light> = scene.lights().iter().map(|l| l.moved_to(vec3(1.5, 5.0, 4.0))).collect();
    assert!(!scene.set_lights(&moved), "a point light has no surface in the BVH");
    r.update(&scene, 1);
    assert_ne!(r.indirect_irradiance(), &before[..]);
    scene.materials_mut()[0] = Material::diffuse(Rgb::new(0.2, 0.9, 0.3));
    r.update(&scene, 1);
    let fresh = Radiosity::compile(&scene, &options(0.4)).unwrap();
    assert_eq!(r.indirect_irradiance(), fresh.indirect_irradiance());
}

#[test]
fn bfloat16_factors_round_to_nearest() {
    assert_eq!(links::to_bf16(1.0), 0x3f80);
    let mut state = 99u64;
    let mut mean_error = 0.0f64;
    for _ in 0..10_000 {
        state = hierarchy::mix(state);
        let x = f32::from_bits(0x3000_0000 + (state as u32 % 0x0f00_0000));
        let y = links::from_bf16(links::to_bf16(x));
        let rel = (y - x) / x;
        assert!(rel.abs() <= 1.0 / 256.0, "{x} → {y}");
        mean_error += rel as f64 / 10_000.0;
    }
    assert!(mean_error.abs() < 1e-4, "biased: {mean_error}");
}

#[test]
fn too_small_a_patch_size_is_refused_before_cutting() {
    let scene = cornell();
    let e = Radiosity::compile(&scene, &options(1e-4)).unwrap_err();
    assert!(e.to_string().contains("choose a larger patch_size"), "{e}");
    // The count matches what cutting makes, before the sides are culled.
    let r = compile(&scene, 0.3, DEFAULT_THRESHOLD);
    let square = scene.bounds();
    let counted: f64 = scene.objects().iter().map(|(s, _)| patches::count(s, 0.3, square)).sum();
    assert_eq!(counted as usize, r.stats().patches + r.stats().dropped);
}
