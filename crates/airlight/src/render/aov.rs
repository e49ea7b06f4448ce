//! Arbitrary output variables (AOVs): per-pixel images beside the beauty
//! pass for compositing and denoising, what the camera's first hit is:
//! its diffuse albedo, its normal and its distance. They are averaged over
//! the same camera rays (anti-aliasing and lens samples) as the render, so
//! edges line up with it. Written as layers of one multi-layer EXR with the
//! channel names compositors (Blender, Nuke) and Intel Open Image Denoise's
//! tools expect: `albedo.R/G/B`, `N.X/Y/Z`, `Z`, `variance.R/G/B`; and,
//! for the single-scattering integrators, the medium's light alone,
//! `inscatter.R/G/B`.

use super::PixelSample;
use crate::Rgb;
use crate::film::Image;
use crate::integrator::Integrator;
use crate::scene::Scene;
use glam::Vec3;
use rayon::prelude::*;
use std::ops::Range;

/// An output beside the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aov {
    /// The diffuse albedo of the first surface (black for a light's own
    /// surface and where the ray meets nothing).
    Albedo,
    /// The first surface's unit normal in world space, turned toward the
    /// camera; zero where the ray meets nothing.
    Normal,
    /// The distance along the camera ray to the first surface (infinite
    /// where it meets nothing; where only some samples meet something,
    /// the mean over those).
    Depth,
    /// The estimated variance of each pixel's mean, per channel (from a
    /// progressive render's accumulated samples).
    Variance,
    /// The light the medium scatters toward the camera, alone: the
    /// single-scattering integrators' in-scattered term, from the same
    /// samples as the render, so that the image minus it is the surfaces'
    /// light as it reaches the camera through the medium.
    Inscatter,
}

impl Aov {
    pub const ALL: [Aov; 5] = [Aov::Albedo, Aov::Normal, Aov::Depth, Aov::Variance, Aov::Inscatter];

    pub fn name(self) -> &'static str {
        match self {
            Aov::Albedo => "albedo",
            Aov::Normal => "normal",
            Aov::Depth => "depth",
            Aov::Variance => "variance",
            Aov::Inscatter => "inscatter",
        }
    }

    /// The EXR channel names of this output.
    pub fn channels(self) -> &'static [&'static str] {
        match self {
            Aov::Albedo => &["albedo.R", "albedo.G", "albedo.B"],
            Aov::Normal => &["N.X", "N.Y", "N.Z"],
            Aov::Depth => &["Z"],
            Aov::Variance => &["variance.R", "variance.G", "variance.B"],
            Aov::Inscatter => &["inscatter.R", "inscatter.G", "inscatter.B"],
        }
    }

    /// The outputs named in a comma-separated list (`albedo,normal`).
    pub fn parse_list(list: &str) -> Result<Vec<Aov>, String> {
        let mut out = Vec::new();
        for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            let aov = Aov::ALL.into_iter().find(|a| a.name() == name).ok_or_else(|| {
                let known: Vec<&str> = Aov::ALL.iter().map(|a| a.name()).collect();
                format!("unknown AOV `{name}`; known: {}", known.join(", "))
            })?;
            if !out.contains(&aov) {
                out.push(aov);
            }
        }
        if out.is_empty() {
            return Err("no AOV named".into());
        }
        Ok(out)
    }
}

/// The first-hit outputs of a render: albedo, normal and depth.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceAovs {
    pub albedo: Image,
    pub normal: Image,
    pub depth: Vec<f32>,
}

impl SurfaceAovs {
    /// The channels of `aov` (row-major, one vector per channel); None for
    /// [`Aov::Variance`] and [`Aov::Inscatter`], which the render's samples give.
    pub fn channels(&self, aov: Aov) -> Option<Vec<Vec<f32>>> {
        let split = |image: &Image| (0..3).map(|c| image.pixels.iter().map(|p| p[c]).collect()).collect();
        match aov {
            Aov::Albedo => Some(split(&self.albedo)),
            Aov::Normal => Some(split(&self.normal)),
            Aov::Depth => Some(vec![self.depth.clone()]),
            Aov::Variance | Aov::Inscatter => None,
        }
    }
}

