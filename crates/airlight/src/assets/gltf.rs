//! glTF 2.0 scenes (`.gltf` with its buffers, or `.glb`), read with the
//! `gltf` crate: the node hierarchy with its transforms, triangle meshes,
//! `KHR_lights_punctual` lights, materials' base colour (factor × texture) and emission
//! (`KHR_materials_emissive_strength`), and the first camera. What Airlight
//! makes of each is in docs/scene-format.md ("glTF scenes").
//!
//! Buffers in files are found beside the glTF file under the asset rules
//! ([`super::AssetPath`]); data URIs are decoded. Every accessor read is
//! checked against its buffer first, so a short or lying file gives an
//! error, never a panic. Errors name the file, the JSON path
//! (`meshes[2].primitives[0]`) and what is wrong.

use super::{Loader, MAX_MESH_BYTES, read_limited};
use crate::camera::Camera;
use crate::geometry::Shape;
use crate::light::{Attenuation, Light, SpotProfile};
use crate::material::{AlphaMode, Cutout, Material, MetallicRoughness, SurfaceMaps, TextureMap, UvTransform};
use crate::scene::{Parts, TexturedEmission, limits};
use crate::texture::{Texture, Wrap};
use base64::Engine;
use glam::{Affine3A, Mat4, Vec2, Vec3};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// Luminous efficacy used to turn glTF's photometric light units into
/// radiometric ones: 683 lm/W, that of light at 555 nm (the definition of
/// the candela). A point light of I cd has I/683 W/sr; a sun of E lux
/// gives E/683 W/m². Blender's exporter writes a P-watt point light as
/// P/(4π)·683 cd, so it comes back as Blender's P/(4π) W/sr.
pub const LUMINOUS_EFFICACY: f32 = 683.0;

/// Deepest node hierarchy followed (a cycle would otherwise never end).
const MAX_DEPTH: usize = 256;

/// Most nodes a scene's hierarchy may place, reused ones counted each
/// time: a node whose children are `[k + 1, k + 1]` thirty levels deep
/// places 2³⁰ of them from a kilobyte of text.
const MAX_PLACED_NODES: u64 = 1 << 20;

/// What a glTF file adds to a scene.
pub(crate) struct Imported {
    pub parts: Parts,
    /// What the file asks for that Airlight does not read (see
    /// [`not_read`]), for the user to be told.
    pub notes: Vec<String>,
    /// The first camera met, with its aspect ratio when the file gives one.
    pub camera: Option<(Camera, Option<f32>)>,
}

/// What is being imported and how: the include's label (for messages),
/// file, scene name, transform and material override.
pub(crate) struct GltfInclude<'a> {
    pub label: &'a str,
    pub file: &'a str,
    pub scene: Option<&'a str>,
    pub transform: Affine3A,
    pub material: Option<&'a str>,
}

