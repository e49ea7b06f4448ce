//! The scene file as written: serde structs for the format that
//! docs/scene-format.md describes, one per type of light, object, material,
//! medium and SDF node (their fields are the type's keys; see
//! [`super::tables`]). Unknown keys are errors. `check.rs` checks the
//! values and turns them into a [`Scene`](crate::Scene).

use super::tables::{NoShared, TableAt, Tagged, tagged};
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
    // The tables below are read by their type's struct when the scene is
    // built ([`super::tables`]); here only their places are kept.
    pub camera: Option<Spanned<TableAt>>,
    pub medium: Option<Spanned<TableAt>>,
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<TableAt>>,
    #[serde(default)]
    pub objects: Vec<Spanned<TableAt>>,
    #[serde(default)]
    pub lights: Vec<Spanned<TableAt>>,
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
/// ([`crate::scene::RENDER_SETTINGS`]) and the integrators' options
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

tagged! {
    /// The `[camera]` table, by its `type`.
    pub(crate) enum CameraDesc {
        tag: "type", family: ("camera", "cameras"), default: Some("perspective"), shared: Aim,
        Perspective(PerspectiveCamera) = "perspective",
        Orthographic(OrthographicCamera) = "orthographic",
        /// An orthographic camera looking down the isometric diagonal at
        /// `look_at`, from `distance` back.
        Isometric(IsometricCamera) = "isometric",
    }
}

/// What every camera has: where it looks, which way is up, and its lens.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Aim {
    pub look_at: Option<Point>,
    pub up: Option<Point>,
    pub aperture: Option<f32>,
    pub focus_distance: Option<f32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PerspectiveCamera {
    pub position: Option<Point>,
    /// The vertical field of view, in degrees.
    pub fov: Option<f32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct OrthographicCamera {
    pub position: Option<Point>,
    /// The height of the view, in world units.
    pub view_height: Option<f32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct IsometricCamera {
    pub view_height: Option<f32>,
    pub distance: Option<f32>,
}

tagged! {
    /// The `[medium]` table, by its `type`.
    pub(crate) enum MediumDesc {
        tag: "type", family: ("medium", "media"), default: Some("homogeneous"), shared: MediumCoefficients,
        Homogeneous(HomogeneousMedium) = "homogeneous",
        Height(HeightMedium) = "height",
        Grid(GridMedium) = "grid",
        Noise(NoiseMedium) = "noise",
    }
}

/// What every medium has: its coefficients (per unit density) and phase.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MediumCoefficients {
    pub sigma_a: Option<Triple>,
    pub sigma_s: Option<Triple>,
    pub g: Option<f32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct HomogeneousMedium {}

/// Density exp(−falloff·(y − base)).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct HeightMedium {
    pub base: Option<f32>,
    pub falloff: Option<f32>,
}

/// A density grid from a Mitsuba `.vol` file, its densities' multiplier
/// and its placement.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct GridMedium {
    pub file: Spanned<String>,
    pub density_scale: Option<f32>,
    pub translate: Option<Point>,
    pub rotate: Option<Point>,
    pub scale: Option<Triple>,
}

/// Procedural fog: its features' size, octaves, gain, offset, seed, box
/// and height falloff.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct NoiseMedium {
    pub scale: Option<Triple>,
    pub octaves: Option<Spanned<i64>>,
    pub gain: Option<f32>,
    pub offset: Option<f32>,
    pub seed: Option<Spanned<i64>>,
    pub min: Option<Point>,
    pub max: Option<Point>,
    pub base: Option<f32>,
    pub falloff: Option<f32>,
}

