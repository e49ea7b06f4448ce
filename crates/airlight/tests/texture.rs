//! Base-colour textures: a 2×2 image on a square, seen straight on by a
//! 4×4 orthographic camera under a sun of irradiance π (so a pixel's
//! radiance is the albedo there), read from a TOML texture material, an
//! OBJ's `map_Kd` with `vt`, and a glTF `baseColorTexture`. Each pixel is
//! checked against bilinear weights worked out by hand and the sRGB
//! formula; bad images give errors that name the file and where.

use airlight::SceneFile;
use airlight::integrator::{IntegratorDesc, IntegratorKind};
use airlight::render::accumulate;
use base64::Engine;
use glam::Vec3;
use std::path::Path;

/// sRGB codes, row by row from the top: red, green-ish / dark blue, white.
const TEXELS: [[u8; 3]; 4] = [[255, 0, 0], [0, 188, 0], [0, 0, 64], [255, 255, 255]];

fn png(texels: &[[u8; 3]], width: u32, height: u32) -> Vec<u8> {
    let mut bytes = Vec::new();
    let flat: Vec<u8> = texels.iter().flatten().copied().collect();
    let encoder = image::codecs::png::PngEncoder::new(&mut bytes);
    image::ImageEncoder::write_image(encoder, &flat, width, height, image::ExtendedColorType::Rgb8).unwrap();
    bytes
}

/// IEC 61966-2-1, written out again here.
fn srgb(code: u8) -> f32 {
    let c = code as f64 / 255.0;
    (if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }) as f32
}

/// The weight of texel column (or row) 0 at pixel column i = 0..4, whose
/// centre sits at u = (i + ½)/4, i.e. at x = 2u − ½ = −¼, ¼, ¾, 1¼ in
/// texel units: with repeat, texel −1 is texel 1 and texel 2 is texel 0;
/// with clamp, both are the edge texels.
fn weight0(i: usize, clamp: bool) -> f32 {
    if clamp { [1.0, 0.75, 0.25, 0.0][i] } else { [0.75, 0.75, 0.25, 0.25][i] }
}

fn expected(i: usize, j: usize, clamp: bool, factor: Vec3) -> Vec3 {
    let (wx, wy) = (weight0(i, clamp), weight0(j, clamp));
    let lin = |t: [u8; 3]| Vec3::new(srgb(t[0]), srgb(t[1]), srgb(t[2]));
    let v = lin(TEXELS[0]) * wx * wy
        + lin(TEXELS[1]) * (1.0 - wx) * wy
        + lin(TEXELS[2]) * wx * (1.0 - wy)
        + lin(TEXELS[3]) * (1.0 - wx) * (1.0 - wy);
    v * factor
}

/// A 2×2 square in the z = 0 plane, from (0, 0) to (2, 2), seen from +z;
/// image right is +x, image up +y. The sun gives irradiance π along −z.
const VIEW: &str = r#"
[render]
width = 4
height = 4
spp = 1
filter = "point"
[camera]
type = "orthographic"
position = [1, 1, 5]
look_at = [1, 1, 0]
view_height = 2
[[lights]]
type = "distant"
direction = [0, 0, -1]
irradiance = 3.14159265
"#;

fn render(text: &str, dir: &Path) -> Vec<Vec<Vec3>> {
    render_with(IntegratorKind::Direct, text, dir)
}

fn render_with(kind: IntegratorKind, text: &str, dir: &Path) -> Vec<Vec<Vec3>> {
    let file = SceneFile::from_toml_str(text, Some(dir)).unwrap_or_else(|e| panic!("{e}"));
    let mut desc = IntegratorDesc::new(kind);
    desc.path.max_depth = 1;
    let integrator = desc.build(&file.scene).unwrap();
    let acc = accumulate(&file.scene, integrator.as_ref(), 0..1, 0..4, &Default::default());
    (0..4).map(|j| (0..4).map(|i| acc.pixel(i, j).unwrap().mean()).collect()).collect()
}

