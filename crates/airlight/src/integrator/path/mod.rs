//! The reference: unidirectional volumetric path tracing with next-event
//! estimation, multiple importance sampling and Russian roulette, built as
//! pbrt-v4's VolPathIntegrator is (Pharr, Jakob and Humphreys, "Physically
//! Based Rendering", 4th ed., ch. 14): free flights drawn exactly by
//! inverting the closed-form optical depth (homogeneous and height fog;
//! delta tracking against a majorant for media without one, tracking.rs),
//! one hero channel sampled per path and the
//! path weighted over the three channels (r_u and r_l hold each channel's
//! unidirectional and light-sampling path pdfs relative to the hero's):
//! by the power heuristic where light sampling and BRDF or phase sampling
//! both find an area light (`mis::power_heuristic`), by the balance heuristic
//! elsewhere. In fog around point lights, new directions are also drawn
//! toward the brightest lights (guide.rs).

mod guide;
mod mis;
mod nee;
mod reuse;
pub mod tracking;

use super::{Integrator, PathOptions};
use crate::Rgb;
use crate::geometry::{Hit, Ray, offset_origin};
use crate::material::Material;
use crate::medium::Medium;
use crate::medium::{henyey_greenstein, sample_henyey_greenstein_cos};
use crate::sampling::{Sampler, to_world};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use guide::{GUIDE_PROBABILITY, Guide, mixed_pdf};
use mis::{avg, power_heuristic};
use nee::{Fog, Segment, direct_light, equiangular_applies, equiangular_light};
use reuse::{FirstVertex, SecondVertex, Split};
use tracking::free_flight;

/// Volumetric path tracer. `max_depth` counts scattering events: 1 is direct
/// light on surfaces plus single scattering in the medium (pbrt-v4's
/// maxdepth 1).
pub struct PathTracer {
    pub max_depth: u32,
    /// Sample delta lights' scattered light equiangularly along each
    /// segment through a medium with a closed-form optical depth (nee.rs).
    /// On by default; off is free-flight sampling alone, as Mitsuba's
    /// volpath.
    pub equiangular: bool,
    /// Draw free flights and shadow rays' transmittance from the medium's
    /// closed-form optical depth where it has one. On by default; off is
    /// delta and ratio tracking against a majorant for every medium (and no
    /// equiangular sampling), as for media without a closed form.
    pub closed_form: bool,
    /// Also draw the new direction of a scattering event toward the point
    /// or spot lights brightest there, where equiangular sampling gathers
    /// the next segment's light (guide.rs): without it, segments that pass
    /// close to a point light make rare, bright pixels. On by default.
    pub guide: bool,
    /// Stratify each pixel's samples: the camera's numbers and, at the
    /// first two scattering events on surfaces, the light samples and the
    /// new direction come from the pixel's Owen-scrambled Sobol' points
    /// (`Bounce`).
    pub stratify: bool,
    /// Share second vertices among neighbouring pixels' paths (reuse.rs),
    /// in scenes without a medium.
    pub reuse: bool,
}

impl PathTracer {
    pub fn new(options: PathOptions) -> Self {
        PathTracer {
            max_depth: options.max_depth,
            equiangular: true,
            closed_form: true,
            guide: true,
            stratify: options.stratify,
            reuse: options.reuse,
        }
    }

    /// Whether a segment that starts after `depth` scattering events
    /// gathers its delta lights' light equiangularly (nee.rs): when a
    /// scattering event on it would still count.
    fn gathers(&self, medium: Option<&Medium>, depth: u32) -> bool {
        self.equiangular && self.closed_form && depth < self.max_depth && medium.is_some_and(equiangular_applies)
    }

    /// Whether the new direction of scattering event `depth` may also be
    /// drawn toward a point light (guide.rs): where the segment it starts
    /// gathers delta lights' light equiangularly.
    fn guides(&self, medium: Option<&Medium>, depth: u32) -> bool {
        self.guide && self.gathers(medium, depth)
    }

