//! The scene file as written: plain serde structs for the format that
//! docs/scene-format.md describes. Unknown keys are errors. `build.rs` checks the values
//! and turns them into a [`Scene`](super::Scene).

use crate::light::{AttenuationModel, SpotProfile};
use crate::options::OptionValue;
use glam::Vec3;
use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use std::collections::BTreeMap;
use std::fmt;
use toml::Spanned;

/// A whole scene file.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    #[serde(default)]
    pub render: RenderDesc,
    pub camera: Option<Spanned<CameraDesc>>,
    pub medium: Option<Spanned<MediumDesc>>,
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<MaterialDesc>>,
    #[serde(default)]
    pub objects: Vec<Spanned<ObjectDesc>>,
    #[serde(default)]
    pub lights: Vec<Spanned<LightDesc>>,
    #[serde(default)]
    pub include: Vec<Spanned<IncludeDesc>>,
}

/// One `[[include]]` table: a glTF or OBJ file placed in the scene.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IncludeDesc {
    pub file: Spanned<String>,
    /// glTF: the scene to take, by name (default: the file's default scene).
    pub scene: Option<String>,
    /// A material from `[materials]` for every surface, instead of the file's.
    pub material: Option<Spanned<String>>,
    pub translate: Option<Point>,
    pub rotate: Option<Point>,
    pub scale: Option<Triple>,
}

/// The `[render]` table as written: each key with its value, both with
/// their place in the text. Its keys are the film settings
/// ([`super::RENDER_SETTINGS`]) and the integrators' options
/// (`crate::integrator::INTEGRATOR_OPTIONS`); each is checked by its own
/// declaration when read, and a key that neither reads is an error
/// (`crate::SceneFile`).
#[derive(Debug, Default, Deserialize)]
#[serde(transparent)]
pub struct RenderDesc(pub BTreeMap<Spanned<String>, Spanned<OptionValue>>);

