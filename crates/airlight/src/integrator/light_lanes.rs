//! The light terms of many shading points at once, for
//! [`DeferredShadows`](super::DeferredShadows): light after light, each
//! lone quad light sampled at eight points side by side in vector lanes,
//! every other light and every glossy point one at a time.
//!
//! One point's light term is a chain of a square root, four divisions and
//! the tests between them, which a processor runs one after another; in
//! lanes, eight points' chains run side by side. The lanes do
//! [`light_term`]'s operations in its order (Rust never fuses a multiply
//! and an add), so each term is the same to the bit, and each point's terms
//! still come in the lights' order, as its sum wants them.

use super::light_term;
use crate::Rgb;
use crate::geometry::{Segment, SurfaceHit, offset_origin};
use crate::isa::Isa;
use crate::light::{Light, LightSample};
use crate::material::Material;
use crate::sampling::keyed2;
use crate::scene::{Scene, toward_sample};
use glam::{Vec2, Vec3};

/// A shading point whose light terms are put off: the point of sample
/// `sample`, seen along `wo` (toward the eye), and the key its
/// generator gave for its light samples ([`keyed2`]).
#[derive(Clone, Copy)]
pub(super) struct LitPoint {
    pub sample: usize,
    pub surface: SurfaceHit,
    pub wo: Vec3,
    pub key: u64,
}

/// A light's contribution to one point, counted if its shadow ray is clear.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Candidate {
    /// The point's sample (see [`LitPoint`]).
    pub sample: usize,
    pub light: usize,
    pub contribution: Rgb,
    /// None: no shadow ray is traced and the light counts as hidden.
    pub segment: Option<Segment>,
    /// The shadow ray's lifted origin, direction and the light's distance
    /// (for a medium's transmittance).
    pub origin: Vec3,
    pub wi: Vec3,
    pub distance: f32,
}

impl Candidate {
    /// The term of `sample` of light `light` at `point`, with its shadow
    /// ray as [`Scene::light_visible`] traces it.
    fn new(scene: &Scene, point: &LitPoint, light: usize, sample: &LightSample, contribution: Rgb) -> Candidate {
        let (p, n, wi, distance) = (point.surface.p, point.surface.n, sample.wi, sample.distance);
        let origin = offset_origin(p, n, wi);
        let segment = scene.light_segment(p, origin, wi, distance);
        Candidate { sample: point.sample, light, contribution, segment, origin, wi, distance }
    }
}

/// Points side by side.
const LANES: usize = 8;

/// What [`light_terms`] works in, kept between calls.
#[derive(Default)]
pub(super) struct LaneScratch {
    materials: Vec<Material>,
    /// Per point, the normal it is shaded with when not its surface's.
    shadings: Vec<Option<glam::Vec3>>,
    /// Per point, its BRDF where it is Lambertian (the lanes take those).
    lambertian: Vec<Option<Rgb>>,
    /// The points the lanes take.
    in_lanes: Vec<u32>,
}

/// Appends to `out` every light term of every point, as
/// [`super::for_each_light_term`] finds them with the point's key: light
/// after light, so that each point's terms come in the lights' order.
pub(super) fn light_terms(scene: &Scene, points: &[LitPoint], scratch: &mut LaneScratch, out: &mut Vec<Candidate>) {
    light_terms_on(Isa::best(), scene, points, scratch, out)
}

