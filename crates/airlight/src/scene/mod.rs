//! The render-time [`Scene`] and the [`SceneBuilder`] that makes one in
//! Rust. A scene file is read into one by [`crate::SceneFile`]; the files
//! it names, by [`crate::assets`].
//!
//! A scene holds geometry, lights, the medium, the camera and the film
//! settings; which integrator renders it, with what options, is not its
//! business (see [`crate::integrator::IntegratorDesc`]). It changes only
//! through its own methods, which keep what depends on each other in step:
//! moving a light ([`Scene::set_lights`], [`Scene::at_time`]) moves its
//! visible surface and the shadow it casts, and re-sorts the light culling.

mod builder;
mod emitters;
mod error;
mod light_queries;
mod textured_emission;
pub(crate) use light_queries::toward_sample;
mod culling;
pub mod limits;
mod settings;
mod warnings;

pub(crate) use builder::Parts;
pub use builder::SceneBuilder;
pub use culling::LightCulling;
pub use error::{SceneError, line_col};
pub use settings::{MAX_IMAGE_SIDE, MAX_PIXELS, MAX_SPP, RENDER_SETTINGS, RenderSettings};

use crate::camera::Camera;
use crate::geometry::{Geometry, GeometryBuilder, Shape, SurfaceHit};
use crate::light::{Keyframes, Light};
use crate::material::Material;
use crate::medium::Medium;
use emitters::Emitters;
use glam::Vec3;
pub use textured_emission::TexturedEmission;

/// The material index of an area light's own surface: it reflects nothing
/// (a glowing mesh's triangles take their material instead).
pub(super) const LIGHT_SURFACE: u32 = u32::MAX;

/// Everything a render needs, built and validated. See the module
/// documentation for what it keeps in step.
#[derive(Debug)]
pub struct Scene {
    settings: RenderSettings,
    camera: Camera,
    materials: Vec<Material>,
    lights: Vec<Light>,
    /// For each light, the path it moves along in animations (None: it
    /// stays put). See [`crate::light::Keyframes`].
    light_paths: Vec<Option<Keyframes>>,
    /// Per light: its emission where it varies over the light (an
    /// emissive texture; see [`Scene::emitted`]).
    light_emission: Vec<Option<Box<TexturedEmission>>>,
    /// Per material index: its cut-out, if any (glTF's alpha), which the
    /// geometry lets rays through.
    cutouts: Vec<Option<crate::material::Cutout>>,
    /// The sky light whose radiance an environment map gives, and the map.
    sky_map: Option<(u32, std::sync::Arc<crate::light::environment::EnvironmentMap>)>,
    /// Per light: the material its surface reflects by (a glowing
    /// surface's own), or [`LIGHT_SURFACE`] (black).
    light_materials: Vec<u32>,
    /// Never a vacuum: a medium that neither absorbs nor scatters is none.
    medium: Option<Medium>,
    /// The scene's objects (not the lights' surfaces), in world space, with
    /// their material index.
    objects: Vec<(Shape, u32)>,
    geometry: Geometry,
    bounds_center: Vec3,
    bounds_radius: f32,
    light_culling: LightCulling,
    /// The lights grouped for sampling: an emitting mesh's triangles as one
    /// (see [`Scene::for_each_emitter_at`]).
    emitters: Emitters,
    /// The indices of the delta lights with a place (see
    /// [`Scene::placed_delta_lights`]).
    placed_delta: Vec<u32>,
    /// The sky lights (see [`Scene::skies`]).
    skies: Vec<u32>,
    /// The files the scene was read from (see [`Scene::files`]).
    pub(crate) files: Vec<std::path::PathBuf>,
    /// What the scene file asked for that Airlight does not do (yet).
    pub(crate) notes: Vec<String>,
}

impl Scene {
    /// The files a scene file's scene was read from, symbolic links
    /// resolved: the scene file, then its meshes (empty for a scene built
    /// in code). Outputs must not replace them.
    pub fn files(&self) -> &[std::path::PathBuf] {
        &self.files
    }