tagged! {
    /// One `[materials.NAME]` table, by its `type`. (Read once per
    /// material: the metallic-roughness variant's size costs nothing.)
    #[allow(clippy::large_enum_variant)]
    pub(crate) enum MaterialDesc {
        tag: "type", family: ("material", "materials"), default: Some("diffuse"), shared: NoShared,
        Diffuse(DiffuseMaterial) = "diffuse",
        Checker(CheckerMaterial) = "checker",
        Phong(PhongMaterial) = "phong",
        Texture(TextureMaterial) = "texture",
        MetallicRoughness(MetallicRoughnessMaterial) = "metallic_roughness",
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct DiffuseMaterial {
    pub albedo: Option<Triple>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CheckerMaterial {
    pub albedo: Option<Triple>,
    pub albedo2: Option<Triple>,
    pub scale: Option<f32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PhongMaterial {
    pub albedo: Option<Triple>,
    pub specular: Option<Triple>,
    pub exponent: Option<f32>,
}

/// An image (PNG or JPEG, under the asset rules) times `albedo`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TextureMaterial {
    pub albedo: Option<Triple>,
    pub file: Spanned<String>,
    /// `repeat`, `clamp` or `mirror`.
    pub wrap: Option<Spanned<String>>,
}

/// glTF 2.0's metallic-roughness material, its factors and optional maps.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MetallicRoughnessMaterial {
    pub base_colour: Option<Triple>,
    pub metallic: Option<Spanned<f32>>,
    pub roughness: Option<Spanned<f32>>,
    /// The dielectric's specular weight (glTF's `KHR_materials_specular`).
    pub specular: Option<Spanned<f32>>,
    /// An sRGB image that multiplies `base_colour`.
    pub base_colour_file: Option<Spanned<String>>,
    /// Data: green multiplies `roughness`, blue `metallic`.
    pub metallic_roughness_file: Option<Spanned<String>>,
    /// A tangent-space normal map (data), glTF's convention.
    pub normal_file: Option<Spanned<String>>,
    /// The normal map's x and y scale.
    pub normal_scale: Option<Spanned<f32>>,
    /// `repeat`, `clamp` or `mirror`, for both images.
    pub wrap: Option<Spanned<String>>,
}

tagged! {
    /// One `[[objects]]` table, by its `type`.
    pub(crate) enum ObjectDesc {
        tag: "type", family: ("object", "objects"), default: None, shared: Placement,
        Sphere(SphereObject) = "sphere",
        Plane(PlaneObject) = "plane",
        Quad(QuadObject) = "quad",
        Box(BoxObject) = "box",
        Mesh(MeshObject) = "mesh",
        /// A signed distance field: the table is its root node, whose
        /// `shape` picks the node's keys ([`SdfNodeDesc`]).
        Sdf(SdfObject) = "sdf",
    }
}

/// What every object has: its material (or the radiance it emits) and its
/// place.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Placement {
    pub material: Option<Spanned<String>>,
    /// Radiance the surface emits (sphere, quad and mesh objects): the
    /// object becomes area lights, one per triangle for a mesh.
    pub emission: Option<Triple>,
    pub translate: Option<Point>,
    pub rotate: Option<Point>,
    pub scale: Option<Triple>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SphereObject {
    pub center: Point,
    pub radius: f32,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PlaneObject {
    pub point: Point,
    pub normal: Point,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct QuadObject {
    pub corner: Point,
    pub edge_u: Point,
    pub edge_v: Point,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct BoxObject {
    pub min: Point,
    pub max: Point,
}

/// An OBJ file, under the asset rules.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MeshObject {
    pub file: Spanned<String>,
}

/// The root node of an SDF object: the table's keys other than the
/// object's, read as the SDF node their `shape` names ([`SdfNodeDesc`])
/// when the object is built. Its keys are every node's.
#[derive(Debug)]
pub(crate) struct SdfObject;

impl<'de> Deserialize<'de> for SdfObject {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Skip;
        impl<'de> Visitor<'de> for Skip {
            type Value = SdfObject;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("the keys of an SDF node")
            }
            fn visit_map<A: de::MapAccess<'de>>(self, mut map: A) -> Result<SdfObject, A::Error> {
                while map.next_entry::<de::IgnoredAny, de::IgnoredAny>()?.is_some() {}
                Ok(SdfObject)
            }
        }
        d.deserialize_struct("SdfObject", sdf_node_keys(), Skip)
    }
}

/// `shape` and the keys of every SDF node's shape.
fn sdf_node_keys() -> &'static [&'static str] {
    static KEYS: std::sync::OnceLock<Vec<&'static str>> = std::sync::OnceLock::new();
    KEYS.get_or_init(|| {
        let mut keys = vec![<SdfNodeDesc as Tagged>::TAG];
        for shape in <SdfNodeDesc as Tagged>::TYPES {
            keys.extend(SdfNodeDesc::keys(shape).iter().filter(|k| !keys.contains(k)).collect::<Vec<_>>());
        }
        keys
    })
}

tagged! {
    /// One node of a signed distance field, by its `shape`: a primitive
    /// with its parameters, or a combination of `children`.
    pub(crate) enum SdfNodeDesc {
        tag: "shape", family: ("node", "nodes"), default: None, shared: NodePlacement,
        Sphere(SdfSphere) = "sphere",
        Box(SdfBox) = "box",
        RoundBox(SdfRoundBox) = "round_box",
        Torus(SdfTorus) = "torus",
        Capsule(SdfSegment) = "capsule",
        Cylinder(SdfSegment) = "cylinder",
        Plane(SdfPlane) = "plane",
        Union(SdfCombination) = "union",
        Intersection(SdfCombination) = "intersection",
        Subtraction(SdfCombination) = "subtraction",
        SmoothUnion(SdfSmoothUnion) = "smooth_union",
    }
}

