//! [`SceneBuilder`]: a scene made in Rust, object by object, with the
//! checks a scene file gets.

use super::emitters::Emitters;
use super::textured_emission::TexturedEmission;
use super::{LightCulling, RenderSettings, Scene, SceneError, default_camera, geometry_of, limits, placed_delta};
use crate::Rgb;
use crate::camera::Camera;
use crate::geometry::{Geometry, Shape};
use crate::light::environment::EnvironmentMap;
use crate::light::{Keyframes, Light};
use crate::material::{Cutout, Material};
use crate::medium::Medium;
use glam::{Affine3A, Vec3};
use std::collections::HashMap;
use std::sync::Arc;

/// What a scene file's object table or an included file adds to a scene:
/// materials by name, surfaces with the names of their materials, and the
/// lights of emitting surfaces.
#[derive(Default)]
pub(crate) struct Parts {
    pub materials: Vec<(String, Material)>,
    pub objects: Vec<(Shape, String)>,
    pub lights: Vec<Light>,
    /// The emission of the lights of `lights` (by index) whose radiance
    /// varies over them.
    pub textured: Vec<(usize, TexturedEmission)>,
    /// The cut-outs of the materials of `materials` (by name) that have one.
    pub cutouts: Vec<(String, Cutout)>,
    /// The material each light of `lights` (by index) reflects by, for
    /// glowing surfaces that also reflect (others reflect nothing).
    pub light_materials: Vec<(usize, String)>,
}

/// Builds a [`Scene`] in Rust, as a World/Camera example in a tutorial would.
#[derive(Default)]
pub struct SceneBuilder {
    settings: RenderSettings,
    camera: Option<Camera>,
    materials: Vec<Material>,
    material_names: HashMap<String, u32>,
    objects: Vec<(Shape, String)>,
    lights: Vec<Light>,
    light_paths: Vec<Option<Keyframes>>,
    textured: Vec<(usize, TexturedEmission)>,
    /// Cut-outs by material name.
    cutouts: HashMap<String, Cutout>,
    /// The sky light an environment map gives, by index, and the map.
    sky_map: Option<(u32, Arc<EnvironmentMap>)>,
    /// Lights (by index) whose surfaces reflect by a material (by name).
    light_materials: Vec<(usize, String)>,
    medium: Option<Medium>,
}

impl SceneBuilder {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.settings.film.width = width;
        self.settings.film.height = height;
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

    /// Adds the parts, materials first.
    pub(crate) fn parts(self, parts: Parts) -> Self {
        let builder = parts.materials.into_iter().fold(self, |b, (name, m)| b.material(&name, m));
        let mut builder = parts.objects.into_iter().fold(builder, |b, (shape, name)| b.object(shape, &name));
        for (name, cutout) in parts.cutouts {
            builder = builder.cutout(&name, cutout);
        }
        let offset = builder.lights.len();
        builder.textured.extend(parts.textured.into_iter().map(|(i, e)| (offset + i, e)));
        builder.light_materials.extend(parts.light_materials.into_iter().map(|(i, m)| (offset + i, m)));
        parts.lights.into_iter().fold(builder, SceneBuilder::light)
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

    /// A sky whose radiance is `scale` × the environment map's (see
    /// [`EnvironmentMap`]); a scene has at most one.
    pub fn environment(mut self, scale: Rgb, map: Arc<EnvironmentMap>) -> Self {
        self.sky_map = Some((self.lights.len() as u32, map));
        self.light(Light::sky(scale))
    }

    /// Makes the material `name` a cut-out (see [`Cutout`]).
    pub fn cutout(mut self, name: &str, cutout: Cutout) -> Self {
        self.cutouts.insert(name.to_string(), cutout);
        self
    }

    pub fn medium(mut self, medium: Medium) -> Self {
        self.medium = Some(medium);
        self
    }

    /// Checks and builds the scene, with its BVH.
    pub fn build(self) -> Result<Scene, SceneError> {
        let SceneBuilder {
            settings,
            camera,
            materials,
            material_names,
            objects,
            lights,
            light_paths,
            textured,
            cutouts: cutouts_by_name,
            sky_map,
            light_materials: light_material_names,
            medium,
        } = self;
        let mut light_materials = vec![super::LIGHT_SURFACE; lights.len()];
        for (i, name) in light_material_names {
            let Some(&index) = material_names.get(&name) else {
                return Err(SceneError::new(format!("a glowing surface of unknown material `{name}`")));
            };
            if let Some(slot) = light_materials.get_mut(i) {
                *slot = index;
            }
        }
        let mut cutouts = vec![None; materials.len()];
        for (name, cutout) in cutouts_by_name {
            let Some(&index) = material_names.get(&name) else {
                return Err(SceneError::new(format!("a cut-out of unknown material `{name}`")));
            };
            cutouts[index as usize] = Some(cutout);
        }
        let mut light_emission: Vec<Option<Box<TexturedEmission>>> = vec![None; lights.len()];
        for (i, e) in textured {
            if let Some(slot) = light_emission.get_mut(i) {
                *slot = Some(Box::new(e));
            }
        }
        settings.validate().map_err(SceneError::new)?;
        let camera = camera.unwrap_or_else(default_camera);
        let mut placed = Vec::with_capacity(objects.len());
        for (shape, name) in objects {
            let Some(&material) = material_names.get(&name) else {
                return Err(SceneError::new(format!("unknown material `{name}`")));
            };
            placed.push((shape, material));
        }
        // The metallic-roughness table is computed once per process; done
        // here it counts as setup, not as the first samples' time (which
        // the command line's time estimate probes).
        if materials.iter().any(|m| matches!(m, Material::MetallicRoughness(_))) {
            crate::material::microfacet::SpecularAlbedo::get();
        }
        let emitters = Emitters::new(&lights);
        let light_culling = LightCulling::new(&lights, emitters.firsts());
        let placed_delta = placed_delta(&lights);
        let skies = super::skies(&lights);
        let mut scene = Scene {
            settings,
            camera,
            materials,
            lights,
            light_paths,
            light_emission,
            cutouts: cutouts.clone(),
            sky_map,
            light_materials,
            medium: medium.filter(|m| !m.is_vacuum()),
            objects: placed,
            geometry: Geometry::default(),
            bounds_center: Vec3::ZERO,
            bounds_radius: 1.0,
            light_culling,
            emitters,
            placed_delta,
            skies,
            files: Vec::new(),
            notes: Vec::new(),
        };
        let geometry = geometry_of(scene.surfaces());
        let same = geometry.largest_group_of_equal_bounds();
        if same > limits::MAX_EQUAL_BOUNDS {
            return Err(SceneError::new(format!(
                "{same} surfaces have exactly the same bounds (duplicated faces, objects or instances); at most {} \
                 may, since no BVH can part them and building one over them takes time that grows as the square \
                 of their number",
                limits::MAX_EQUAL_BOUNDS
            )));
        }
        scene.geometry = geometry.build();
        scene.geometry.set_cutouts(cutouts);
        scene.update_bounds();
        scene.check_medium_depth().map_err(SceneError::new)?;
        Ok(scene)
    }
}
