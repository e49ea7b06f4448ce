//! The hostile-input cases for the library: values whose f32 arithmetic would
//! overflow or vanish, files a scene may not read, sizes that do not fit.
//! Each is refused with a message that names the real limit, or renders
//! right; none panics.

use airlight::assets::AssetPath;
use airlight::film::Image;
use airlight::prelude::*;
use std::path::Path;

const TAIL: &str = "[materials.m]\nalbedo = 0.5\n";

fn load(text: &str) -> Result<SceneFile, String> {
    SceneFile::from_toml_str(text, None).map_err(|e| e.to_string())
}

fn image(text: &str) -> Image {
    let SceneFile { scene, integrator } = load(text).unwrap();
    let integrator = integrator.build(&scene).unwrap();
    airlight::render(&scene, integrator.as_ref(), &RenderObserver::none())
}

fn lit_floor(normal: &str, sun: &str, spot: &str) -> String {
    format!(
        "[render]\nwidth = 12\nheight = 8\nspp = 1\n[camera]\nposition = [0, 2, -4]\nlook_at = [0, 0, 0]\n{TAIL}\
         [[objects]]\ntype = \"plane\"\npoint = [0, 0, 0]\nnormal = {normal}\nmaterial = \"m\"\n\
         [[lights]]\ntype = \"distant\"\ndirection = {sun}\nirradiance = 1\n\
         [[lights]]\ntype = \"spot\"\nposition = [0, 3, 0]\ndirection = {spot}\nintensity = 10\n"
    )
}

#[test]
fn directions_too_long_or_short_for_f32_squares_render_as_unit_ones() {
    let unit = image(&lit_floor("[0, 1, 0]", "[0, -1, 0]", "[0, -1, 0]"));
    assert!(unit.mean().x > 0.1);
    for (normal, sun, spot) in
        [("[0, 1e20, 0]", "[0, -1e20, 0]", "[0, -1e30, 0]"), ("[0, 1e-30, 0]", "[0, -1e-40, 0]", "[0, -1e-45, 0]")]
    {
        assert_eq!(image(&lit_floor(normal, sun, spot)), unit, "{normal} {sun} {spot}");
    }
}

#[test]
fn what_lies_too_far_for_f32_is_refused_with_the_limit() {
    let cases = [
        (
            "[camera]\nposition = [0, 0, 1e30]\nlook_at = [0, 0, 0]\n",
            "line 2, column 12: camera.position reaches 1e30 world units",
        ),
        (
            "[[objects]]\ntype = \"quad\"\ncorner = [0, 0, 0]\nedge_u = [1e19, 0, 0]\nedge_v = [0, 0, 1e19]\nmaterial = \"m\"\n",
            "objects[0] (quad).edge_u or edge_v reaches 1e19 world units",
        ),
        (
            "[[lights]]\ntype = \"quad\"\ncorner = [0, 3, 0]\nedge_u = [1e19, 0, 0]\nedge_v = [0, 0, 1]\nradiance = 1\n",
            "lights[0] (quad).edge_u or edge_v reaches 1e19",
        ),
        (
            "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nscale = 1e10\nmaterial = \"m\"\n",
            "objects[0] (sphere) reaches 1e10 world units",
        ),
        (
            "[[lights]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = 1\nkeyframes = [{ time = 0, position = [2e9, 0, 0] }]\n",
            "lights[0].keyframes[0] reaches 2e9",
        ),
        (
            "[[objects]]\ntype = \"quad\"\ncorner = [0, 0, 0]\nedge_u = [1e-20, 0, 0]\nedge_v = [0, 0, 1e-20]\nmaterial = \"m\"\n",
            "the area |edge_u × edge_v| = 1.000e-40 is too small for 32-bit floats; it must be at least 1.1e-19",
        ),
        (
            "[camera]\nposition = [0, 5, 0]\nlook_at = [0, 0, 0]\nup = [0, 1e-30, 0]\n",
            "camera.up must not be parallel to the view direction",
        ),
    ];
    for (text, expected) in cases {
        let e = load(&format!("{text}{TAIL}")).unwrap_err();
        assert!(e.contains(expected), "{text}\n→ {e}");
        assert!(e.contains("within 1e9 of it") || !expected.contains("reaches"), "{e}");
    }
    // An up vector 1e30 times shorter than the view direction, but not parallel to it, is fine.
    assert!(load(&format!("[camera]\nposition = [0, 5, -1]\nlook_at = [0, 0, 0]\nup = [0, 1e-30, 0]\n{TAIL}")).is_ok());
}