    /// The numbers of scattering event `depth` (1 for the first) on a surface.
    fn bounce(&self, depth: u32, sampler: &mut Sampler) -> Bounce {
        if self.stratify && depth <= STRATIFIED_EVENTS {
            // The direction gets dimensions 0 and 1, the pair that is a
            // (0, 2)-net (every elementary interval holds its share), the
            // light samples 2 and 3: the Cornell box's error at 512 spp
            // fell 1.8% so (0.00250 to 0.00245, seeds 0 and 1). Two padded
            // 2D sequences, each a net, gave 0.00247 and cost 7% more time.
            let [d0, d1, l0, l1] = sampler.stratified4(depth);
            Bounce { light: Some(Vec2::new(l0, l1)), direction: Vec2::new(d0, d1) }
        } else {
            Bounce { light: None, direction: sampler.next2() }
        }
    }
}

/// How many of a path's first scattering events on surfaces take their
/// numbers from the pixel's Sobol' points; later ones draw independent
/// numbers. Deeper events' stratification lowered no error measurably and
/// cost time: on the Cornell box (`scenes/compare_cornell.toml`, 512 spp,
/// two seed pairs) the seed-to-seed error was 0.00350 and 0.00321 with
/// every event stratified, 0.00349 and 0.00320 with the first two; the
/// later events' scrambled Sobol' points took 5% of the render's time.
const STRATIFIED_EVENTS: u32 = 2;

/// The numbers one scattering event draws its light samples and its new
/// direction from. Stratified (the first [`STRATIFIED_EVENTS`]): the
/// event's group of the pixel's Sobol' points (group `depth`; group 0 is
/// the camera's), so that across a pixel's samples the first bounces' light
/// samples and directions are spread evenly rather than clumped, which is
/// what lowers the noise of direct and first-bounce light; independent
/// otherwise.
pub(super) struct Bounce {
    /// Light samples: None draws them independently per light (keyed).
    pub light: Option<Vec2>,
    pub direction: Vec2,
}

/// Where light scatters: a surface or a point in the medium; `wo` points
/// back along the path, toward where the light will go.
enum Vertex<'a> {
    /// `material` as it is at the hit (a texture looked up);
    /// `light_numbers`, if stratified, the light samples' numbers.
    /// `shading`: the normal the point is shaded with when not `n`.
    Surface { p: Vec3, n: Vec3, shading: Option<Vec3>, wo: Vec3, material: &'a Material, light_numbers: Option<Vec2> },
    /// `on_gathered_segment`: on a segment whose delta lights' scattered
    /// light was gathered equiangularly (nee.rs).
    Medium { p: Vec3, wo: Vec3, on_gathered_segment: bool },
}

impl Vertex<'_> {
    fn p(&self) -> Vec3 {
        match *self {
            Vertex::Surface { p, .. } | Vertex::Medium { p, .. } => p,
        }
    }

    fn wo(&self) -> Vec3 {
        match *self {
            Vertex::Surface { wo, .. } | Vertex::Medium { wo, .. } => wo,
        }
    }
}

impl Integrator for PathTracer {
    fn stratified(&self) -> bool {
        self.stratify
    }

    fn shares_between_pixels(&self) -> bool {
        self.reuse
    }

    fn radiance(&self, scene: &Scene, camera_ray: &Ray, sampler: &mut Sampler) -> Rgb {
        self.trace(scene, camera_ray, None, sampler, None)
    }

    /// The camera rays' first hits found together as packets (bit for bit
    /// the one-ray query's), then each path traced on from its hit.
    fn radiance_batch(&self, scene: &Scene, rays: &[Ray], samplers: &mut [Sampler], out: &mut [Rgb]) {
        let mut hits = vec![None; rays.len()];
        scene.geometry().intersect_packet(rays, f32::INFINITY, &mut hits);
        if self.reuse && scene.medium().is_none() {
            let mut splits = vec![Split::default(); rays.len()];
            let mut traced = vec![Rgb::ZERO; rays.len()];
            for ((((ray, hit), sampler), split), traced) in
                rays.iter().zip(hits).zip(samplers.iter_mut()).zip(splits.iter_mut()).zip(traced.iter_mut())
            {
                *traced = self.trace(scene, ray, Some(hit), sampler, Some(split));
            }
            for ((splits, traced), out) in
                splits.chunks(reuse::GROUP).zip(traced.chunks(reuse::GROUP)).zip(out.chunks_mut(reuse::GROUP))
            {
                reuse::share(scene, splits, traced, out);
            }
            return;
        }
        for (((ray, hit), sampler), out) in rays.iter().zip(hits).zip(samplers.iter_mut()).zip(out.iter_mut()) {
            *out = self.trace(scene, ray, Some(hit), sampler, None);
        }
    }
}

