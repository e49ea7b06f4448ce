//! Emitting meshes sampled as one light each. An emitting mesh is one
//! triangle light per triangle (`Light::triangles_of`), and a loop that
//! samples every light at every shading point would trace one shadow ray
//! per triangle. So a run of consecutive triangle lights (the triangles of
//! one mesh, in the order they were added) is one *emitter*: a shading
//! point draws one of its triangles, with a chance in proportion to the
//! triangle's power (its area times the sum of its radiance's channels),
//! and then a point on it uniformly by area. For a mesh of one radiance
//! that is a point uniform by area over the whole run; a mesh whose
//! triangles glow unevenly (an emissive texture) is sampled where it
//! glows. The solid-angle density is the triangle's own times the chance.
//! Any grouping would be unbiased; this one keeps a mesh's triangles
//! together, and two meshes that happen to follow each other are one
//! emitter, which is as right.

use crate::light::{Light, LightSample};
use glam::{Vec2, Vec3};

/// For each light, the emitter it belongs to and its chance within it.
#[derive(Clone, Debug, Default)]
pub struct Emitters {
    /// The emitters' first lights, in index order: every light that is not
    /// in a run of two or more triangle lights, and each run's first.
    firsts: Vec<u32>,
    /// Per light: the index of its emitter's first light.
    first_of: Vec<u32>,
    /// Per light: the end of its emitter's range (exclusive).
    end_of: Vec<u32>,
    /// Per light: the chance of drawing it within its emitter, summed over
    /// the emitter's lights up to and including it (1 at the run's last,
    /// and for a light alone).
    cumulative: Vec<f32>,
}

impl Emitters {
    pub fn new(lights: &[Light]) -> Self {
        let n = lights.len();
        let mut emitters =
            Emitters { firsts: Vec::new(), first_of: vec![0; n], end_of: vec![0; n], cumulative: vec![1.0; n] };
        let mut start = 0;
        while start < n {
            let mut end = start + 1;
            if is_triangle(&lights[start]) {
                while end < n && is_triangle(&lights[end]) {
                    end += 1;
                }
            }
            emitters.firsts.push(start as u32);
            let mut areas: Vec<f64> = lights[start..end].iter().map(power).collect();
            let mut total: f64 = areas.iter().sum();
            if !(total > 0.0 && total.is_finite()) {
                // Black triangles (or a sum past f64): evenly.
                areas.iter_mut().for_each(|a| *a = 1.0);
                total = areas.len() as f64;
            }
            let mut sum = 0.0;
            for (k, a) in areas.iter().enumerate() {
                let i = start + k;
                sum += a;
                emitters.first_of[i] = start as u32;
                emitters.end_of[i] = end as u32;
                // The last exactly 1, so that every u in [0, 1) draws one.
                emitters.cumulative[i] = if i + 1 == end { 1.0 } else { (sum / total) as f32 };
            }
            start = end;
        }
        emitters
    }

    /// The emitters' first lights, in index order.
    pub fn firsts(&self) -> &[u32] {
        &self.firsts
    }

    /// Whether the emitter that starts at `first` is that light alone:
    /// [`Emitters::draw`] then returns it, chance 1 and `u` as they are.
    pub fn is_alone(&self, first: usize) -> bool {
        self.end_of[first] as usize - first == 1
    }

    /// The chance of drawing light `index` within its emitter: the step of
    /// the cumulative table at it, so that it is exactly the measure of
    /// the numbers that [`Emitters::draw`] maps to it.
    pub fn chance(&self, index: usize) -> f32 {
        self.share(index).1
    }

    /// Light `index`'s share of [0, 1) within its emitter: where it starts
    /// and its width (the chance).
    fn share(&self, index: usize) -> (f32, f32) {
        let first = self.first_of[index] as usize;
        let below = if index == first { 0.0 } else { self.cumulative[index - 1] };
        (below, self.cumulative[index] - below)
    }