/// A scene folder with a mesh, an asset folder with another, and files
/// outside both.
struct Folders {
    _root: tempfile::TempDir,
    scene: std::path::PathBuf,
    assets: std::path::PathBuf,
}

const TRIANGLE: &str = "mtllib /nonexistent/x.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

fn folders() -> Folders {
    let root = tempfile::tempdir().unwrap();
    let (scene, assets) = (root.path().join("scene"), root.path().join("assets"));
    std::fs::create_dir_all(scene.join("meshes")).unwrap();
    std::fs::create_dir_all(&assets).unwrap();
    std::fs::write(scene.join("meshes/a.obj"), TRIANGLE).unwrap();
    std::fs::write(assets.join("b.obj"), TRIANGLE).unwrap();
    std::fs::write(root.path().join("secret.obj"), TRIANGLE).unwrap();
    std::os::unix::fs::symlink(root.path().join("secret.obj"), scene.join("link.obj")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", scene.join("zero.obj")).unwrap();
    Folders { _root: root, scene, assets }
}

fn mesh_scene(dir: &Path, file: &str) -> std::path::PathBuf {
    let path = dir.join("s.toml");
    let text = format!("{TAIL}[[objects]]\ntype = \"mesh\"\nfile = \"{file}\"\nmaterial = \"m\"\n");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn meshes_come_from_the_scene_folder_or_asset_folders_only() {
    let f = folders();
    let extra = [f.assets.clone()];
    let load = |file: &str| SceneFile::load_with(&mesh_scene(&f.scene, file), &extra).map_err(|e| e.to_string());
    let ok = load("meshes/a.obj").unwrap();
    assert_eq!(ok.scene.files().len(), 2, "the scene file and its mesh");
    assert!(ok.scene.files()[1].ends_with("scene/meshes/a.obj"));
    assert!(load("b.obj").is_ok(), "found in the asset folder");
    // Outside by name: one message, whether the file exists or not.
    let named = |file: &str| load(file).unwrap_err().replace(file, "NAME");
    assert_eq!(named("../secret.obj"), named("../missing.obj"));
    assert_eq!(named("/etc/passwd"), named("/etc/no-such-file"));
    assert!(named("/proc/self/environ").contains("must be a relative path inside the scene's folder"));
    // Outside through a link, or a device: as if there were no such file.
    assert_eq!(named("link.obj"), named("missing.obj"));
    assert_eq!(named("zero.obj"), named("missing.obj"));
    assert!(named("missing.obj").contains("no file `NAME` in the scene's folder"));
    assert!(named("missing.obj").contains("or the asset folders"));
    // Without the asset folder, b.obj is not found.
    assert!(SceneFile::load(&mesh_scene(&f.scene, "b.obj")).is_err());
    assert_eq!(AssetPath::new(Some(&f.scene), &extra).folders().len(), 2);
}

#[test]
fn obj_errors_name_the_mesh_file_and_its_line() {
    let f = folders();
    std::fs::write(f.scene.join("bad.obj"), "v 0 0 0\nv 1 0 0\n# a comment\nf 1 2 7\n").unwrap();
    let e = SceneFile::load(&mesh_scene(&f.scene, "bad.obj")).unwrap_err().to_string();
    assert!(e.contains("s.toml:5:8: objects[0] (mesh): cannot load mesh "), "{e}");
    assert!(e.contains("bad.obj:4: a face refers to vertex 7, but the file has 2"), "{e}");
}

#[test]
fn oversized_and_broken_files_are_refused_with_the_limit() {
    let e = SceneFile::load(Path::new("/dev/zero")).unwrap_err().to_string();
    assert_eq!(e, "/dev/zero: cannot read the scene file: it holds more than 16777216 bytes, the most read");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("latin1.toml");
    std::fs::write(&path, b"[render]\nwidth = 8 # caf\xe9\n").unwrap();
    let e = SceneFile::load(&path).unwrap_err();
    assert_eq!(e.location, Some((2, 16)));
    assert!(e.to_string().ends_with("latin1.toml:2:16: not UTF-8 text"), "{e}");
}

/// A valid 1×1 EXR (a few hundred bytes) whose header then claims `w`×`h` pixels.
pub fn exr_claiming(w: i32, h: i32) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.exr");
    Image::new(1, 1).save(&path).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    for name in [&b"dataWindow\0box2i\0"[..], b"displayWindow\0box2i\0"] {
        let at = bytes.windows(name.len()).position(|x| x == name).unwrap() + name.len() + 4;
        bytes[at + 8..at + 12].copy_from_slice(&(w - 1).to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&(h - 1).to_le_bytes());
    }
    bytes
}

#[test]
fn an_exr_header_declaring_more_pixels_than_allowed_is_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.exr");
    let bytes = exr_claiming(100_000, 100_000);
    assert!(bytes.len() < 400, "{} bytes", bytes.len());
    std::fs::write(&path, bytes).unwrap();
    let e = Image::read_exr(&path).unwrap_err().to_string();
    assert!(e.contains("huge.exr: its header declares 100000×100000 pixels; at most 65536 on a side"), "{e}");
    std::fs::write(&path, exr_claiming(16384, 16385)).unwrap();
    let e = Image::read_exr(&path).unwrap_err().to_string();
    assert!(e.contains("268435456 in all"), "{e}");
    assert!(Image::read_exr(Path::new("/dev/zero")).unwrap_err().to_string().contains("not a regular file"));
}