impl PathTracer {
    /// The path from `camera_ray`, whose nearest hit is `camera_hit` when
    /// the caller has found it already.
    fn trace(
        &self,
        scene: &Scene,
        camera_ray: &Ray,
        mut camera_hit: Option<Option<Hit>>,
        sampler: &mut Sampler,
        mut split: Option<&mut Split>,
    ) -> Rgb {
        let medium = scene.medium();
        let max_distance = scene.settings().max_distance;
        let hero = ((sampler.next() * 3.0) as usize).min(2);
        let (mut l, mut beta, mut r_u, mut r_l) = (Rgb::ZERO, Rgb::ONE, Rgb::ONE, Rgb::ONE);
        let mut depth = 0u32;
        let mut ray = *camera_ray;
        let mut prev_p = ray.origin;
        // Russian roulette after a scattering event waits, where the next
        // segment gathers delta lights' light equiangularly, until it has:
        // a direction drawn close to a light's axis (guide.rs) has a small
        // weight that offsets the segment's large estimate (∝ 1/h, h its
        // distance from the light), and roulette on that weight would end
        // the path almost surely and lift the survivor's weight, and so
        // its estimate, a thousandfold. (Traced in a firefly that guiding
        // left: a pixel at 2470 where its median is 0.15.)
        let mut roulette_pending = false;
        // The weight Russian roulette sees is β times this: the path's
        // weight at its shared second vertex, where β starts again at 1.
        let mut roulette_scale = Rgb::ONE;
        loop {
            let hit = camera_hit.take().unwrap_or_else(|| scene.geometry().intersect(&ray, f32::INFINITY));
            let t_hit = hit.map_or(f32::INFINITY, |h| h.t);
            if let Some(m) = medium {
                // The medium scatters within max_distance along a ray (as the
                // ray marcher); beyond it a far surface is only attenuated.
                let t_medium = t_hit.min(max_distance);
                // Delta lights' light scattered along the segment, also from
                // equiangular points (nee.rs), when a scattering event here
                // would still count.
                let segment = Segment::new(ray, t_medium);
                let equiangular = self.gathers(Some(m), depth);
                if equiangular {
                    l += equiangular_light(scene, m, &segment, beta, r_u, hero, sampler);
                }
                if std::mem::take(&mut roulette_pending)
                    && !russian_roulette(&mut beta, roulette_scale, r_u, depth, sampler)
                {
                    return l;
                }
                let mut scattered: Option<Ray> = None;
                let mut terminated = false;
                let t_maj = free_flight(m, &ray, t_medium, hero, self.closed_form, sampler, |c, sampler| {
                    let p_absorb = c.sigma_a[hero] / c.sigma_maj[hero];
                    let p_scatter = c.sigma_s[hero] / c.sigma_maj[hero];
                    let u = sampler.next();
                    if u < p_absorb {
                        terminated = true;
                        false
                    } else if u < p_absorb + p_scatter {
                        if depth >= self.max_depth {
                            terminated = true;
                            return false;
                        }
                        depth += 1;
                        // Independent numbers in the medium: with stratified
                        // phase directions the fog comparison scene showed
                        // rare fireflies (2 of 8 renders at 128 spp had a
                        // pixel 5–8× the brightest of independent renders),
                        // whose cause is not yet understood.
                        let direction = sampler.next2();
                        let pdf = c.t_maj[hero] * c.sigma_s[hero];
                        beta *= c.t_maj * c.sigma_s / pdf;
                        r_u *= c.t_maj * c.sigma_s / pdf;
                        if beta.max_element() <= 0.0 || r_u.max_element() <= 0.0 {
                            terminated = true;
                            return false;
                        }
                        let p = ray.at(c.t);
                        let wo = -ray.dir;
                        let guide = if self.guides(Some(m), depth) { Guide::at(scene, p) } else { None };
                        let vertex = Vertex::Medium { p, wo, on_gathered_segment: equiangular };
                        let fog = Fog { medium: Some(m), closed_form: self.closed_form };
                        l += beta * direct_light(scene, fog, &vertex, r_u, hero, guide.as_ref(), sampler);
                        let (wi, phase) = match guided(guide.as_ref(), sampler) {
                            Some((guide, choice)) => {
                                let wi = guide.sample(choice, direction);
                                (wi, m.phase(wo, wi))
                            }
                            _ => {
                                let cos = sample_henyey_greenstein_cos(m.g, direction.x);
                                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                                let phi = 2.0 * std::f32::consts::PI * direction.y;
                                (
                                    to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos), wo),
                                    henyey_greenstein(cos, m.g),
                                )
                            }
                        };
                        // Phase sampling alone: its weight p/pdf is 1.
                        let pdf = mixed_pdf(phase, guide.as_ref(), wi);
                        if guide.is_some() {
                            // Infinite on the axis itself, a draw of measure zero.
                            if !pdf.is_finite() {
                                terminated = true;
                                return false;
                            }
                            beta *= phase / pdf;
                        }
                        r_l = r_u / pdf;
                        prev_p = p;
                        scattered = Some(Ray::new(p, wi));
                        false
                    } else {
                        let sigma_n = (c.sigma_maj - c.sigma_a - c.sigma_s).max(Rgb::ZERO);
                        let pdf = c.t_maj[hero] * sigma_n[hero];
                        if pdf <= 0.0 {
                            terminated = true;
                            return false;
                        }
                        beta *= c.t_maj * sigma_n / pdf;
                        r_u *= c.t_maj * sigma_n / pdf;
                        r_l *= c.t_maj * c.sigma_maj / pdf;
                        beta.max_element() > 0.0 && r_u.max_element() > 0.0
                    }
                });
                if terminated {
                    return l;
                }
                if let Some(next) = scattered {
                    ray = next;
                    if self.gathers(medium, depth) {
                        roulette_pending = true;
                    } else if !russian_roulette(&mut beta, roulette_scale, r_u, depth, sampler) {
                        return l;
                    }
                    continue;
                }
                beta *= t_maj / t_maj[hero];
                r_u *= t_maj / t_maj[hero];
                r_l *= t_maj / t_maj[hero];
                if t_hit > max_distance && t_hit.is_finite() {
                    beta *= m.transmittance(ray.origin, ray.dir, max_distance, t_hit);
                }
            }
            let Some(hit) = hit else {
                // Escaped: the background, which nothing samples directly,
                // and the skies, which next-event estimation samples too.
                l += beta * scene.settings().background / avg(r_u);
                for &index in scene.skies() {
                    let le = scene.sky_radiance(index as usize, ray.dir);
                    if depth == 0 {
                        l += beta * le / avg(r_u);
                    } else {
                        let r_l = r_l * scene.sky_pdf(index as usize, ray.dir);
                        l += beta * le * power_heuristic(r_u, r_l, hero);
                    }
                }
                return l;
            };
            let surface = scene.geometry().surface(&ray, hit);
            if let Some(index) = surface.emitter {
                let light = &scene.lights()[index as usize];
                let le = scene.emitted(index as usize, surface.p, surface.n, ray.dir);
                if le != Rgb::ZERO {
                    if depth == 0 {
                        l += beta * le / avg(r_u);
                    } else {
                        // A light that next-event estimation samples as a
                        // point (an approximated sphere) was counted there.
                        let light_pdf = light.pdf(prev_p, ray.dir, (surface.p - prev_p).length());
                        if light_pdf > 0.0 {
                            // Next-event estimation drew this light with its
                            // chance within its emitter (an emitting mesh's
                            // triangle). A triangle too small ever to be drawn
                            // (chance 0 in f32) is found by this direction
                            // alone, which then takes the whole weight.
                            let r_l = r_l * (light_pdf * scene.emitter_chance(index as usize));
                            l += beta * le * power_heuristic(r_u, r_l, hero);
                        }
                    }
                }
            }
            if depth >= self.max_depth {
                return l;
            }
            depth += 1;
            let numbers = self.bounce(depth, sampler);
            let material = scene.material_at(&surface);
            let shading = scene.shading_normal(&surface);
            if depth == 2
                && let Some(split) = split.as_deref_mut()
                && split.first.is_some()
                && reuse::lambertian(&material)
                && shading.is_none()
            {
                split.second = Some(SecondVertex { p: surface.p, n: surface.n, own: l });
                (roulette_scale, beta, l) = (beta, Rgb::ONE, Rgb::ZERO);
            }
            let wo = -ray.dir;
            let vertex = Vertex::Surface {
                p: surface.p,
                n: surface.n,
                shading,
                wo,
                material: &material,
                light_numbers: numbers.light,
            };
            let fog = Fog { medium, closed_form: self.closed_form };
            let guide = if self.guides(medium, depth) { Guide::at(scene, surface.p) } else { None };
            l += beta * direct_light(scene, fog, &vertex, r_u, hero, guide.as_ref(), sampler);
            let (wi, f, pdf) = match guided(guide.as_ref(), sampler) {
                Some((guide, choice)) => {
                    let wi = guide.sample(choice, numbers.direction);
                    let (f, pdf) = material.eval_at(surface.p, surface.n, shading, wo, wi);
                    (wi, f, pdf)
                }
                _ => {
                    let sample =
                        material.sample_at(surface.p, surface.n, shading, wo, numbers.direction, sampler.next());
                    let Some(bs) = sample else {
                        return l;
                    };
                    (bs.wi, bs.f, bs.pdf)
                }
            };
            let pdf = mixed_pdf(pdf, guide.as_ref(), wi);
            if pdf.is_nan() || pdf <= 0.0 {
                return l;
            }
            beta *= f * (wi.dot(surface.n).abs() / pdf);
            r_l = r_u / pdf;
            prev_p = surface.p;
            ray = Ray::new(offset_origin(surface.p, surface.n, wi), wi);
            if beta.max_element() <= 0.0 {
                return l;
            }
            if depth == 1
                && let Some(split) = split.as_deref_mut()
            {
                split.first = Some(FirstVertex { p: surface.p, n: surface.n, shading, wo, material: material.clone() });
            }
            if self.gathers(medium, depth) {
                roulette_pending = true;
            } else if !russian_roulette(&mut beta, roulette_scale, r_u, depth, sampler) {
                return l;
            }
        }
    }
}