/// [`light_terms`] with the lanes on the instruction set `isa`.
fn light_terms_on(isa: Isa, scene: &Scene, points: &[LitPoint], scratch: &mut LaneScratch, out: &mut Vec<Candidate>) {
    let LaneScratch { materials, shadings, lambertian, in_lanes } = scratch;
    materials.clear();
    materials.extend(points.iter().map(|point| scene.material_at(&point.surface)));
    shadings.clear();
    shadings.extend(points.iter().map(|point| scene.shading_normal(&point.surface)));
    let one_point = |k: usize, index: usize, out: &mut Vec<Candidate>| {
        let point = &points[k];
        if let Some((sample, contribution)) =
            light_term(scene, index, &point.surface, shadings[k], point.wo, &materials[k], point.key)
        {
            out.push(Candidate::new(scene, point, index, &sample, contribution));
        }
    };
    if scene.culls_lights() {
        // Each point has its own lights.
        for (k, point) in points.iter().enumerate() {
            scene.for_each_emitter_at(point.surface.p, |index, _| one_point(k, index, out));
        }
        return;
    }
    lambertian.clear();
    // A smooth-shaded point's BRDF depends on the directions.
    lambertian.extend(points.iter().zip(materials.iter()).zip(shadings.iter()).map(|((point, m), shading)| {
        m.lambertian_brdf(point.surface.p, point.surface.n).filter(|_| shading.is_none())
    }));
    in_lanes.clear();
    in_lanes.extend((0..points.len() as u32).filter(|&k| lambertian[k as usize].is_some()));
    for &first in scene.emitter_firsts() {
        let index = first as usize;
        let quad = match scene.lights()[index] {
            Light::Quad { corner, edge_u, edge_v, radiance } if scene.emitter_is_alone(index) => {
                QuadLight { corner, edge_u, edge_v, normal_area: edge_u.cross(edge_v), radiance }
            }
            _ => {
                (0..points.len()).for_each(|k| one_point(k, index, out));
                continue;
            }
        };
        for chunk in in_lanes.chunks(LANES) {
            let mut lanes = QuadLanes::default();
            for (lane, &k) in chunk.iter().enumerate() {
                let point = &points[k as usize];
                lanes.set(lane, point, lambertian[k as usize].unwrap_or_default(), keyed2(point.key, index as u64));
            }
            lanes.sample_on(isa, &quad);
            for (lane, &k) in chunk.iter().enumerate() {
                if let Some(candidate) = lanes.candidate(lane, points[k as usize].sample, index) {
                    out.push(candidate);
                }
            }
        }
        for k in (0..points.len()).filter(|&k| lambertian[k].is_none()) {
            one_point(k, index, out);
        }
    }
}

/// [`Material::brdf`]'s test of (n·wo)(n·wi) for its two directions on
/// one side of the surface, which lets a NaN through.
#[inline(always)]
fn brdf_is_on_one_side(cos_product: f32) -> bool {
    cos_product > 0.0 || cos_product.is_nan()
}

/// A quad light, with its normal times its area.
struct QuadLight {
    corner: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    normal_area: Vec3,
    radiance: Rgb,
}

/// Up to [`LANES`] Lambertian points and a quad light's sample at each,
/// one array per coordinate. An unused lane has a zero BRDF and adds
/// nothing.
#[derive(Default)]
struct QuadLanes {
    p: [[f32; LANES]; 3],
    n: [[f32; LANES]; 3],
    n_dot_wo: [f32; LANES],
    brdf: [[f32; LANES]; 3],
    u: [[f32; LANES]; 2],
    // The sample, its term and its shadow ray.
    wi: [[f32; LANES]; 3],
    distance: [f32; LANES],
    contribution: [[f32; LANES]; 3],
    counts: [bool; LANES],
    origin: [[f32; LANES]; 3],
    dir: [[f32; LANES]; 3],
    tmax: [f32; LANES],
}

impl QuadLanes {
    fn set(&mut self, lane: usize, point: &LitPoint, brdf: Rgb, u: Vec2) {
        let (p, n) = (point.surface.p, point.surface.n);
        for axis in 0..3 {
            (self.p[axis][lane], self.n[axis][lane], self.brdf[axis][lane]) = (p[axis], n[axis], brdf[axis]);
        }
        self.n_dot_wo[lane] = n.dot(point.wo);
        (self.u[0][lane], self.u[1][lane]) = (u.x, u.y);
    }

