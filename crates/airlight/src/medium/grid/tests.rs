use super::*;
use crate::sampling::Sampler;

/// A grid of `values` in the box [0, n]·`voxel` at the origin, unrotated.
fn grid(resolution: [usize; 3], values: Vec<f32>, voxel: f32) -> DensityGrid {
    let n = Vec3::new(resolution[0] as f32, resolution[1] as f32, resolution[2] as f32);
    DensityGrid::new(resolution, values, Vec3::ZERO, n * voxel, Affine3A::IDENTITY).unwrap()
}

/// A smooth random grid: a few random sinusoids, sampled at voxel centres.
pub(crate) fn smooth_random(resolution: [usize; 3], seed: u64) -> Vec<f32> {
    let mut s = Sampler::for_pixel(seed, 0, 0);
    let waves: Vec<(Vec3, f32)> =
        (0..4).map(|_| (Vec3::new(s.next(), s.next(), s.next()) * 0.6, s.next() * 6.0)).collect();
    let mut values = Vec::new();
    for z in 0..resolution[2] {
        for y in 0..resolution[1] {
            for x in 0..resolution[0] {
                let p = Vec3::new(x as f32, y as f32, z as f32);
                let v: f32 = waves.iter().map(|(k, phase)| (k.dot(p) + phase).sin()).sum::<f32>();
                values.push((1.0 + 0.25 * v).max(0.0) * 0.8);
            }
        }
    }
    values
}