impl Loader<'_> {
    /// The glTF file's scene, placed; errors are whole messages (the
    /// caller places them in the scene file).
    pub(crate) fn gltf(&self, include: &GltfInclude) -> Result<Imported, String> {
        let name = include.file;
        let fail = |why: String| format!("{}: `{name}`: {why}", include.label);
        let path = self.resolve(name).map_err(|why| fail(format!("cannot load: {why}")))?;
        let bytes = read_limited(&path, MAX_MESH_BYTES).map_err(|why| fail(format!("cannot load: {why}")))?;
        // The crate validates the document, and refuses one that requires
        // an extension other than those Airlight reads (Cargo.toml); what
        // it would panic on is refused first.
        let doc = before_the_crate(&bytes).map_err(|why| fail(format!("not a valid glTF file: {why}")))?;
        let gltf = gltf::Gltf::from_slice(&bytes).map_err(|e| fail(format!("not a valid glTF file: {e}")))?;
        self.record(path);
        let buffers = self.gltf_buffers(&gltf, Path::new(name)).map_err(fail)?;
        let scene = match include.scene {
            Some(wanted) => gltf.scenes().find(|s| s.name() == Some(wanted)).ok_or_else(|| {
                let names: Vec<String> = gltf.scenes().filter_map(|s| s.name().map(|n| format!("`{n}`"))).collect();
                fail(format!(
                    "no scene named `{wanted}` (it has {})",
                    if names.is_empty() { "none named".into() } else { names.join(", ") }
                ))
            })?,
            None => {
                gltf.default_scene().or_else(|| gltf.scenes().next()).ok_or_else(|| fail("it holds no scene".into()))?
            }
        };
        // Memory: the triangles of every mesh each time a node places it,
        // counted before any is read (a mesh may be placed many times),
        // with their texture coordinates and vertex normals (72 bytes a
        // triangle in the geometry, at most).
        let triangles = placed_triangles(&scene).map_err(&fail)?;
        let bytes = triangles.saturating_mul(super::obj::BYTES_PER_TRIANGLE + 72);
        self.reserve(bytes, || format!("the scene's meshes ({triangles} triangles placed by this glTF)"))
            .map_err(fail)?;

        let unread = doc.as_ref().map(not_read).unwrap_or_default();
        let notes = unread.into_iter().map(|what| format!("{}: `{name}`: {what}", include.label)).collect();
        let mut out = Imported { parts: Parts::default(), notes, camera: None };
        let mut textures = Textures { file: Path::new(name), buffers: &buffers, read: HashMap::new() };
        let mut stack: Vec<(gltf::Node, Affine3A, usize)> =
            scene.nodes().map(|n| (n, include.transform, 0)).collect::<Vec<_>>();
        stack.reverse();
        while let Some((node, parent, depth)) = stack.pop() {
            let at = format!("nodes[{}]", node.index());
            if depth > MAX_DEPTH {
                return Err(fail(format!("{at}: the node hierarchy is deeper than {MAX_DEPTH} (a cycle?)")));
            }
            let local = Mat4::from_cols_array_2d(&node.transform().matrix());
            if !local.is_finite() || local.row(3) != glam::Vec4::W {
                return Err(fail(format!("{at}: its transform is not a finite affine matrix: {local}")));
            }
            let world = parent * Affine3A::from_mat4(local);
            if let Some(mesh) = node.mesh() {
                self.gltf_mesh(include, &mesh, world, &mut textures, &mut out).map_err(&fail)?;
            }
            if let Some(light) = node.light() {
                out.parts.lights.push(gltf_light(&light, world).map_err(|why| fail(format!("{at}: {why}")))?);
            }
            if let (Some(camera), None) = (node.camera(), &out.camera) {
                out.camera = Some(gltf_camera(&camera, world).map_err(|why| fail(format!("{at}: {why}")))?);
            }
            for child in node.children().collect::<Vec<_>>().into_iter().rev() {
                stack.push((child, world, depth + 1));
            }
        }
        Ok(out)
    }

    /// Each buffer's bytes: the GLB's BIN chunk (the first buffer's only, as
    /// the specification says: each other one would be a copy of it), a
    /// data URI, or a file beside the glTF file (its URI percent-decoded).
    fn gltf_buffers(&self, gltf: &gltf::Gltf, file: &Path) -> Result<Vec<Vec<u8>>, String> {
        let mut buffers = Vec::new();
        for buffer in gltf.buffers() {
            let at = format!("buffers[{}]", buffer.index());
            let data = match buffer.source() {
                gltf::buffer::Source::Bin if buffer.index() != 0 => {
                    return Err(format!("{at}: has no uri; only buffers[0] may be the GLB's BIN chunk"));
                }
                gltf::buffer::Source::Bin => {
                    gltf.blob.clone().ok_or_else(|| format!("{at}: refers to a BIN chunk the file does not have"))?
                }
                gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                    let (_, encoded) =
                        uri.split_once(";base64,").ok_or_else(|| format!("{at}: a data URI that is not base64"))?;
                    base64::engine::general_purpose::STANDARD
                        .decode(encoded)
                        .map_err(|e| format!("{at}: its data URI is not valid base64: {e}"))?
                }
                gltf::buffer::Source::Uri(uri) => {
                    let uri = &percent_decoded(uri);
                    let beside = file.parent().unwrap_or(Path::new("")).join(uri);
                    let path = self.resolve(&beside.to_string_lossy()).map_err(|why| format!("{at}: {why}"))?;
                    let data = read_limited(&path, MAX_MESH_BYTES).map_err(|why| format!("{at}: `{uri}`: {why}"))?;
                    self.record(path);
                    data
                }
            };
            if data.len() < buffer.length() {
                return Err(format!("{at}: holds {} bytes, but the file says {}", data.len(), buffer.length()));
            }
            buffers.push(data);
        }
        Ok(buffers)
    }

    fn gltf_mesh(
        &self,
        include: &GltfInclude,
        mesh: &gltf::Mesh,
        world: Affine3A,
        textures: &mut Textures,
        out: &mut Imported,
    ) -> Result<(), String> {
        let buffers = textures.buffers;
        // A mirroring transform turns counter-clockwise front faces clockwise.
        let mirrored = world.matrix3.determinant() < 0.0;
        for primitive in mesh.primitives() {
            let at = format!("meshes[{}].primitives[{}]", mesh.index(), primitive.index());
            if primitive.mode() != gltf::mesh::Mode::Triangles {
                return Err(format!("{at}: mode {:?} is not triangles", primitive.mode()));
            }
            let positions_accessor =
                primitive.get(&gltf::Semantic::Positions).ok_or_else(|| format!("{at}: has no POSITION"))?;
            use gltf::accessor::{DataType, Dimensions};
            typed(&positions_accessor, Dimensions::Vec3, &[DataType::F32])
                .and_then(|()| fits(&positions_accessor, buffers))
                .map_err(|why| format!("{at}: POSITION: {why}"))?;
            if let Some(indices) = primitive.indices() {
                typed(&indices, Dimensions::Scalar, &[DataType::U8, DataType::U16, DataType::U32])
                    .and_then(|()| fits(&indices, buffers))
                    .map_err(|why| format!("{at}: indices: {why}"))?;
            }
            let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let positions: Vec<Vec3> = reader
                .read_positions()
                .ok_or_else(|| format!("{at}: POSITION cannot be read"))?
                .map(|p| world.transform_point3(Vec3::from_array(p)))
                .collect();
            if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
                return Err(format!("{at}: a vertex is not finite once placed: {p}"));
            }
            // The scene file's rule for every point: within reach of f32.
            if let Some(p) = positions.iter().find(|p| p.abs().max_element() > limits::MAX_COORDINATE) {
                return Err(limits::too_far(&format!("{at}: the vertex {p}"), p.abs().max_element()));
            }
            let indices: Vec<u32> = match reader.read_indices() {
                Some(indices) => indices.into_u32().collect(),
                None => (0..positions.len() as u32).collect(),
            };
            if let Some(i) = indices.iter().find(|&&i| i as usize >= positions.len()) {
                return Err(format!("{at}: index {i} is beyond its {} vertices", positions.len()));
            }
            let triangles: Vec<[u32; 3]> = indices
                .chunks_exact(3)
                .map(|t| if mirrored { [t[0], t[2], t[1]] } else { [t[0], t[1], t[2]] })
                .collect();
            if triangles.is_empty() {
                continue;
            }
            let material = primitive.material();
            let strength = material.emissive_strength().unwrap_or(1.0);
            let emission = Vec3::from_array(material.emissive_factor()) * strength;
            if !(emission.is_finite() && emission.min_element() >= 0.0) {
                return Err(format!("{at}: its material's emission is not finite and ≥ 0: {emission}"));
            }
            let mut uvs = Vec::new();
            let name = match include.material {
                Some(name) => name.to_string(),
                None => {
                    let name = match material.index() {
                        Some(i) => format!("{}#materials[{i}]", include.file),
                        None => format!("{}#default", include.file),
                    };
                    if let Some(set) = uv_set(&material) {
                        uvs = texture_coordinates(&primitive, set, positions.len(), buffers)
                            .map_err(|why| format!("{at}: {why}"))?;
                    }
                    if !out.parts.materials.iter().any(|(n, _)| *n == name) {
                        let m = self.gltf_material(&material, textures)?;
                        out.parts.materials.push((name.clone(), m));
                        if let Some(cutout) = self.gltf_cutout(&material, textures)? {
                            out.parts.cutouts.push((name.clone(), cutout));
                        }
                    }
                    name
                }
            };
            let mut triangles = triangles;
            if emission.max_element() > 0.0 && include.material.is_none() {
                // The glowing triangles reflect by the material too.
                let Some(info) = material.emissive_texture() else {
                    let first = out.parts.lights.len();
                    out.parts.lights.extend(Light::triangles_of(&positions, &triangles, emission));
                    out.parts.light_materials.extend((first..out.parts.lights.len()).map(|i| (i, name.clone())));
                    continue;
                };
                // Each triangle glows with the texture at each of its
                // points; its light carries the texture's mean over it (its
                // power, by which its mesh's triangles are drawn). The dark
                // ones stay surfaces of the material.
                let at_material = material_label(&material);
                let map = self
                    .gltf_map(textures, &info, "emissiveTexture", false)
                    .map_err(|why| format!("{at_material}.{why}"))?;
                let uvs = texture_coordinates(&primitive, info_set(&info), positions.len(), buffers)
                    .map_err(|why| format!("{at}: {why}"))?;
                let mut dark = Vec::new();
                for t in triangles {
                    let corners = t.map(|i| uvs[i as usize]);
                    let radiance = emission * map.mean_over_triangle(corners);
                    if radiance.max_element() > 0.0 {
                        let light = Light::triangles_of(&positions, &[t], radiance);
                        if !light.is_empty() {
                            let e = TexturedEmission { map: map.clone(), factor: emission, uvs: corners };
                            out.parts.textured.push((out.parts.lights.len(), e));
                            out.parts.light_materials.push((out.parts.lights.len(), name.clone()));
                            out.parts.lights.extend(light);
                        }
                    } else {
                        dark.push(t);
                    }
                }
                triangles = dark;
                if triangles.is_empty() {
                    continue;
                }
            }
            let normals =
                vertex_normals(&primitive, world, positions.len(), buffers).map_err(|why| format!("{at}: {why}"))?;
            out.parts.objects.push((Shape::Mesh { positions, triangles, uvs, normals }, name));
        }
        Ok(())
    }
}