/// Albedo, normal and depth of the first surface, averaged over samples
/// `samples` of every pixel, with the camera rays the render of an
/// integrator draws (`stratified`: whether it takes them from the pixel's
/// stratified sequence, [`crate::integrator::Integrator::stratified`]).
pub fn surface_aovs(scene: &Scene, stratified: bool, samples: Range<u64>) -> SurfaceAovs {
    let s = scene.settings();
    let (width, height) = (s.film.width, s.film.height);
    let pixels: Vec<(Rgb, Vec3, f32)> = (0..width as usize * height as usize)
        .into_par_iter()
        .map(|index| {
            let (x, y) = ((index % width as usize) as u32, (index / width as usize) as u32);
            let (mut albedo, mut normal, mut depth, mut hits) = (Rgb::ZERO, Vec3::ZERO, 0.0f64, 0u64);
            for i in samples.clone() {
                let ray = PixelSample::new(s, s.seed, stratified, x, y, i).ray(scene);
                let Some(hit) = scene.geometry().intersect(&ray, f32::INFINITY) else { continue };
                let surface = scene.geometry().surface(&ray, hit);
                if surface.emitter.is_none() {
                    albedo += scene.material_at(&surface).albedo(surface.p, surface.n);
                }
                normal += if surface.n.dot(ray.dir) > 0.0 { -surface.n } else { surface.n };
                depth += hit.t as f64;
                hits += 1;
            }
            let n = (samples.end - samples.start).max(1) as f32;
            let depth = if hits == 0 { f32::INFINITY } else { (depth / hits as f64) as f32 };
            (albedo / n, normal / n, depth)
        })
        .collect();
    SurfaceAovs {
        albedo: Image { width, height, pixels: pixels.iter().map(|p| p.0).collect() },
        normal: Image { width, height, pixels: pixels.iter().map(|p| p.1).collect() },
        depth: pixels.iter().map(|p| p.2).collect(),
    }
}

