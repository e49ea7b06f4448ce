//! The render-time [`Scene`], the [`SceneBuilder`] that makes one in Rust, and
//! the TOML scene description ([`SceneDesc`]) that makes one from a file.

mod build;
mod desc;
mod error;
mod lights;
mod sdf;

pub use build::{from_toml_str, load};
pub use desc::SceneDesc;
pub use error::{SceneError, line_col};
pub use lights::LightCulling;

use crate::Rgb;
use crate::camera::Camera;
use crate::geometry::{Geometry, GeometryBuilder, Shape};
use crate::integrator::analytic::LightQuadrature;
use crate::integrator::{IntegratorKind, Sampling};
use crate::light::{Keyframes, Light};
use crate::material::Material;
use crate::medium::Medium;
use glam::{Affine3A, Vec3};
use std::collections::HashMap;

/// How the image is turned into 8-bit PNG values (EXR output is always linear).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Tonemap {
    /// Clip to [0, 1].
    #[default]
    Clamp,
    /// The ACES filmic curve as fitted by Narkowicz (2015).
    Filmic,
}

/// The `[render]` settings.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub integrator: IntegratorKind,
    /// Samples per pixel.
    pub spp: u32,
    /// March samples per ray (raymarch).
    pub steps: u32,
    /// How far a ray that hits nothing is followed (and marched).
    pub max_distance: f32,
    /// Most scattering events (path).
    pub max_depth: u32,
    pub seed: u64,
    /// Radiance of rays that escape.
    pub background: Rgb,
    /// Stops, for PNG output only.
    pub exposure: f32,
    pub tonemap: Tonemap,
    /// Offset march samples by a random fraction of a step per pixel sample.
    pub jitter: bool,
    /// analytic: volumetric shadows (lit intervals of each ray).
    pub shadows: bool,
    /// analytic: points per dimension of a line or quad light's superposition.
    pub light_steps: u32,
    /// analytic: how those points are placed and weighted.
    pub light_quadrature: LightQuadrature,
    /// Radiosity: the side length (world units) surfaces are cut into
    /// patches of; None picks 1/32 of the largest extent of the bounded
    /// geometry (see `radiosity::CompileParams`).
    pub patch_size: Option<f32>,
    /// Radiosity: bounces of indirect light (1 = one bounce, as the seed).
    pub bounces: u32,
    /// Radiosity: a patch links to a whole cluster instead of its children
    /// when the cluster's estimated form factor A_j/(π d²) is below this.
    pub link_threshold: f32,
    /// Skip lights whose range ends before a point (finite-range falloffs).
    pub cull_lights: bool,
    /// Stochastic: how the point on the camera segment is drawn.
    pub sampling: Sampling,
    /// Stochastic: stratify each pixel's samples (Owen-scrambled Sobol').
    pub stratify: bool,
    /// How a pixel gathers its samples.
    pub filter: PixelFilter,
}

/// How the samples of a pixel are placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PixelFilter {
    /// The mean over the pixel's square: samples jittered across it (anti-aliasing).
    #[default]
    Box,
    /// Every sample through the pixel's centre: no anti-aliasing, but images
    /// whose integrators take different sample counts share their camera rays.
    Point,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 640,
            height: 480,
            integrator: IntegratorKind::Direct,
            spp: 16,
            steps: 64,
            max_distance: 100.0,
            max_depth: 8,
            seed: 0,
            background: Rgb::ZERO,
            exposure: 0.0,
            tonemap: Tonemap::Clamp,
            jitter: true,
            cull_lights: true,
            filter: PixelFilter::Box,
            patch_size: None,
            bounces: 1,
            link_threshold: DEFAULT_LINK_THRESHOLD,
            shadows: false,
            light_steps: 16,
            light_quadrature: LightQuadrature::Gauss,
            sampling: Sampling::default(),
            stratify: true,
        }
    }
}

/// Default of [`RenderSettings::link_threshold`].
pub const DEFAULT_LINK_THRESHOLD: f32 = 0.02;

/// Everything a render needs, built and validated.
#[derive(Debug)]
pub struct Scene {
    pub settings: RenderSettings,
    pub camera: Camera,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    /// For each light in `lights`, the path it moves along in animations
    /// (None: it stays put). See [`crate::light::Keyframes`].
    pub light_paths: Vec<Option<Keyframes>>,
    pub medium: Option<Medium>,
    pub geometry: Geometry,
    /// The scene's objects (not the lights' surfaces), in world space, with
    /// their material index: what radiosity cuts into patches.
    pub objects: Vec<(Shape, u32)>,
    /// Centre and radius of a sphere around the bounded geometry, the lights
    /// and the camera; a sun's light enters the scene from its surface, as in
    /// pbrt-v4 and Mitsuba 3.
    pub bounds_center: Vec3,
    pub bounds_radius: f32,
    pub light_culling: LightCulling,
}

