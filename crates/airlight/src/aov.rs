//! Arbitrary output variables (AOVs): per-pixel images beside the beauty
//! pass for compositing and denoising, what the camera's first hit is:
//! its diffuse albedo, its normal and its distance. They are averaged over
//! the same camera rays (anti-aliasing and lens samples) as the render, so
//! edges line up with it. Written as layers of one multi-layer EXR with the
//! channel names compositors (Blender, Nuke) and Intel Open Image Denoise's
//! tools expect: `albedo.R/G/B`, `N.X/Y/Z`, `Z`, `variance.R/G/B`.

use crate::Rgb;
use crate::film::Image;
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
}

impl Aov {
    pub const ALL: [Aov; 4] = [Aov::Albedo, Aov::Normal, Aov::Depth, Aov::Variance];

    pub fn name(self) -> &'static str {
        match self {
            Aov::Albedo => "albedo",
            Aov::Normal => "normal",
            Aov::Depth => "depth",
            Aov::Variance => "variance",
        }
    }

    /// The EXR channel names of this output.
    pub fn channels(self) -> &'static [&'static str] {
        match self {
            Aov::Albedo => &["albedo.R", "albedo.G", "albedo.B"],
            Aov::Normal => &["N.X", "N.Y", "N.Z"],
            Aov::Depth => &["Z"],
            Aov::Variance => &["variance.R", "variance.G", "variance.B"],
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
    /// [`Aov::Variance`], which the render's samples give.
    pub fn channels(&self, aov: Aov) -> Option<Vec<Vec<f32>>> {
        let split = |image: &Image| (0..3).map(|c| image.pixels.iter().map(|p| p[c]).collect()).collect();
        match aov {
            Aov::Albedo => Some(split(&self.albedo)),
            Aov::Normal => Some(split(&self.normal)),
            Aov::Depth => Some(vec![self.depth.clone()]),
            Aov::Variance => None,
        }
    }
}

/// Albedo, normal and depth of the first surface, averaged over samples
/// `samples` of every pixel, with the camera rays the render of an
/// integrator draws (`stratified`: whether it takes them from the pixel's
/// stratified sequence, [`crate::integrator::Integrator::stratified`]).
pub fn surface_aovs(scene: &Scene, stratified: bool, samples: Range<u64>) -> SurfaceAovs {
    let s = scene.settings();
    let (width, height) = (s.width, s.height);
    let pixels: Vec<(Rgb, Vec3, f32)> = (0..width as usize * height as usize)
        .into_par_iter()
        .map(|index| {
            let (x, y) = ((index % width as usize) as u32, (index / width as usize) as u32);
            let (mut albedo, mut normal, mut depth, mut hits) = (Rgb::ZERO, Vec3::ZERO, 0.0f64, 0u64);
            for i in samples.clone() {
                let index = y as u64 * width as u64 + x as u64;
                let mut sampler = crate::sampling::Sampler::for_pixel(s.seed, index, i);
                let ray = crate::render::camera_ray(scene, stratified, x, y, &mut sampler);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prelude::*;
    use crate::scene::RenderSettings;

    /// A red floor at y = 0 seen from straight above at height 2, and a
    /// quad light at the image's corner that is not its own albedo.
    fn scene() -> Scene {
        let mut settings = RenderSettings::default();
        (settings.width, settings.height) = (8, 8);
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
}