impl RenderDesc {
    /// The value given for `key`.
    pub fn get(&self, key: &str) -> Option<&Spanned<OptionValue>> {
        self.0.iter().find(|(k, _)| k.get_ref() == key).map(|(_, v)| v)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CameraType {
    Perspective,
    Orthographic,
    Isometric,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    #[serde(rename = "type", default = "perspective")]
    pub kind: CameraType,
    pub position: Option<Point>,
    pub look_at: Option<Point>,
    pub up: Option<Point>,
    pub fov: Option<f32>,
    pub view_height: Option<f32>,
    pub aperture: Option<f32>,
    pub focus_distance: Option<f32>,
    /// Isometric only: how far back from look_at the camera stands.
    pub distance: Option<f32>,
}

fn perspective() -> CameraType {
    CameraType::Perspective
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MediumType {
    Homogeneous,
    Height,
    Grid,
    Noise,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MediumDesc {
    #[serde(rename = "type", default = "homogeneous")]
    pub kind: MediumType,
    pub sigma_a: Option<Triple>,
    pub sigma_s: Option<Triple>,
    pub g: Option<f32>,
    pub base: Option<f32>,
    pub falloff: Option<f32>,
    /// Grid: the `.vol` file, its densities' multiplier and its placement.
    pub file: Option<Spanned<String>>,
    pub density_scale: Option<f32>,
    pub translate: Option<Point>,
    pub rotate: Option<Point>,
    /// Grid: the transform's scale; noise: the largest features' size.
    pub scale: Option<Triple>,
    /// Noise: its octaves, gain, offset, seed and box.
    pub octaves: Option<Spanned<i64>>,
    pub gain: Option<f32>,
    pub offset: Option<f32>,
    pub seed: Option<Spanned<i64>>,
    pub min: Option<Point>,
    pub max: Option<Point>,
}

fn homogeneous() -> MediumType {
    MediumType::Homogeneous
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MaterialType {
    Diffuse,
    Checker,
    Phong,
    Texture,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDesc {
    #[serde(rename = "type", default = "diffuse")]
    pub kind: MaterialType,
    pub albedo: Option<Triple>,
    pub albedo2: Option<Triple>,
    pub scale: Option<f32>,
    pub specular: Option<Triple>,
    pub exponent: Option<f32>,
    /// texture: the image file (PNG or JPEG), under the asset rules.
    pub file: Option<Spanned<String>>,
    /// texture: `repeat`, `clamp` or `mirror`.
    pub wrap: Option<Spanned<String>>,
}

fn diffuse() -> MaterialType {
    MaterialType::Diffuse
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ObjectType {
    Sphere,
    Plane,
    Quad,
    Box,
    Mesh,
    Sdf,
}

/// One `[[objects]]` table. Fields are optional here; which ones a type
/// needs (and allows) is checked when the scene is built.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    #[serde(rename = "type")]
    pub kind: ObjectType,
    pub material: Option<Spanned<String>>,
    pub center: Option<Point>,
    pub radius: Option<f32>,
    pub point: Option<Point>,
    pub normal: Option<Point>,
    pub corner: Option<Point>,
    pub edge_u: Option<Point>,
    pub edge_v: Option<Point>,
    pub min: Option<Point>,
    pub max: Option<Point>,
    pub file: Option<Spanned<String>>,
    /// Radiance the surface emits (sphere, quad and mesh objects): the
    /// object becomes area lights, one per triangle for a mesh.
    pub emission: Option<Triple>,
    pub translate: Option<Point>,
    pub rotate: Option<Point>,
    pub scale: Option<Triple>,
    // Signed distance fields (`type = "sdf"`): the root node's fields, as in
    // [`SdfNodeDesc`].
    pub shape: Option<SdfShape>,
    pub children: Option<Vec<Spanned<SdfNodeDesc>>>,
    pub blend: Option<f32>,
    pub a: Option<Point>,
    pub b: Option<Point>,
    pub major_radius: Option<f32>,
    pub minor_radius: Option<f32>,
    pub rounding: Option<f32>,
}

/// The kinds of node of a signed distance field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SdfShape {
    Sphere,
    Box,
    RoundBox,
    Torus,
    Capsule,
    Cylinder,
    Plane,
    Union,
    Intersection,
    Subtraction,
    SmoothUnion,
}

/// One node of a signed distance field: a primitive with its parameters or
/// a combination with `children`, each placed by its own translate, rotate,
/// scale. Which fields a shape takes is checked when the scene is built.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SdfNodeDesc {
    pub shape: SdfShape,
    pub center: Option<Point>,
    pub radius: Option<f32>,
    pub min: Option<Point>,
    pub max: Option<Point>,
    pub point: Option<Point>,
    pub normal: Option<Point>,
    pub a: Option<Point>,
    pub b: Option<Point>,
    pub major_radius: Option<f32>,
    pub minor_radius: Option<f32>,
    pub rounding: Option<f32>,
    pub blend: Option<f32>,
    pub children: Option<Vec<Spanned<SdfNodeDesc>>>,
    pub translate: Option<Point>,
    pub rotate: Option<Point>,
    pub scale: Option<Triple>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightType {
    Point,
    Spot,
    Distant,
    Sphere,
    Quad,
    Line,
    /// A volume light filling a box.
    Box,
}

/// One `[[lights]]` table; as for objects, the fields a type needs are
/// checked when the scene is built.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDesc {
    #[serde(rename = "type")]
    pub kind: LightType,
    pub position: Option<Point>,
    pub intensity: Option<Triple>,
    pub direction: Option<Point>,
    pub look_at: Option<Point>,
    pub cone_angle: Option<f32>,
    pub falloff_start: Option<f32>,
    pub profile: Option<SpotProfileDesc>,
    pub irradiance: Option<Triple>,
    pub center: Option<Point>,
    pub radius: Option<f32>,
    pub radiance: Option<Triple>,
    pub corner: Option<Point>,
    pub edge_u: Option<Point>,
    pub edge_v: Option<Point>,
    pub start: Option<Point>,
    pub end: Option<Point>,
    /// Point, spot and sphere lights: how light falls off with distance.
    pub attenuation: Option<AttenuationModel>,
    /// Irradiance below which a finite-range falloff drops the light.
    pub cutoff: Option<f32>,
    /// d_max: how far from its surface a finite-range falloff reaches.
    pub range: Option<f32>,
    /// Box light: its corners.
    pub min: Option<Point>,
    pub max: Option<Point>,
    /// Sphere light: a glowing ball (volume light of `intensity`) instead of
    /// a surface of `radiance`.
    pub volume: Option<bool>,
    /// The path the light moves along in animations; see
    /// [`crate::light::Keyframes`].
    pub keyframes: Option<Spanned<Vec<Spanned<KeyframeDesc>>>>,
}

/// One key of a moving light: `{ time = 0.0, position = [x, y, z] }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyframeDesc {
    pub time: f32,
    pub position: Point,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SpotProfileDesc {
    Smoothstep,
    Linear,
}

impl From<SpotProfileDesc> for SpotProfile {
    fn from(p: SpotProfileDesc) -> Self {
        match p {
            SpotProfileDesc::Smoothstep => SpotProfile::Smoothstep,
            SpotProfileDesc::Linear => SpotProfile::Linear,
        }
    }
}

/// A value of the file found wrong after parsing: where it is (a byte range
/// of the text) and what was expected.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldError {
    pub span: std::ops::Range<usize>,
    pub message: String,
}

/// A name from a closed set (an integrator, a tone curve, …), parsed by the
/// type that owns the set; its error placed at the value.
pub fn parse_name<T: std::str::FromStr<Err = String>>(v: &Spanned<String>, key: &str) -> Result<T, FieldError> {
    v.get_ref().parse().map_err(|e| FieldError { span: v.span(), message: format!("{key}: {e}") })
}

/// A point or vector: exactly three numbers (integers allowed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point(pub Vec3);

/// A colour, coefficient or scale: one number (the same on all three
/// channels or axes) or three.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triple(pub Vec3);

struct TripleVisitor {
    allow_scalar: bool,
}

impl<'de> Visitor<'de> for TripleVisitor {
    type Value = Vec3;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        if self.allow_scalar {
            f.write_str("a number or an array of three numbers")
        } else {
            f.write_str("an array of three numbers")
        }
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Vec3, E> {
        if self.allow_scalar {
            Ok(Vec3::splat(v as f32))
        } else {
            Err(E::invalid_type(de::Unexpected::Float(v), &self))
        }
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Vec3, E> {
        if self.allow_scalar {
            Ok(Vec3::splat(v as f32))
        } else {
            Err(E::invalid_type(de::Unexpected::Signed(v), &self))
        }
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec3, A::Error> {
        let mut v = [0.0f32; 3];
        for (i, slot) in v.iter_mut().enumerate() {
            *slot = seq.next_element::<f32>()?.ok_or_else(|| de::Error::invalid_length(i, &self))?;
        }
        if seq.next_element::<de::IgnoredAny>()?.is_some() {
            return Err(de::Error::invalid_length(4, &self));
        }
        Ok(Vec3::from_array(v))
    }
}

impl<'de> Deserialize<'de> for Point {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TripleVisitor { allow_scalar: false }).map(Point)
    }
}

impl<'de> Deserialize<'de> for Triple {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TripleVisitor { allow_scalar: true }).map(Triple)
    }
}