impl Scene {
    /// The distance a shadow ray toward a light sample should span: the
    /// sample's distance, or for a sun, across the scene's bounding sphere.
    pub fn light_distance(&self, distance: f32) -> f32 {
        if distance.is_finite() { distance } else { 2.0 * self.bounds_radius }
    }

    /// Whether the light sample at `p + wi·distance` (a sun's when distance
    /// is infinite) is visible from `origin`, which is `p` or `p` lifted off
    /// its surface. The shadow ray aims from `origin` at the sample point
    /// itself and stops just short of it. Keeping the direction wi from the
    /// lifted origin would not do: that ray runs beside the sample point, and
    /// where it meets the light's own surface at a slant (a floor point
    /// seeing a ceiling light at 50° or more from the vertical) it meets it
    /// before any span measured along wi ends, and calls the light a blocker
    /// of itself (the Cornell box's one-bounce walls read 5.5% dark so).
    #[inline]
    pub fn light_visible(&self, p: Vec3, origin: Vec3, wi: Vec3, distance: f32) -> bool {
        const SHORT: f32 = 1.0 - 1e-4;
        if !distance.is_finite() {
            return !self.geometry.occluded(origin, wi, 2.0 * self.bounds_radius * SHORT);
        }
        let to = p + wi * distance - origin;
        let length = to.length();
        length > 0.0 && !self.geometry.occluded(origin, to / length, length * SHORT)
    }

    /// Calls `f(index, light)` for every light that may reach `p`, in index
    /// order: with culling, lights whose range ends before `p` are skipped
    /// without being looked at.
    pub fn for_each_light_at(&self, p: Vec3, mut f: impl FnMut(usize, &Light)) {
        if !self.settings.cull_lights || !self.light_culling.has_ranges() {
            for (i, light) in self.lights.iter().enumerate() {
                f(i, light);
            }
            return;
        }
        thread_local! {
            static FOUND: std::cell::RefCell<Vec<u32>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let mut visit = |found: &mut Vec<u32>| {
            self.light_culling.lights_at(p, found);
            for &i in found.iter() {
                f(i as usize, &self.lights[i as usize]);
            }
        };
        // A reused buffer, or a fresh one if a caller nests these loops.
        FOUND.with(|found| match found.try_borrow_mut() {
            Ok(mut found) => visit(&mut found),
            Err(_) => visit(&mut Vec::new()),
        });
    }

    /// The lights at `time` in [0, 1] of the animation: each light with
    /// keyframes moved to its keyframed position, the others as they are.
    pub fn lights_at(&self, time: f32) -> Vec<Light> {
        self.lights
            .iter()
            .zip(&self.light_paths)
            .map(|(light, path)| match path {
                Some(path) => light.moved_to(path.at(time)),
                None => *light,
            })
            .collect()
    }

    /// Whether any light moves.
    pub fn is_animated(&self) -> bool {
        self.light_paths.iter().any(Option::is_some)
    }
}

/// Builds a [`Scene`] in Rust, as the seed's World/Camera example does.
#[derive(Default)]
pub struct SceneBuilder {
    settings: RenderSettings,
    camera: Option<Camera>,
    materials: Vec<Material>,
    material_names: HashMap<String, u32>,
    objects: Vec<(Shape, String)>,
    lights: Vec<Light>,
    light_paths: Vec<Option<Keyframes>>,
    medium: Option<Medium>,
}

impl SceneBuilder {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.settings.width = width;
        self.settings.height = height;
        self
    }

    pub fn settings(mut self, settings: RenderSettings) -> Self {
        self.settings = settings;
        self
    }

    /// Changes the settings in place.
    pub fn with_settings(mut self, change: impl FnOnce(&mut RenderSettings)) -> Self {
        change(&mut self.settings);
        self
    }

    pub fn camera(mut self, camera: Camera) -> Self {
        self.camera = Some(camera);
        self
    }

    /// Names a material; a later one of the same name replaces it.
    pub fn material(mut self, name: &str, material: Material) -> Self {
        match self.material_names.get(name) {
            Some(&i) => self.materials[i as usize] = material,
            None => {
                self.material_names.insert(name.to_string(), self.materials.len() as u32);
                self.materials.push(material);
            }
        }
        self
    }

    pub fn object(mut self, shape: Shape, material: &str) -> Self {
        self.objects.push((shape, material.to_string()));
        self
    }

