//! Primary-ray throughput on a mesh of over a million triangles.
//!
//! `cargo run --release --example bench_bvh [-- SUBDIVISIONS] [--no-reference] [--dump-rays DIR]`
//!
//! Builds a displaced sphere (a UV sphere with SUBDIVISIONS² quads, default
//! 750² → 1.12 M triangles, radius modulated by a sum of sines), prints
//! the tree's shape and its expected visits per ray, frames it
//! with a camera and traces one coherent primary ray per pixel of a
//! 1024×1024 image, in 8×8 blocks, then one shadow ray from each hit toward
//! a point light, each on one thread and then on all threads: in packets
//! (`intersect_packet`, `occluded_packet`, 256 rays a call) with each lane
//! width the processor has, widest first (sixteen rays at a time with
//! AVX-512, eight with AVX, four with SSE), and one ray at a time
//! (`intersect`, `occluded`). Then incoherent rays: from each hit a
//! diffuse bounce into the mesh (across its inside, as rays between the
//! walls of a room) and one out of it, one ray at a time and in packets
//! (`tools/mitsuba_rays.py` traces the same through Mitsuba). Last, the
//! camera and shadow rays through obvhs's compressed 8-wide BVH and its
//! traversal (what Airlight used before its own wide tree), unless
//! `--no-reference` is given. In between, the whole
//! render of that image with the direct integrator (camera ray, shadow ray
//! and shading; the scene of `tools/mesh_scene.py`) on all threads, with
//! samples handed over in blocks (packets) and one by one.
//!
//! Each ray throughput is the median of 7 timed passes (with the range of
//! the one-thread passes): on a shared machine one pass of about 0.1 s can
//! be a third off.
//!
//! With `--dump-rays DIR` it writes the mesh and the bounce rays to DIR
//! (`bounce_in.bin`, `bounce_out.bin`) and stops: `tools/embree_rays.c`
//! traces them through Embree one at a time, for the figure against it.

use airlight::geometry::{GeometryBuilder, Hit, LaneWidth, Ray, Segment, Shape, intersect_triangle, offset_origin};
use airlight::integrator::{Direct, Integrator};
use airlight::prelude::*;
use glam::Vec2;
use rayon::prelude::*;
use std::time::Instant;

