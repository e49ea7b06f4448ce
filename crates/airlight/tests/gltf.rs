//! glTF import: a small scene written as glTF (a node hierarchy with TRS
//! and matrix transforms, a mirrored mesh, an emissive quad, a
//! `KHR_lights_punctual` point light in candela, a camera) renders as the
//! same scene written by hand in Airlight's TOML; bad files give errors
//! that name the file, the JSON path and what is wrong.

use airlight::SceneFile;
use airlight::film::Accumulator;
use airlight::integrator::{IntegratorDesc, IntegratorKind};
use airlight::light::Light;
use airlight::render::accumulate;
use base64::Engine;

const SIZE: u32 = 12;

/// The buffer: a unit square in XZ (for the floor, scaled ×2) and the same
/// square wound the other way (the lamp, facing down), as f32 positions,
/// then u16 indices for each.
fn buffer() -> Vec<u8> {
    let square = [[-1.0f32, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]];
    let mut bytes = Vec::new();
    for p in square.iter().chain(square.iter()) {
        for x in p {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
    }
    // Floor: counter-clockwise seen from above (normal +y).
    // Lamp: clockwise seen from above, so it faces down.
    for i in [0u16, 2, 1, 0, 3, 2, 0, 1, 2, 0, 2, 3] {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    bytes
}

/// The glTF JSON, its buffer inline as a data URI unless `buffer_uri` names a file.
fn gltf_json(buffer_uri: Option<&str>, extra_required: &str, lamp_mode: u32) -> String {
    let data = buffer();
    let uri = match buffer_uri {
        Some(u) => u.to_string(),
        None => {
            format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&data))
        }
    };
    format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
  "extensionsRequired": [{extra_required}],
  "scene": 0,
  "scenes": [{{ "name": "room", "nodes": [0, 1, 3, 4] }}],
  "nodes": [
    {{ "name": "floor", "mesh": 0, "scale": [2, 1, 2] }},
    {{ "name": "lamp holder", "translation": [0, 1, 0], "children": [2] }},
    {{ "name": "lamp", "mesh": 1, "matrix": [0.5,0,0,0, 0,1,0,0, 0,0,0.5,0, 0,0.5,0,1] }},
    {{ "name": "bulb", "translation": [1, 1, -1], "extensions": {{ "KHR_lights_punctual": {{ "light": 0 }} }} }},
    {{ "name": "eye", "translation": [0.3, 1, -3], "rotation": [0, 1, 0, 0], "camera": 0 }}
  ],
  "cameras": [{{ "type": "perspective", "perspective": {{ "yfov": 1.0471976, "aspectRatio": 1.0, "znear": 0.01 }} }}],
  "extensions": {{ "KHR_lights_punctual": {{ "lights": [{{ "type": "point", "color": [1, 0.5, 0.25], "intensity": 1366 }}] }} }},
  "materials": [
    {{ "pbrMetallicRoughness": {{ "baseColorFactor": [0.6, 0.2, 0.1, 1] }} }},
    {{ "pbrMetallicRoughness": {{ "baseColorFactor": [0, 0, 0, 1] }}, "emissiveFactor": [1, 0.8333333, 0.6666667],
       "extensions": {{ "KHR_materials_emissive_strength": {{ "emissiveStrength": 6 }} }} }}
  ],
  "meshes": [
    {{ "primitives": [{{ "attributes": {{ "POSITION": 0 }}, "indices": 2, "material": 0 }}] }},
    {{ "primitives": [{{ "attributes": {{ "POSITION": 1 }}, "indices": 3, "material": 1, "mode": {lamp_mode} }}] }}
  ],
  "buffers": [{{ "byteLength": {len}, "uri": "{uri}" }}],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": 96 }},
    {{ "buffer": 0, "byteOffset": 96, "byteLength": 24 }}
  ],
  "accessors": [
    {{ "bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1,0,-1], "max": [1,0,1] }},
    {{ "bufferView": 0, "byteOffset": 48, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1,0,-1], "max": [1,0,1] }},
    {{ "bufferView": 1, "byteOffset": 0, "componentType": 5123, "count": 6, "type": "SCALAR" }},
    {{ "bufferView": 1, "byteOffset": 12, "componentType": 5123, "count": 6, "type": "SCALAR" }}
  ]
}}"#,
        len = data.len()
    )
}