fn check(what: &str, image: &[Vec<Vec3>], clamp: bool, factor: Vec3) {
    for (j, row) in image.iter().enumerate() {
        for (i, &got) in row.iter().enumerate() {
            let want = expected(i, j, clamp, factor);
            assert!((got - want).abs().max_element() < 2e-5, "{what}: pixel ({i}, {j}): {got} ≠ {want}");
        }
    }
}

fn folder() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tex.png"), png(&TEXELS, 2, 2)).unwrap();
    dir
}

#[test]
fn a_texture_material_on_a_quad_is_filtered_bilinearly_in_linear_light() {
    let dir = folder();
    for (wrap, clamp) in [("", false), ("wrap = \"clamp\"", true)] {
        let text = format!(
            "{VIEW}\n[materials.t]\ntype = \"texture\"\nfile = \"tex.png\"\nalbedo = [1, 0.5, 0.25]\n{wrap}\n\
             [[objects]]\ntype = \"quad\"\ncorner = [0, 0, 0]\nedge_u = [2, 0, 0]\nedge_v = [0, 2, 0]\nmaterial = \"t\"\n"
        );
        check(&format!("toml {wrap}"), &render(&text, dir.path()), clamp, Vec3::new(1.0, 0.5, 0.25));
        // The path tracer's light sample (the sun is found only by it)
        // sees the texel's colour too, not the texture's mean.
        let image = render_with(IntegratorKind::Path, &text, dir.path());
        check(&format!("path, toml {wrap}"), &image, clamp, Vec3::new(1.0, 0.5, 0.25));
    }
}

/// The square as an OBJ with `vt` (v up, as OBJ has it), its material a
/// `map_Kd` in a library in a subfolder, naming the image relative to it.
#[test]
fn an_obj_map_kd_with_texture_coordinates() {
    let dir = folder();
    std::fs::create_dir(dir.path().join("m")).unwrap();
    std::fs::write(dir.path().join("m/tex.png"), png(&TEXELS, 2, 2)).unwrap();
    std::fs::write(
        dir.path().join("m/sq.obj"),
        "mtllib sq.mtl\nv 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3 4/4\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("m/sq.mtl"), "newmtl t\nKd 0.5 0.5 1\nmap_Kd -bm 1 tex.png\n").unwrap();
    let text = format!("{VIEW}\n[[objects]]\ntype = \"mesh\"\nfile = \"m/sq.obj\"\n");
    check("obj", &render(&text, dir.path()), false, Vec3::new(0.5, 0.5, 1.0));

    // A missing or corrupt map names the library and its line.
    std::fs::write(dir.path().join("m/sq.mtl"), "newmtl t\n\nmap_Kd nothing.png\n").unwrap();
    let e = SceneFile::from_toml_str(&text, Some(dir.path())).unwrap_err().to_string();
    assert!(e.contains("sq.mtl:3: map_Kd: no file `m/nothing.png`"), "{e}");
    std::fs::write(dir.path().join("m/bad.png"), b"\x89PNG\r\n\x1a\nnot really").unwrap();
    std::fs::write(dir.path().join("m/sq.mtl"), "newmtl t\nmap_Kd bad.png\n").unwrap();
    let e = SceneFile::from_toml_str(&text, Some(dir.path())).unwrap_err().to_string();
    assert!(e.contains("sq.mtl:2: map_Kd: `m/bad.png`: cannot"), "{e}");
}

/// The square as glTF: positions, TEXCOORD_0 and indices in a data-URI
/// buffer; the image a file, a data URI, or a buffer view. Its material is
/// diffuse (no metalness, no specular lobe: `KHR_materials_specular`'s
/// factor 0), so that the image shows the texture.
fn gltf(image: &str, sampler: &str, attributes: &str) -> String {
    gltf_with(image, sampler, attributes, "")
}

/// The same with `extra` in the base colour texture's `textureInfo`.
fn gltf_with(image: &str, sampler: &str, attributes: &str, extra: &str) -> String {
    let mut data = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0]] {
        p.iter().for_each(|x| data.extend_from_slice(&x.to_le_bytes()));
    }
    for t in [[0.0f32, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]] {
        t.iter().for_each(|x| data.extend_from_slice(&x.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        data.extend_from_slice(&i.to_le_bytes());
    }
    let png_bytes = png(&TEXELS, 2, 2);
    let png_offset = data.len();
    data.extend_from_slice(&png_bytes);
    let b64 = base64::engine::general_purpose::STANDARD.encode(&data);
    format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "scenes": [{{ "nodes": [0] }}],
  "nodes": [{{ "mesh": 0 }}],
  "meshes": [{{ "primitives": [{{ "attributes": {{ {attributes} }}, "indices": 2, "material": 0 }}] }}],
  "materials": [{{ "pbrMetallicRoughness": {{ "baseColorFactor": [1, 0.5, 0.5, 1], "metallicFactor": 0,
                     "baseColorTexture": {{ "index": 0 {extra} }} }},
                  "extensions": {{ "KHR_materials_specular": {{ "specularFactor": 0 }} }} }}],
  "textures": [{{ "source": 0 {sampler} }}],
  "samplers": [{{ "wrapS": 33071, "wrapT": 33071 }}],
  "images": [{image}],
  "buffers": [{{ "byteLength": {len}, "uri": "data:application/octet-stream;base64,{b64}" }}],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": 48 }},
    {{ "buffer": 0, "byteOffset": 48, "byteLength": 32 }},
    {{ "buffer": 0, "byteOffset": 80, "byteLength": 12 }},
    {{ "buffer": 0, "byteOffset": {png_offset}, "byteLength": {png_len} }}
  ],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [2,2,0] }},
    {{ "bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2" }},
    {{ "bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR" }}
  ]
}}"#,
        len = data.len(),
        png_len = png_bytes.len(),
    )
}