fn displaced_sphere(n: u32) -> Shape {
    let mut positions = Vec::with_capacity(((n + 1) * (n + 1)) as usize);
    for i in 0..=n {
        let theta = std::f32::consts::PI * i as f32 / n as f32;
        for j in 0..=n {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / n as f32;
            let dir = vec3(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            let r = 1.0 + 0.05 * (7.0 * theta).sin() * (9.0 * phi).sin() + 0.02 * (31.0 * theta + 3.0 * phi).sin();
            positions.push(dir * r);
        }
    }
    let mut triangles = Vec::with_capacity((2 * n * n) as usize);
    for i in 0..n {
        for j in 0..n {
            let a = i * (n + 1) + j;
            let b = a + n + 1;
            triangles.push([a, b, a + 1]);
            triangles.push([a + 1, b, b + 1]);
        }
    }
    Shape::Mesh { positions, triangles, uvs: Vec::new(), normals: Vec::new() }
}

fn main() {
    let n: u32 = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(750);
    let t = Instant::now();
    let mesh = displaced_sphere(n);
    let Shape::Mesh { triangles, .. } = &mesh else { unreachable!() };
    let tris = triangles.len();
    let mut builder = GeometryBuilder::default();
    builder.add(&mesh, 0, None);
    let generated = t.elapsed();
    let t = Instant::now();
    let geometry = builder.build();
    let build = t.elapsed();
    println!(
        "mesh: {tris} triangles (generated in {:.2} s), BVH built in {:.2} s",
        generated.as_secs_f64(),
        build.as_secs_f64()
    );
    if let Some(shape) = geometry.tree_shape() {
        println!("tree: {shape}");
    }

    let (w, h) = (1024u32, 1024u32);
    let camera = Camera::look_at(vec3(0.0, 0.6, -3.2), Vec3::ZERO, Vec3::Y, 40.0);
    // Rays in 8×8 blocks, each in Z order (every four rays a 2×2 square),
    // as the renderer issues them.
    let mut rays = Vec::with_capacity((w * h) as usize);
    for ty in (0..h).step_by(8) {
        for tx in (0..w).step_by(8) {
            for (dx, dy) in airlight::render::BLOCK_ORDER {
                let (x, y) = (tx + dx, ty + dy);
                rays.push(camera.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), w, h, Vec2::ZERO));
            }
        }
    }
    let threads = rayon::current_num_threads();
    let hit_points: Vec<Option<(Vec3, Vec3)>> = rays
        .iter()
        .map(|ray| geometry.intersect(ray, f32::INFINITY).map(|hit| (ray.at(hit.t), geometry.surface(ray, hit).n)))
        .collect();
    // Incoherent rays: from each hit, a diffuse bounce (cosine-weighted
    // about the normal) into the mesh, across its inside as between the
    // walls of a room, and one out of it, back toward the camera.
    let bounce = |inward: bool| -> Vec<Ray> {
        rays.iter()
            .zip(&hit_points)
            .filter_map(|(ray, hit)| hit.map(|(p, n)| (ray, p, n)))
            .enumerate()
            .map(|(i, (ray, p, n))| {
                let along = if n.dot(ray.dir) < 0.0 { -n } else { n };
                let normal = if inward { along } else { -along };
                let dir = (normal + uniform_sphere(bounce_numbers(i as u64))).normalize();
                Ray::new(offset_origin(p, normal, dir), dir)
            })
            .collect()
    };
    let (bounce_in, bounce_out) = (bounce(true), bounce(false));
    if let Some(dir) = std::env::args().skip_while(|a| a != "--dump-rays").nth(1) {
        let Shape::Mesh { positions, triangles, .. } = &mesh else { unreachable!() };
        for (name, rays) in [("bounce_in.bin", &bounce_in), ("bounce_out.bin", &bounce_out)] {
            let path = std::path::Path::new(&dir).join(name);
            if let Err(e) = std::fs::write(&path, ray_file(positions, triangles, rays)) {
                eprintln!("error: cannot write {}: {e}", path.display());
                std::process::exit(1);
            }
            println!("wrote {} ({} rays)", path.display(), rays.len());
        }
        return;
    }
    let hits = hit_points.iter().filter(|h| h.is_some()).count();
    println!("{} primary rays, {:.1}% hit the mesh", rays.len(), 100.0 * hits as f64 / rays.len() as f64);
    // One shadow ray from each hit toward a point light, as direct lighting
    // issues them.
    let light = vec3(2.0, 3.0, -3.0);
    let shadow: Vec<Segment> = hit_points
        .iter()
        .flatten()
        .map(|&(p, n)| {
            let origin = offset_origin(p, n, light - p);
            let to = light - origin;
            Segment { origin, dir: to.normalize(), tmax: to.length() }
        })
        .collect();

    let primary = |rays: &[Ray]| rays.iter().map(|ray| geometry.intersect(ray, f32::INFINITY).is_some() as u64).sum();
    let occluded =
        |segments: &[Segment]| segments.iter().map(|s| geometry.occluded(s.origin, s.dir, s.tmax) as u64).sum();
    // A packet query on the given lanes as a count of hits.
    let geometry = &geometry;
    let primary_with = |lanes: LaneWidth| {
        move |rays: &[Ray]| {
            let mut hits: [Option<Hit>; CHUNK] = [None; CHUNK];
            let hits = &mut hits[..rays.len()];
            geometry.intersect_packet_on(lanes, rays, f32::INFINITY, hits);
            hits.iter().filter(|h| h.is_some()).count() as u64
        }
    };
    let occluded_with = |lanes: LaneWidth| {
        move |segments: &[Segment]| {
            let mut blocked = [false; CHUNK];
            let blocked = &mut blocked[..segments.len()];
            geometry.occluded_packet_on(lanes, segments, blocked);
            blocked.iter().filter(|&&b| b).count() as u64
        }
    };
    let p = time(&rays, primary);
    let s = time(&shadow, occluded);
    // Each lane width this processor has, widest (the queries' default) first.
    let mut widths =
        LaneWidth::ALL.into_iter().filter(|l| l.available() && *l != LaneWidth::Portable).collect::<Vec<_>>();
    widths.reverse();
    let mut by_width = Vec::new();
    for lanes in widths {
        let pp = time(&rays, primary_with(lanes));
        let sp = time(&shadow, occluded_with(lanes));
        assert_eq!((pp.sum, sp.sum), (p.sum, s.sum), "{lanes:?}-lane packets and single rays disagree on hits");
        report(&format!("Airlight BVH8, packets of coherent rays, {lanes:?} lanes"), &pp, &sp, threads);
        by_width.push((lanes, pp, sp));
    }
    let (widest, pp, sp) = &by_width[0];
    for (lanes, pp_n, sp_n) in &by_width[1..] {
        println!(
            "packets, {widest:?} lanes against {lanes:?}, per CPU second, 1 thread: primary {:.2}×, shadow {:.2}×",
            pp_n.one_cpu / pp.one_cpu,
            sp_n.one_cpu / sp.one_cpu
        );
    }
    report("Airlight BVH8, one ray at a time", &p, &s, threads);
    println!("  {:.1}% of shadow rays blocked", 100.0 * s.sum as f64 / shadow.len() as f64);
    println!(
        "packets against one ray at a time, per CPU second, 1 thread: primary {:.2}×, shadow {:.2}×",
        p.one_cpu / pp.one_cpu,
        s.one_cpu / sp.one_cpu
    );

    for (name, bounce) in [("bounce rays into the mesh", &bounce_in), ("bounce rays out of it", &bounce_out)] {
        let one = time(bounce, |rays: &[Ray]| {
            rays.iter().map(|ray| geometry.intersect(ray, f32::INFINITY).is_some() as u64).sum()
        });
        let packets = time(bounce, primary_with(LaneWidth::widest()));
        assert_eq!(one.sum, packets.sum, "{name}: packets and single rays disagree on hits");
        println!(
            "{name} ({} rays, {:.1}% hit; medians of {PASSES} passes):",
            bounce.len(),
            100.0 * one.sum as f64 / bounce.len() as f64
        );
        let m = bounce.len() as f64 / 1e6;
        for (kind, t) in [("one ray at a time", &one), ("packets", &packets)] {
            println!(
                "  {kind:17} 1 thread: {:6.2} M rays/s   {threads} threads: {:6.2} M rays/s",
                m / t.one,
                m / t.all
            );
        }
    }

    render_direct(mesh.clone(), camera, light, w, h);

    // The traversal Airlight used before: obvhs's compressed 8-wide BVH and
    // its own traversal over the same triangles, for a side-by-side figure.
    if std::env::args().any(|a| a == "--no-reference") {
        return;
    }
    let tris: Vec<obvhs::triangle::Triangle> = triangles
        .iter()
        .map(|t| {
            let Shape::Mesh { positions, .. } = &mesh else { unreachable!() };
            let [v0, v1, v2] = t.map(|i| positions[i as usize].into());
            obvhs::triangle::Triangle { v0, v1, v2 }
        })
        .collect();
    let t = Instant::now();
    let cwbvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(
        &tris,
        obvhs::BvhBuildParams::medium_build(),
        &mut std::time::Duration::default(),
    );
    let tris: Vec<[Vec3; 3]> = cwbvh
        .primitive_indices
        .iter()
        .map(|&i| {
            let t = &tris[i as usize];
            let v0 = Vec3::from(t.v0);
            [v0, Vec3::from(t.v1) - v0, Vec3::from(t.v2) - v0]
        })
        .collect();
    println!("reference CWBVH built in {:.2} s", t.elapsed().as_secs_f64());
    let bvh_ray = |o: Vec3, d: Vec3, tmax: f32| {
        obvhs::ray::Ray::new(o.into(), glam::Vec3A::from(d) + glam::Vec3A::ZERO, 0.0, tmax)
    };
    let primary_ref = |rays: &[Ray]| {
        rays.iter()
            .map(|ray| {
                let mut hit = obvhs::ray::RayHit::none();
                cwbvh.ray_traverse(bvh_ray(ray.origin, ray.dir, f32::INFINITY), &mut hit, |r, id| {
                    let [v0, e1, e2] = tris[id];
                    intersect_triangle(v0, e1, e2, ray.origin, ray.dir, 0.0, r.tmax)
                }) as u64
            })
            .sum()
    };
    let occluded_ref = |segments: &[Segment]| {
        segments
            .iter()
            .map(|&Segment { origin: o, dir: d, tmax }| {
                !cwbvh.ray_traverse_miss(bvh_ray(o, d, tmax), |r, id| {
                    let [v0, e1, e2] = tris[id];
                    intersect_triangle(v0, e1, e2, o, d, 0.0, r.tmax)
                }) as u64
            })
            .sum()
    };
    let pr = time(&rays, primary_ref);
    let sr = time(&shadow, occluded_ref);
    assert_eq!((pr.sum, sr.sum), (p.sum, s.sum), "the two traversals disagree on hits");
    report("obvhs CWBVH (before)", &pr, &sr, threads);
    println!(
        "against obvhs, per CPU second, 1 thread: one ray at a time primary {:.2}×, shadow {:.2}×; packets primary {:.2}×, shadow {:.2}×",
        pr.one_cpu / p.one_cpu,
        sr.one_cpu / s.one_cpu,
        pr.one_cpu / pp.one_cpu,
        sr.one_cpu / sp.one_cpu
    );
}