/// The texture coordinate set a material's maps read: its base colour
/// texture's, or else its metallic-roughness texture's (a
/// `KHR_texture_transform` may name another). Meshes carry one set;
/// [`not_read`] says so when a material's maps ask for two.
fn uv_set(material: &gltf::Material) -> Option<u32> {
    let pbr = material.pbr_metallic_roughness();
    let set = |info: gltf::texture::Info| info_set(&info);
    let normal = || material.normal_texture().map(|n| n.tex_coord());
    pbr.base_color_texture().map(set).or_else(|| pbr.metallic_roughness_texture().map(set)).or_else(normal)
}

impl Loader<'_> {
    /// A glTF material as Airlight's: metallic-roughness with its maps,
    /// or, when it has no specular reflection at all (metallic 0 and
    /// `KHR_materials_specular`'s factor 0, as Blender writes a diffuse
    /// surface) the Lambertian material it then is, which the integrators
    /// treat faster.
    fn gltf_material(&self, material: &gltf::Material, textures: &mut Textures) -> Result<Material, String> {
        let at = &material_label(material);
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, _] = pbr.base_color_factor();
        let base = Vec3::new(r, g, b);
        if !(base.is_finite() && base.min_element() >= 0.0) {
            return Err(format!("{at}: its base colour is not finite and ≥ 0: {base}"));
        }
        let unit = |v: f32, what: &str| {
            if (0.0..=1.0).contains(&v) { Ok(v) } else { Err(format!("{at}: its {what} is {v}, not in [0, 1]")) }
        };
        let metallic = unit(pbr.metallic_factor(), "metallicFactor")?;
        let roughness = unit(pbr.roughness_factor(), "roughnessFactor")?;
        let specular = unit(material.specular().map_or(1.0, |s| s.specular_factor()), "specularFactor")?;
        // A normal map (its KHR_texture_transform, which the crate does
        // not give for normal textures, is not read).
        let normal = match material.normal_texture() {
            Some(n) => {
                let scale = n.scale();
                if !scale.is_finite() {
                    return Err(format!("{at}.normalTexture: its scale is {scale}"));
                }
                let texture = self
                    .gltf_texture(textures, &n.texture(), true)
                    .map_err(|why| format!("{at}.normalTexture: {why}"))?;
                Some((TextureMap::new(texture), scale))
            }
            None => None,
        };
        let mut map = |info: Option<gltf::texture::Info>, what: &str, data: bool| {
            info.map(|info| self.gltf_map(textures, &info, what, data).map_err(|why| format!("{at}.{why}"))).transpose()
        };
        let maps = SurfaceMaps {
            normal,
            base_colour: map(pbr.base_color_texture(), "pbrMetallicRoughness.baseColorTexture", false)?,
            metallic_roughness: map(
                pbr.metallic_roughness_texture(),
                "pbrMetallicRoughness.metallicRoughnessTexture",
                true,
            )?,
        };
        if metallic == 0.0 && specular == 0.0 && maps.metallic_roughness.is_none() && maps.normal.is_none() {
            return Ok(match maps.base_colour {
                Some(m) if m.transform == UvTransform::IDENTITY => Material::textured(base, m.texture),
                Some(m) => {
                    let maps = SurfaceMaps { base_colour: Some(m), metallic_roughness: None, normal: None };
                    let lambertian = MetallicRoughness::lambertian(base);
                    Material::MetallicRoughness(MetallicRoughness { maps: Some(Arc::new(maps)), ..lambertian })
                }
                None => Material::diffuse(base),
            });
        }
        let has_maps = maps.base_colour.is_some() || maps.metallic_roughness.is_some() || maps.normal.is_some();
        Ok(Material::MetallicRoughness(MetallicRoughness {
            base,
            metallic,
            roughness,
            specular,
            maps: has_maps.then(|| Arc::new(maps)),
        }))
    }
}