    /// What the scene file asked for that Airlight does not do yet (a
    /// glTF texture, for one), for the user to be told.
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// The film settings, to change (size, samples, seed, …); a render
    /// checks them ([`RenderSettings::validate`]).
    pub fn settings_mut(&mut self) -> &mut RenderSettings {
        &mut self.settings
    }

    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Moves the camera (the scene's bounding sphere follows).
    pub fn set_camera(&mut self, camera: Camera) {
        self.camera = camera;
        self.update_bounds();
    }

    /// The materials the scene's objects name, in the order defined.
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// The materials, to change their values (radiosity relights with them).
    pub fn materials_mut(&mut self) -> &mut [Material] {
        &mut self.materials
    }

    /// The material of a surface: its object's, or black for an area light's
    /// own surface (it emits, it does not reflect).
    #[inline]
    pub fn material(&self, index: u32) -> &Material {
        self.materials.get(index as usize).unwrap_or(&Material::BLACK)
    }

    /// Whether some material is cut out (has a coverage rays pass through).
    pub fn has_cutouts(&self) -> bool {
        self.cutouts.iter().any(Option::is_some)
    }

    /// The normal a hit is shaded with when it is not its surface's own: a
    /// mesh's vertex normals interpolated (see [`crate::material::shading`]).
    /// A normal map's normal where its material has one (see
    /// [`crate::material::SurfaceMaps::mapped_normal`]).
    #[inline]
    pub fn shading_normal(&self, surface: &SurfaceHit) -> Option<Vec3> {
        let vertex = self.geometry.vertex_normal(surface);
        if let Material::MetallicRoughness(m) = self.material(surface.material)
            && let Some(maps) = &m.maps
            && maps.normal.is_some()
            && let Some(uv) = self.geometry.uv(surface)
            && let Some((dpdu, dpdv)) = self.geometry.uv_derivatives(surface)
        {
            return maps.mapped_normal(uv, vertex.unwrap_or(surface.n), dpdu, dpdv).or(vertex);
        }
        vertex
    }

    /// The material at a hit, a texture looked up at its texture
    /// coordinates ([`Material::at_uv`]).
    #[inline]
    pub fn material_at(&self, surface: &SurfaceHit) -> Material {
        let material = self.material(surface.material);
        if material.has_maps() { material.at_uv(self.geometry.uv(surface)) } else { material.clone() }
    }

    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// For each light, the path it moves along in animations.
    pub fn light_paths(&self) -> &[Option<Keyframes>] {
        &self.light_paths
    }

    /// The participating medium, if there is one that absorbs or scatters.
    pub fn medium(&self) -> Option<&Medium> {
        self.medium.as_ref()
    }

    /// Replaces the medium (None, or a vacuum: no medium). Integrators
    /// built for the scene before must be built again.
    /// Replaces the medium; one too thick for any image to show is refused
    /// ([`Scene::check_medium_depth`]) and the scene keeps its own.
    pub fn set_medium(&mut self, medium: Option<Medium>) -> Result<(), String> {
        let old = std::mem::replace(&mut self.medium, medium.filter(|m| !m.is_vacuum()));
        self.check_medium_depth().inspect_err(|_| self.medium = old)
    }

    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// The scene's objects in world space with their material index; the
    /// lights' surfaces are not among them (see [`Scene::surfaces`]).
    pub fn objects(&self) -> &[(Shape, u32)] {
        &self.objects
    }

    /// Every surface rays can meet, as shapes: the objects with their
    /// material, then the sphere and quad lights' surfaces with the index of
    /// their light. The geometry's BVH is built from exactly these.
    pub fn surfaces(&self) -> impl Iterator<Item = Surface> + '_ {
        let objects = self.objects.iter().map(|(shape, material)| Surface {
            shape: shape.clone(),
            material: *material,
            emitter: None,
        });
        let lights = self.lights.iter().enumerate().filter_map(|(i, light)| {
            let material = self.light_materials.get(i).copied().unwrap_or(LIGHT_SURFACE);
            let mut shape = light.surface()?;
            // A glowing triangle with texture coordinates (its emissive
            // texture's) reflects by its material's textures there too.
            if let (Shape::Mesh { uvs, .. }, Some(Some(e))) = (&mut shape, self.light_emission.get(i)) {
                *uvs = e.uvs.to_vec();
            }
            Some(Surface { shape, material, emitter: Some(i as u32) })
        });
        objects.chain(lights)
    }

