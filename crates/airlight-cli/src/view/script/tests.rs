use super::*;
use glam::vec3;

fn scene() -> Scene {
    airlight::SceneFile::from_toml_str(crate::view::DEFAULT_SCENE, None).unwrap().scene
}

fn err(text: &str) -> String {
    parse(text, &scene()).unwrap_err().to_string()
}

#[test]
fn an_empty_script_keeps_the_scene_as_it_is() {
    let s = scene();
    let script = parse("", &s).unwrap();
    assert_eq!(script.camera_at(7, s.camera()), *s.camera());
    assert_eq!(script.lights_at(7, 10, s.lights(), s.light_paths()), s.lights());
    assert_eq!(script.integrator, None);
}

#[test]
fn camera_and_light_keys_interpolate_linearly_and_hold_the_ends() {
    let s = scene();
    let text = r#"
integrator = "raymarch"
[[camera]]
frame = 10
position = [0, 1, -5]
look_at = [0, 1, 0]
fov = 40
[[camera]]
frame = 20
position = [2, 1, -5]
look_at = [2, 1, 0]
fov = 60
[[light]]
light = 0
frame = 0
position = [1, 5, 1]
[[light]]
light = 0
frame = 4
position = [3, 5, 1]
"#;
    let script = parse(text, &s).unwrap();
    assert_eq!(script.integrator, Some(Mode::Raymarch));
    let c = script.camera_at(15, s.camera());
    assert!((c.position - vec3(1.0, 1.0, -5.0)).length() < 1e-6);
    assert!((c.forward - Vec3::Z).length() < 1e-6);
    assert_eq!(c.projection, Projection::Perspective { fov_degrees: 50.0 });
    assert_eq!(script.camera_at(0, s.camera()).position, vec3(0.0, 1.0, -5.0));
    assert_eq!(script.camera_at(99, s.camera()).position, vec3(2.0, 1.0, -5.0));
    let lights = script.lights_at(1, 10, s.lights(), s.light_paths());
    assert!((lights[0].position().unwrap() - vec3(1.5, 5.0, 1.0)).length() < 1e-6);
    assert_eq!(script.lights_at(9, 10, s.lights(), s.light_paths())[0].position(), Some(vec3(3.0, 5.0, 1.0)));
}

#[test]
fn scene_keyframes_play_the_scenes_own_light_paths_over_the_frames() {
    let s = scene();
    let script = parse("scene_keyframes = true", &s).unwrap();
    let path = s.light_paths()[0].as_ref().unwrap();
    for (frame, time) in [(0, 0.0), (2, 0.5), (4, 1.0)] {
        let p = script.lights_at(frame, 5, s.lights(), s.light_paths())[0].position().unwrap();
        // A quad light moves by its corner, so its centre comes back rounded.
        assert!((p - path.at(time)).length() < 1e-5, "frame {frame}: {p}");
    }
}

#[test]
fn bad_scripts_say_where_and_what_was_expected() {
    let e = err(
        "[[camera]]\nframe = 0\nposition = [0, 1, -5]\nlook_at = [0, 1, 0]\n\n[[camera]]\nframe = 0\nposition = [1, 1, -5]\nlook_at = [0, 1, 0]\n",
    );
    assert!(e.starts_with("line 7, column 9:") && e.contains("greater than the previous key's frame (0)"), "{e}");
    let e = err("[[light]]\nlight = 3\nframe = 0\nposition = [0, 1, 0]\n");
    assert!(e.starts_with("line 2,") && e.contains("the scene has 1 lights, numbered 0 to 0"), "{e}");
    let e = err("[[camera]]\nframe = -1\nposition = [0, 1, -5]\nlook_at = [0, 1, 0]\n");
    assert!(e.starts_with("line 2,") && e.contains("integer ≥ 0"), "{e}");
    let e = err("[[camera]]\nframe = 0\nposition = [0, 1, -5]\nlook_at = [0, 1, -5]\n");
    assert!(e.starts_with("line 4,") && e.contains("must differ"), "{e}");
    let e = err("[[camera]]\nframe = 0\nposition = [0, 1]\nlook_at = [0, 1, 0]\n");
    assert!(e.starts_with("line 3,"), "{e}");
    let e = err("integrator = \"path\"\n");
    assert!(e.starts_with("line 1,") && e.contains("expected preview, raymarch or stochastic"), "{e}");
    let e = err("[[camera]]\nframe = 0\nposition = [0, 1, -5]\nlook_at = [0, 1, 0]\nfov = 190\n");
    assert!(e.starts_with("line 5,") && e.contains("(0, 180)"), "{e}");
    let e = err("[[camera]]\nframe = 0\nposition = [0, 1, -5]\nlookat = [0, 1, 0]\n");
    assert!(e.starts_with("line 4,") && e.contains("lookat"), "{e}");
    let e = err("[[light]]\nlight = 0\nframe = 0\nposition = [nan, 1, 0]\n");
    assert!(e.starts_with("line 4,") && e.contains("finite"), "{e}");
}

#[test]
fn a_missing_file_names_the_file() {
    let e = load(Path::new("/nonexistent/camera.toml"), &scene()).unwrap_err().to_string();
    assert!(e.starts_with("/nonexistent/camera.toml: cannot read the path file"), "{e}");
}

#[test]
fn a_camera_interpolated_through_its_target_is_refused_with_the_frame() {
    // Between these keys the camera passes through the point it looks at
    // (frame 15: position = look_at = [0, 1, 0]).
    let through = "[[camera]]\nframe = 0\nposition = [0, 1, -5]\nlook_at = [0, 1, 5]\n\n\
                   [[camera]]\nframe = 30\nposition = [0, 1, 5]\nlook_at = [0, 1, -5]\n";
    let e = err(through);
    assert!(e.starts_with("line 7, column 9:"), "{e}");
    assert!(
        e.contains("between the camera keys at frames 0 and 30, the camera at frame 15 would stand on its look_at")
    );
    // Turning to look straight down on the way: refused at the frame it does.
    let down = "[[camera]]\nframe = 0\nposition = [-1, 5, 0]\nlook_at = [1, 0, 0]\n\n\
                [[camera]]\nframe = 10\nposition = [1, 5, 0]\nlook_at = [-1, 0, 0]\n";
    let e = err(down);
    assert!(e.contains("the camera at frame 5 would look straight up or down"), "{e}");
    // Passing near but not through at any frame is fine.
    let near = "[[camera]]\nframe = 0\nposition = [-1, 5, 0]\nlook_at = [1, 0, 0]\n\n\
                [[camera]]\nframe = 9\nposition = [1, 5, 0.5]\nlook_at = [-1, 0, 0.5]\n";
    let s = scene();
    let script = parse(near, &s).unwrap();
    for frame in 0..10 {
        let c = script.camera_at(frame, s.camera());
        assert!(c.forward.is_finite() && c.right.is_finite(), "frame {frame}");
    }
}

#[test]
fn keys_far_away_are_refused_with_the_limit() {
    let e = err("[[camera]]\nframe = 0\nposition = [0, 1, -1e30]\nlook_at = [0, 1, 0]\n");
    assert!(e.starts_with("line 3,") && e.contains("reaches 1e30 world units from the origin"), "{e}");
    let e = err("[[light]]\nlight = 0\nframe = 0\nposition = [0, 1e12, 0]\n");
    assert!(e.starts_with("line 4,") && e.contains("within 1e9"), "{e}");
}