/// Two numbers in [0, 1) for bounce `i`: SplitMix64 of i + 1 (Steele, Lea
/// and Flood 2014), its top and next 24 bits, so that
/// `tools/mitsuba_rays.py` draws the same bounces.
fn bounce_numbers(i: u64) -> glam::Vec2 {
    let mut z = (i + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    let unit = |bits: u64| bits as f32 / (1u32 << 24) as f32;
    glam::Vec2::new(unit(z >> 40), unit((z >> 8) & 0xff_ffff))
}

/// The mesh and rays for `tools/embree_rays.c`, little-endian: the vertex
/// count and the vertices (3 f32 each), the triangle count and the
/// triangles (3 u32 each), the ray count and the rays (origin and
/// direction, 6 f32 each).
fn ray_file(positions: &[Vec3], triangles: &[[u32; 3]], rays: &[Ray]) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(&(positions.len() as u32).to_le_bytes());
    positions.iter().flat_map(|p| p.to_array()).for_each(|x| out.extend_from_slice(&x.to_le_bytes()));
    out.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    triangles.iter().flatten().for_each(|i| out.extend_from_slice(&i.to_le_bytes()));
    out.extend_from_slice(&(rays.len() as u32).to_le_bytes());
    for r in rays {
        r.origin.to_array().iter().chain(&r.dir.to_array()).for_each(|x| out.extend_from_slice(&x.to_le_bytes()));
    }
    out
}