    /// A BVH of the objects alone, without the lights' surfaces: for what is
    /// computed once while lights move (the viewer's cached camera hits).
    pub fn objects_geometry(&self) -> Geometry {
        let mut geometry = build_geometry(self.surfaces().filter(|s| s.emitter.is_none()));
        geometry.set_cutouts(self.cutouts.clone());
        geometry
    }

    /// Centre and radius of a sphere around the bounded geometry, the lights
    /// and the camera; a sun's light enters the scene from its surface, as in
    /// pbrt-v4 and Mitsuba 3.
    pub fn bounds(&self) -> (Vec3, f32) {
        (self.bounds_center, self.bounds_radius)
    }

    pub fn light_culling(&self) -> &LightCulling {
        &self.light_culling
    }

    /// The indices, in order, of the point, spot and line lights: the delta
    /// lights with a place ([`Light::anchor`]), which the path tracer also
    /// samples along each segment through a medium. Kept with the lights,
    /// so that the many area lights of an emissive mesh are not walked per
    /// scattering event.
    pub fn placed_delta_lights(&self) -> &[u32] {
        &self.placed_delta
    }

    /// The indices of the sky lights: what a ray that leaves the scene
    /// sees, besides the background.
    pub fn skies(&self) -> &[u32] {
        &self.skies
    }

    /// What a ray along `dir` that leaves the scene sees, unweighted: the
    /// background and every sky. (The path tracer weighs the skies against
    /// their samples instead.)
    pub fn escaped_radiance(&self, dir: Vec3) -> crate::Rgb {
        self.skies.iter().fold(self.settings.background, |sum, &i| sum + self.sky_radiance(i as usize, dir))
    }

    /// Makes the scene's sky `radiance` (zero: no sky): the first sky light
    /// takes it and any others go dark, or a sky is added when there is
    /// none. The other lights keep their places and their animation paths.
    pub fn set_sky(&mut self, radiance: crate::Rgb) {
        let mut lights = self.lights.clone();
        let mut first = true;
        for light in lights.iter_mut().filter(|l| matches!(l, Light::Sky { .. })) {
            *light = Light::sky(if first { radiance } else { crate::Rgb::ZERO });
            first = false;
        }
        if first && radiance != crate::Rgb::ZERO {
            lights.push(Light::sky(radiance));
        }
        self.set_lights(&lights);
    }

    /// Replaces the lights (moved, dimmed, others) and brings everything
    /// that depends on them in step: the area lights' surfaces in the BVH
    /// (so the camera sees a light where it now is and its old surface casts
    /// no shadow), the light culling and the bounding sphere. Lights beyond
    /// the old count get no animation path. Returns whether the BVH was
    /// rebuilt (only when an area light's surface changed).
    pub fn set_lights(&mut self, lights: &[Light]) -> bool {
        let surfaces_moved = self.lights.len() != lights.len()
            || self.lights.iter().zip(lights).any(|(a, b)| a.surface() != b.surface());
        self.lights = lights.to_vec();
        self.light_paths.resize(self.lights.len(), None);
        self.light_emission.resize(self.lights.len(), None);
        self.light_materials.resize(self.lights.len(), LIGHT_SURFACE);
        self.emitters = Emitters::new(&self.lights);
        self.light_culling = LightCulling::new(&self.lights, self.emitters.firsts());
        self.placed_delta = placed_delta(&self.lights);
        self.skies = skies(&self.lights);
        if surfaces_moved {
            self.geometry = build_geometry(self.surfaces());
            self.geometry.set_cutouts(self.cutouts.clone());
        }
        self.update_bounds();
        surfaces_moved
    }