impl Loader<'_> {
    /// A material's cut-out: its `alphaMode` MASK (with `alphaCutoff`) or
    /// BLEND over the base colour's alpha, factor × texture; None for OPAQUE.
    fn gltf_cutout(&self, material: &gltf::Material, textures: &mut Textures) -> Result<Option<Cutout>, String> {
        use gltf::material::AlphaMode as Gltf;
        let at = material_label(material);
        let mode = match material.alpha_mode() {
            Gltf::Opaque => return Ok(None),
            Gltf::Blend => AlphaMode::Blend,
            Gltf::Mask => {
                let cutoff = material.alpha_cutoff().unwrap_or(0.5);
                if !(cutoff.is_finite() && cutoff >= 0.0) {
                    return Err(format!("{at}: its alphaCutoff is {cutoff}, not a number ≥ 0"));
                }
                AlphaMode::Mask { cutoff }
            }
        };
        let pbr = material.pbr_metallic_roughness();
        let factor = pbr.base_color_factor()[3];
        if !(0.0..=1.0).contains(&factor) {
            return Err(format!("{at}: its base colour's alpha is {factor}, not in [0, 1]"));
        }
        let map = match pbr.base_color_texture() {
            Some(info) => Some(
                self.gltf_map(textures, &info, "pbrMetallicRoughness.baseColorTexture", false)
                    .map_err(|why| format!("{at}.{why}"))?,
            ),
            None => None,
        };
        Ok(Some(Cutout { factor, map, mode }))
    }
}

/// How errors name a material: its JSON path, or the default material.
fn material_label(material: &gltf::Material) -> String {
    material.index().map_or("the default material".to_string(), |i| format!("materials[{i}]"))
}

/// The coordinate set a texture reads (a `KHR_texture_transform` may name another).
fn info_set(info: &gltf::texture::Info) -> u32 {
    info.texture_transform().and_then(|t| t.tex_coord()).unwrap_or(info.tex_coord())
}

impl Loader<'_> {
    /// A material's texture (`what`, its key) with its
    /// `KHR_texture_transform`; errors begin with `what`.
    fn gltf_map(
        &self,
        textures: &mut Textures,
        info: &gltf::texture::Info,
        what: &str,
        data: bool,
    ) -> Result<TextureMap, String> {
        let texture = self.gltf_texture(textures, &info.texture(), data).map_err(|why| format!("{what}: {why}"))?;
        let transform = match info.texture_transform() {
            Some(t) => {
                let transform = UvTransform {
                    offset: Vec2::from_array(t.offset()),
                    rotation: t.rotation(),
                    scale: Vec2::from_array(t.scale()),
                };
                if !(transform.offset.is_finite() && transform.rotation.is_finite() && transform.scale.is_finite()) {
                    return Err(format!("{what}: its KHR_texture_transform is not finite"));
                }
                transform
            }
            None => UvTransform::IDENTITY,
        };
        Ok(TextureMap { texture, transform })
    }
}

/// The glTF file's images, read once each, and what they are read from.
struct Textures<'a> {
    /// The glTF file's name in the scene (images in files lie beside it).
    file: &'a Path,
    buffers: &'a [Vec<u8>],
    /// By texture index and whether read as data: an image with its
    /// sampler's wrap modes.
    read: HashMap<(usize, bool), Arc<Texture>>,
}

