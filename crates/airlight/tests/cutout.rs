//! Cut-outs: a glTF quad whose base colour texture's alpha is opaque on
//! half of each period (alphaMode MASK, cutoff ½: by the symmetry of the
//! filtered stripes, exactly half of the quad is open) casts a shadow of
//! which exactly half is lit, for every integrator that traces shadow
//! rays; the same quad OPAQUE casts a whole shadow; BLEND at alpha ¼ lets
//! three quarters through on average.

use airlight::SceneFile;
use airlight::integrator::{IntegratorDesc, IntegratorKind};
use airlight::render::accumulate;
use base64::Engine;

fn png_rgba(texels: &[[u8; 4]], width: u32, height: u32) -> Vec<u8> {
    let mut bytes = Vec::new();
    let flat: Vec<u8> = texels.iter().flatten().copied().collect();
    let encoder = image::codecs::png::PngEncoder::new(&mut bytes);
    image::ImageEncoder::write_image(encoder, &flat, width, height, image::ExtendedColorType::Rgba8).unwrap();
    bytes
}

/// A 2 × 2 quad at height 1 (x, z in [0, 2]) facing up, its texture
/// repeated eight times along x: stripes a quarter wide.
fn quad_gltf(material: &str) -> String {
    let mut data = Vec::new();
    for p in [[0.0f32, 1.0, 0.0], [0.0, 1.0, 2.0], [2.0, 1.0, 2.0], [2.0, 1.0, 0.0]] {
        p.iter().for_each(|x| data.extend_from_slice(&x.to_le_bytes()));
    }
    for t in [[0.0f32, 0.0], [0.0, 1.0], [8.0, 1.0], [8.0, 0.0]] {
        t.iter().for_each(|x| data.extend_from_slice(&x.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        data.extend_from_slice(&i.to_le_bytes());
    }
    let b64 = base64::engine::general_purpose::STANDARD.encode(&data);
    format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "scenes": [{{ "nodes": [0] }}],
  "nodes": [{{ "mesh": 0 }}],
  "meshes": [{{ "primitives": [{{ "attributes": {{ "POSITION": 0, "TEXCOORD_0": 1 }}, "indices": 2, "material": 0 }}] }}],
  "materials": [{{ "pbrMetallicRoughness": {{ "metallicFactor": 0, "baseColorTexture": {{ "index": 0 }} }}, {material} }}],
  "textures": [{{ "source": 0 }}],
  "images": [{{ "uri": "stripes.png" }}],
  "buffers": [{{ "byteLength": {len}, "uri": "data:application/octet-stream;base64,{b64}" }}],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": 48 }},
    {{ "buffer": 0, "byteOffset": 48, "byteLength": 32 }},
    {{ "buffer": 0, "byteOffset": 80, "byteLength": 12 }}
  ],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,1,0], "max": [2,1,2] }},
    {{ "bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2" }},
    {{ "bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR" }}
  ]
}}"#,
        len = data.len()
    )
}

/// The sun comes down at 45° toward +x, so the quad's shadow falls on the
/// floor at x in [1, 3]; the orthographic camera looks straight down at
/// x in [2.25, 2.75], z in [0.75, 1.25] (two stripes' shadows), where it
/// sees the floor and not the quad.
fn scene(dir: &std::path::Path, with_quad: bool) -> SceneFile {
    let include = if with_quad { "[[include]]\nfile = \"quad.gltf\"\n" } else { "" };
    let text = format!(
        r#"
[render]
width = 32
height = 32
[camera]
type = "orthographic"
position = [2.5, 5, 1]
look_at = [2.5, 0, 1]
up = [0, 0, 1]
view_height = 0.5
[materials.floor]
albedo = 0.5
[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"
[[lights]]
type = "distant"
direction = [1, -1, 0]
irradiance = 1
{include}"#
    );
    SceneFile::from_toml_str(&text, Some(dir)).unwrap_or_else(|e| panic!("{e}"))
}

fn mean(file: &SceneFile, kind: IntegratorKind, spp: u64) -> f64 {
    // Direct light only: the path tracer's bounces would add the floor's
    // light reflected back by the quad's underside.
    let mut desc = IntegratorDesc::new(kind);
    desc.path.max_depth = 1;
    let integrator = desc.build(&file.scene).unwrap();
    let acc = accumulate(&file.scene, integrator.as_ref(), 0..spp, 0..32, &Default::default());
    let mut sum = 0.0;
    for y in 0..32 {
        for x in 0..32 {
            sum += acc.pixel(x, y).unwrap().mean().x as f64;
        }
    }
    sum / 1024.0
}

#[test]
fn a_masked_quad_lets_through_the_light_of_its_open_part() {
    let dir = tempfile::tempdir().unwrap();
    // Alpha opaque then clear along u, repeating.
    std::fs::write(dir.path().join("stripes.png"), png_rgba(&[[200, 200, 200, 255], [200, 200, 200, 0]], 2, 1))
        .unwrap();
    let lit = mean(&scene(dir.path(), false), IntegratorKind::Direct, 4);
    assert!(lit > 0.05, "{lit}");
    for (material, open) in [
        (r#""alphaMode": "MASK""#, 0.5),
        (r#""alphaMode": "OPAQUE""#, 0.0),
        (r#""alphaMode": "MASK", "alphaCutoff": 0.0"#, 0.0),
    ] {
        std::fs::write(dir.path().join("quad.gltf"), quad_gltf(material)).unwrap();
        let file = scene(dir.path(), true);
        for kind in [IntegratorKind::Direct, IntegratorKind::Raymarch, IntegratorKind::Path] {
            let fraction = mean(&file, kind, 8) / lit;
            assert!((fraction - open).abs() < 0.02, "{material}, {kind:?}: {fraction} of the light, not {open}");
        }
    }
    // BLEND: a base colour alpha of ¼ over an opaque texture lets three
    // quarters of the rays through, on average over many.
    std::fs::write(dir.path().join("stripes.png"), png_rgba(&[[200, 200, 200, 255], [200, 200, 200, 255]], 2, 1))
        .unwrap();
    let blend = quad_gltf(r#""alphaMode": "BLEND""#)
        .replace(r#""metallicFactor": 0,"#, r#""metallicFactor": 0, "baseColorFactor": [1, 1, 1, 0.25],"#);
    std::fs::write(dir.path().join("quad.gltf"), blend).unwrap();
    let fraction = mean(&scene(dir.path(), true), IntegratorKind::Direct, 64) / lit;
    assert!((fraction - 0.75).abs() < 0.02, "blend: {fraction} of the light, not 0.75");
    // The analytic integrator's exact shadows cannot follow the alpha: it
    // says so (without shadows it renders).
    let file = scene(dir.path(), true);
    let mut analytic = IntegratorDesc::new(IntegratorKind::Analytic);
    analytic.analytic.shadows = true;
    let e = analytic.build(&file.scene).err().expect("analytic shadows refused");
    assert!(e.to_string().contains("cut-out materials"), "{e}");
    analytic.analytic.shadows = false;
    assert!(analytic.build(&file.scene).is_ok());
}