    /// Draws a light of the emitter that starts at `first` with `u.x`, and
    /// returns it with its chance and `u` with `u.x` stretched back over
    /// [0, 1) within the light's share (so stratified numbers stay so).
    pub fn draw(&self, first: usize, u: Vec2) -> (usize, f32, Vec2) {
        if self.is_alone(first) {
            return (first, 1.0, u);
        }
        let end = self.end_of[first] as usize;
        let table = &self.cumulative[first..end];
        // The first light whose cumulative chance exceeds u.x.
        let k = table.partition_point(|&c| c <= u.x).min(table.len() - 1);
        let index = first + k;
        let (below, chance) = self.share(index);
        let stretched = ((u.x - below) / chance).clamp(0.0, ONE_BELOW);
        (index, chance, Vec2::new(stretched, u.y))
    }

    /// A sample of the emitter that starts at light `first`, seen from `p`:
    /// one of its lights drawn by [`Emitters::draw`] (its index given),
    /// then a point of it, with the density and weight of both choices
    /// together.
    pub fn sample(&self, lights: &[Light], first: usize, p: Vec3, u: Vec2) -> Option<(usize, LightSample)> {
        let (index, chance, u) = self.draw(first, u);
        let sample = lights[index].sample(p, u)?;
        if chance == 1.0 {
            return Some((index, sample));
        }
        Some((index, LightSample { pdf: sample.pdf * chance, weight: sample.weight / chance, ..sample }))
    }
}

/// The largest f32 below 1.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

fn is_triangle(light: &Light) -> bool {
    matches!(light, Light::Triangle { .. })
}