impl Loader<'_> {
    /// A glTF texture: its image (a file beside the glTF file under the
    /// asset rules, a data URI, or a buffer view), decoded to sRGB texels,
    /// with its sampler's wrap modes, as colour or (`data`) as numbers;
    /// read once per texture and use.
    fn gltf_texture(
        &self,
        textures: &mut Textures,
        texture: &gltf::Texture,
        data: bool,
    ) -> Result<Arc<Texture>, String> {
        if let Some(t) = textures.read.get(&(texture.index(), data)) {
            return Ok(t.clone());
        }
        let image = texture.source();
        let at = format!("textures[{}] → images[{}]", texture.index(), image.index());
        let bytes: Vec<u8> = match image.source() {
            gltf::image::Source::View { view, .. } => {
                let buffer = textures.buffers.get(view.buffer().index()).map_or(&[][..], Vec::as_slice);
                let range = view.offset()..view.offset().saturating_add(view.length());
                buffer
                    .get(range)
                    .ok_or_else(|| format!("{at}: bufferViews[{}] runs past the end of its buffer", view.index()))?
                    .to_vec()
            }
            gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => {
                let (_, encoded) =
                    uri.split_once(";base64,").ok_or_else(|| format!("{at}: a data URI that is not base64"))?;
                base64::engine::general_purpose::STANDARD
                    .decode(encoded)
                    .map_err(|e| format!("{at}: its data URI is not valid base64: {e}"))?
            }
            gltf::image::Source::Uri { uri, .. } => {
                let uri = percent_decoded(uri);
                let beside = textures.file.parent().unwrap_or(Path::new("")).join(&uri);
                let path = self.resolve(&beside.to_string_lossy()).map_err(|why| format!("{at}: {why}"))?;
                let data = read_limited(&path, MAX_MESH_BYTES).map_err(|why| format!("{at}: `{uri}`: {why}"))?;
                self.record(path);
                data
            }
        };
        let decoded = self.texture_bytes(&bytes, &at).map_err(|why| format!("{at}: {why}"))?;
        let sampler = texture.sampler();
        let decoded = decoded.with_wrap(wrap(sampler.wrap_s()), wrap(sampler.wrap_t()));
        let texture_arc = Arc::new(if data { decoded.as_data() } else { decoded });
        textures.read.insert((texture.index(), data), texture_arc.clone());
        Ok(texture_arc)
    }
}

/// What a glTF file's materials, meshes and extensions ask for that
/// Airlight does not read, each with what the image shows instead: the
/// file loads, but it does not render as its author saw it, and the user
/// is told so rather than left to find out. Read from the JSON itself
/// (`doc`), defaults as the glTF 2.0 specification gives them.
fn not_read(doc: &serde_json::Value) -> Vec<String> {
    use serde_json::Value;
    let empty = Vec::new();
    let materials = doc.get("materials").and_then(Value::as_array).unwrap_or(&empty);
    let number = |v: Option<&Value>, default: f64| v.and_then(Value::as_f64).unwrap_or(default);
    let count = |test: &dyn Fn(&Value) -> bool| materials.iter().filter(|m| test(m)).count();
    let mut notes = Vec::new();
    let mut note = |n: usize, what: &str, instead: &str| {
        if n > 0 {
            let of = if n == 1 { "1 material".to_string() } else { format!("{n} materials") };
            notes.push(format!("{what} ({of}) not read: {instead}"));
        }
    };
    let moved_normal = |m: &Value| {
        m.get("normalTexture")
            .and_then(|n| n.get("extensions"))
            .is_some_and(|e| e.get("KHR_texture_transform").is_some())
    };
    note(count(&moved_normal), "a normal map's KHR_texture_transform", "the map is read untransformed");
    // KHR_materials_specular's factor is read; its colour and textures not.
    let specular = |m: &Value| {
        m.get("extensions").and_then(|e| e.get("KHR_materials_specular")).is_some_and(|s| {
            ["specularTexture", "specularColorFactor", "specularColorTexture"].iter().any(|k| s.get(k).is_some())
        })
    };
    note(count(&specular), "KHR_materials_specular colours and textures", "only its specularFactor weighs the lobe");
    let set = |info: Option<&Value>| {
        let info = info?;
        let moved = info.get("extensions").and_then(|e| e.get("KHR_texture_transform")).and_then(|t| t.get("texCoord"));
        Some(number(moved.or(info.get("texCoord")), 0.0))
    };
    let two_sets = |m: &Value| {
        let pbr = m.get("pbrMetallicRoughness");
        let (a, b) = (
            set(pbr.and_then(|p| p.get("baseColorTexture"))),
            set(pbr.and_then(|p| p.get("metallicRoughnessTexture"))),
        );
        a.zip(b).is_some_and(|(a, b)| a != b)
    };
    note(count(&two_sets), "a second texture coordinate set", "the metallic-roughness map reads the base colour's");
    let used = doc.get("extensionsUsed").and_then(Value::as_array).unwrap_or(&empty);
    for name in used.iter().filter_map(Value::as_str) {
        if !READ_EXTENSIONS.contains(&name) {
            notes.push(format!("the extension {name} not read"));
        }
    }
    notes
}

/// The glTF extensions Airlight reads (the `gltf` crate's features in
/// Cargo.toml).
const READ_EXTENSIONS: [&str; 4] =
    ["KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_specular", "KHR_texture_transform"];