/// A uniform direction: z = 1 − 2u, the azimuth 2πv.
fn uniform_sphere(u: glam::Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * u.y;
    vec3(r * phi.cos(), r * phi.sin(), z)
}

/// The CPU time this thread or process has used: rates per CPU second hold
/// while other programs share the cores, where wall-clock rates do not.
fn cpu_seconds(clock: libc::clockid_t) -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes one timespec to a valid pointer.
    unsafe { libc::clock_gettime(clock, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// Timed runs: wall seconds on one thread, that thread's CPU seconds, wall
/// seconds on all threads, the process's CPU seconds for it (each the
/// median of [`PASSES`] passes), the summed result and the number of rays.
struct Timing {
    one: f64,
    one_cpu: f64,
    /// The fastest and slowest pass's CPU seconds on one thread.
    one_cpu_range: (f64, f64),
    all: f64,
    all_cpu: f64,
    sum: u64,
    n: usize,
}

/// Rays handed over per call (and per parallel task).
const CHUNK: usize = 256;

/// Passes timed, each way: one pass over a million rays on one thread
/// takes about 0.1 s, short enough for another process's burst to move a
/// single figure by a third; the median of several holds still.
const PASSES: usize = 7;

/// Times `f` over `items` in chunks of [`CHUNK`], summing what it returns.
fn time<T: Sync>(items: &[T], f: impl Fn(&[T]) -> u64 + Sync) -> Timing {
    let warm: u64 = items[..items.len().min(100_000)].chunks(CHUNK).map(&f).sum();
    std::hint::black_box(warm);
    let (mut one, mut one_cpu, mut all, mut all_cpu) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut sum = 0;
    for _ in 0..PASSES {
        let (t, c) = (Instant::now(), cpu_seconds(libc::CLOCK_THREAD_CPUTIME_ID));
        sum = items.chunks(CHUNK).map(&f).sum();
        one.push(t.elapsed().as_secs_f64());
        one_cpu.push(cpu_seconds(libc::CLOCK_THREAD_CPUTIME_ID) - c);
        let (t, c) = (Instant::now(), cpu_seconds(libc::CLOCK_PROCESS_CPUTIME_ID));
        let all_sum: u64 = items.par_chunks(CHUNK).map(&f).sum();
        all.push(t.elapsed().as_secs_f64());
        all_cpu.push(cpu_seconds(libc::CLOCK_PROCESS_CPUTIME_ID) - c);
        assert_eq!(sum, all_sum);
    }
    let one_cpu_range = (min(&one_cpu), max(&one_cpu));
    Timing {
        one: median(one),
        one_cpu: median(one_cpu),
        one_cpu_range,
        all: median(all),
        all_cpu: median(all_cpu),
        sum,
        n: items.len(),
    }
}

fn median(mut seconds: Vec<f64>) -> f64 {
    seconds.sort_by(f64::total_cmp);
    seconds[seconds.len() / 2]
}

fn min(seconds: &[f64]) -> f64 {
    seconds.iter().copied().fold(f64::INFINITY, f64::min)
}

fn max(seconds: &[f64]) -> f64 {
    seconds.iter().copied().fold(0.0, f64::max)
}

fn report(name: &str, primary: &Timing, shadow: &Timing, threads: usize) {
    println!("{name} (medians of {PASSES} passes):");
    for (kind, t) in [("primary", primary), ("shadow", shadow)] {
        let m = t.n as f64 / 1e6;
        let (fastest, slowest) = t.one_cpu_range;
        println!(
            "  {kind:7} 1 thread: {:6.2} M rays/s ({:6.2} per CPU s, passes {:.2}-{:.2})   {threads} threads: {:6.2} M rays/s ({:6.2} per CPU s)",
            m / t.one,
            m / t.one_cpu,
            m / slowest,
            m / fastest,
            m / t.all,
            m / t.all_cpu
        );
    }
}

/// The direct integrator as it was before packets: one sample at a time
/// (the trait's default `radiance_batch`).
struct OneByOne;

impl Integrator for OneByOne {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut airlight::sampling::Sampler) -> Rgb {
        Direct.radiance(scene, ray, sampler)
    }
}

/// Renders the mesh under a point light with `direct`, 1 spp, on all
/// threads: blocks of samples traced as packets, then one by one; three
/// times each, alternating, the fastest kept. The images must be the same.
fn render_direct(mesh: Shape, camera: Camera, light: Vec3, w: u32, h: u32) {
    let scene = SceneBuilder::new()
        .size(w, h)
        .with_settings(|s| s.spp = 1)
        .camera(camera)
        .material("grey", Material::diffuse(Rgb::splat(0.7)))
        .object(mesh, "grey")
        .light(Light::point(light, Rgb::splat(20.0)))
        .build()
        .expect("the mesh scene builds");
    let mut best = [f64::INFINITY; 2];
    let mut images: [Option<Image>; 2] = [None, None];
    for _ in 0..3 {
        for (k, integrator) in [&Direct as &dyn Integrator, &OneByOne].into_iter().enumerate() {
            let t = Instant::now();
            let image = render(&scene, integrator, &RenderObserver::none());
            best[k] = best[k].min(t.elapsed().as_secs_f64());
            images[k] = Some(image);
        }
    }
    assert!(images[0] == images[1], "the packet render differs from the one-by-one render");
    println!(
        "direct render, {w}×{h}, 1 spp, {} threads, fastest of 3: packets {:.3} s, one by one {:.3} s ({:.2}×)",
        rayon::current_num_threads(),
        best[0],
        best[1],
        best[1] / best[0]
    );
}
