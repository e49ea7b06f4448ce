//! A denial-of-service budget: inputs that ask for far more memory or work
//! than they are worth (a few kilobytes claiming gigabytes), each run by
//! the `airlight` binary under a memory limit. Each must be refused with
//! its reason, its measured peak memory (the child's maximum resident set,
//! from `wait4`) must stay under the limit it was given, and it must end
//! promptly. The times measured on an idle machine are in BENCHMARKS.md
//! ("A denial-of-service budget"); here only a hang is a failure.

use airlight::film::Tonemap;
use airlight::film::partial::{Partial, PartialHeader};
use airlight::prelude::*;
use airlight::render::accumulate;
use base64::Engine;
use std::io::Read;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Longer than this is a hang, not a refusal.
const HANG: Duration = Duration::from_secs(30);

/// One hostile input: its files, the command that reads them, the memory
/// limit it runs under, and a phrase of the refusal.
struct Case {
    name: &'static str,
    args: Vec<String>,
    limit_mib: u64,
    refusal: &'static str,
}

/// Runs `case` in `dir`: its exit, stderr, peak memory (bytes) and time.
// The child is reaped by wait4, which gives its resource usage.
#[allow(clippy::zombie_processes)]
fn run(dir: &Path, case: &Case) -> (Option<i32>, String, u64, Duration) {
    let start = Instant::now();
    let mut command = Command::new(env!("CARGO_BIN_EXE_airlight"));
    command
        .current_dir(dir)
        .args(&case.args)
        .env("AIRLIGHT_MEMORY_LIMIT", format!("{}M", case.limit_mib))
        .env_remove("AIRLIGHT_ASSET_PATH")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .process_group(0);
    // A child made by vfork (posix_spawn) would start its peak memory at
    // this process's own; a forked copy starts it at this process's memory
    // at the fork (a few MiB), which a hook before exec forces.
    // SAFETY: the hook does nothing, so it is async-signal-safe.
    unsafe { command.pre_exec(|| Ok(())) };
    let mut child = command.spawn().unwrap();
    let pid = child.id() as libc::pid_t;
    // A watchdog: a hang is killed (and then fails the case below).
    let watchdog = std::thread::spawn(move || {
        std::thread::sleep(HANG);
        // SAFETY: kill(2) on the child's own process group.
        unsafe { libc::kill(-pid, libc::SIGKILL) };
    });
    let mut status = 0;
    // SAFETY: an all-zero rusage is a valid value for wait4 to fill.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: wait4 on our own child, with valid pointers.
    let reaped = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(reaped, pid, "wait4");
    let took = start.elapsed();
    drop(watchdog);
    let mut stderr = String::new();
    child.stderr.take().unwrap().read_to_string(&mut stderr).unwrap();
    let code = libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status));
    // ru_maxrss is in kilobytes on Linux.
    (code, stderr, usage.ru_maxrss as u64 * 1024, took)
}

/// A GLB of `json` and `bin`.
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut text = json.as_bytes().to_vec();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((12 + 8 + text.len() as u32 + 8 + bin.len() as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(text);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// A glTF document of one mesh (a triangle's 3 vertices indexed `faces`
/// times) in a data URI buffer, placed by `nodes` and `scene_nodes`.
fn gltf_of_mesh(faces: usize, nodes: &str, scene_nodes: &str) -> String {
    let mut data: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.].iter().flat_map(|v| v.to_le_bytes()).collect();
    let positions = data.len();
    data.extend((0..faces * 3).flat_map(|i| ((i % 3) as u16).to_le_bytes()));
    let uri = base64::engine::general_purpose::STANDARD.encode(&data);
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{scene_nodes}}}],"nodes":{nodes},
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5123,"count":{n},"type":"SCALAR"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{positions}}},{{"buffer":0,"byteOffset":{positions},"byteLength":{ib}}}],
"buffers":[{{"byteLength":{len},"uri":"data:application/octet-stream;base64,{uri}"}}]}}"#,
        n = faces * 3,
        ib = faces * 6,
        len = data.len()
    )
}