/// The in-scattered light ([`Aov::Inscatter`]) averaged over samples
/// `samples` of every pixel, drawn exactly as a render of `integrator`
/// draws them (the same samplers, camera rays and order), so that each
/// pixel of the render minus it is the surface part of the same samples.
/// None when the integrator does not separate the two
/// ([`Integrator::radiance_parts`]).
pub fn in_scattered_aov(scene: &Scene, integrator: &dyn Integrator, samples: Range<u64>) -> Option<Image> {
    let s = scene.settings();
    let (width, height) = (s.film.width, s.film.height);
    let stratified = integrator.stratified();
    let pixels: Option<Vec<Rgb>> = (0..width as usize * height as usize)
        .into_par_iter()
        .map(|index| {
            let (x, y) = ((index % width as usize) as u32, (index / width as usize) as u32);
            // Summed as the render sums (fixed point): the same samples give
            // the same mean, bit for bit.
            let mut sum = crate::film::PixelSum::default();
            for i in samples.clone() {
                let mut sample = PixelSample::new(s, s.seed, stratified, x, y, i);
                let ray = sample.ray(scene);
                sum.add(integrator.radiance_parts(scene, &ray, &mut sample.sampler)?.in_scattered);
            }
            Some(sum.mean())
        })
        .collect();
    Some(Image { width, height, pixels: pixels? })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::{IntegratorDesc, IntegratorKind};
    use crate::prelude::*;
    use crate::scene::RenderSettings;

    /// A red floor at y = 0 seen from straight above at height 2, and a
    /// quad light at the image's corner that is not its own albedo.
    fn scene() -> Scene {
        let mut settings = RenderSettings::default();
        (settings.film.width, settings.film.height) = (8, 8);
        SceneBuilder::new()
            .settings(settings)
            .camera(Camera::look_at(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, Vec3::Z, 20.0))
            .material("red", Material::diffuse(Rgb::new(0.6, 0.1, 0.05)))
            .object(crate::geometry::Shape::plane(Vec3::ZERO, Vec3::NEG_Y), "red")
            .light(Light::point(Vec3::new(0.0, 1.0, 0.0), Rgb::ONE))
            .build()
            .unwrap()
    }

    #[test]
    fn a_floor_seen_from_above_has_its_albedo_an_upward_normal_and_its_distance() {
        let aovs = surface_aovs(&scene(), false, 0..4);
        for (i, albedo) in aovs.albedo.pixels.iter().enumerate() {
            assert!((*albedo - Rgb::new(0.6, 0.1, 0.05)).length() < 1e-6, "pixel {i}: {albedo}");
            // Turned toward the camera, though the plane was given facing down.
            assert!((aovs.normal.pixels[i] - Vec3::Y).length() < 1e-6, "{}", aovs.normal.pixels[i]);
            // Distance along the ray: 2 at the centre, 2/cos θ at the edges,
            // θ at most half the diagonal of a 20° view.
            let max = 2.0 / (10f32.to_radians().tan() * 2f32.sqrt()).atan().cos();
            assert!(aovs.depth[i] >= 2.0 - 1e-5 && aovs.depth[i] <= max + 1e-5, "{}", aovs.depth[i]);
        }
    }

    #[test]
    fn aovs_are_listed_by_name() {
        assert_eq!(Aov::parse_list("albedo, normal,albedo").unwrap(), vec![Aov::Albedo, Aov::Normal]);
        assert_eq!(Aov::parse_list("depth,variance").unwrap(), vec![Aov::Depth, Aov::Variance]);
        assert!(Aov::parse_list("albedo,colour").unwrap_err().contains("unknown AOV `colour`"));
        assert!(Aov::parse_list(" , ").is_err());
    }

    /// The floor scene in fog, or without the floor, or in vacuum.
    fn foggy(floor: bool, fog: bool) -> Scene {
        let mut settings = RenderSettings::default();
        (settings.film.width, settings.film.height, settings.max_distance) = (6, 6, 8.0);
        let mut b = SceneBuilder::new()
            .settings(settings)
            .camera(Camera::look_at(Vec3::new(0.0, 2.0, -3.0), Vec3::ZERO, Vec3::Y, 50.0))
            .material("red", Material::diffuse(Rgb::new(0.6, 0.1, 0.05)))
            .light(Light::point(Vec3::new(0.3, 1.0, 0.2), Rgb::splat(2.0)));
        if floor {
            b = b.object(crate::geometry::Shape::plane(Vec3::ZERO, Vec3::Y), "red");
        }
        if fog {
            b = b.medium(crate::medium::Medium::homogeneous(Rgb::splat(0.05), Rgb::new(0.2, 0.3, 0.4), 0.2));
        }
        b.build().unwrap()
    }

    fn single_scattering(scene: &Scene) -> Vec<(IntegratorKind, Box<dyn Integrator>)> {
        IntegratorKind::ALL
            .into_iter()
            .filter(|k| k.separates_in_scattering())
            .map(|kind| (kind, IntegratorDesc::new(kind).build(scene).unwrap()))
            .collect()
    }

    #[test]
    fn each_kind_says_whether_its_integrator_separates_the_medium_light() {
        let scene = foggy(true, true);
        let ray = crate::geometry::Ray::new(Vec3::new(0.0, 1.0, -4.0), Vec3::Z);
        for kind in IntegratorKind::ALL {
            let integrator = IntegratorDesc::new(kind).build(&scene).unwrap();
            let mut sampler = crate::sampling::Sampler::for_pixel(1, 2, 3);
            let parts = integrator.radiance_parts(&scene, &ray, &mut sampler);
            assert_eq!(parts.is_some(), kind.separates_in_scattering(), "{kind}");
        }
    }

    #[test]
    fn in_scattered_light_is_the_whole_image_without_surfaces_and_nothing_in_vacuum() {
        let samples = 0..4;
        // Only fog: the image is its in-scattered light, sample for sample.
        let scene = foggy(false, true);
        for (kind, integrator) in single_scattering(&scene) {
            let beauty =
                crate::render::accumulate(&scene, integrator.as_ref(), samples.clone(), 0..6, &Default::default());
            let aov = in_scattered_aov(&scene, integrator.as_ref(), samples.clone()).unwrap();
            for (i, p) in aov.pixels.iter().enumerate() {
                let b = beauty.pixel(i as u32 % 6, i as u32 / 6).unwrap().mean();
                assert_eq!(*p, b, "{kind}: pixel {i}");
            }
            assert!(aov.pixels.iter().all(|p| p.min_element() > 0.0), "{kind}: the fog is dark");
        }
        // Vacuum: nothing in-scattered, while the floor is lit.
        let scene = foggy(true, false);
        for (kind, integrator) in single_scattering(&scene) {
            let aov = in_scattered_aov(&scene, integrator.as_ref(), samples.clone()).unwrap();
            assert!(aov.pixels.iter().all(|p| *p == Rgb::ZERO), "{kind}");
            let beauty =
                crate::render::accumulate(&scene, integrator.as_ref(), samples.clone(), 0..6, &Default::default());
            assert!(beauty.pixel(3, 5).unwrap().mean().x > 0.0, "{kind}: the floor is dark");
        }
        // Integrators that do not separate the two say so.
        let path = IntegratorDesc::new(IntegratorKind::Path).build(&scene).unwrap();
        assert!(in_scattered_aov(&scene, path.as_ref(), samples).is_none());
    }

    #[test]
    fn the_image_is_the_surface_part_plus_the_in_scattered_light() {
        // Floor and fog: per sample, radiance = surface part + in-scattered
        // part; so per pixel, the image minus the AOV is the mean of the
        // surfaces' parts, drawn here sample by sample.
        let scene = foggy(true, true);
        let samples = 0..4u64;
        for (kind, integrator) in single_scattering(&scene) {
            let beauty =
                crate::render::accumulate(&scene, integrator.as_ref(), samples.clone(), 0..6, &Default::default());
            let aov = in_scattered_aov(&scene, integrator.as_ref(), samples.clone()).unwrap();
            let mut floor_seen = false;
            for (i, in_scattered) in aov.pixels.iter().enumerate() {
                let (x, y) = (i as u32 % 6, i as u32 / 6);
                let mut surface = glam::DVec3::ZERO;
                for k in samples.clone() {
                    let s = scene.settings();
                    let mut sample = PixelSample::new(s, s.seed, integrator.stratified(), x, y, k);
                    let ray = sample.ray(&scene);
                    surface += integrator.radiance_parts(&scene, &ray, &mut sample.sampler).unwrap().surface.as_dvec3();
                }
                let surface = (surface / samples.end as f64).as_vec3();
                floor_seen |= surface.x > 0.0;
                let b = beauty.pixel(x, y).unwrap().mean();
                assert!(
                    (b - (surface + *in_scattered)).abs().max_element() <= 1e-5 * b.max_element().max(1.0),
                    "{kind}: pixel {i}: {b} vs {surface} + {in_scattered}"
                );
                assert!(in_scattered.min_element() > 0.0);
            }
            assert!(floor_seen, "{kind}: no floor");
        }
    }
}
