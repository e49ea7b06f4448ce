//! A uniform sky: a diffuse ball under a sky of radiance L reflects a·L
//! everywhere (it is convex, so it sees nothing but sky: the closed form
//! of the white furnace), through every integrator that lights surfaces
//! and the path tracer with both of its strategies (sky samples and
//! escaping directions, weighed by multiple importance sampling); the sky
//! itself is seen where rays leave the scene.

use airlight::SceneFile;
use airlight::integrator::{IntegratorDesc, IntegratorKind};
use airlight::render::accumulate;

const SIDE: u32 = 16;

fn scene(material: &str) -> SceneFile {
    let text = format!(
        r#"
[render]
width = {SIDE}
height = {SIDE}
[camera]
position = [0, 0, -4]
look_at = [0, 0, 0]
fov = 40
[materials.ball]
{material}
[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "ball"
[[lights]]
type = "sky"
radiance = [1, 0.5, 0.25]
"#
    );
    SceneFile::from_toml_str(&text, None).unwrap_or_else(|e| panic!("{e}"))
}

/// The mean over the pixels well inside the ball's disk and the pixels in
/// the corners (sky), of channel 0 over channel c's sky radiance.
fn ball_and_sky(kind: IntegratorKind, file: &SceneFile, spp: u64) -> ([f64; 3], [f64; 3]) {
    let integrator = IntegratorDesc::new(kind).build(&file.scene).unwrap();
    let acc = accumulate(&file.scene, integrator.as_ref(), 0..spp, 0..SIDE, &Default::default());
    let (mut ball, mut sky, mut nb, mut ns) = ([0.0; 3], [0.0; 3], 0.0, 0.0);
    for y in 0..SIDE {
        for x in 0..SIDE {
            let (dx, dy) = (x as f64 + 0.5 - SIDE as f64 / 2.0, y as f64 + 0.5 - SIDE as f64 / 2.0);
            let r = (dx * dx + dy * dy).sqrt() / (SIDE as f64 / 2.0);
            let m = acc.pixel(x, y).unwrap().mean().as_dvec3();
            // The ball spans tan⁻¹(1/√15) ≈ 14.5° of the 20° half view: r < 0.72.
            if r < 0.6 {
                (0..3).for_each(|c| ball[c] += m[c]);
                nb += 1.0;
            } else if r > 0.9 {
                (0..3).for_each(|c| sky[c] += m[c]);
                ns += 1.0;
            }
        }
    }
    (ball.map(|b| b / nb), sky.map(|s| s / ns))
}

#[test]
fn a_diffuse_ball_under_a_uniform_sky_reflects_its_albedo_times_the_sky() {
    let sky = [1.0, 0.5, 0.25];
    let file = scene("albedo = 0.6");
    for (kind, spp, tolerance) in [(IntegratorKind::Direct, 256, 0.02), (IntegratorKind::Path, 256, 0.02)] {
        let (ball, seen) = ball_and_sky(kind, &file, spp);
        for c in 0..3 {
            assert!((seen[c] - sky[c]).abs() < 1e-6, "{kind:?}: the sky seen is {seen:?}");
            let ratio = ball[c] / sky[c];
            assert!((ratio - 0.6).abs() < tolerance, "{kind:?}: channel {c} reflects {ratio} of the sky, not 0.6");
        }
    }
}

#[test]
fn a_metal_ball_under_a_sky_reflects_at_most_the_sky() {
    // A white, smooth-ish metal: its albedo is close to one at every angle
    // (Schlick's F rises toward grazing), never above it.
    let file = scene("type = \"metallic_roughness\"\nbase_colour = 1\nmetallic = 1\nroughness = 0.3");
    let (ball, _) = ball_and_sky(IntegratorKind::Path, &file, 256);
    let ratio = ball[0];
    assert!(ratio > 0.9 && ratio < 1.01, "the white metal reflects {ratio} of the sky");
}

/// A glTF file opened alone with neither lights nor a camera: it is lit
/// by a sky and framed by a camera that looks at it, and both are said.
#[test]
fn a_model_alone_gets_a_sky_and_a_camera_and_says_so() {
    use base64::Engine;
    let mut data = Vec::new();
    for p in [[10.0f32, 20.0, 0.0], [12.0, 20.0, 0.0], [10.0, 22.0, 0.0]] {
        p.iter().for_each(|x| data.extend_from_slice(&x.to_le_bytes()));
    }
    let b64 = base64::engine::general_purpose::STANDARD.encode(&data);
    let json = format!(
        r#"{{ "asset": {{ "version": "2.0" }}, "scenes": [{{ "nodes": [0] }}], "nodes": [{{ "mesh": 0 }}],
  "meshes": [{{ "primitives": [{{ "attributes": {{ "POSITION": 0 }} }}] }}],
  "buffers": [{{ "byteLength": 36, "uri": "data:application/octet-stream;base64,{b64}" }}],
  "bufferViews": [{{ "buffer": 0, "byteLength": 36 }}],
  "accessors": [{{ "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [10, 20, 0], "max": [12, 22, 0] }}] }}"#
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("triangle.gltf");
    std::fs::write(&path, json).unwrap();
    let file = SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let notes = file.scene.notes().join("\n");
    assert!(notes.contains("the model has no lights: added a uniform sky of radiance 1"), "{notes}");
    assert!(notes.contains("the model has no camera: added one at"), "{notes}");
    assert!(matches!(file.scene.lights(), [airlight::light::Light::Sky { .. }]), "{:?}", file.scene.lights());
    // The camera looks at the centre of the triangle's bounds.
    let camera = file.scene.camera();
    let to_centre = (glam::Vec3::new(11.0, 21.0, 0.0) - camera.position).normalize();
    assert!(to_centre.dot(camera.forward) > 0.9999, "{camera:?}");
    // Seen, and lit: the image's centre shows the sky's light on the
    // triangle (glTF's default material, a rough white metal), not black.
    let integrator = IntegratorDesc::new(IntegratorKind::Path).build(&file.scene).unwrap();
    let (w, h) = (file.scene.settings().film.width, file.scene.settings().film.height);
    let acc = accumulate(&file.scene, integrator.as_ref(), 0..16, h / 2..h / 2 + 1, &Default::default());
    let centre = acc.pixel(w / 2 - w / 20, h / 2).unwrap().mean();
    assert!(centre.x > 0.2, "the triangle's centre is {centre}");
    // With a light or a camera of its own, a scene file that includes the
    // model adds neither.
    let text =
        "[[include]]\nfile = \"triangle.gltf\"\n[[lights]]\ntype = \"point\"\nposition = [0, 5, 5]\nintensity = 1\n";
    let included = SceneFile::from_toml_str(text, Some(dir.path())).unwrap();
    assert!(included.scene.notes().is_empty() && included.scene.lights().len() == 1);
}

/// An environment map (a Radiance HDR file): a diffuse ball facing the
/// camera reflects albedo/π × ∫ L(ω) cos⁺ dω, the integral taken here by
/// a fine quadrature over the sphere of the map's radiance (texel by
/// texel, as the map defines it), through direct and path alike.
#[test]
fn a_ball_under_an_environment_map_reflects_its_integral() {
    let (w, h) = (16usize, 8usize);
    // A dim sky and a bright patch just above the horizon toward −z (the
    // image's centre) and a little to +x, seen by the ball's front.
    let radiance = |i: usize, j: usize| -> [f32; 3] {
        if (8..10).contains(&i) && j == 3 { [30.0, 20.0, 10.0] } else { [0.3, 0.4, 0.5] }
    };
    let pixels: Vec<image::Rgb<f32>> = (0..w * h).map(|k| image::Rgb(radiance(k % w, k / w))).collect();
    let dir = tempfile::tempdir().unwrap();
    let file = std::fs::File::create(dir.path().join("sky.hdr")).unwrap();
    image::codecs::hdr::HdrEncoder::new(file).encode(&pixels, w, h).unwrap();
    // Radiance HDR stores shared-exponent values: read back what it holds.
    let stored = image::open(dir.path().join("sky.hdr")).unwrap().into_rgb32f();
    let texel = |i: usize, j: usize| glam::Vec3::from_array(stored.get_pixel(i as u32, j as u32).0);

    let text = r#"
[render]
width = 8
height = 8
[camera]
position = [0, 0, -4]
look_at = [0, 0, 0]
fov = 10
[materials.ball]
albedo = 0.5
[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "ball"
[[lights]]
type = "sky"
file = "sky.hdr"
radiance = 2
"#;
    let scene = SceneFile::from_toml_str(text, Some(dir.path())).unwrap_or_else(|e| panic!("{e}"));
    // The quadrature: the normal at the ball's front is −z.
    let n = glam::Vec3::NEG_Z;
    let (steps_t, steps_p) = (400, 800);
    let mut irradiance = glam::DVec3::ZERO;
    for a in 0..steps_t {
        let theta = std::f64::consts::PI * (a as f64 + 0.5) / steps_t as f64;
        for b in 0..steps_p {
            let phi = 2.0 * std::f64::consts::PI * ((b as f64 + 0.5) / steps_p as f64 - 0.5);
            let d = glam::DVec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos());
            let cos = d.dot(n.as_dvec3()).max(0.0);
            let (i, j) = (
                (((phi / (2.0 * std::f64::consts::PI)) + 0.5) * w as f64) as usize,
                (theta / std::f64::consts::PI * h as f64) as usize,
            );
            let d_omega =
                theta.sin() * (std::f64::consts::PI / steps_t as f64) * (2.0 * std::f64::consts::PI / steps_p as f64);
            irradiance += texel(i.min(w - 1), j.min(h - 1)).as_dvec3() * 2.0 * cos * d_omega;
        }
    }
    let expected = irradiance * 0.5 / std::f64::consts::PI;
    for kind in [IntegratorKind::Direct, IntegratorKind::Path] {
        let mut desc = IntegratorDesc::new(kind);
        desc.path.max_depth = 1;
        let integrator = desc.build(&scene.scene).unwrap();
        let acc = accumulate(&scene.scene, integrator.as_ref(), 0..2048, 3..5, &Default::default());
        let mut got = glam::DVec3::ZERO;
        for (x, y) in [(3, 3), (4, 3), (3, 4), (4, 4)] {
            got += acc.pixel(x, y).unwrap().mean().as_dvec3() / 4.0;
        }
        for c in 0..3 {
            assert!((got[c] / expected[c] - 1.0).abs() < 0.03, "{kind:?}: {got} against the quadrature's {expected}");
        }
    }
    // Seen directly, looking away from the ball along −z (the image's
    // centre column, at the horizon: texel (8, 4)): the map times its scale.
    use airlight::integrator::Integrator;
    let ray = airlight::geometry::Ray::new(glam::Vec3::new(0.0, 0.0, -4.0), glam::Vec3::NEG_Z);
    let seen =
        airlight::integrator::Direct.radiance(&scene.scene, &ray, &mut airlight::sampling::Sampler::for_pixel(0, 0, 0));
    assert_eq!(seen, texel(8, 4) * 2.0);
}