    /// Moves every light with keyframes to where it is at `time` in [0, 1]
    /// of the animation (see [`Scene::set_lights`] for what follows).
    /// Returns whether the BVH was rebuilt.
    pub fn at_time(&mut self, time: f32) -> bool {
        let lights = self.lights_at(time);
        self.set_lights(&lights)
    }

    /// The lights at `time` of the animation, without changing the scene.
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

    /// Refuses a medium crossed by null collisions that is more than
    /// [`limits::MAX_OPTICAL_DEPTH`] mean free paths across the scene: no
    /// image can show its inside, and tracking through it would take about
    /// that many steps a path.
    pub fn check_medium_depth(&self) -> Result<(), String> {
        let Some(m) = &self.medium else { return Ok(()) };
        let Some(peak) = m.tracked_peak_density() else { return Ok(()) };
        let sigma_t = m.sigma_t().max_element();
        let depth = sigma_t * peak * 2.0 * self.bounds_radius;
        if depth <= limits::MAX_OPTICAL_DEPTH {
            return Ok(());
        }
        Err(format!(
            "the medium is {depth:.3e} mean free paths across the scene (σt {sigma_t} × peak density {peak}): more \
             than {:.0e}, where a free path is below what 32-bit positions resolve and no image can show its \
             inside; lower sigma_a, sigma_s or the density",
            limits::MAX_OPTICAL_DEPTH
        ))
    }

    fn update_bounds(&mut self) {
        (self.bounds_center, self.bounds_radius) = bounding_sphere(&self.geometry, &self.lights, &self.camera);
    }

    /// Replaces the falloff model of every point, spot and sphere light
    /// (each keeps its radius, cutoff and range).
    pub fn set_attenuation_model(&mut self, model: crate::light::AttenuationModel) -> Result<(), String> {
        let mut lights = self.lights.clone();
        for light in &mut lights {
            if let Some(a) = light.attenuation() {
                *light = light.with_attenuation(a.with_model(model)?);
            }
        }
        self.set_lights(&lights);
        Ok(())
    }
}

/// One surface of a scene: its shape in world space, its material index
/// (see [`Scene::material`]) and the light it is the surface of, if any.
#[derive(Clone, Debug)]
pub struct Surface {
    pub shape: Shape,
    pub material: u32,
    pub emitter: Option<u32>,
}

/// See [`Scene::skies`].
fn skies(lights: &[Light]) -> Vec<u32> {
    lights.iter().enumerate().filter(|(_, light)| matches!(light, Light::Sky { .. })).map(|(i, _)| i as u32).collect()
}

/// See [`Scene::placed_delta_lights`].
fn placed_delta(lights: &[Light]) -> Vec<u32> {
    lights.iter().enumerate().filter(|(_, light)| light.is_placed_delta()).map(|(i, _)| i as u32).collect()
}

fn build_geometry(surfaces: impl Iterator<Item = Surface>) -> Geometry {
    geometry_of(surfaces).build()
}

fn geometry_of(surfaces: impl Iterator<Item = Surface>) -> GeometryBuilder {
    let mut geometry = GeometryBuilder::default();
    for s in surfaces {
        geometry.add(&s.shape, s.material, s.emitter);
    }
    geometry
}

/// The camera of a scene that names none.
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
            Light::Triangle { a, edge_1, edge_2, .. } => {
                for p in [a, a + edge_1, a + edge_2] {
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
            Light::Distant { .. } | Light::Sky { .. } => {}
        }
    }
    let center = 0.5 * (min + max);
    (center, (0.5 * (max - min).length()).max(1.0))
}

#[cfg(test)]
mod tests;