    /// [`QuadLanes::sample`] on the instruction set `isa`.
    fn sample_on(&mut self, isa: Isa, light: &QuadLight) {
        match isa {
            // SAFETY: `isa` names only instruction sets the processor has.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 | Isa::Avx512 => unsafe { self.sample_avx2(light) },
            _ => self.sample(light),
        }
    }

    /// Eight lanes fill one AVX register: AVX-512 adds nothing here.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn sample_avx2(&mut self, light: &QuadLight) {
        self.sample(light)
    }

    /// Each lane's [`light_term`] for `light`: a point uniform on the quad
    /// by area (`Light::sample`), its weight radiance/pdf, f·weight·|cos|
    /// and the shadow ray toward it ([`Candidate::new`]).
    // One index across the lanes' arrays.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn sample(&mut self, light: &QuadLight) {
        let QuadLight { corner, edge_u, edge_v, normal_area: na, radiance } = *light;
        for k in 0..LANES {
            let (ux, uy) = (self.u[0][k], self.u[1][k]);
            let p = Vec3::new(self.p[0][k], self.p[1][k], self.p[2][k]);
            let x = corner + edge_u * ux + edge_v * uy;
            let to = x - p;
            let distance = to.length_squared().sqrt();
            let wi = to / distance;
            let projected_area = -wi.dot(na);
            let pdf = if projected_area <= 0.0 { 0.0 } else { distance * distance / projected_area };
            let weight = radiance / pdf;
            let n = Vec3::new(self.n[0][k], self.n[1][k], self.n[2][k]);
            let cos = wi.dot(n).abs();
            let f = Vec3::new(self.brdf[0][k], self.brdf[1][k], self.brdf[2][k]);
            let contribution = f * weight * cos;
            self.counts[k] = (pdf > 0.0 && pdf.is_finite())
                & (weight != Rgb::ZERO)
                & (cos != 0.0)
                & brdf_is_on_one_side(self.n_dot_wo[k] * n.dot(wi))
                & (f != Rgb::ZERO);
            for axis in 0..3 {
                (self.wi[axis][k], self.contribution[axis][k]) = (wi[axis], contribution[axis]);
            }
            self.distance[k] = distance;
        }
        // The shadow rays, in a loop of their own: in one with the above,
        // the compiler gave up the lanes.
        for k in 0..LANES {
            let p = Vec3::new(self.p[0][k], self.p[1][k], self.p[2][k]);
            let n = Vec3::new(self.n[0][k], self.n[1][k], self.n[2][k]);
            let wi = Vec3::new(self.wi[0][k], self.wi[1][k], self.wi[2][k]);
            let origin = offset_origin(p, n, wi);
            let (dir, tmax) = toward_sample(p, origin, wi, self.distance[k]);
            for axis in 0..3 {
                (self.origin[axis][k], self.dir[axis][k]) = (origin[axis], dir[axis]);
            }
            self.tmax[k] = tmax;
        }
    }

    /// Lane `lane`'s term as sample `sample`'s candidate of light `light`,
    /// None where it adds nothing.
    fn candidate(&self, lane: usize, sample: usize, light: usize) -> Option<Candidate> {
        let at = |v: &[[f32; LANES]; 3]| Vec3::new(v[0][lane], v[1][lane], v[2][lane]);
        self.counts[lane].then(|| {
            let (origin, tmax) = (at(&self.origin), self.tmax[lane]);
            // `Scene::light_segment` for a finite distance.
            let segment = (tmax > 0.0).then_some(Segment { origin, dir: at(&self.dir), tmax });
            let (contribution, wi, distance) = (at(&self.contribution), at(&self.wi), self.distance[lane]);
            Candidate { sample, light, contribution, segment, origin, wi, distance }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::geometry::{Ray, Shape};
    use crate::sampling::{Sampler, uniform_sphere};
    use crate::scene::SceneBuilder;
    use glam::vec3;

    /// The lanes against one point at a time ([`light_term`] and
    /// [`Candidate::new`]) on every instruction set: a checkered floor, a
    /// glossy ball and a box, lit by two quads (one seen from behind by
    /// some points), a point light, a sphere light and an emitting mesh of
    /// two triangles, from points all over them.
    #[test]
    fn lanes_give_each_point_the_terms_one_point_at_a_time_gives() {
        let mut builder = SceneBuilder::new()
            .camera(Camera::look_at(vec3(0.0, 2.0, -6.0), Vec3::ZERO, Vec3::Y, 50.0))
            .material("floor", Material::checker(Rgb::splat(0.8), Rgb::new(0.1, 0.2, 0.0), 0.5))
            .material("shiny", Material::phong(Rgb::new(0.2, 0.3, 0.8), Rgb::splat(0.3), 30.0))
            .material("white", Material::diffuse(Rgb::splat(0.7)))
            .object(Shape::plane(Vec3::ZERO, Vec3::Y), "floor")
            .object(Shape::sphere(vec3(-1.0, 1.0, 0.0), 1.0), "shiny")
            .object(Shape::cuboid(vec3(0.5, 0.0, -0.5), vec3(1.5, 1.5, 0.5)), "white")
            .light(Light::quad(vec3(-1.0, 4.0, -1.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 0.0, 2.0), Rgb::splat(5.0)))
            .light(Light::point(vec3(2.0, 3.0, -2.0), Rgb::splat(10.0)))
            .light(Light::quad(vec3(3.0, 0.5, -1.0), vec3(0.0, 0.0, 2.0), vec3(0.0, 1.5, 0.0), Rgb::new(1.0, 2.0, 3.0)))
            .light(Light::sphere(vec3(-2.5, 2.5, -1.0), 0.3, Rgb::splat(20.0)));
        let mesh = [vec3(-3.0, 3.0, 2.0), vec3(-1.0, 3.0, 2.0), vec3(-1.0, 3.5, 3.0), vec3(-3.0, 3.5, 3.0)];
        for light in Light::triangles_of(&mesh, &[[0, 1, 2], [0, 2, 3]], Rgb::splat(4.0)) {
            builder = builder.light(light);
        }
        let scene = builder.build().unwrap();
        assert!(!scene.culls_lights());
        let mut s = Sampler::for_pixel(3, 1, 0);
        let mut points = Vec::new();
        while points.len() < 301 {
            let ray = Ray::new(vec3(0.0, 2.5, -5.0) + uniform_sphere(s.next2()) * 0.5, uniform_sphere(s.next2()));
            if let Some(hit) = scene.geometry().intersect(&ray, f32::INFINITY) {
                let surface = scene.geometry().surface(&ray, hit);
                points.push(LitPoint { sample: points.len(), surface, wo: -ray.dir, key: s.next_key() });
            }
        }
        let mut want: Vec<Vec<Candidate>> = vec![Vec::new(); points.len()];
        for point in &points {
            let material = scene.material_at(&point.surface);
            let shading = scene.shading_normal(&point.surface);
            for &index in scene.emitter_firsts() {
                let term = light_term(&scene, index as usize, &point.surface, shading, point.wo, &material, point.key);
                if let Some((sample, contribution)) = term {
                    want[point.sample].push(Candidate::new(&scene, point, index as usize, &sample, contribution));
                }
            }
        }
        let from_quads =
            want.iter().flatten().filter(|c| matches!(scene.lights()[c.light], Light::Quad { .. })).count();
        assert!(from_quads > 200, "{from_quads} terms of quad lights");
        for isa in Isa::available() {
            let mut out = Vec::new();
            light_terms_on(isa, &scene, &points, &mut LaneScratch::default(), &mut out);
            let mut got: Vec<Vec<Candidate>> = vec![Vec::new(); points.len()];
            for c in out {
                got[c.sample].push(c);
            }
            for (k, (got, want)) in got.iter().zip(&want).enumerate() {
                assert_eq!(got, want, "{isa:?}: point {k}");
            }
        }
    }
}
