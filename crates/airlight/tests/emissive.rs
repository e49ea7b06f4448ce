//! Emitting objects: a mesh with `emission` becomes one triangle light per
//! triangle. A square of four emitting triangles of unequal areas must
//! light a room as the quad light of the same radiance does, in every
//! integrator that takes area lights (those that sample the mesh as one
//! emitter, a triangle drawn by area, and those that visit each triangle),
//! and look the same to the camera.

use airlight::SceneFile;
use airlight::film::Accumulator;
use airlight::integrator::{IntegratorDesc, IntegratorKind};
use airlight::light::Light;
use airlight::render::accumulate;

const SIZE: u32 = 12;

/// A floor, a back wall and a ball under a 1×1 light at height 1.5 facing
/// down (`LIGHT` is put in place of the light), in fog when `fog`.
fn scene_text(light: &str, fog: bool) -> String {
    let medium = if fog { "[medium]\nsigma_s = [0.15, 0.15, 0.15]\nsigma_a = [0.05, 0.05, 0.05]\n" } else { "" };
    format!(
        r#"
[render]
width = {SIZE}
height = {SIZE}
[camera]
position = [0.3, 1.0, -3.0]
look_at = [0.0, 0.6, 0.0]
fov = 60
{medium}
[materials.white]
albedo = [0.7, 0.7, 0.7]
[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "white"
[[objects]]
type = "quad"
corner = [-2, 0, 1.5]
edge_u = [4, 0, 0]
edge_v = [0, 3, 0]
material = "white"
[[objects]]
type = "sphere"
center = [0.4, 0.3, 0.2]
radius = 0.3
material = "white"
{light}
"#
    )
}

const QUAD_LIGHT: &str = r#"
[[lights]]
type = "quad"
corner = [-0.5, 1.5, -0.5]
edge_u = [1, 0, 0]
edge_v = [0, 0, 1]
radiance = [6, 5, 4]
"#;

const MESH_LIGHT: &str = r#"
[[objects]]
type = "mesh"
file = "square.obj"
emission = [6, 5, 4]
"#;

/// The same square as a fan of four triangles from one corner, of areas
/// 0.15, 0.35, 0.2 and 0.3, wound to face down (OBJ's counter-clockwise
/// front).
const SQUARE_OBJ: &str = "v -0.5 1.5 -0.5\nv 0.5 1.5 -0.5\nv 0.5 1.5 -0.2\nv 0.5 1.5 0.5\nv 0.1 1.5 0.5\nv -0.5 1.5 0.5\n\
                          f 1 2 3\nf 1 3 4\nf 1 4 5\nf 1 5 6\n";

fn load(text: &str) -> SceneFile {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("square.obj"), SQUARE_OBJ).unwrap();
    SceneFile::from_toml_str(text, Some(dir.path())).unwrap()
}

fn render(text: &str, kind: IntegratorKind, spp: u64) -> Accumulator {
    let file = load(text);
    let mut desc = IntegratorDesc::new(kind);
    desc.path.max_depth = 3;
    desc.raymarch.steps = 128;
    desc.analytic.shadows = true;
    let integrator = desc.build(&file.scene).unwrap();
    accumulate(&file.scene, integrator.as_ref(), 0..spp, 0..SIZE, &Default::default())
}

/// Mean and variance of the mean over a block of pixels (channels averaged).
fn block(acc: &Accumulator, xs: std::ops::Range<u32>, ys: std::ops::Range<u32>) -> (f64, f64) {
    let (mut mean, mut var, mut n) = (0.0, 0.0, 0.0);
    for y in ys {
        for x in xs.clone() {
            let p = acc.pixel(x, y).unwrap();
            mean += p.mean().as_dvec3().element_sum() / 3.0;
            let v = p.variance_of_mean().element_sum() / 9.0;
            assert!(v.is_finite(), "pixel {x},{y}: no variance estimate");
            var += v;
            n += 1.0;
        }
    }
    (mean / n, var / (n * n))
}

