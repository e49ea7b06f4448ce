//! Structure-aware fuzzing of the files a render imports or a farm hands
//! back: glTF scenes (the JSON mutated as a tree, the binary chunk, data
//! URI buffers and buffer files by byte, the GLB framing by byte) and
//! partial EXR renders (read, then merged with a sound part as `merge`
//! and `--resume` would), and a sky's environment maps (Radiance HDR and
//! OpenEXR, by byte, then rendered). Each input runs under `catch_unwind`: a panic or
//! an empty error fails the test with the seed that replays it
//! (`AIRLIGHT_FUZZ_SEED=… cargo test -p airlight --test fuzz_imports`).
//!
//! The normal run tries 10,000 glTF files, 10,000 partial files and 2,000
//! environment maps; the
//! ignored tests a million of each (`cargo test --release -p airlight
//! --test fuzz_imports -- --ignored`). `AIRLIGHT_FUZZ_INPUTS` sets the count.

#[path = "fuzz/json.rs"]
mod json;
#[path = "fuzz/mutate.rs"]
mod mutate;
#[path = "fuzz/run.rs"]
mod run;

use airlight::film::partial::{self, Partial, PartialHeader};
use airlight::film::{Accumulator, Tonemap};
use airlight::prelude::*;
use airlight::render::{RenderObserver, accumulate};
use base64::Engine;
use mutate::{Rng, mutate_bytes};
use run::{count, fuzz, replaying};
use std::path::Path;