/// The same room by hand: the floor ±2 at y = 0 a rough metal (glTF's
/// default factors), the lamp ±0.5 at y = 1.5
/// facing down with radiance [6, 5, 4], a point light of 1366 cd × colour
/// over 683 lm/W, and the camera 60° high looking along +z.
const BY_HAND: &str = r#"
[render]
width = 12
height = 12
[camera]
position = [0.3, 1, -3]
look_at = [0.3, 1, 0]
fov = 60
[materials.red]
type = "metallic_roughness"
base_colour = [0.6, 0.2, 0.1]
metallic = 1
roughness = 1
[[objects]]
type = "quad"
corner = [-2, 0, -2]
edge_u = [0, 0, 4]
edge_v = [4, 0, 0]
material = "red"
[[lights]]
type = "quad"
corner = [-0.5, 1.5, -0.5]
edge_u = [1, 0, 0]
edge_v = [0, 0, 1]
radiance = [6, 5, 4]
[[lights]]
type = "point"
position = [1, 1, -1]
intensity = [2, 1, 0.5]
"#;

fn render(file: &SceneFile) -> Accumulator {
    let mut desc = IntegratorDesc::new(IntegratorKind::Path);
    desc.path.max_depth = 2;
    let integrator = desc.build(&file.scene).unwrap();
    accumulate(&file.scene, integrator.as_ref(), 0..256, 0..SIZE, &Default::default())
}

fn block(acc: &Accumulator, xs: std::ops::Range<u32>, ys: std::ops::Range<u32>) -> (f64, f64) {
    let (mut mean, mut var, mut n) = (0.0, 0.0, 0.0);
    for y in ys {
        for x in xs.clone() {
            let p = acc.pixel(x, y).unwrap();
            mean += p.mean().as_dvec3().element_sum() / 3.0;
            let v = p.variance_of_mean().element_sum() / 9.0;
            assert!(v.is_finite());
            var += v;
            n += 1.0;
        }
    }
    (mean / n, var / (n * n))
}

#[test]
fn a_gltf_room_renders_as_the_room_written_by_hand() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("room.gltf");
    std::fs::write(&path, gltf_json(None, "", 4)).unwrap();
    // `airlight render room.gltf`: the file alone is a scene; its camera's
    // aspect ratio sets the height.
    let direct = SceneFile::load(&path).unwrap();
    assert_eq!(direct.scene.settings().film.height, direct.scene.settings().film.width);
    let lights = direct.scene.lights();
    assert_eq!(lights.iter().filter(|l| matches!(l, Light::Triangle { .. })).count(), 2);
    let Some(Light::Point { position, intensity, .. }) = lights.iter().find(|l| matches!(l, Light::Point { .. }))
    else {
        panic!("no point light: {lights:?}");
    };
    assert!((*position - glam::Vec3::new(1.0, 1.0, -1.0)).length() < 1e-6);
    assert!((*intensity - glam::Vec3::new(2.0, 1.0, 0.5)).length() < 1e-5, "{intensity}");

    // The same through a scene file's [[include]], sized as the hand-written one.
    let text = "[render]\nwidth = 12\nheight = 12\n[[include]]\nfile = \"room.gltf\"\n";
    let included = SceneFile::from_toml_str(text, Some(dir.path())).unwrap();
    let by_hand = SceneFile::from_toml_str(BY_HAND, None).unwrap();
    let (a, b) = (render(&by_hand), render(&included));
    let h = SIZE / 2;
    for (xs, ys) in [(0..SIZE, 0..SIZE), (0..h, 0..h), (h..SIZE, 0..h), (0..h, h..SIZE), (h..SIZE, h..SIZE)] {
        let ((ma, va), (mb, vb)) = (block(&a, xs.clone(), ys.clone()), block(&b, xs.clone(), ys.clone()));
        let allowed = 5.0 * (va + vb).sqrt() + 0.005 * ma.max(mb);
        assert!((ma - mb).abs() <= allowed, "pixels {xs:?}×{ys:?}: by hand {ma}, glTF {mb}, allowed ±{allowed}");
    }
    assert!(block(&a, 0..SIZE, 0..SIZE).0 > 0.05, "the room is dark");
}