/// Whether the image and its four quarters agree within 5 standard errors
/// plus `tolerance` of the larger value.
fn assert_agree(what: &str, a: &Accumulator, b: &Accumulator, tolerance: f64) {
    let h = SIZE / 2;
    for (xs, ys) in [(0..SIZE, 0..SIZE), (0..h, 0..h), (h..SIZE, 0..h), (0..h, h..SIZE), (h..SIZE, h..SIZE)] {
        let ((ma, va), (mb, vb)) = (block(a, xs.clone(), ys.clone()), block(b, xs.clone(), ys.clone()));
        let allowed = 5.0 * (va + vb).sqrt() + tolerance * ma.max(mb);
        assert!((ma - mb).abs() <= allowed, "{what}, pixels {xs:?}×{ys:?}: quad {ma} mesh {mb}, allowed ±{allowed}");
    }
    assert!(block(a, 0..SIZE, 0..SIZE).0 > 0.01, "{what}: the room is dark");
}

#[test]
fn an_emitting_mesh_becomes_one_triangle_light_per_triangle() {
    let file = load(&scene_text(MESH_LIGHT, false));
    let lights = file.scene.lights();
    assert_eq!(lights.len(), 4);
    let areas: Vec<f32> = lights
        .iter()
        .map(|light| match *light {
            Light::Triangle { edge_1, edge_2, .. } => 0.5 * edge_1.cross(edge_2).length(),
            _ => 0.0,
        })
        .collect();
    for (area, want) in areas.iter().zip([0.15, 0.35, 0.2, 0.3]) {
        assert!((area - want).abs() < 1e-6, "{areas:?}");
    }
    for light in lights {
        let Light::Triangle { edge_1, edge_2, radiance, .. } = *light else { panic!("not a triangle: {light:?}") };
        assert!(edge_1.cross(edge_2).y < 0.0, "faces down as the file winds it");
        assert_eq!(radiance.to_array(), [6.0, 5.0, 4.0]);
    }
}

#[test]
fn a_square_of_emitting_triangles_lights_a_room_as_its_quad_light() {
    for kind in [IntegratorKind::Path, IntegratorKind::Direct, IntegratorKind::Radiosity] {
        let spp = if kind == IntegratorKind::Radiosity { 4 } else { 256 };
        let quad = render(&scene_text(QUAD_LIGHT, false), kind, spp);
        let mesh = render(&scene_text(MESH_LIGHT, false), kind, spp);
        // Radiosity's patches see the two lights through the same
        // quadrature; 1% for its deterministic differences.
        assert_agree(&format!("{kind:?}"), &quad, &mesh, 0.01);
    }
}

#[test]
fn a_square_of_emitting_triangles_lights_fog_as_its_quad_light() {
    for kind in [IntegratorKind::Raymarch, IntegratorKind::Analytic, IntegratorKind::Stochastic, IntegratorKind::Path] {
        // The analytic integrator is deterministic: two samples tell (and
        // give a variance, zero).
        let spp = if kind == IntegratorKind::Analytic { 2 } else { 64 };
        let quad = render(&scene_text(QUAD_LIGHT, true), kind, spp);
        let mesh = render(&scene_text(MESH_LIGHT, true), kind, spp);
        // The analytic integrator sums Gauss points over each light: a
        // square's and four triangles' points differ; 1% for that.
        assert_agree(&format!("{kind:?} in fog"), &quad, &mesh, 0.01);
    }
}