/// What a triangle light's chance is in proportion to: its area times the
/// sum of its radiance's channels (a light alone gets 1: its chance is 1
/// anyway).
fn power(light: &Light) -> f64 {
    match *light {
        Light::Triangle { edge_1, edge_2, radiance, .. } => {
            let area = 0.5 * edge_1.as_dvec3().cross(edge_2.as_dvec3()).length();
            area * radiance.as_dvec3().element_sum()
        }
        _ => 1.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Rgb;
    use glam::vec3;

    /// A unit square at height 1 facing down, cut into triangles of unequal
    /// area (a fan from one corner over points along the far edges).
    fn fan(radiance: Rgb) -> Vec<Light> {
        let corner = vec3(0.0, 1.0, 0.0);
        let rim = [
            vec3(1.0, 1.0, 0.0),
            vec3(1.0, 1.0, 0.2),
            vec3(1.0, 1.0, 0.7),
            vec3(1.0, 1.0, 1.0),
            vec3(0.6, 1.0, 1.0),
            vec3(0.0, 1.0, 1.0),
        ];
        // Wound so that the normal faces −y, toward the origin below.
        rim.windows(2).map(|w| Light::triangle(corner, w[0], w[1], radiance)).collect()
    }

    #[test]
    fn runs_of_triangles_are_one_emitter_drawn_by_power_and_others_stand_alone() {
        let red = Rgb::new(4.0, 1.0, 1.0);
        let mut lights = vec![Light::point(Vec3::ONE, Rgb::ONE)];
        lights.extend(fan(red));
        lights.extend(fan(Rgb::splat(4.0)));
        lights.push(Light::quad(Vec3::ZERO, Vec3::X, Vec3::Z, red));
        let emitters = Emitters::new(&lights);
        assert_eq!(emitters.firsts(), &[0, 1, 11]);
        for (i, first) in [(0, 0), (1, 1), (3, 1), (5, 1), (6, 1), (10, 1), (11, 11)] {
            assert_eq!(emitters.first_of[i], first, "light {i}");
        }
        // The areas' shares of each square are 0.1, 0.25, 0.15, 0.2, 0.3;
        // the white square has twice the red one's power (channels summing
        // to 12 against 6), so a third of the draws go to the red one.
        let chances: Vec<f32> = (1..11).map(|i| emitters.chance(i)).collect();
        let shares = [0.1, 0.25, 0.15, 0.2, 0.3];
        let want = shares.iter().map(|s| s / 3.0).chain(shares.iter().map(|s| s * 2.0 / 3.0));
        for (got, want) in chances.iter().zip(want) {
            assert!((got - want).abs() < 1e-6, "{chances:?}");
        }
        assert_eq!(emitters.chance(0), 1.0);
        assert_eq!(emitters.chance(11), 1.0);
    }

    /// A triangle far too small for an f32 chance is never drawn, and says
    /// so (chance 0), so that a light hit found by a BRDF or phase sample
    /// takes the whole weight there.
    #[test]
    fn a_triangle_too_small_to_draw_has_chance_zero() {
        let big = Light::triangle(Vec3::ZERO, vec3(0.0, 0.0, 1.0), Vec3::X, Rgb::ONE);
        let tiny = Light::triangle(Vec3::ZERO, vec3(0.0, 0.0, 1e-6), vec3(1e-6, 0.0, 0.0), Rgb::ONE);
        let emitters = Emitters::new(&[big, tiny, big]);
        assert_eq!(emitters.firsts(), &[0]);
        assert_eq!(emitters.chance(1), 0.0);
        assert_eq!(emitters.chance(0) + emitters.chance(2), 1.0);
        for j in 0..1000 {
            let (index, chance, _) = emitters.draw(0, Vec2::new(j as f32 / 1000.0, 0.5));
            assert!(index != 1 && chance > 0.0, "u = {}", j as f32 / 1000.0);
        }
        // u.x right at the first triangle's end draws the third.
        assert_eq!(emitters.draw(0, Vec2::new(emitters.cumulative[0], 0.5)).0, 2);
    }

    #[test]
    fn drawing_gives_each_light_its_chance_and_keeps_numbers_uniform() {
        let lights = fan(Rgb::ONE);
        let emitters = Emitters::new(&lights);
        let n = 100_000;
        let mut counts = [0usize; 5];
        let mut stretched_sum = 0.0;
        for j in 0..n {
            let u = Vec2::new((j as f32 + 0.5) / n as f32, 0.3);
            let (index, chance, v) = emitters.draw(0, u);
            assert_eq!(chance, emitters.chance(index));
            assert!((0.0..1.0).contains(&v.x) && v.y == 0.3, "{v}");
            counts[index] += 1;
            stretched_sum += v.x as f64;
        }
        for (i, &c) in counts.iter().enumerate() {
            let share = c as f32 / n as f32;
            assert!((share - emitters.chance(i)).abs() < 1e-4, "light {i}: {share} against {}", emitters.chance(i));
        }
        assert!((stretched_sum / n as f64 - 0.5).abs() < 1e-3, "{}", stretched_sum / n as f64);
    }

    /// An emitter's samples are those of a point uniform over the whole
    /// square: the density at each sampled direction is the quad light's,
    /// and the irradiance they estimate at a point below is the quad's.
    #[test]
    fn a_run_samples_as_the_quad_it_tiles() {
        let lights = fan(Rgb::ONE);
        let emitters = Emitters::new(&lights);
        let quad = Light::quad(vec3(0.0, 1.0, 0.0), Vec3::X, Vec3::Z, Rgb::ONE);
        let p = vec3(0.3, 0.0, 0.6);
        let (mut from_run, mut from_quad) = (0.0f64, 0.0f64);
        let side = 300;
        for a in 0..side {
            for b in 0..side {
                let u = Vec2::new((a as f32 + 0.5) / side as f32, (b as f32 + 0.5) / side as f32);
                let (_, s) = emitters.sample(&lights, 0, p, u).expect("the square faces the point");
                let quad_pdf = quad.pdf(p, s.wi, s.distance);
                assert!((s.pdf / quad_pdf - 1.0).abs() < 1e-3, "{} against the quad's {quad_pdf}", s.pdf);
                from_run += (s.weight.x * s.wi.y.abs()) as f64;
                let q = quad.sample(p, u).expect("the quad faces the point");
                from_quad += (q.weight.x * q.wi.y.abs()) as f64;
            }
        }
        let n = (side * side) as f64;
        let (from_run, from_quad) = (from_run / n, from_quad / n);
        assert!((from_run / from_quad - 1.0).abs() < 2e-3, "irradiance {from_run} against the quad's {from_quad}");
    }
}
