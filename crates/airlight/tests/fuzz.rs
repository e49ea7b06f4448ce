//! Structure-aware fuzzing of what Airlight reads: scene files (the
//! example scenes mutated as TOML trees and as text), OBJ meshes through a
//! scene, and EXR images as `airlight compare` reads them. Each input runs
//! under `catch_unwind`: any panic fails the test with the seed that
//! replays it (`AIRLIGHT_FUZZ_SEED=… cargo test -p airlight --test fuzz`),
//! and so does an error that does not name its file (and, for text, its
//! line). Scenes that load are rendered at 3×2 pixels, 1 sample, so that
//! what validation lets through is run too.
//!
//! The normal run tries 10,000 scenes and 10,000 EXR files; the ignored
//! tests a million of each (`cargo test --release -p airlight --test fuzz
//! -- --ignored`). `AIRLIGHT_FUZZ_INPUTS` sets the count.

#[path = "fuzz/mutate.rs"]
mod mutate;
#[path = "fuzz/run.rs"]
mod run;

use airlight::film::{self, Image};
use airlight::integrator::IntegratorKind;
use airlight::{RenderObserver, Rgb, SceneFile};
use mutate::{Rng, mutate_bytes, mutate_obj, mutate_text, mutate_tree};
use run::{count, fuzz};
use std::path::Path;

/// Names the declarations do not give: the tables, a keyframe's `time`,
/// the mesh file's name.
const OTHER_NAMES: &[&str] =
    &["render", "camera", "medium", "materials", "objects", "lights", "include", "time", "mesh.obj"];

/// Every key and value name the mutations use, as declared: the `[render]`
/// keys and integrator names, every typed table's tag, types and keys,
/// then [`OTHER_NAMES`].
fn names() -> Vec<&'static str> {
    airlight::SceneFile::render_keys()
        .chain(airlight::integrator::IntegratorKind::NAMES)
        .chain(airlight::SceneFile::table_words())
        .chain(OTHER_NAMES.iter().copied())
        .collect()
}

/// A scene with a mesh, and the mesh: a cube of quads, with the
/// statements an OBJ exporter writes that Airlight skips.
const MESH_SCENE: &str = r#"
[render]
width = 8
height = 6
integrator = "direct"
[camera]
position = [3, 2, -4]
look_at = [0, 0, 0]
[materials.m]
albedo = 0.7
[[objects]]
type = "mesh"
file = "mesh.obj"
material = "m"
rotate = [0, 30, 0]
[[lights]]
type = "point"
position = [2, 4, -2]
intensity = 20
"#;

const CUBE_OBJ: &str = "# cube\nmtllib cube.mtl\no cube\nv -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\n\
v 1 -1 1\nv 1 1 1\nv -1 1 1\nvt 0 0\nvn 0 0 -1\nusemtl grey\ns off\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf 5 8 7 6\n\
f 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf -8 -4 -1 -5\n";

fn base_scenes() -> Vec<toml::Table> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    names.sort();
    let mut scenes: Vec<toml::Table> =
        names.iter().map(|p| toml::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()).collect();
    // The mesh scene counts thrice: OBJ files are fuzzed through it.
    for _ in 0..3 {
        scenes.push(toml::from_str(MESH_SCENE).unwrap());
    }
    scenes
}

/// Loads (and, when it loads, renders) one mutated scene.
fn scene_input(seed: u64, bases: &[toml::Table], dir: &Path) -> Result<bool, String> {
    let mut rng = Rng(seed);
    let mut doc = rng.pick(bases).clone();
    let has_mesh = toml::to_string(&doc).is_ok_and(|t| t.contains("mesh.obj"));
    if !has_mesh || rng.chance(3) {
        mutate_tree(&mut rng, &mut doc, &names(), 3);
    }
    let text = toml::to_string(&doc).map_err(|e| format!("the mutator wrote no TOML: {e}"))?;
    let bytes = if rng.chance(4) { mutate_text(&mut rng, &text) } else { text.into_bytes() };
    let scene_path = dir.join("scene.toml");
    std::fs::write(&scene_path, &bytes).unwrap();
    let obj = if has_mesh && !rng.chance(4) { mutate_obj(&mut rng, CUBE_OBJ) } else { CUBE_OBJ.as_bytes().to_vec() };
    std::fs::write(dir.join("mesh.obj"), &obj).unwrap();
    if std::env::var_os("AIRLIGHT_FUZZ_SEED").is_some() {
        eprintln!("scene.toml:\n{}\nmesh.obj:\n{}", String::from_utf8_lossy(&bytes), String::from_utf8_lossy(&obj));
    }
    match SceneFile::load(&scene_path) {
        Ok(SceneFile { mut scene, integrator }) => {
            let s = scene.settings_mut();
            (s.film.width, s.film.height, s.spp) = (3, 2, 1);
            // Radiosity compiles its whole solution first: too slow here.
            if integrator.kind != IntegratorKind::Radiosity
                && let Ok(built) = integrator.build(&scene)
            {
                airlight::render(&scene, built.as_ref(), &RenderObserver::none());
            }
            Ok(true)
        }
        Err(e) => {
            if e.file.as_deref() != Some(scene_path.as_path()) {
                return Err(format!("error without its file: {e}"));
            }
            // An OBJ's errors name the mesh file and its line (or the file
            // as a whole: no faces, too big), at the scene's `file` line.
            let located = e.location.is_some();
            if !located {
                return Err(format!("error without a line: {e}"));
            }
            if e.message.contains("cannot load mesh ") && e.message.contains("mesh.obj:") {
                let after = e.message.split("mesh.obj:").nth(1).unwrap_or_default();
                if after.split(':').next().is_none_or(|n| n.parse::<usize>().is_err()) {
                    return Err(format!("an OBJ error without its line: {e}"));
                }
            }
            Ok(false)
        }
    }
}