/// Refuses an extension the file requires and Airlight does not read, and
/// what the `gltf` crate (1.4) panics on rather than reporting, found by
/// fuzzing (tests/fuzz_imports.rs): a GLB whose header gives a length below
/// the header's own 12 bytes (a subtraction that overflows), a mesh
/// primitive's attribute naming an accessor that does not exist (its
/// validation indexes the accessors before it checks the index), an image
/// in a buffer view without a `mimeType`, and an image with neither a `uri`
/// nor a buffer view (both required by the glTF 2.0 specification, read
/// with `unwrap`). Anything else is left to the crate's own validation.
/// Gives the JSON document when it parses (what is not read is told from
/// it, [`not_read`]).
fn before_the_crate(bytes: &[u8]) -> Result<Option<serde_json::Value>, String> {
    let json = match bytes.strip_prefix(b"glTF") {
        Some(rest) => {
            let word = |at: usize| rest.get(at..at + 4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]));
            match word(4) {
                Some(length) if length >= 12 => {}
                Some(length) => {
                    return Err(format!("its GLB header gives a length of {length} bytes, less than the header"));
                }
                None => return Err("its GLB header is cut short".into()),
            }
            // The JSON chunk: its length, its type, its bytes.
            let length = word(8).unwrap_or(0) as usize;
            match rest.get(16..16usize.saturating_add(length)) {
                Some(chunk) => chunk,
                None => return Ok(None), // the crate reports a short chunk
            }
        }
        None => bytes,
    };
    let Ok(doc) = serde_json::from_slice::<serde_json::Value>(json) else {
        return Ok(None); // the crate reports what is wrong with the JSON
    };
    // A required extension Airlight does not read (Draco, meshopt) is the
    // one thing to say: the crate would list every accessor it leaves
    // without data first.
    let required = doc.get("extensionsRequired").and_then(|r| r.as_array()).cloned().unwrap_or_default();
    if let Some(name) = required.iter().filter_map(|e| e.as_str()).find(|e| !READ_EXTENSIONS.contains(e)) {
        return Err(format!(
            "it requires the extension `{name}`, which Airlight does not read (it reads {}); export the file without it",
            READ_EXTENSIONS.join(", ")
        ));
    }
    let count = |key: &str| doc.get(key).and_then(|v| v.as_array()).map_or(0, Vec::len) as u64;
    let accessors = count("accessors");
    let items = |key: &str| doc.get(key).and_then(|v| v.as_array()).cloned().unwrap_or_default();
    for (m, mesh) in items("meshes").iter().enumerate() {
        let primitives = mesh.get("primitives").and_then(|p| p.as_array()).cloned().unwrap_or_default();
        for (p, primitive) in primitives.iter().enumerate() {
            let Some(attributes) = primitive.get("attributes").and_then(|a| a.as_object()) else { continue };
            for (name, index) in attributes {
                if let Some(i) = index.as_u64().filter(|&i| i >= accessors) {
                    return Err(format!(
                        "meshes[{m}].primitives[{p}].attributes.{name}: accessor {i} does not exist (the file has {accessors})"
                    ));
                }
            }
        }
    }
    for (i, image) in items("images").iter().enumerate() {
        // A key whose value is null reads as absent.
        let given = |key: &str| image.get(key).filter(|v| !v.is_null());
        match (given("bufferView"), given("uri")) {
            (Some(_), _) if !image.get("mimeType").is_some_and(|m| m.is_string()) => {
                return Err(format!("images[{i}]: an image in a buffer view needs a `mimeType`"));
            }
            (None, uri) if !uri.is_some_and(|u| u.is_string()) => {
                return Err(format!("images[{i}]: an image needs a `uri` or a `bufferView`"));
            }
            _ => {}
        }
    }
    Ok(Some(doc))
}

fn wrap(mode: gltf::texture::WrappingMode) -> Wrap {
    match mode {
        gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
    }
}

