use super::*;

#[test]
fn builder_rejects_unknown_materials_and_empty_images() {
    let unknown = SceneBuilder::new().object(Shape::sphere(Vec3::ZERO, 1.0), "nope").build();
    assert!(unknown.unwrap_err().message.contains("unknown material `nope`"));
    let empty = SceneBuilder::new().size(0, 10).build();
    assert!(empty.unwrap_err().message.contains("width must be an integer from 1 to 65536, got 0"));
}