/// Where a node sits in its parent (a root node is placed by its object's
/// keys instead).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct NodePlacement {
    pub translate: Option<Point>,
    pub rotate: Option<Point>,
    pub scale: Option<Triple>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SdfSphere {
    pub center: Option<Point>,
    pub radius: f32,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SdfBox {
    pub min: Point,
    pub max: Point,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SdfRoundBox {
    pub min: Point,
    pub max: Point,
    pub rounding: f32,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SdfTorus {
    pub center: Option<Point>,
    pub major_radius: f32,
    pub minor_radius: f32,
}

/// A capsule or a cylinder: the segment from `a` to `b`, and the radius.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SdfSegment {
    pub a: Point,
    pub b: Point,
    pub radius: f32,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SdfPlane {
    pub point: Option<Point>,
    pub normal: Point,
}

/// A union, intersection or subtraction: its children, each read as a node
/// when built.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SdfCombination {
    pub children: Vec<Spanned<TableAt>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SdfSmoothUnion {
    pub children: Vec<Spanned<TableAt>>,
    pub blend: f32,
}

tagged! {
    /// One `[[lights]]` table, by its `type`.
    pub(crate) enum LightDesc {
        tag: "type", family: ("light", "lights"), default: None, shared: LightMotion,
        Point(PointLight) = "point",
        Spot(SpotLight) = "spot",
        Distant(DistantLight) = "distant",
        /// A uniform sky.
        Sky(SkyLight) = "sky",
        Sphere(SphereLight) = "sphere",
        Quad(QuadLight) = "quad",
        Line(LineLight) = "line",
        /// A volume light filling a box.
        Box(BoxLight) = "box",
    }
}

/// The path a light moves along in animations; see
/// [`crate::light::Keyframes`]. Every type takes it; a distant light, which
/// has no position, refuses it when built.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LightMotion {
    pub keyframes: Option<Spanned<Vec<Spanned<KeyframeDesc>>>>,
}

/// How a point, spot or sphere light falls off with distance: the model,
/// the light's radius (for the physical model's near field), the
/// irradiance below which a finite-range falloff drops the light, and
/// d_max, how far from its surface it reaches. Each of the three types
/// declares these keys (serde cannot flatten a struct whose keys are
/// checked).
macro_rules! falloff_keys {
    ($(#[$meta:meta])* pub(crate) struct $name:ident { $($field:ident: $ty:ty,)* }) => {
        $(#[$meta])*
        #[derive(Debug, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub(crate) struct $name {
            $(pub $field: $ty,)*
            pub attenuation: Option<AttenuationModel>,
            pub radius: Option<f32>,
            pub cutoff: Option<f32>,
            pub range: Option<f32>,
        }

        impl $name {
            pub(crate) fn falloff(&self) -> Falloff {
                Falloff { model: self.attenuation, radius: self.radius, cutoff: self.cutoff, range: self.range }
            }
        }
    };
}

/// A point, spot or sphere light's falloff keys, as given.
pub(crate) struct Falloff {
    pub model: Option<AttenuationModel>,
    pub radius: Option<f32>,
    pub cutoff: Option<f32>,
    pub range: Option<f32>,
}

falloff_keys! {
    pub(crate) struct PointLight {
        position: Point,
        intensity: Triple,
    }
}

falloff_keys! {
    /// Aimed by `direction` or `look_at`; its cone's half-angle and where
    /// the falloff to its edge starts, in degrees.
    pub(crate) struct SpotLight {
        position: Point,
        intensity: Triple,
        direction: Option<Point>,
        look_at: Option<Point>,
        cone_angle: Option<f32>,
        falloff_start: Option<f32>,
        profile: Option<SpotProfileDesc>,
    }
}

falloff_keys! {
    /// A surface of `radiance`, or with `volume = true` a glowing ball of
    /// `intensity` (which takes no falloff).
    pub(crate) struct SphereLight {
        center: Point,
        radiance: Option<Triple>,
        volume: Option<bool>,
        intensity: Option<Triple>,
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SkyLight {
    pub radiance: Option<Triple>,
    /// An equirectangular environment map (Radiance HDR or OpenEXR).
    pub file: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct DistantLight {
    pub direction: Point,
    pub irradiance: Triple,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct QuadLight {
    pub corner: Point,
    pub edge_u: Point,
    pub edge_v: Point,
    pub radiance: Triple,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LineLight {
    pub start: Point,
    pub end: Point,
    pub intensity: Triple,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct BoxLight {
    pub min: Point,
    pub max: Point,
    pub intensity: Triple,
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