#[test]
fn a_thousand_identical_spheres_render_as_one() {
    // Identical bounds make obvhs's tree deeper than its traversal stack;
    // the scene is then searched linearly instead of losing nodes.
    let camera = "[render]\nwidth = 16\nheight = 12\nspp = 1\n[camera]\nposition = [0, 0, -4]\nlook_at = [0, 0, 0]\n";
    let light = "[[lights]]\ntype = \"point\"\nposition = [1, 3, -3]\nintensity = 10\n";
    let sphere = "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n";
    let one = image(&format!("{camera}{TAIL}{light}{sphere}"));
    let many = image(&format!("{camera}{TAIL}{light}{}", sphere.repeat(1000)));
    assert!(one.mean().x > 0.01);
    assert_eq!(many, one);
}

#[test]
fn thousands_of_identical_faces_are_refused_before_the_bvh_is_built() {
    // A BVH over identical boxes takes time that grows as the square of
    // their number: 100,000 copies of one face (an 800 KB file) ran for
    // hours. Past the limit the scene is refused, at once.
    let dir = tempfile::tempdir().unwrap();
    let faces = "f 1 2 3\n".repeat(airlight::scene::limits::MAX_EQUAL_BOUNDS + 1);
    std::fs::write(dir.path().join("same.obj"), format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{faces}")).unwrap();
    let e = SceneFile::load(&mesh_scene(dir.path(), "same.obj")).unwrap_err().to_string();
    assert!(e.contains("4097 surfaces have exactly the same bounds"), "{e}");
    // At the limit the scene loads.
    let faces = "f 1 2 3\n".repeat(airlight::scene::limits::MAX_EQUAL_BOUNDS);
    std::fs::write(dir.path().join("same.obj"), format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{faces}")).unwrap();
    assert!(SceneFile::load(&mesh_scene(dir.path(), "same.obj")).is_ok());
}

#[test]
fn a_medium_too_thick_for_any_image_is_refused_not_tracked_forever() {
    // Noise fog is crossed by null collisions: at σs = 10¹⁰ a path never
    // finished, at 10⁶ it slowed in proportion. Beyond a million mean free
    // paths across the scene, the scene is refused; below, it renders.
    let scene = |sigma_s: &str| {
        format!(
            "[render]\nwidth = 4\nheight = 3\nspp = 1\nintegrator = \"path\"\n{TAIL}\
             [medium]\ntype = \"noise\"\nsigma_s = {sigma_s}\nscale = 1\nmin = [-2, -2, -2]\nmax = [2, 2, 2]\n\
             [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n\
             [[lights]]\ntype = \"point\"\nposition = [0, 3, -3]\nintensity = 10\n"
        )
    };
    for thick in ["1e10", "1e6"] {
        let e = load(&scene(thick)).unwrap_err();
        assert!(e.contains("mean free paths across the scene") && e.contains("more than 1e6"), "{thick}: {e}");
    }
    assert!(image(&scene("0.5")).mean().x > 0.0);
}

#[test]
fn a_focus_beyond_the_scenes_reach_is_refused_not_rendered_black() {
    // 1e20 squared overflows f32: every lens ray was lost and the image
    // black, while 1e19 rendered.
    let scene = |focus: &str| {
        format!(
            "[render]\nwidth = 8\nheight = 6\nspp = 2\n[camera]\nposition = [0, 1, -4]\nlook_at = [0, 0, 0]\n\
             aperture = 0.1\nfocus_distance = {focus}\n{TAIL}\
             [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n\
             [[lights]]\ntype = \"point\"\nposition = [0, 3, -3]\nintensity = 10\n"
        )
    };
    let e = load(&scene("1e20")).unwrap_err();
    assert!(e.contains("camera.focus_distance must be at most 1e9"), "{e}");
    assert!(image(&scene("1e9")).mean().x > 0.0);
}