/// Composite Simpson over [a, b], n even.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut sum = f(a) + f(b);
    for i in 1..n {
        sum += f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

#[test]
fn values_sit_at_voxel_centres_and_are_clamped_to_the_box() {
    // Two voxels along x, 0 and 1, in the box [0, 2]: centres at 0.5, 1.5.
    let g = grid([2, 1, 1], vec![0.0, 1.0], 1.0);
    let at = |x: f32| g.density(Vec3::new(x, 0.5, 0.5));
    assert_eq!(at(0.1), 0.0, "clamped between the face and the first centre");
    assert_eq!(at(0.5), 0.0);
    assert_eq!(at(1.0), 0.5, "halfway between centres");
    assert_eq!(at(1.25), 0.75);
    assert_eq!(at(1.5), 1.0);
    assert_eq!(at(1.99), 1.0);
    assert_eq!(at(2.01), 0.0, "vacuum outside");
    assert_eq!(at(-0.01), 0.0);
    assert_eq!(g.density(Vec3::new(1.5, 1.5, 0.5)), 0.0);
}

/// A multilinear function of the voxel coordinates, which the trilinear
/// interpolant of its values at the centres reproduces exactly: every
/// corner of a cell weighs in, so a corner read in the wrong place shows.
fn multilinear(x: f64, y: f64, z: f64) -> f64 {
    1.0 + 2.0 * x + 3.0 * y + 5.0 * z + 7.0 * x * y + 11.0 * y * z + 13.0 * x * z + 17.0 * x * y * z
}

#[test]
fn density_and_its_integral_reproduce_a_multilinear_function_between_centres() {
    // Two voxels a side, centres at 0.5 and 1.5: one whole cell between them.
    let mut values = Vec::new();
    for k in 0..2 {
        for j in 0..2 {
            for i in 0..2 {
                values.push(multilinear(i as f64, j as f64, k as f64) as f32);
            }
        }
    }
    let g = grid([2, 2, 2], values, 1.0);
    let mut s = Sampler::for_pixel(4, 0, 0);
    for _ in 0..200 {
        let u = Vec3::new(s.next(), s.next(), s.next());
        let expected = multilinear(u.x as f64, u.y as f64, u.z as f64);
        let got = g.density(u + 0.5) as f64;
        assert!((got - expected).abs() < 1e-5 * expected, "at {u}: {got} against {expected}");
    }
    // Chords of the cell between the centres, against Simpson on the
    // function itself.
    for _ in 0..40 {
        let (a, b) = (Vec3::new(s.next(), s.next(), s.next()), Vec3::new(s.next(), s.next(), s.next()));
        let (length, d) = ((b - a).length(), (b - a).normalize());
        let o = a + 0.5;
        let exact = g.integral(o, d, 0.0, length);
        let on_chord = |t: f64| {
            let q = a.as_dvec3() + d.as_dvec3() * t;
            multilinear(q.x, q.y, q.z)
        };
        let numeric = simpson(on_chord, 0.0, length as f64, 2_000);
        assert!((exact - numeric).abs() < 1e-5 * numeric.max(1.0), "{exact} against {numeric}");
    }
}

#[test]
fn the_integral_of_two_constant_halves_is_the_hand_computed_one() {
    // 8 voxels of size 0.25 along x: 4 of a, 4 of b. Across the whole box
    // the density is a for 3.5 voxels, a ramp from a to b over one, b for
    // 3.5: (a + b)·4·0.25 = a + b.
    let (a, b) = (0.3f32, 2.0f32);
    let values = (0..8).map(|i| if i < 4 { a } else { b }).collect();
    let g = grid([8, 1, 1], values, 0.25);
    let through = g.integral(Vec3::new(-1.0, 0.1, 0.1), Vec3::X, 0.0, 10.0);
    assert!((through - (a + b) as f64).abs() < 1e-6, "{through}");
    // Along y through the a half, one voxel thick: a·0.25.
    let across = g.integral(Vec3::new(0.3, -5.0, 0.1), Vec3::Y, 0.0, f32::INFINITY);
    assert!((across - (a * 0.25) as f64).abs() < 1e-7, "{across}");
}

#[test]
fn the_integral_is_exact_for_the_trilinear_density_on_any_ray() {
    let resolution = [7, 5, 6];
    let g = DensityGrid::new(
        resolution,
        smooth_random(resolution, 3),
        Vec3::new(-1.0, 0.0, -2.0),
        Vec3::new(1.5, 1.0, 1.0),
        Affine3A::from_rotation_y(0.4) * Affine3A::from_translation(Vec3::new(0.2, 0.1, 0.0)),
    )
    .unwrap();
    let mut s = Sampler::for_pixel(9, 1, 0);
    for _ in 0..40 {
        let o = Vec3::new(s.next() - 0.5, s.next(), s.next() - 0.5) * 6.0;
        let target = Vec3::new(s.next() - 0.5, s.next(), s.next() - 0.5) * 1.5;
        let d = (target - o).normalize();
        let (t0, t1) = (0.3f32, 5.0 + 4.0 * s.next());
        let exact = g.integral(o, d, t0, t1);
        // Simpson on a fine uniform grid, which knows nothing of voxels.
        let numeric = simpson(|t| g.density(o + d * t as f32) as f64, t0 as f64, t1 as f64, 200_000);
        assert!((exact - numeric).abs() < 2e-4 * (1.0 + numeric), "{exact} vs {numeric}");
    }
}

#[test]
fn majorant_cells_bound_the_density_and_cover_the_box() {
    let resolution = [20, 9, 33];
    let values = smooth_random(resolution, 5);
    let mut g = DensityGrid::new(resolution, values, Vec3::ZERO, Vec3::new(2.0, 1.0, 3.0), Affine3A::IDENTITY).unwrap();
    for cells in [16, 4, 1] {
        g.set_majorant_resolution(cells);
        let mut s = Sampler::for_pixel(2, cells as u64, 0);
        for _ in 0..50 {
            let o = Vec3::new(-1.0, s.next() * 1.0, s.next() * 3.0);
            let d = Vec3::new(1.0, s.next() - 0.5, s.next() - 0.5).normalize();
            let (lo, hi) = g.clip(o, d, 0.0, 100.0).map_or((0.0, 0.0), |c| c);
            let mut covered = lo;
            g.majorant_segments(o, d, 0.0, 100.0, |a, b, bound| {
                assert!((a - covered).abs() < 1e-5, "segments follow each other");
                covered = b;
                for k in 0..=8 {
                    let t = a + (b - a) * k as f32 / 8.0;
                    assert!(g.density(o + d * t) <= bound + 1e-6);
                }
                true
            });
            assert!((covered - hi).abs() < 1e-5);
        }
    }
}

#[test]
fn bad_grids_are_refused() {
    let ok =
        |values: Vec<f32>| DensityGrid::new([2, 1, 1], values, Vec3::ZERO, Vec3::ONE, Affine3A::IDENTITY).is_some();
    assert!(ok(vec![0.0, 1.0]));
    assert!(!ok(vec![0.0]));
    assert!(!ok(vec![0.0, -1.0]));
    assert!(!ok(vec![0.0, f32::NAN]));
    assert!(DensityGrid::new([1, 1, 1], vec![1.0], Vec3::ONE, Vec3::ONE, Affine3A::IDENTITY).is_none());
}
