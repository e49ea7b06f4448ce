//! Airlight: a CPU renderer for light that you can see.
//!
//! The library holds the render-time scene ([`Scene`]), the scene file
//! format that makes one ([`scene_file`]), the readers of the files a scene
//! names ([`assets`]: OBJ, MTL, glTF, images, `.vol` grids), geometry with
//! a BVH, lights, participating media, cameras and the integrators. It knows nothing of terminals: the
//! `airlight` command is a thin shell around it.
//!
//! ```
//! use airlight::prelude::*;
//! let scene = SceneBuilder::new()
//!     .size(32, 24)
//!     .camera(Camera::look_at(vec3(0.0, 1.0, -5.0), vec3(0.0, 1.0, 0.0), Vec3::Y, 40.0))
//!     .material("white", Material::diffuse(Rgb::splat(0.8)))
//!     .object(Shape::sphere(vec3(0.0, 1.0, 0.0), 1.0), "white")
//!     .light(Light::point(vec3(0.0, 4.0, -2.0), Rgb::splat(20.0)))
//!     .build()
//!     .unwrap();
//! let integrator = IntegratorDesc::new(IntegratorKind::Direct).build(&scene).unwrap();
//! let image = airlight::render(&scene, integrator.as_ref(), &RenderObserver::none());
//! assert!(image.pixel(16, 12).x > 0.0);
//! # let dir = std::env::temp_dir().join(format!("airlight-doc-{}", std::process::id()));
//! # std::fs::create_dir_all(&dir).unwrap();
//! image.save(dir.join("sphere.png")).unwrap();
//! # std::fs::remove_dir_all(&dir).unwrap();
//! ```
//!
//! A scene file gives a scene and the integrator it asks for:
//! [`SceneFile::load`]. The file format, units and conventions are in
//! docs/scene-format.md.

pub mod assets;
pub mod camera;
pub mod denoise;
pub mod film;
pub mod geometry;
pub mod integrator;
mod isa;
pub mod light;
pub mod material;
pub mod medium;
pub mod memory;
pub mod options;
pub mod preview;
pub mod radiosity;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod scene_file;
mod scratch;
pub mod texture;

/// Linear RGB radiance, irradiance or reflectance.
pub type Rgb = glam::Vec3;

pub use camera::{Camera, CameraRays};
pub use film::Image;
pub use render::aov;
pub use render::{RenderObserver, render};
pub use scene::{Scene, SceneBuilder};
pub use scene_file::{SceneFile, fingerprint};

/// The names most programs need.
pub mod prelude {
    pub use crate::Rgb;
    pub use crate::camera::Camera;
    pub use crate::film::Image;
    pub use crate::geometry::Shape;
    pub use crate::integrator::{IntegratorDesc, IntegratorKind};
    pub use crate::light::Light;
    pub use crate::material::Material;
    pub use crate::medium::Medium;
    pub use crate::render::{RenderObserver, render};
    pub use crate::scene::{Scene, SceneBuilder};
    pub use crate::scene_file::SceneFile;
    pub use glam::{Vec3, vec3};
}