/// Whether this scattering event draws its new direction toward a light
/// (with chance [`GUIDE_PROBABILITY`], where there is a guide), and if so
/// the guide and the number that chooses its light: one number for both.
fn guided<'a>(guide: Option<&'a Guide>, sampler: &mut Sampler) -> Option<(&'a Guide, f32)> {
    let guide = guide?;
    let u = sampler.next();
    (u < GUIDE_PROBABILITY).then(|| (guide, u / GUIDE_PROBABILITY))
}

/// The scattering event from which Russian roulette may end a path, as
/// Mitsuba 3's default `rr_depth`. Measured against starting at the 2nd
/// event (512 spp Cornell box, 128 spp fog scenes; time × error², seeds 0
/// and 1): the Cornell box 1.31× more efficient, the hard spot in fog
/// 1.07×, the point light in fog 0.92× (10% more time per sample). The
/// early events of a closed room carry much of its light; killing them
/// costs more in noise than it saves in time.
const RUSSIAN_ROULETTE_FROM: u32 = 5;

/// Russian roulette from event [`RUSSIAN_ROULETTE_FROM`] on, on the path's
/// weight `beta · scale` (`scale` is 1 but after a shared second vertex,
/// where `beta` starts again: reuse.rs): false if the path ends, else
/// `beta` is raised to keep the estimate unbiased.
fn russian_roulette(beta: &mut Rgb, scale: Rgb, r_u: Rgb, depth: u32, sampler: &mut Sampler) -> bool {
    let rr = (*beta * scale / avg(r_u)).max_element();
    if rr < 1.0 && depth >= RUSSIAN_ROULETTE_FROM {
        let q = (1.0 - rr).max(0.0);
        if sampler.next() < q {
            return false;
        }
        *beta /= 1.0 - q;
    }
    true
}
