//! Bad scene files: each must give one clear error naming the line and column
//! (where the file has one) and what was expected, and never panic.

use airlight::SceneFile;
use airlight::scene::SceneError;

const GOOD_TAIL: &str = r#"
[materials.white]
albedo = 0.8

[[objects]]
type = "sphere"
center = [0, 1, 0]
radius = 1
material = "white"

[[lights]]
type = "point"
position = [0, 4, 0]
intensity = 10
"#;

fn error_of(text: &str) -> SceneError {
    match SceneFile::from_toml_str(text, None) {
        Ok(_) => panic!("scene should have been rejected:\n{text}"),
        Err(e) => e,
    }
}

/// (scene text, expected line, a phrase the message must contain)
fn cases() -> Vec<(String, usize, &'static str)> {
    let with = |head: &str| format!("{head}\n{GOOD_TAIL}");
    vec![
        // 1. Not TOML at all.
        ("[render\nwidth = 3".into(), 1, "unclosed table, expected `]`"),
        // 2. A key without a value.
        ("[render]\nwidth =\n".into(), 2, "string values must be quoted"),
        // 3. Unknown top-level table.
        (with("[rendr]\nwidth = 4"), 1, "unknown field `rendr`"),
        // 4. Unknown key in [render].
        (with("[render]\nwdith = 4"), 2, "unknown field `wdith`"),
        // 5. Mistyped field: a string for a number.
        (
            with("[render]\nwidth = \"wide\""),
            2,
            "render.width must be an integer from 1 to 65536, got the text \"wide\"",
        ),
        // 6. Zero-size image.
        (with("[render]\nwidth = 0"), 2, "render.width must be an integer from 1 to 65536, got 0"),
        // 7. Negative spp.
        (with("[render]\nspp = -3"), 2, "render.spp must be an integer from 1 to 16777216"),
        // 8. Unknown integrator.
        (
            with("[render]\nintegrator = \"magic\""),
            2,
            "render.integrator must be direct, raymarch, analytic, stochastic, path, radiosity or ambient_occlusion, got the text \"magic\"",
        ),
        // 9. Position with two numbers.
        (with("[camera]\nposition = [0, 1]"), 2, "invalid length 2, expected an array of three numbers"),
        // 10. Unknown object type.
        (
            "[[objects]]\ntype = \"cone\"\nmaterial = \"m\"\n".into(),
            2,
            "unknown type `cone`; objects are sphere, plane, quad, box, mesh or sdf",
        ),
        // 11. Missing radius.
        (
            format!("{GOOD_TAIL}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nmaterial = \"white\"\n"),
            16,
            "a sphere object needs `radius`",
        ),
        // 12. Negative radius.
        (
            format!(
                "{GOOD_TAIL}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -1\nmaterial = \"white\"\n"
            ),
            19,
            "objects[1] (sphere).radius must be a positive finite number, got -1",
        ),
        // 13. NaN radius.
        (
            format!(
                "{GOOD_TAIL}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = nan\nmaterial = \"white\"\n"
            ),
            19,
            "got NaN",
        ),
        // 14. Unknown material name: points at the name itself.
        (
            format!(
                "{GOOD_TAIL}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"chrome\"\n"
            ),
            20,
            "unknown material `chrome`; the scene defines: `white`",
        ),
        // 15. A field from another shape.
        (
            format!(
                "{GOOD_TAIL}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nnormal = [0, 1, 0]\nmaterial = \"white\"\n"
            ),
            20,
            "`normal` is a key of plane or sdf objects, not of sphere objects",
        ),
        // 16. Unknown light type.
        (format!("{GOOD_TAIL}\n[[lights]]\ntype = \"laser\"\n"), 17, "unknown type `laser`; lights are point, spot"),
        // 17. Spot without a direction.
        (
            format!("{GOOD_TAIL}\n[[lights]]\ntype = \"spot\"\nposition = [0, 3, 0]\nintensity = 5\n"),
            16,
            "a spot needs `direction` or `look_at`",
        ),
        // 18. Negative intensity.
        (
            format!("{GOOD_TAIL}\n[[lights]]\ntype = \"point\"\nposition = [0, 3, 0]\nintensity = -5\n"),
            19,
            "intensity must be finite and ≥ 0",
        ),
        // 19. falloff_start beyond the cone.
        (
            format!(
                "{GOOD_TAIL}\n[[lights]]\ntype = \"spot\"\nposition = [0, 3, 0]\ndirection = [0, -1, 0]\nintensity = 5\ncone_angle = 20\nfalloff_start = 30\n"
            ),
            22,
            "falloff_start must be in [0, cone_angle = 20] degrees, got 30",
        ),
        // 20. Degenerate quad.
        (
            format!(
                "{GOOD_TAIL}\n[[objects]]\ntype = \"quad\"\ncorner = [0, 0, 0]\nedge_u = [1, 0, 0]\nedge_v = [2, 0, 0]\nmaterial = \"white\"\n"
            ),
            20,
            "edge_u and edge_v must not be parallel or zero",
        ),
        // 21. Box with min above max.
        (
            format!(
                "{GOOD_TAIL}\n[[objects]]\ntype = \"box\"\nmin = [0, 2, 0]\nmax = [1, 1, 1]\nmaterial = \"white\"\n"
            ),
            19,
            "min must be less than max on every axis",
        ),
        // 22. Medium with g out of range.
        (with("[medium]\nsigma_s = 0.1\ng = 1.5"), 3, "medium.g must lie strictly between -1 and 1, got 1.5"),
        // 23. Height fields on a homogeneous medium.
        (
            with("[medium]\nsigma_s = 0.1\nfalloff = 2"),
            3,
            "`falloff` is a key of height or noise media, not of homogeneous media",
        ),
        // 24. Negative scattering coefficient.
        (with("[medium]\nsigma_s = [0.1, -0.2, 0.1]"), 2, "medium.sigma_s must be finite and ≥ 0"),
        // 25. Unknown material type.
        (
            "[materials.m]\ntype = \"glass\"\n".into(),
            2,
            "unknown type `glass`; materials are diffuse, checker, phong, texture or metallic_roughness",
        ),
        // 26. Checker field on a diffuse material.
        (
            "[materials.m]\nalbedo2 = 0.3\n".into(),
            2,
            "`albedo2` is a key of checker materials, not of diffuse materials",
        ),
        // 27. Perspective camera with a view_height.
        (
            with("[camera]\nview_height = 3"),
            2,
            "`view_height` is a key of orthographic or isometric cameras, not of perspective cameras",
        ),
        // 28. Camera looking at itself.
        (
            with("[camera]\nposition = [1, 1, 1]\nlook_at = [1, 1, 1]"),
            3,
            "camera.position and camera.look_at must differ",
        ),
        // 29. Zero scale.
        (
            format!(
                "{GOOD_TAIL}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nscale = [1, 0, 1]\nmaterial = \"white\"\n"
            ),
            20,
            "scale must not be zero on any axis",
        ),
        // 30. Object without a material.
        (
            format!("{GOOD_TAIL}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n"),
            16,
            "needs a `material`",
        ),
        // 31. Mesh file that does not exist.
        (
            format!("{GOOD_TAIL}\n[[objects]]\ntype = \"mesh\"\nfile = \"no/such/file.obj\"\nmaterial = \"white\"\n"),
            18,
            "cannot load mesh: no file `no/such/file.obj` in the scene's folder",
        ),
        // 32. A spot light's key on a point light: named at the key, with
        // the type that takes it.
        (
            format!(
                "{GOOD_TAIL}\n[[lights]]\ntype = \"point\"\nposition = [0, 3, 0]\nintensity = 5\ncone_angle = 20\n"
            ),
            20,
            "lights[1] (point): `cone_angle` is a key of spot lights, not of point lights",
        ),
        // 33. An isometric camera's key on a perspective one (once ignored).
        (with("[camera]\ndistance = 20"), 2, "`distance` is a key of isometric cameras, not of perspective cameras"),
        // 35. A keyframe without its time: said of the keyframe, at it.
        (
            format!(
                "{GOOD_TAIL}\n[[lights]]\ntype = \"point\"\nposition = [0, 3, 0]\nintensity = 5\nkeyframes = [{{ position = [0, 1, 0] }}]\n"
            ),
            20,
            "lights[1] (point): missing field `time`",
        ),
        // 34. A key no type takes, a slip away from one this type takes.
        (
            format!("{GOOD_TAIL}\n[[lights]]\ntype = \"point\"\nposition = [0, 3, 0]\nintensity = 5\nintensty = 5\n"),
            20,
            "`intensty` is not a key of point lights; did you mean `intensity`?",
        ),
    ]
}