/// A glTF file to mutate: its JSON, its binary chunk (a GLB's), and the
/// files beside it.
#[derive(Clone)]
struct GltfBase {
    json: serde_json::Value,
    bin: Option<Vec<u8>>,
    beside: Vec<(&'static str, Vec<u8>)>,
}

/// A GLB's JSON and BIN chunks (glTF 2.0 specification, "GLB File Format").
fn glb_chunks(bytes: &[u8]) -> (serde_json::Value, Option<Vec<u8>>) {
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let json_len = word(12);
    let json = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin = (bytes.len() > 20 + json_len + 8).then(|| {
        let at = 20 + json_len;
        bytes[at + 8..at + 8 + word(at)].to_vec()
    });
    (json, bin)
}

/// A GLB of `json` and `bin`, its chunks padded to four bytes.
fn glb(json: &serde_json::Value, bin: Option<&[u8]>) -> Vec<u8> {
    let mut text = serde_json::to_vec(json).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut chunks = Vec::new();
    chunks.extend((text.len() as u32).to_le_bytes());
    chunks.extend(b"JSON");
    chunks.extend(&text);
    if let Some(bin) = bin {
        let mut bin = bin.to_vec();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        chunks.extend((bin.len() as u32).to_le_bytes());
        chunks.extend(b"BIN\0");
        chunks.extend(&bin);
    }
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((12 + chunks.len() as u32).to_le_bytes());
    out.extend(chunks);
    out
}

/// The example scenes' glTF files: a `.gltf` with a data URI buffer, a
/// `.glb` with a binary chunk and a texture beside it, the same GLB as a
/// `.gltf` whose buffer is a file beside it, and the GLB with its floor's
/// material using every map Airlight reads (normal, emissive and
/// metallic-roughness textures, a texture transform, a cut-out).
fn gltf_bases() -> Vec<GltfBase> {
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/models");
    let lamp = serde_json::from_slice(&std::fs::read(models.join("lamp_room.gltf")).unwrap()).unwrap();
    let (room, bin) = glb_chunks(&std::fs::read(models.join("blender_room.glb")).unwrap());
    let floor = std::fs::read(models.join("blender_floor.png")).unwrap();
    let mut room_files = room.clone();
    room_files["buffers"][0]["uri"] = "room.bin".into();
    let mut mapped = room.clone();
    let floor_material = &mut mapped["materials"][0];
    floor_material["normalTexture"] = serde_json::json!({ "index": 0, "scale": 0.8 });
    floor_material["emissiveTexture"] = serde_json::json!({ "index": 0 });
    floor_material["emissiveFactor"] = serde_json::json!([0.5, 0.4, 0.3]);
    floor_material["alphaMode"] = "MASK".into();
    floor_material["pbrMetallicRoughness"]["metallicFactor"] = 0.5.into();
    floor_material["pbrMetallicRoughness"]["metallicRoughnessTexture"] = serde_json::json!({ "index": 0 });
    floor_material["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] =
        serde_json::json!({ "KHR_texture_transform": { "offset": [0.1, 0.2], "rotation": 0.3, "scale": [2, 2] } });
    vec![
        GltfBase { json: mapped, bin: bin.clone(), beside: vec![("blender_floor.png", floor.clone())] },
        GltfBase { json: lamp, bin: None, beside: vec![] },
        GltfBase { json: room, bin: bin.clone(), beside: vec![("blender_floor.png", floor.clone())] },
        GltfBase {
            json: room_files,
            bin: None,
            beside: vec![("blender_floor.png", floor), ("room.bin", bin.unwrap_or_default())],
        },
    ]
}

/// The data URI buffer of `json`'s first buffer, its bytes mutated.
fn mutate_data_uri(rng: &mut Rng, json: &mut serde_json::Value) {
    let engine = base64::engine::general_purpose::STANDARD;
    let Some(uri) = json["buffers"][0]["uri"].as_str() else { return };
    let Some((head, data)) = uri.split_once(";base64,") else { return };
    let Ok(mut bytes) = engine.decode(data) else { return };
    mutate_bytes(rng, &mut bytes, &[]);
    json["buffers"][0]["uri"] = format!("{head};base64,{}", engine.encode(&bytes)).into();
}

/// Loads (and, when it loads, renders) one mutated glTF file.
fn gltf_input(seed: u64, bases: &[GltfBase], dir: &Path) -> Result<bool, String> {
    let mut rng = Rng(seed);
    let GltfBase { mut json, mut bin, mut beside } = rng.pick(bases).clone();
    if !rng.chance(4) {
        json::mutate_json(&mut rng, &mut json);
    }
    if rng.chance(3) {
        mutate_data_uri(&mut rng, &mut json);
    }
    if let Some(bin) = bin.as_mut().filter(|_| rng.chance(3)) {
        mutate_bytes(&mut rng, bin, &[]);
    }
    if let Some((_, bytes)) = beside.last_mut().filter(|_| rng.chance(4)) {
        mutate_bytes(&mut rng, bytes, &[]);
    }
    for entry in std::fs::read_dir(dir).unwrap() {
        std::fs::remove_file(entry.unwrap().path()).unwrap();
    }
    for (name, bytes) in &beside {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    let path = match bin {
        Some(bin) => {
            let mut bytes = glb(&json, Some(&bin));
            if rng.chance(8) {
                // The framing: chunk lengths, magic, version.
                mutate_bytes(&mut rng, &mut bytes, &[8, 12, 16, 20]);
            }
            let path = dir.join("scene.glb");
            std::fs::write(&path, bytes).unwrap();
            path
        }
        None => {
            let path = dir.join("scene.gltf");
            std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
            path
        }
    };
    if replaying() {
        std::fs::copy(&path, Path::new("/tmp").join(path.file_name().unwrap())).unwrap();
        eprintln!("{}", serde_json::to_string_pretty(&json).unwrap());
    }
    match SceneFile::load(&path) {
        Ok(SceneFile { mut scene, integrator }) => {
            let s = scene.settings_mut();
            (s.film.width, s.film.height, s.spp) = (3, 2, 1);
            if let Ok(built) = integrator.build(&scene) {
                airlight::render(&scene, built.as_ref(), &RenderObserver::none());
            }
            Ok(true)
        }
        Err(e) if e.message.trim().is_empty() => Err(format!("an empty error: {e:?}")),
        Err(e) if !e.to_string().contains("scene.gl") => Err(format!("an error that does not name the file: {e}")),
        Err(_) => Ok(false),
    }
}

fn fuzz_gltf(n: u64) {
    let bases = gltf_bases();
    let dir = tempfile::tempdir().unwrap();
    fuzz("glTF", 0x91F, n, |seed| gltf_input(seed, &bases, dir.path()));
}

#[test]
fn mutated_gltf_files_never_panic_and_errors_name_the_file() {
    fuzz_gltf(count(10_000));
}

#[test]
#[ignore = "a million inputs: run by hand (docs/developing.md, BENCHMARKS.md)"]
fn a_million_mutated_gltf_files() {
    fuzz_gltf(count(1_000_000));
}

/// Two halves of a small render's samples as partial files' bytes: the
/// first mutated, the second what it is merged with.
fn partial_bases(dir: &Path) -> Vec<Vec<u8>> {
    let scene = SceneBuilder::new()
        .size(6, 4)
        .with_settings(|s| s.spp = 4)
        .camera(Camera::look_at(vec3(0.0, 1.0, -4.0), vec3(0.0, 0.5, 0.0), Vec3::Y, 50.0))
        .material("grey", Material::diffuse(Rgb::splat(0.5)))
        .object(Shape::sphere(vec3(0.0, 0.5, 0.0), 0.5), "grey")
        .light(Light::point(vec3(1.0, 2.5, -1.0), Rgb::splat(8.0)))
        .build()
        .unwrap();
    let integrator = IntegratorDesc::new(IntegratorKind::Direct).build(&scene).unwrap();
    let header = |samples: std::ops::Range<u64>, rows: std::ops::Range<u32>| PartialHeader {
        version: "fuzz".into(),
        scene: "0123456789abcdef".into(),
        seed: 0,
        width: 6,
        height: 4,
        spp: 4,
        samples,
        rows,
        frame: Some((1, 3)),
        exposure: 0.0,
        tonemap: Tonemap::Clamp,
    };
    let part = |samples: std::ops::Range<u64>, rows: std::ops::Range<u32>| {
        let sums: Accumulator =
            accumulate(&scene, integrator.as_ref(), samples.clone(), rows.clone(), &RenderObserver::none());
        let path = dir.join("base.exr");
        Partial { header: header(samples, rows), sums }.write(&path).unwrap();
        std::fs::read(&path).unwrap()
    };
    vec![part(0..2, 0..4), part(2..4, 0..4), part(0..4, 1..3)]
}

/// Offsets worth hitting in a partial file: the windows' corners and the
/// digits of the header's fields.
fn header_fields(bytes: &[u8]) -> Vec<usize> {
    let mut fields = Vec::new();
    for name in [&b"dataWindow\0box2i\0"[..], b"displayWindow\0box2i\0"] {
        if let Some(at) = bytes.windows(name.len()).position(|w| w == name) {
            fields.extend((0..4).map(|k| at + name.len() + 4 + 4 * k));
        }
    }
    let header = &bytes[..bytes.len().min(2048)];
    fields.extend(
        header.windows(2).enumerate().filter(|(_, w)| w[0] == b'=' && w[1].is_ascii_digit()).map(|(i, _)| i + 1),
    );
    fields
}

/// Reads one mutated partial file and merges it with a sound one.
fn partial_input(seed: u64, bases: &[Vec<u8>], dir: &Path) -> Result<bool, String> {
    let mut rng = Rng(seed);
    let (first, other) = if rng.chance(2) { (&bases[0], &bases[1]) } else { (&bases[1], &bases[0]) };
    let first = if rng.chance(5) { &bases[2] } else { first };
    let mut bytes = first.clone();
    let fields = header_fields(&bytes);
    mutate_bytes(&mut rng, &mut bytes, &fields);
    let path = dir.join("mutated.exr");
    std::fs::write(&path, &bytes).unwrap();
    if replaying() {
        std::fs::write("/tmp/airlight-fuzz-replay.partial.exr", &bytes).unwrap();
    }
    let part = match Partial::read(&path) {
        Ok(part) => part,
        Err(e) if e.trim().is_empty() => return Err("an empty error".into()),
        Err(_) => return Ok(false),
    };
    // What the sums give on their own, then a merge with the other half.
    part.sums.image();
    part.sums.variance();
    let sound = std::fs::write(dir.join("other.exr"), other).map(|()| Partial::read(&dir.join("other.exr")));
    let sound = sound.unwrap().map_err(|e| format!("the sound part does not read: {e}"))?;
    match partial::merge(&[("mutated.exr".into(), part), ("other.exr".into(), sound)]) {
        Ok((_, merged)) => {
            merged.image();
            Ok(true)
        }
        Err(e) if e.trim().is_empty() => Err("an empty merge error".into()),
        Err(_) => Ok(false),
    }
}

fn fuzz_partials(n: u64) {
    let dir = tempfile::tempdir().unwrap();
    let bases = partial_bases(dir.path());
    fuzz("partial EXR", 0x9A27, n, |seed| partial_input(seed, &bases, dir.path()));
}

#[test]
fn mutated_partial_files_never_panic_when_read_or_merged() {
    fuzz_partials(count(10_000));
}

#[test]
#[ignore = "a million inputs: run by hand (docs/developing.md, BENCHMARKS.md)"]
fn a_million_mutated_partial_files() {
    fuzz_partials(count(1_000_000));
}

/// A sky's environment maps to mutate: a Radiance HDR image and an
/// OpenEXR one (written by the `image` crate), 8 × 4 texels.
fn environment_bases() -> Vec<Vec<u8>> {
    let texels: Vec<image::Rgb<f32>> =
        (0..32).map(|k| image::Rgb([k as f32 * 0.1, 1.0 / (k as f32 + 1.0), 0.5])).collect();
    let mut hdr = Vec::new();
    image::codecs::hdr::HdrEncoder::new(&mut hdr).encode(&texels, 8, 4).unwrap();
    let flat: Vec<f32> = texels.iter().flat_map(|t| t.0).collect();
    let mut exr = std::io::Cursor::new(Vec::new());
    let buffer = image::ImageBuffer::<image::Rgb<f32>, Vec<f32>>::from_raw(8, 4, flat).unwrap();
    image::DynamicImage::ImageRgb32F(buffer).write_to(&mut exr, image::ImageFormat::OpenExr).unwrap();
    vec![hdr, exr.into_inner()]
}

/// Loads one mutated environment map as a scene's sky and renders a few
/// samples of it.
fn environment_input(seed: u64, bases: &[Vec<u8>], dir: &Path) -> Result<bool, String> {
    let mut rng = Rng(seed);
    let mut bytes = rng.pick(bases).clone();
    mutate_bytes(&mut rng, &mut bytes, &[]);
    std::fs::write(dir.join("sky.map"), &bytes).unwrap();
    if replaying() {
        std::fs::write("/tmp/airlight-fuzz-replay.sky", &bytes).unwrap();
    }
    let text = "[render]\nwidth = 4\nheight = 4\n[materials.m]\nalbedo = 0.5\n\
                [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n\
                [[lights]]\ntype = \"sky\"\nfile = \"sky.map\"\n";
    let file = match SceneFile::from_toml_str(text, Some(dir)) {
        Ok(file) => file,
        Err(e) if !e.to_string().contains("sky.map") => return Err(format!("the error does not name the file: {e}")),
        Err(_) => return Ok(false),
    };
    let integrator = IntegratorDesc::new(IntegratorKind::Path).build(&file.scene).map_err(|e| e.to_string())?;
    accumulate(&file.scene, integrator.as_ref(), 0..2, 0..4, &RenderObserver::default());
    Ok(true)
}

fn fuzz_environments(n: u64) {
    let dir = tempfile::tempdir().unwrap();
    let bases = environment_bases();
    fuzz("environment map", 0x5C1E, n, |seed| environment_input(seed, &bases, dir.path()));
}

#[test]
fn mutated_environment_maps_never_panic_and_errors_name_the_file() {
    fuzz_environments(count(2_000));
}
