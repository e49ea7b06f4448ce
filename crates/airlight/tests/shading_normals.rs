//! Smooth shading: a tessellated sphere whose vertex normals are the
//! sphere's renders like the sphere itself (the closed form of a
//! Lambertian ball under a sun, albedo/π · E · max(0, n·l), at each pixel's
//! point of the true sphere), where the same mesh shaded flat shows its
//! facets; and a glTF file's NORMALs arrive placed by its node.

use airlight::geometry::Ray;
use airlight::integrator::{Direct, Integrator, PathOptions, PathTracer};
use airlight::prelude::*;
use airlight::sampling::Sampler;

/// A UV sphere of radius 1 at the origin, `rings` × `segments` quads cut
/// in two, with the sphere's normals at its vertices (or none).
fn tessellated_sphere(rings: u32, segments: u32, smooth: bool) -> Shape {
    let mut positions = Vec::new();
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..=segments {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / segments as f32;
            positions.push(vec3(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()));
        }
    }
    let at = |i: u32, j: u32| i * (segments + 1) + j;
    let mut triangles = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            // Wound counter-clockwise seen from outside.
            triangles.push([at(i, j), at(i, j + 1), at(i + 1, j)]);
            triangles.push([at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)]);
        }
    }
    let normals = if smooth { positions.clone() } else { Vec::new() };
    Shape::Mesh { positions, triangles, uvs: Vec::new(), normals }
}

const SUN: Vec3 = Vec3::new(0.4, 0.5, -0.768);
const ALBEDO: f32 = 0.6;

fn scene(shape: Shape) -> Scene {
    SceneBuilder::new()
        .material("m", Material::diffuse(Rgb::splat(ALBEDO)))
        .object(shape, "m")
        .light(Light::distant(-SUN, Rgb::splat(std::f32::consts::PI)))
        .build()
        .unwrap()
}

/// The mean absolute error against the closed form over rays straight
/// down −z through a grid of points of the disk r < 0.9, for an integrator.
fn error(scene: &Scene, integrator: &dyn Integrator, samples: u32) -> f64 {
    let mut sampler = Sampler::for_pixel(1, 2, 3);
    let (mut sum, mut n) = (0.0, 0);
    let side = 24;
    for a in 0..side {
        for b in 0..side {
            let (x, y) = (2.0 * (a as f32 + 0.5) / side as f32 - 1.0, 2.0 * (b as f32 + 0.5) / side as f32 - 1.0);
            if x * x + y * y > 0.81 {
                continue;
            }
            let normal = vec3(x, y, -(1.0 - x * x - y * y).sqrt());
            let exact = ALBEDO * normal.dot(SUN.normalize()).max(0.0);
            let ray = Ray::new(vec3(x, y, -5.0), Vec3::Z);
            let got: f32 =
                (0..samples).map(|_| integrator.radiance(scene, &ray, &mut sampler).x).sum::<f32>() / samples as f32;
            sum += (got - exact).abs() as f64;
            n += 1;
        }
    }
    sum / n as f64
}

#[test]
fn smooth_normals_on_a_tessellated_sphere_shade_it_as_the_sphere() {
    let smooth = scene(tessellated_sphere(12, 24, true));
    let flat = scene(tessellated_sphere(12, 24, false));
    let (e_smooth, e_flat) = (error(&smooth, &Direct, 1), error(&flat, &Direct, 1));
    // The shading normals differ from the sphere's by the interpolation
    // across a facet (a few thousandths here); the facets' own normals by
    // up to half a facet's angle (7.5°): several hundredths.
    assert!(e_smooth < 0.006, "smooth: mean error {e_smooth}");
    assert!(e_flat > 4.0 * e_smooth, "flat {e_flat} against smooth {e_smooth}");
    // The path tracer, one bounce, sampling both the sun and its BRDF
    // (cosine about the shading normal): the same within its noise.
    let path = PathTracer::new(PathOptions { max_depth: 1, ..Default::default() });
    let e_path = error(&smooth, &path, 16);
    assert!(e_path < 0.01, "path: mean error {e_path}");
}

/// A normal map of one texel that tilts the normal by about 30° toward
/// the quad's u direction and 15° up its image shades the quad as a quad
/// tilted so: the same radiance under a sun, for the normal the texel
/// decodes to (a bitangent of the wrong sign would tilt it the other way).
#[test]
fn a_normal_map_of_constant_tilt_shades_as_the_tilted_surface() {
    let dir = tempfile::tempdir().unwrap();
    let texel = [191u8, 160, 230];
    let mut png = Vec::new();
    let encoder = image::codecs::png::PngEncoder::new(&mut png);
    image::ImageEncoder::write_image(encoder, &texel, 1, 1, image::ExtendedColorType::Rgb8).unwrap();
    std::fs::write(dir.path().join("tilt.png"), png).unwrap();
    // The quad faces +y; its u runs along +x (the tangent) and its v
    // along +z, down the image, so the bitangent (up the image) is −z.
    let c = Vec3::from_array(texel.map(|b| 2.0 * b as f32 / 255.0 - 1.0));
    let tilted = (Vec3::X * c.x + Vec3::NEG_Z * c.y + Vec3::Y * c.z).normalize();
    let material = "type = \"metallic_roughness\"\nbase_colour = 0.7\nspecular = 0\nmetallic = 0";
    let sun = "[[lights]]\ntype = \"distant\"\ndirection = [0.8, -1, 0.1]\nirradiance = 2";
    let mapped = format!(
        "[materials.m]\n{material}\nnormal_file = \"tilt.png\"\n[[objects]]\ntype = \"quad\"\n\
         corner = [-1, 0, 1]\nedge_u = [2, 0, 0]\nedge_v = [0, 0, -2]\nmaterial = \"m\"\n{sun}\n"
    );
    // The same quad turned to face `tilted`.
    let (t, b) = airlight::sampling::basis(tilted);
    let (eu, ev) = (t * 2.0, b * 2.0);
    let corner = -0.5 * (eu + ev);
    let toml3 = |v: Vec3| format!("[{}, {}, {}]", v.x, v.y, v.z);
    let geometric = format!(
        "[materials.m]\n{material}\n[[objects]]\ntype = \"quad\"\ncorner = {}\nedge_u = {}\nedge_v = {}\n\
         material = \"m\"\n{sun}\n",
        toml3(corner),
        toml3(eu),
        toml3(ev)
    );
    let radiance = |text: &str| {
        let file = airlight::SceneFile::from_toml_str(text, Some(dir.path())).unwrap_or_else(|e| panic!("{e}"));
        let ray = Ray::new(vec3(0.05, 3.0, 0.02), Vec3::NEG_Y);
        Direct.radiance(&file.scene, &ray, &mut Sampler::for_pixel(0, 0, 0))
    };
    let (a, b) = (radiance(&mapped), radiance(&geometric));
    assert!(b.x > 0.1, "{b}");
    assert!((a - b).abs().max_element() < 1e-4 * b.max_element(), "mapped {a} against tilted {b}");
    // Without the map, the flat quad: a different value.
    let flat = radiance(&mapped.replace("normal_file = \"tilt.png\"\n", ""));
    assert!((flat - b).abs().max_element() > 0.05 * b.max_element(), "flat {flat} against tilted {b}");
}