#[test]
fn every_bad_scene_gets_its_own_message_and_location() {
    let cases = cases();
    assert!(cases.len() >= 20);
    let mut failures = Vec::new();
    for (i, (text, line, phrase)) in cases.iter().enumerate() {
        let e = error_of(text);
        let ok_line = e.location.map(|(l, _)| l) == Some(*line);
        if !e.message.contains(phrase) || !ok_line {
            failures.push(format!(
                "case {}: expected line {line} and «{phrase}», got {:?}: {}",
                i + 1,
                e.location,
                e.message
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn malformed_mesh_is_rejected_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 7\n").unwrap();
    std::fs::write(dir.path().join("empty.obj"), "# nothing\n").unwrap();
    for (file, phrase) in [("bad.obj", "cannot load mesh"), ("empty.obj", "cannot load mesh")] {
        let text = format!("{GOOD_TAIL}\n[[objects]]\ntype = \"mesh\"\nfile = \"{file}\"\nmaterial = \"white\"\n");
        let e = SceneFile::from_toml_str(&text, Some(dir.path())).unwrap_err();
        assert!(e.message.contains(phrase), "{file}: {}", e.message);
        assert_eq!(e.location.map(|l| l.0), Some(18));
    }
}

#[test]
fn errors_display_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, "[render]\nwidth = 0\n").unwrap();
    let e = airlight::SceneFile::load(&path).unwrap_err();
    let shown = e.to_string();
    assert!(shown.starts_with(&format!("{}:2:9: ", path.display())), "{shown}");
    let missing = airlight::SceneFile::load(&dir.path().join("nope.toml")).unwrap_err();
    assert!(missing.to_string().contains("cannot read the scene file"), "{missing}");
}

#[test]
fn garbage_never_panics() {
    // Truncations of a valid scene at every byte, and a few oddities.
    let text = format!("[render]\nwidth = 8\nheight = 6\n{GOOD_TAIL}");
    for cut in 0..text.len() {
        if text.is_char_boundary(cut) {
            let _ = SceneFile::from_toml_str(&text[..cut], None);
        }
    }
    for odd in ["\u{0}", "[[objects]]\n", "[[lights]]\ntype = 3", "render = 5", "[materials]\nx = 1", "🙂 = 1"] {
        assert!(SceneFile::from_toml_str(odd, None).is_err(), "{odd:?}");
    }
}

#[test]
fn analytic_settings_and_line_lights_are_checked() {
    let tail = "[materials.white]\nalbedo = 0.8\n";
    for (text, line, phrase) in [
        ("[render]\nlight_steps = 0\n", 2, "render.light_steps must be an integer from 1 to 4096, got 0"),
        ("[render]\nlight_steps = 5000\n", 2, "render.light_steps must be an integer from 1 to 4096, got 5000"),
        ("[render]\nshadows = 1\n", 2, "render.shadows must be true or false, got 1"),
        (
            "[render]\nlight_quadrature = \"simpson\"\n",
            2,
            "render.light_quadrature must be gauss or uniform, got the text \"simpson\"",
        ),
        ("[[lights]]\ntype = \"line\"\nstart = [0, 1, 0]\nintensity = 3\n", 1, "a line light needs `end`"),
        (
            "[[lights]]\ntype = \"line\"\nstart = [0, 1, 0]\nend = [0, 1, 0]\nintensity = 3\n",
            4,
            "start and end must differ",
        ),
        (
            "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nend = [0, 1, 0]\nintensity = 3\n",
            4,
            "`end` is a key of line lights, not of point lights",
        ),
    ] {
        let full = format!("{text}{tail}");
        let e = error_of(&full);
        assert!(e.message.contains(phrase), "{full}\n→ {e}");
        assert_eq!(e.location.map(|l| l.0), Some(line), "{full}\n→ {e}");
    }
    let ok = SceneFile::from_toml_str(
        "[render]\nshadows = true\nlight_steps = 8\nlight_quadrature = \"uniform\"\n\
         [[lights]]\ntype = \"line\"\nstart = [0, 1, 0]\nend = [1, 1, 0]\nintensity = 3\n",
        None,
    )
    .unwrap();
    assert!(ok.integrator.analytic.shadows);
    assert_eq!(ok.integrator.analytic.light_steps, 8);
}