    pub fn object_transformed(self, shape: Shape, transform: Affine3A, material: &str) -> Self {
        self.object(shape.transformed(transform), material)
    }

    pub fn light(mut self, light: Light) -> Self {
        self.lights.push(light);
        self.light_paths.push(None);
        self
    }

    /// A light that moves along `path` in animations.
    pub fn moving_light(mut self, light: Light, path: Keyframes) -> Self {
        self.lights.push(light);
        self.light_paths.push(Some(path));
        self
    }

    pub fn medium(mut self, medium: Medium) -> Self {
        self.medium = Some(medium);
        self
    }

    /// Checks and builds the scene, with its BVH.
    pub fn build(self) -> Result<Scene, SceneError> {
        let SceneBuilder { settings, camera, mut materials, material_names, objects, lights, light_paths, medium } =
            self;
        if settings.width == 0 || settings.height == 0 {
            return Err(SceneError::new(format!(
                "image size must be at least 1×1, got {}×{}",
                settings.width, settings.height
            )));
        }
        if settings.spp == 0 {
            return Err(SceneError::new("spp must be at least 1"));
        }
        if settings.steps == 0 {
            return Err(SceneError::new("steps must be at least 1"));
        }
        if settings.light_steps == 0 {
            return Err(SceneError::new("light_steps must be at least 1"));
        }
        let camera = camera.unwrap_or_else(default_camera);
        if settings.bounces == 0 {
            return Err(SceneError::new("bounces must be at least 1"));
        }
        if settings.patch_size.is_some_and(|p| !(p.is_finite() && p > 0.0)) {
            return Err(SceneError::new("patch_size must be a positive number"));
        }
        if !(settings.link_threshold.is_finite() && settings.link_threshold > 0.0) {
            return Err(SceneError::new("link_threshold must be a positive number"));
        }
        let mut geometry = GeometryBuilder::default();
        let mut placed = Vec::with_capacity(objects.len());
        for (shape, name) in objects {
            let Some(&material) = material_names.get(&name) else {
                return Err(SceneError::new(format!("unknown material `{name}`")));
            };
            geometry.add(&shape, material, None);
            placed.push((shape, material));
        }
        // Area lights are surfaces too: the camera sees them, and they cast
        // shadows. They reflect nothing.
        let black = materials.len() as u32;
        materials.push(Material::BLACK);
        for (i, light) in lights.iter().enumerate() {
            let shape = match *light {
                Light::Sphere { center, radius, .. } => Shape::sphere(center, radius),
                Light::Quad { corner, edge_u, edge_v, .. } => Shape::quad(corner, edge_u, edge_v),
                _ => continue,
            };
            geometry.add(&shape, black, Some(i as u32));
        }
        let geometry = geometry.build();
        let (bounds_center, bounds_radius) = bounding_sphere(&geometry, &lights, &camera);
        let light_culling = LightCulling::new(&lights);
        Ok(Scene {
            settings,
            camera,
            materials,
            lights,
            light_paths,
            medium,
            geometry,
            objects: placed,
            bounds_center,
            bounds_radius,
            light_culling,
        })
    }
}

/// The camera of a scene that names none: DESIGN.md's example camera.
pub fn default_camera() -> Camera {
    Camera::look_at(Vec3::new(0.0, 2.0, -6.0), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 40.0)
}

fn bounding_sphere(geometry: &Geometry, lights: &[Light], camera: &Camera) -> (Vec3, f32) {
    let mut min = camera.position;
    let mut max = camera.position;
    let mut grow = |p: Vec3| {
        min = min.min(p);
        max = max.max(p);
    };
    if let Some((lo, hi)) = geometry.bounds() {
        grow(lo);
        grow(hi);
    }
    for light in lights {
        match *light {
            Light::Point { position, .. } | Light::Spot { position, .. } => grow(position),
            Light::Sphere { center, radius, .. } => {
                grow(center - radius);
                grow(center + radius);
            }
            Light::Quad { corner, edge_u, edge_v, .. } => {
                for p in [corner, corner + edge_u, corner + edge_v, corner + edge_u + edge_v] {
                    grow(p);
                }
            }
            Light::Line { start, end, .. } => {
                grow(start);
                grow(end);
            }
            Light::Volume { shape, .. } => {
                let (lo, hi) = shape.bounds();
                grow(lo);
                grow(hi);
            }
            Light::Distant { .. } => {}
        }
    }
    let center = 0.5 * (min + max);
    (center, (0.5 * (max - min).length()).max(1.0))
}

#[cfg(test)]
mod tests;