#[test]
fn include_moves_and_recolours_a_gltf_and_reads_its_buffer_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("models")).unwrap();
    std::fs::write(dir.path().join("models/room.bin"), buffer()).unwrap();
    std::fs::write(dir.path().join("models/room.gltf"), gltf_json(Some("room.bin"), "", 4)).unwrap();
    let text = "[materials.grey]\n[[include]]\nfile = \"models/room.gltf\"\nscene = \"room\"\ntranslate = [0, 2, 0]\n\
                material = \"grey\"\n";
    let file = SceneFile::from_toml_str(text, Some(dir.path())).unwrap();
    // With a material for everything, the lamp is a grey surface, not a light.
    assert_eq!(file.scene.lights().len(), 1);
    let Light::Point { position, .. } = file.scene.lights()[0] else { panic!() };
    assert!((position - glam::Vec3::new(1.0, 3.0, -1.0)).length() < 1e-6);
    assert_eq!(file.scene.objects().len(), 2);
    assert!(file.scene.files().iter().any(|f| f.ends_with("models/room.bin")));
}

#[test]
fn bad_gltf_files_name_the_file_the_json_path_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let error = |json: &str| {
        let path = dir.path().join("bad.gltf");
        std::fs::write(&path, json).unwrap();
        SceneFile::load(&path).unwrap_err().to_string()
    };
    let e = error(&gltf_json(None, r#""KHR_draco_mesh_compression""#, 4));
    assert!(
        e.contains("bad.gltf: include[0]: `bad.gltf`: not a valid glTF file: it requires the extension `KHR_draco_mesh_compression`, which Airlight does not read")
            && e.lines().count() == 1,
        "{e}"
    );
    let e = error(&gltf_json(None, "", 1));
    assert!(e.contains("meshes[1].primitives[0]: mode Lines is not triangles"), "{e}");
    let e = error(&gltf_json(Some("missing.bin"), "", 4));
    assert!(e.contains("buffers[0]: no file `missing.bin`"), "{e}");
    std::fs::write(dir.path().join("short.bin"), &buffer()[..100]).unwrap();
    let e = error(&gltf_json(Some("short.bin"), "", 4));
    assert!(e.contains("buffers[0]: holds 100 bytes, but the file says 120"), "{e}");
    let e = error(&gltf_json(Some("../outside.bin"), "", 4));
    assert!(e.contains("must be a relative path inside"), "{e}");
    let e = error(&gltf_json(None, "", 4).replace("0,0.5,0,1]", "0,0.5,0,2]"));
    assert!(e.contains("nodes[2]: its transform is not a finite affine matrix"), "{e}");
    let e = error("{ \"asset\": { \"version\": \"2.0\" }, \"nodes\": [{ \"mesh\": 7 }] }");
    assert!(e.contains("not a valid glTF file"), "{e}");
    let e = error("not json");
    assert!(e.contains("not a valid glTF file"), "{e}");
    // A stride shorter than an element (the gltf crate's reader panics on
    // it) and accessors of a type their use does not allow (it misreads
    // them) are refused with the specification's rule.
    let short_stride = gltf_json(None, "", 4)
        .replace(r#""byteOffset": 0, "byteLength": 96 }"#, r#""byteOffset": 0, "byteLength": 96, "byteStride": 4 }"#);
    let e = error(&short_stride);
    assert!(e.contains("POSITION: bufferViews[0].byteStride is 4; its accessors' elements take 12 bytes"), "{e}");
    let scalar_positions =
        gltf_json(None, "", 4).replacen(r#""count": 4, "type": "VEC3""#, r#""count": 4, "type": "SCALAR""#, 1);
    let e = error(&scalar_positions);
    assert!(e.contains("POSITION: accessors[0] is Scalar of F32; the specification asks for Vec3 of F32"), "{e}");
    let byte_positions = gltf_json(None, "", 4).replacen(
        r#""componentType": 5126, "count": 4"#,
        r#""componentType": 5121, "count": 4"#,
        1,
    );
    let e = error(&byte_positions);
    assert!(e.contains("POSITION: accessors[0] is Vec3 of U8"), "{e}");
}

/// What a glTF file places is held to the scene file's rules, and its
/// sizes are counted as it places them: a second buffer cannot copy the
/// BIN chunk, reused nodes cannot multiply without bound, vertices, lights
/// and cameras must lie within reach of f32, a spot's cone within π/2.
#[test]
fn imported_content_obeys_the_scene_files_rules_and_limits() {
    let dir = tempfile::tempdir().unwrap();
    let error = |json: &str| {
        let path = dir.path().join("bad.gltf");
        std::fs::write(&path, json).unwrap();
        SceneFile::load(&path).unwrap_err().to_string()
    };
    let good = gltf_json(None, "", 4);
    let far_vertex = good.replace(r#""mesh": 0, "scale": [2, 1, 2]"#, r#""mesh": 0, "scale": [1e10, 1, 2]"#);
    let e = error(&far_vertex);
    assert!(e.contains("meshes[0].primitives[0]: the vertex") && e.contains("world units from the origin"), "{e}");
    let far_light = good.replace(r#""translation": [1, 1, -1]"#, r#""translation": [1e30, 1, -1]"#);
    let e = error(&far_light);
    assert!(e.contains("a light at") && e.contains("world units from the origin"), "{e}");
    let far_camera = good.replace(r#""translation": [0.3, 1, -3]"#, r#""translation": [0.3, 1e30, -3]"#);
    let e = error(&far_camera);
    assert!(e.contains("the camera at") && e.contains("world units from the origin"), "{e}");
    let wide_spot = good.replace(
        r#"{ "type": "point", "color": [1, 0.5, 0.25], "intensity": 1366 }"#,
        r#"{ "type": "spot", "color": [1, 0.5, 0.25], "intensity": 1366, "spot": { "outerConeAngle": 1000000 } }"#,
    );
    let e = error(&wide_spot);
    assert!(e.contains("a spot's cone angles must satisfy 0 ≤ inner ≤ outer ≤ π/2"), "{e}");
    // A node whose children are [k + 1, k + 1], 30 levels: 2³⁰ placements
    // from a kilobyte.
    let mut nodes: Vec<String> = (0..30).map(|k| format!(r#"{{ "children": [{}, {}] }}"#, k + 1, k + 1)).collect();
    nodes.push(r#"{ "name": "leaf" }"#.into());
    let doubling = format!(
        r#"{{ "asset": {{ "version": "2.0" }}, "scene": 0, "scenes": [{{ "nodes": [0] }}], "nodes": [{}] }}"#,
        nodes.join(", ")
    );
    let e = error(&doubling);
    assert!(e.contains("the node hierarchy places more than 1048576 nodes"), "{e}");
    // Only the first buffer may be a GLB's BIN chunk (each other one
    // without a uri copied all of it).
    let second_bin = good.replace(" }],\n  \"bufferViews\"", " }, { \"byteLength\": 4 }],\n  \"bufferViews\"");
    assert_ne!(second_bin, good);
    let e = error(&second_bin);
    assert!(e.contains("buffers[1]: has no uri; only buffers[0] may be the GLB's BIN chunk"), "{e}");
}

/// An include's tiny scale keeps its lights' and camera's directions
/// (normalised in 64-bit floats, as the scene file's are); a huge one puts
/// its vertices out of reach, and says so.
#[test]
fn an_includes_extreme_scale_is_refused_or_kept_as_the_file_would() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("room.gltf"), gltf_json(None, "", 4)).unwrap();
    let load = |scale: &str| {
        let path = dir.path().join("s.toml");
        std::fs::write(&path, format!("[[include]]\nfile = \"room.gltf\"\nscale = {scale}\n")).unwrap();
        SceneFile::load(&path).map_err(|e| e.to_string())
    };
    let e = load("1e30").unwrap_err();
    assert!(e.contains("world units from the origin"), "{e}");
    let (tiny, whole) = (load("1e-30").unwrap(), load("1").unwrap());
    let (a, b) = (tiny.scene.camera().forward, whole.scene.camera().forward);
    assert!((a - b).length() < 1e-6, "{a} against {b}");
    assert!(tiny.scene.lights().iter().any(|l| matches!(l, airlight::light::Light::Point { .. })));
}
