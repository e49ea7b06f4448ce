use super::*;

#[test]
fn builder_rejects_unknown_materials_and_empty_images() {
    let unknown = SceneBuilder::new().object(Shape::sphere(Vec3::ZERO, 1.0), "nope").build();
    assert!(unknown.unwrap_err().message.contains("unknown material `nope`"));
    let empty = SceneBuilder::new().size(0, 10).build();
    assert!(empty.unwrap_err().message.contains("width must be an integer from 1 to 65536, got 0"));
}

#[test]
fn a_medium_from_command_line_options_follows_the_scene_file_rules() {
    let m = medium_from_options("sigma_s=0.05,sigma_a=0.01,g=0.3").unwrap();
    assert_eq!(m, Medium::homogeneous(Vec3::splat(0.01), Vec3::splat(0.05), 0.3));
    let m = medium_from_options(r#"type = "height", sigma_s = [0.1, 0.2, 0.3], falloff = 2"#).unwrap();
    assert_eq!(m, Medium::height(Vec3::ZERO, Vec3::new(0.1, 0.2, 0.3), 0.0, 0.0, 2.0));
    // The same text in a scene file's [medium] gives the same medium.
    let desc = parse("[medium]\nsigma_s = 0.05\nsigma_a = 0.01\ng = 0.3\n").unwrap();
    let scene =
        build(&desc, "[medium]\nsigma_s = 0.05\nsigma_a = 0.01\ng = 0.3\n", &AssetPath::new(None, &[])).unwrap();
    assert_eq!(scene.medium(), Some(&medium_from_options("sigma_s=0.05,sigma_a=0.01,g=0.3").unwrap()));
    for (options, message) in [
        ("g = 1", "medium.g must lie strictly between -1 and 1, got 1"),
        ("sigma_s = -1", "medium.sigma_s must be finite and ≥ 0, got [-1, -1, -1]"),
        ("falloff = 1", "`falloff` is a key of height or noise media, not of homogeneous media"),
        ("density = 1", "`density` is not a key of homogeneous media; they take sigma_a, sigma_s, g"),
        ("type = \"grid\", file = \"a.vol\", density_scael = 2", "did you mean `density_scale`?"),
    ] {
        let e = medium_from_options(options).unwrap_err();
        assert!(e.contains(message), "{options}: {e}");
    }
}