/// The hostile inputs, written into `dir`.
fn cases(dir: &Path) -> Vec<Case> {
    let write = |name: &str, bytes: &[u8]| std::fs::write(dir.join(name), bytes).unwrap();
    let words = |args: &[&str]| args.iter().map(|a| a.to_string()).collect::<Vec<_>>();
    let mut cases = Vec::new();

    // 200 buffers without a uri, each the GLB's 4 MiB binary chunk again.
    let buffers: Vec<String> = (0..200).map(|_| r#"{"byteLength":4194304}"#.to_string()).collect();
    let json = format!(r#"{{"asset":{{"version":"2.0"}},"buffers":[{}]}}"#, buffers.join(","));
    write("copies.glb", &glb(&json, &vec![0; 4 << 20]));
    cases.push(Case {
        name: "glTF: 200 buffers that are the binary chunk",
        args: words(&["info", "copies.glb"]),
        limit_mib: 64,
        refusal: "only buffers[0] may be the GLB's BIN chunk",
    });

    // One mesh of 2,000 triangles placed by 20,000 nodes.
    let nodes: Vec<String> = (0..20_000).map(|_| r#"{"mesh":0}"#.to_string()).collect();
    let list: Vec<String> = (0..20_000).map(|i| i.to_string()).collect();
    write(
        "instances.gltf",
        gltf_of_mesh(2000, &format!("[{}]", nodes.join(",")), &format!("[{}]", list.join(","))).as_bytes(),
    );
    cases.push(Case {
        name: "glTF: one mesh placed by 20,000 nodes",
        args: words(&["info", "instances.gltf"]),
        limit_mib: 64,
        refusal: "40000000 triangles placed by this glTF",
    });

    // Node k's children are [k + 1, k + 1], 30 levels: 2³⁰ placements.
    let nodes: Vec<String> =
        (0..30).map(|k| format!(r#"{{"children":[{},{}]}}"#, k + 1, k + 1)).chain([r#"{"mesh":0}"#.into()]).collect();
    write("doubling.gltf", gltf_of_mesh(1, &format!("[{}]", nodes.join(",")), "[0]").as_bytes());
    cases.push(Case {
        name: "glTF: 2³⁰ placements from 31 nodes",
        args: words(&["info", "doubling.gltf"]),
        limit_mib: 64,
        refusal: "nodes",
    });

    // A partial render whose header claims 4096² pixels, and its sound
    // other half.
    let header = |samples: std::ops::Range<u64>| PartialHeader {
        version: env!("CARGO_PKG_VERSION").into(),
        scene: "0123456789abcdef".into(),
        seed: 0,
        width: 4,
        height: 4,
        spp: 2,
        samples,
        rows: 0..4,
        frame: None,
        exposure: 0.0,
        tonemap: Tonemap::Clamp,
    };
    let scene = SceneBuilder::new()
        .size(4, 4)
        .with_settings(|s| s.spp = 2)
        .material("grey", Material::diffuse(Rgb::splat(0.5)))
        .object(Shape::sphere(vec3(0.0, 1.0, 0.0), 0.5), "grey")
        .light(Light::point(vec3(1.0, 3.0, -2.0), Rgb::splat(8.0)))
        .build()
        .unwrap();
    let integrator = IntegratorDesc::new(IntegratorKind::Direct).build(&scene).unwrap();
    for (k, samples) in [(0, 0..1), (1, 1..2)] {
        let sums = accumulate(&scene, integrator.as_ref(), samples.clone(), 0..4, &RenderObserver::none());
        Partial { header: header(samples), sums }.write(&dir.join(format!("q{k}.exr"))).unwrap();
    }
    // Its fields' text attribute rewritten to claim 4096² (the pixels, and
    // the offsets that the longer header shifts, left as they are).
    let bytes = std::fs::read(dir.join("q1.exr")).unwrap();
    let key = b"airlight.partial\0string\0";
    let at = bytes.windows(key.len()).position(|w| w == key).expect("the fields attribute") + key.len();
    let size = i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let fields = String::from_utf8(bytes[at + 4..at + 4 + size].to_vec()).unwrap();
    let claimed = fields.replace("width=4\n", "width=4096\n").replace("height=4\n", "height=4096\n");
    let claimed = claimed.replace("rows=0..4\n", "rows=0..4096\n");
    assert_ne!(claimed, fields);
    let mut bytes_out = bytes[..at].to_vec();
    bytes_out.extend((claimed.len() as i32).to_le_bytes());
    bytes_out.extend(claimed.as_bytes());
    bytes_out.extend(&bytes[at + 4 + size..]);
    let bytes = bytes_out;
    write("q1.exr", &bytes);
    cases.push(Case {
        name: "merge: a part whose header claims 4096²",
        args: words(&["merge", "q0.exr", "q1.exr", "-o", "merged.exr"]),
        limit_mib: 64,
        refusal: "q1.exr",
    });

    // A 2048² 16-bit PNG (a few kilobytes) that decodes to 32 MiB.
    image::ImageBuffer::<image::Rgba<u16>, Vec<u16>>::new(2048, 2048).save(dir.join("big.png")).unwrap();
    write(
        "texture.toml",
        b"[materials.t]\ntype = \"texture\"\nfile = \"big.png\"\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"t\"\n",
    );
    cases.push(Case {
        name: "texture: a 2048² 16-bit PNG under 24 MiB",
        args: words(&["info", "texture.toml"]),
        limit_mib: 24,
        refusal: "decoding a 2048×2048 texture needs about",
    });

    // 100,000 identical faces (a BVH over them would be quadratic).
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\n".to_string() + &"f 1 2 3\n".repeat(100_000);
    write("same.obj", obj.as_bytes());
    write("same.toml", b"[materials.m]\n[[objects]]\ntype = \"mesh\"\nfile = \"same.obj\"\nmaterial = \"m\"\n");
    cases.push(Case {
        name: "OBJ: 100,000 identical faces",
        args: words(&["info", "same.toml"]),
        limit_mib: 256,
        refusal: "the same bounds",
    });

    // A render of the largest image, in passes.
    write(
        "small.toml",
        b"[materials.m]\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n",
    );
    cases.push(Case {
        name: "render: 16384² in passes",
        args: words(&["render", "small.toml", "--width", "16384", "--height", "16384", "--progressive", "-q"]),
        limit_mib: 1024,
        refusal: "a 16384×16384 render needs about",
    });

    // Fog no image can show through, which tracking would cross in 1e10
    // steps a path.
    write(
        "thick.toml",
        b"[medium]\ntype = \"noise\"\nsigma_s = 1e10\n[materials.m]\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n",
    );
    cases.push(Case {
        name: "medium: noise fog of sigma_s = 1e10",
        args: words(&["info", "thick.toml"]),
        limit_mib: 64,
        refusal: "mean free paths across the scene",
    });
    cases
}

#[test]
fn hostile_inputs_are_refused_within_their_memory_limit() {
    let dir = tempfile::tempdir().unwrap();
    let cases = cases(dir.path());
    let mut failures = Vec::new();
    eprintln!("{:<46} {:>9} {:>9} {:>8}", "input", "limit", "peak", "time");
    for case in &cases {
        let (code, stderr, peak, took) = run(dir.path(), case);
        let limit = case.limit_mib << 20;
        eprintln!(
            "{:<46} {:>5} MiB {:>5.1} MiB {:>6.3} s",
            case.name,
            case.limit_mib,
            peak as f64 / (1u64 << 20) as f64,
            took.as_secs_f64()
        );
        if code != Some(1) || !stderr.contains(case.refusal) || stderr.contains("panicked") {
            failures
                .push(format!("{}: exit {code:?}, expected a refusal with `{}`: {stderr}", case.name, case.refusal));
        }
        if peak >= limit {
            failures.push(format!("{}: peak {peak} bytes, over its limit of {limit}", case.name));
        }
        if took >= HANG {
            failures.push(format!("{}: still running after {HANG:?}", case.name));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