fn fuzz_scenes(n: u64) {
    let bases = base_scenes();
    let dir = tempfile::tempdir().unwrap();
    fuzz("scene", 0x5CE7E, n, |seed| scene_input(seed, &bases, dir.path()));
}

#[test]
fn mutated_scenes_and_meshes_never_panic_and_errors_name_file_and_line() {
    fuzz_scenes(count(10_000));
}

#[test]
#[ignore = "a million inputs: run by hand (docs/developing.md, BENCHMARKS.md)"]
fn a_million_mutated_scenes() {
    fuzz_scenes(count(1_000_000));
}

/// Small EXR files in the encodings a reader meets: Airlight's own (ZIP16
/// scan lines), and through the exr crate uncompressed, RLE, PIZ, tiles,
/// half floats, with alpha.
fn base_exrs() -> Vec<Vec<u8>> {
    use exr::prelude::{
        Blocks, Compression, Encoding, Layer, LayerAttributes, LineOrder, SpecificChannels, Vec2, WritableImage, f16,
    };
    let dir = tempfile::tempdir().unwrap();
    let mut image = Image::new(7, 5);
    for (i, p) in image.pixels.iter_mut().enumerate() {
        *p = Rgb::new(i as f32 * 0.1, 1.0 / (1.0 + i as f32), 0.5);
    }
    image.save(dir.path().join("a.exr")).unwrap();
    let mut out = vec![std::fs::read(dir.path().join("a.exr")).unwrap()];
    let blocks = [Blocks::ScanLines, Blocks::Tiles(Vec2(4, 4))];
    let compressions = [Compression::Uncompressed, Compression::RLE, Compression::PIZ, Compression::ZIP1];
    for (k, compression) in compressions.into_iter().enumerate() {
        let encoding = Encoding { compression, blocks: blocks[k % 2], line_order: LineOrder::Increasing };
        let pixel = |pos: Vec2<usize>| image.pixels[pos.y() * 7 + pos.x()];
        let mut bytes = std::io::Cursor::new(Vec::new());
        if k % 2 == 0 {
            let channels = SpecificChannels::rgb(|pos: Vec2<usize>| {
                let p = pixel(pos);
                (f16::from_f32(p.x), f16::from_f32(p.y), f16::from_f32(p.z))
            });
            let layer = Layer::new((7, 5), LayerAttributes::default(), encoding, channels);
            exr::prelude::Image::from_layer(layer).write().to_buffered(&mut bytes).unwrap();
        } else {
            let channels = SpecificChannels::rgba(|pos: Vec2<usize>| {
                let p = pixel(pos);
                (p.x, p.y, p.z, 1.0f32)
            });
            let layer = Layer::new((7, 5), LayerAttributes::default(), encoding, channels);
            exr::prelude::Image::from_layer(layer).write().to_buffered(&mut bytes).unwrap();
        }
        out.push(bytes.into_inner());
    }
    out
}

/// Offsets of the header's size fields (the windows' corners), which a
/// mutation should hit often.
fn size_fields(bytes: &[u8]) -> Vec<usize> {
    let mut fields = Vec::new();
    for name in [&b"dataWindow\0box2i\0"[..], b"displayWindow\0box2i\0"] {
        if let Some(at) = bytes.windows(name.len()).position(|w| w == name) {
            let values = at + name.len() + 4;
            fields.extend((0..4).map(|k| values + 4 * k));
        }
    }
    fields
}

fn exr_input(seed: u64, bases: &[Vec<u8>], dir: &Path) -> Result<bool, String> {
    let mut rng = Rng(seed);
    let mut bytes = rng.pick(bases).clone();
    let fields = size_fields(&bytes);
    mutate_bytes(&mut rng, &mut bytes, &fields);
    let path = dir.join("mutated.exr");
    if std::env::var_os("AIRLIGHT_FUZZ_SEED").is_some() {
        std::fs::write("/tmp/airlight-fuzz-replay.exr", &bytes).unwrap();
    }
    std::fs::write(&path, &bytes).unwrap();
    match Image::read_exr(&path) {
        Ok(image) => {
            // What `compare` does with it: measures against itself and
            // against the original, a map, the means.
            let reference = Image::read_exr(&dir.join("base.exr")).map_err(|e| e.to_string())?;
            if let Some(e) = film::compare(&image, &image) {
                film::error_map(&image, &image, e.max as f32);
            }
            film::compare(&image, &reference);
            image.mean();
            Ok(true)
        }
        Err(e) if e.to_string().contains(&path.display().to_string()) => Ok(false),
        Err(e) => Err(format!("error without its file: {e}")),
    }
}

fn fuzz_exrs(n: u64) {
    let bases = base_exrs();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("base.exr"), &bases[0]).unwrap();
    fuzz("EXR", 0xE8E, n, |seed| exr_input(seed, &bases, dir.path()));
}

#[test]
fn mutated_exr_files_never_panic_and_errors_name_the_file() {
    fuzz_exrs(count(10_000));
}

#[test]
#[ignore = "a million inputs: run by hand (docs/developing.md, BENCHMARKS.md)"]
fn a_million_mutated_exr_files() {
    fuzz_exrs(count(1_000_000));
}