const ATTRIBUTES: &str = r#""POSITION": 0, "TEXCOORD_0": 1"#;

#[test]
fn a_gltf_base_colour_texture_with_its_sampler() {
    let dir = folder();
    let text = format!("{VIEW}\n[[include]]\nfile = \"sq.gltf\"\n");
    let data_uri = format!(
        r#"{{ "uri": "data:image/png;base64,{}" }}"#,
        base64::engine::general_purpose::STANDARD.encode(png(&TEXELS, 2, 2))
    );
    for (image, sampler, clamp) in [
        (r#"{ "uri": "tex.png" }"#.to_string(), r#", "sampler": 0"#, true),
        (data_uri, "", false),
        (r#"{ "bufferView": 3, "mimeType": "image/png" }"#.to_string(), r#", "sampler": 0"#, true),
    ] {
        std::fs::write(dir.path().join("sq.gltf"), gltf(&image, sampler, ATTRIBUTES)).unwrap();
        check(&format!("gltf {image}"), &render(&text, dir.path()), clamp, Vec3::new(1.0, 0.5, 0.5));
    }

    let error = |image: &str, attributes: &str| {
        std::fs::write(dir.path().join("sq.gltf"), gltf(image, "", attributes)).unwrap();
        SceneFile::from_toml_str(&text, Some(dir.path())).unwrap_err().to_string()
    };
    let e = error(r#"{ "uri": "missing.png" }"#, ATTRIBUTES);
    assert!(e.contains("`sq.gltf`: materials[0].pbrMetallicRoughness.baseColorTexture: textures[0] → images[0]: no file `missing.png`"), "{e}");
    std::fs::write(dir.path().join("bad.png"), b"GIF89a").unwrap();
    let e = error(r#"{ "uri": "bad.png" }"#, ATTRIBUTES);
    assert!(e.contains("textures[0] → images[0]: a Gif image; textures are PNG or JPEG"), "{e}");
    let e = error(r#"{ "uri": "tex.png" }"#, r#""POSITION": 0"#);
    assert!(
        e.contains("meshes[0].primitives[0]: its material's textures use TEXCOORD_0, which it does not have"),
        "{e}"
    );
}

/// `KHR_texture_transform` on the base colour texture: scale −1 and
/// offset 1 along u mirror the image left to right, and a transform's
/// `texCoord` picks the coordinate set it names.
#[test]
fn a_gltf_texture_transform_moves_the_image() {
    let dir = folder();
    let text = format!("{VIEW}\n[[include]]\nfile = \"sq.gltf\"\n");
    let mirror = r#", "extensions": { "KHR_texture_transform": { "offset": [1, 0], "scale": [-1, 1] } }"#;
    std::fs::write(
        dir.path().join("sq.gltf"),
        gltf_with(r#"{ "uri": "tex.png" }"#, r#", "sampler": 0"#, ATTRIBUTES, mirror),
    )
    .unwrap();
    let image = render(&text, dir.path());
    let mirrored: Vec<Vec<Vec3>> = image.iter().map(|row| row.iter().rev().copied().collect()).collect();
    check("mirrored by its transform", &mirrored, true, Vec3::new(1.0, 0.5, 0.5));
    // The transform names TEXCOORD_1, which the primitive lacks: said so.
    let other_set = r#", "extensions": { "KHR_texture_transform": { "texCoord": 1 } }"#;
    std::fs::write(dir.path().join("sq.gltf"), gltf_with(r#"{ "uri": "tex.png" }"#, "", ATTRIBUTES, other_set))
        .unwrap();
    let e = SceneFile::from_toml_str(&text, Some(dir.path())).unwrap_err().to_string();
    assert!(e.contains("its material's textures use TEXCOORD_1, which it does not have"), "{e}");
}

/// An emissive texture: each triangle glows with the factor × strength ×
/// the texture's mean over it, and a triangle where it is black is no
/// light but a surface of its material.
#[test]
fn a_gltf_emissive_texture_sets_each_triangles_radiance() {
    let dir = folder();
    let text = format!("{VIEW}\n[[include]]\nfile = \"sq.gltf\"\n");
    let emissive = r#""emissiveFactor": [1, 0.5, 0.25], "emissiveTexture": { "index": 0 },
                  "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 4 },"#;
    for (code, lights) in [(128u8, 2), (0, 0)] {
        std::fs::write(dir.path().join("one.png"), png(&[[code; 3]], 1, 1)).unwrap();
        let json = gltf(r#"{ "uri": "one.png" }"#, "", ATTRIBUTES).replace(
            r#""extensions": { "KHR_materials_specular":"#,
            &format!("{emissive} \"KHR_materials_specular\":"),
        );
        std::fs::write(dir.path().join("sq.gltf"), json).unwrap();
        let file = SceneFile::from_toml_str(&text, Some(dir.path())).unwrap_or_else(|e| panic!("{e}"));
        let radiances: Vec<Vec3> = file
            .scene
            .lights()
            .iter()
            .filter_map(|l| match l {
                airlight::light::Light::Triangle { radiance, .. } => Some(*radiance),
                _ => None,
            })
            .collect();
        assert_eq!(radiances.len(), lights, "grey {code}");
        let want = Vec3::new(1.0, 0.5, 0.25) * 4.0 * srgb(code);
        assert!(radiances.iter().all(|r| (*r - want).abs().max_element() < 1e-5), "{radiances:?} against {want}");
        // The dark square is a surface again.
        assert_eq!(file.scene.objects().len(), if lights == 0 { 1 } else { 0 }, "grey {code}");
    }
}

/// The camera sees an emissive texture texel by texel, as a base colour
/// texture under the sun: the same bilinear values, times the factor; and
/// the glowing surface still reflects the sun by its base colour texture.
#[test]
fn a_gltf_emissive_texture_is_seen_point_by_point() {
    let dir = folder();
    let text = format!("{VIEW}\n[[include]]\nfile = \"sq.gltf\"\n");
    let emissive = r#""emissiveFactor": [1, 0.5, 0.25], "emissiveTexture": { "index": 0 },
                  "extensions": {"#;
    let json = gltf(r#"{ "uri": "tex.png" }"#, r#", "sampler": 0"#, ATTRIBUTES)
        .replace(r#""extensions": { "KHR_materials_specular":"#, &format!("{emissive} \"KHR_materials_specular\":"));
    std::fs::write(dir.path().join("sq.gltf"), json).unwrap();
    // Emitted (factor [1, 0.5, 0.25]) plus reflected (albedo factor
    // [1, 0.5, 0.5] under irradiance π): the texture's value times their sum.
    check("emissive", &render(&text, dir.path()), true, Vec3::new(2.0, 1.0, 0.75));
}