/// A URI's `%XX` escapes decoded (glTF URIs are escaped: `my%20wood.png`).
fn percent_decoded(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%'
            && let (Some(hi), Some(lo)) =
                (bytes.get(i + 1).and_then(|&b| hex(b)), bytes.get(i + 2).and_then(|&b| hex(b)))
        {
            out.push((hi * 16 + lo) as u8);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// A primitive's `NORMAL`s placed in the world (by the inverse transpose
/// of the node's transform) and normalised; none when it has none. A
/// normal of zero length stays zero (the triangle's own is used there).
fn vertex_normals(
    primitive: &gltf::Primitive,
    world: Affine3A,
    vertices: usize,
    buffers: &[Vec<u8>],
) -> Result<Vec<Vec3>, String> {
    let Some(accessor) = primitive.get(&gltf::Semantic::Normals) else { return Ok(Vec::new()) };
    use gltf::accessor::{DataType, Dimensions};
    typed(&accessor, Dimensions::Vec3, &[DataType::F32])
        .and_then(|()| fits(&accessor, buffers))
        .map_err(|why| format!("NORMAL: {why}"))?;
    let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let to_world = world.matrix3.inverse().transpose();
    let normals: Vec<Vec3> = reader
        .read_normals()
        .ok_or("NORMAL cannot be read")?
        .map(|n| (to_world * Vec3::from_array(n)).normalize_or_zero())
        .collect();
    if normals.len() != vertices {
        return Err(format!("NORMAL has {} elements for {vertices} vertices", normals.len()));
    }
    if let Some(n) = normals.iter().find(|n| !n.is_finite()) {
        return Err(format!("NORMAL: a normal is not finite once placed: {n}"));
    }
    Ok(normals)
}

/// A primitive's `TEXCOORD_<set>`, one per vertex, finite.
fn texture_coordinates(
    primitive: &gltf::Primitive,
    set: u32,
    vertices: usize,
    buffers: &[Vec<u8>],
) -> Result<Vec<Vec2>, String> {
    let accessor = primitive
        .get(&gltf::Semantic::TexCoords(set))
        .ok_or_else(|| format!("its material's textures use TEXCOORD_{set}, which it does not have"))?;
    use gltf::accessor::{DataType, Dimensions};
    typed(&accessor, Dimensions::Vec2, &[DataType::F32, DataType::U8, DataType::U16])
        .and_then(|()| fits(&accessor, buffers))
        .map_err(|why| format!("TEXCOORD_{set}: {why}"))?;
    let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let uvs: Vec<Vec2> = reader
        .read_tex_coords(set)
        .ok_or_else(|| format!("TEXCOORD_{set} cannot be read"))?
        .into_f32()
        .map(Vec2::from_array)
        .collect();
    if uvs.len() != vertices {
        return Err(format!("TEXCOORD_{set} has {} elements for {vertices} vertices", uvs.len()));
    }
    if let Some(uv) = uvs.iter().find(|uv| !uv.is_finite()) {
        return Err(format!("TEXCOORD_{set}: a coordinate is not finite: {uv}"));
    }
    Ok(uvs)
}

/// Whether an accessor is of a type the glTF specification allows for
/// what it is read as (the crate's reader would misread another silently).
fn typed(
    accessor: &gltf::Accessor,
    dimensions: gltf::accessor::Dimensions,
    types: &[gltf::accessor::DataType],
) -> Result<(), String> {
    let (d, t) = (accessor.dimensions(), accessor.data_type());
    if d != dimensions || !types.contains(&t) {
        return Err(format!(
            "accessors[{}] is {d:?} of {t:?}; the specification asks for {dimensions:?} of {}",
            accessor.index(),
            types.iter().map(|t| format!("{t:?}")).collect::<Vec<_>>().join(" or ")
        ));
    }
    Ok(())
}

/// Whether an accessor's bytes lie inside its buffer view and the view
/// inside its buffer, and its view's stride holds an element (the crate's
/// reader assumes so, and panics on a shorter stride).
fn fits(accessor: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<(), String> {
    if accessor.sparse().is_some() {
        return Err("sparse accessors are not read".into());
    }
    let view = accessor.view().ok_or("an accessor without a bufferView")?;
    if let Some(stride) = view.stride()
        && (stride < accessor.size() || !(4..=252).contains(&stride) || stride % 4 != 0)
    {
        return Err(format!(
            "bufferViews[{}].byteStride is {stride}; its accessors' elements take {} bytes, and a stride is a \
             multiple of 4 from 4 to 252 that holds one",
            view.index(),
            accessor.size()
        ));
    }
    let buffer = buffers.get(view.buffer().index()).map_or(0, Vec::len);
    let view_end = view.offset().checked_add(view.length());
    if view_end.is_none_or(|end| end > buffer) {
        return Err(format!("bufferViews[{}] runs past the end of its buffer", view.index()));
    }
    let stride = view.stride().unwrap_or(accessor.size());
    // The specification's least count is 1; the crate's reader takes
    // count − 1 unchecked.
    let end = match accessor.count() {
        0 => return Err(format!("accessors[{}] has count 0; at least 1 is required", accessor.index())),
        n => (n - 1).checked_mul(stride).and_then(|s| s.checked_add(accessor.offset().checked_add(accessor.size())?)),
    };
    if end.is_none_or(|end| end > view.length()) {
        return Err(format!("{} elements run past the end of bufferViews[{}]", accessor.count(), view.index()));
    }
    Ok(())
}

/// A node's axis in world space, normalised in 64-bit floats as the scene
/// file's directions are, so that a tiny scale (an include's `scale =
/// 1e-30`) keeps its direction; None when the transform flattens it.
fn node_axis(world: Affine3A, axis: Vec3) -> Option<Vec3> {
    // (An f32's square cannot underflow an f64.)
    world.transform_vector3(axis).as_dvec3().try_normalize().map(|d| d.as_vec3())
}

/// The triangles the scene's nodes place, a mesh counted each time a node
/// places it; refuses a hierarchy deeper than [`MAX_DEPTH`] or placing
/// more than [`MAX_PLACED_NODES`] nodes, before anything is read.
fn placed_triangles(scene: &gltf::Scene) -> Result<u64, String> {
    let mut stack: Vec<(gltf::Node, usize)> = scene.nodes().map(|n| (n, 0)).collect();
    let (mut placed, mut triangles) = (0u64, 0u64);
    while let Some((node, depth)) = stack.pop() {
        placed += 1;
        if depth > MAX_DEPTH {
            return Err(format!("nodes[{}]: the node hierarchy is deeper than {MAX_DEPTH} (a cycle?)", node.index()));
        }
        if placed > MAX_PLACED_NODES {
            return Err(format!(
                "the node hierarchy places more than {MAX_PLACED_NODES} nodes (nodes reused as children of many)"
            ));
        }
        if let Some(mesh) = node.mesh() {
            let count = |p: gltf::Primitive| {
                p.indices().or_else(|| p.get(&gltf::Semantic::Positions)).map_or(0, |a| a.count() as u64 / 3)
            };
            triangles = triangles.saturating_add(mesh.primitives().map(count).sum());
        }
        stack.extend(node.children().map(|c| (c, depth + 1)));
    }
    Ok(triangles)
}

/// A `KHR_lights_punctual` light placed by its node: it shines along the
/// node's −Z; colour × intensity, in candela (lux for a sun), over
/// [`LUMINOUS_EFFICACY`]. A spot's outer cone is Airlight's `cone_angle`,
/// its inner one `falloff_start`, with the smoothstep profile between.
/// `range` is not used: lights fall off by the inverse-square law.
fn gltf_light(light: &gltf::khr_lights_punctual::Light, world: Affine3A) -> Result<Light, String> {
    let power = Vec3::from_array(light.color()) * (light.intensity() / LUMINOUS_EFFICACY);
    if !(power.is_finite() && power.min_element() >= 0.0) {
        return Err(format!("a light's colour × intensity is not finite and ≥ 0: {power}"));
    }
    let position = world.transform_point3(Vec3::ZERO);
    if !position.is_finite() || position.abs().max_element() > limits::MAX_COORDINATE {
        return Err(limits::too_far(&format!("a light at {position}"), position.abs().max_element()));
    }
    let direction = node_axis(world, Vec3::NEG_Z).ok_or("a light's node has no direction")?;
    use gltf::khr_lights_punctual::Kind;
    Ok(match light.kind() {
        Kind::Point => Light::point(position, power),
        Kind::Directional => Light::distant(direction, power),
        Kind::Spot { inner_cone_angle, outer_cone_angle } => {
            // The extension's rule: 0 ≤ inner < outer ≤ π/2.
            let quarter = std::f32::consts::FRAC_PI_2;
            if !(outer_cone_angle > 0.0
                && outer_cone_angle <= quarter
                && inner_cone_angle >= 0.0
                && inner_cone_angle <= outer_cone_angle)
            {
                return Err(format!(
                    "a spot's cone angles must satisfy 0 ≤ inner ≤ outer ≤ π/2, outer > 0: {inner_cone_angle}, \
                     {outer_cone_angle}"
                ));
            }
            Light::Spot {
                position,
                direction,
                intensity: power,
                cone_angle: outer_cone_angle,
                falloff_start: inner_cone_angle,
                profile: SpotProfile::Smoothstep,
                attenuation: Attenuation::PHYSICAL,
            }
        }
    })
}

/// A camera placed by its node: it looks along −Z with +Y up; `yfov` is
/// Airlight's vertical `fov`, twice `ymag` its orthographic `view_height`.
fn gltf_camera(camera: &gltf::Camera, world: Affine3A) -> Result<(Camera, Option<f32>), String> {
    let position = world.transform_point3(Vec3::ZERO);
    if !position.is_finite() || position.abs().max_element() > limits::MAX_COORDINATE {
        return Err(limits::too_far(&format!("the camera at {position}"), position.abs().max_element()));
    }
    let forward = node_axis(world, Vec3::NEG_Z).ok_or("the camera's node has no direction")?;
    let up = node_axis(world, Vec3::Y).ok_or("the camera's node has no up direction")?;
    Ok(match camera.projection() {
        gltf::camera::Projection::Perspective(p) => {
            let fov = p.yfov().to_degrees();
            if !(fov > 0.0 && fov < 180.0) {
                return Err(format!("yfov must lie in (0, π), got {}", p.yfov()));
            }
            (Camera::look_at(position, position + forward, up, fov), p.aspect_ratio())
        }
        gltf::camera::Projection::Orthographic(o) => {
            if !(o.ymag() > 0.0 && o.ymag().is_finite()) {
                return Err(format!("ymag must be a positive number, got {}", o.ymag()));
            }
            (Camera::orthographic(position, position + forward, up, 2.0 * o.ymag()), Some(o.xmag() / o.ymag()))
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_is_not_read_is_said_with_what_shows_instead() {
        let doc = serde_json::json!({
            "extensionsUsed": ["KHR_texture_transform", "KHR_lights_punctual", "KHR_materials_sheen"],
            "materials": [
                { "alphaMode": "MASK", "normalTexture": { "index": 0 } },
                { "pbrMetallicRoughness": { "metallicFactor": 0 }, "emissiveTexture": { "index": 0 },
                  "extensions": { "KHR_materials_specular": { "specularFactor": 0 } } },
                { "pbrMetallicRoughness": { "metallicFactor": 0, "baseColorTexture": { "index": 0 },
                    "metallicRoughnessTexture": { "index": 1, "extensions": { "KHR_texture_transform": { "texCoord": 1 } } } },
                  "alphaMode": "OPAQUE",
                  "extensions": { "KHR_materials_specular": { "specularColorFactor": [1, 0, 0] } } },
            ],
            "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0, "NORMAL": 1 } }] }],
        });
        assert_eq!(
            not_read(&doc),
            [
                "KHR_materials_specular colours and textures (1 material) not read: only its specularFactor weighs the lobe",
                "a second texture coordinate set (1 material) not read: the metallic-roughness map reads the base colour's",
                "the extension KHR_materials_sheen not read",
            ]
        );
        // A metallic-roughness, opaque file without normals has nothing to say.
        let plain = serde_json::json!({ "materials": [{ "pbrMetallicRoughness": { "metallicFactor": 0.5 } }] });
        assert!(not_read(&plain).is_empty());
    }
}