#[test]
fn emission_is_checked() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("square.obj"), SQUARE_OBJ).unwrap();
    let error = |object: &str| {
        let text = format!("[materials.m]\n[[objects]]\n{object}\n");
        SceneFile::from_toml_str(&text, Some(dir.path())).unwrap_err().to_string()
    };
    let e = error("type = \"box\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\nemission = [1, 1, 1]");
    assert!(e.contains("only sphere, quad and mesh objects can emit"), "{e}");
    let e = error("type = \"mesh\"\nfile = \"square.obj\"\nemission = [1, -1, 1]");
    assert!(e.contains("emission must be finite and ≥ 0"), "{e}");
    let e = error("type = \"mesh\"\nfile = \"square.obj\"\nemission = [1, 1, 1]\nmaterial = \"m\"");
    assert!(e.contains("drop its `material`"), "{e}");
}

/// A room of one OBJ file whose `.mtl` colours the walls (`Kd`) and makes
/// the ceiling lamp emit (`Ke`), against the same room written out in the
/// scene file.
#[test]
fn obj_materials_colour_faces_and_make_lamps() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("room")).unwrap();
    std::fs::write(
        dir.path().join("room/room.obj"),
        "mtllib room.mtl\n\
         v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\n\
         v -0.5 1.5 -0.5\nv 0.5 1.5 -0.5\nv 0.5 1.5 0.5\nv -0.5 1.5 0.5\n\
         usemtl red floor\nf 1 4 3 2\n\
         usemtl lamp\nf 5 6 7\nf 5 7 8\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("room/room.mtl"),
        "newmtl red floor\nKd 0.6 0.2 0.1\nnewmtl lamp\nKd 0 0 0\nKe 6 5 4\n",
    )
    .unwrap();
    let common =
        "[render]\nwidth = 12\nheight = 12\n[camera]\nposition = [0.3, 1.0, -3.0]\nlook_at = [0.0, 0.3, 0.0]\n";
    let from_obj = format!("{common}[[objects]]\ntype = \"mesh\"\nfile = \"room/room.obj\"\n");
    let by_hand = format!(
        "{common}[materials.red]\nalbedo = [0.6, 0.2, 0.1]\n[[objects]]\ntype = \"quad\"\ncorner = [-2, 0, -2]\n\
         edge_u = [0, 0, 4]\nedge_v = [4, 0, 0]\nmaterial = \"red\"\n{QUAD_LIGHT}"
    );
    let render = |text: &str| {
        let file = SceneFile::from_toml_str(text, Some(dir.path())).unwrap();
        let mut desc = IntegratorDesc::new(IntegratorKind::Path);
        desc.path.max_depth = 3;
        let integrator = desc.build(&file.scene).unwrap();
        (file.scene.lights().len(), accumulate(&file.scene, integrator.as_ref(), 0..256, 0..SIZE, &Default::default()))
    };
    let ((obj_lights, obj), (_, hand)) = (render(&from_obj), render(&by_hand));
    assert_eq!(obj_lights, 2, "the lamp's two triangles");
    assert_agree("path, OBJ room", &hand, &obj, 0.01);
    // The floor is red: more red than blue comes back.
    let mean = (0..SIZE)
        .flat_map(|y| (0..SIZE).map(move |x| (x, y)))
        .fold(glam::DVec3::ZERO, |s, (x, y)| s + obj.pixel(x, y).unwrap().mean().as_dvec3());
    assert!(mean.x > 2.0 * mean.z, "{mean}");

    // A usemtl that its libraries do not define is reported at its line.
    std::fs::write(dir.path().join("room/room.mtl"), "newmtl lamp\nKe 1 1 1\n").unwrap();
    let e = SceneFile::from_toml_str(&from_obj, Some(dir.path())).unwrap_err().to_string();
    assert!(
        e.contains("room/room.obj:10: usemtl `red floor`: no such material in its libraries (they define `lamp`)"),
        "{e}"
    );
    // A library outside the scene's folders is not opened.
    std::fs::write(dir.path().join("room/room.obj"), "mtllib ../../x.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
        .unwrap();
    let e = SceneFile::from_toml_str(&from_obj, Some(dir.path())).unwrap_err().to_string();
    assert!(e.contains("room/room.obj:1: `room/../../x.mtl` must be a relative path inside"), "{e}");
}
