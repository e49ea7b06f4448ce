//! Writes scenes/models/cloud.vol, the density grid of scenes/cloud_sun.toml:
//! a broken cloud layer with gaps over a thin haze, as a Mitsuba `.vol`
//! file (float32, x fastest), made from the library's own fractal noise;
//! and scenes/models/compare_cloud.vol, the small cloud of the Mitsuba
//! comparison scenes (scenes/compare_grid_*.toml).
//!
//!     cargo run --release -p airlight --example cloud_grid [-- FOLDER]
//!
//! The grid fills the box [−24, 0, −20]–[24, 10, 44] (world units, metres
//! in the scene): density 0.05 of haze below height 7, up to 4 in the
//! cloud between heights 6 and 9, whose noise cuts gaps for the sun.

use airlight::assets::vol::{self, VolGrid};
use airlight::medium::NoiseFog;
use glam::Vec3;

fn main() -> std::io::Result<()> {
    let folder = std::env::args().nth(1).unwrap_or_else(|| "scenes/models".into());
    write_small_cloud(&format!("{folder}/compare_cloud.vol"))?;
    let out = format!("{folder}/cloud.vol");
    let (min, max) = (Vec3::new(-24.0, 0.0, -20.0), Vec3::new(24.0, 10.0, 44.0));
    let resolution = [72, 20, 96];
    let noise = NoiseFog {
        scale: Vec3::new(9.0, 3.0, 9.0),
        octaves: 5,
        gain: 0.55,
        offset: 0.0,
        seed: 21,
        bounds: None,
        height: None,
    };
    let cell = (max - min) / Vec3::new(resolution[0] as f32, resolution[1] as f32, resolution[2] as f32);
    let mut values = Vec::with_capacity(resolution.iter().product());
    for z in 0..resolution[2] {
        for y in 0..resolution[1] {
            for x in 0..resolution[0] {
                let p = min + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * cell;
                // The layer: a bump in height from 6 to 9, its base wavy.
                let layer = 1.0 - ((p.y - 7.5) / 1.5).powi(2);
                let cloud = (noise.fractal(p) - 0.12).max(0.0) * 10.0 * layer.max(0.0);
                let haze = if p.y < 7.0 { 0.05 } else { 0.0 };
                values.push(cloud.min(4.0) + haze);
            }
        }
    }
    let bytes = vol::write(&VolGrid { resolution, min, max, values });
    std::fs::write(&out, bytes)?;
    eprintln!("wrote {out}");
    Ok(())
}

/// A 32³ cloud in the box [−1, 1]³: an ellipsoid of density up to about
/// 3 with noisy edges, empty corners.
fn write_small_cloud(out: &str) -> std::io::Result<()> {
    let n = 32;
    let noise =
        NoiseFog { scale: Vec3::splat(0.6), octaves: 3, gain: 0.5, offset: 0.0, seed: 5, bounds: None, height: None };
    let mut values = Vec::with_capacity(n * n * n);
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let p = (Vec3::new(x as f32, y as f32, z as f32) + 0.5) / n as f32 * 2.0 - 1.0;
                let r = (p / Vec3::new(0.9, 0.6, 0.8)).length();
                values.push((3.0 * (1.0 - r) + 1.5 * noise.fractal(p)).clamp(0.0, 3.0));
            }
        }
    }
    std::fs::write(out, vol::write(&VolGrid { resolution: [n; 3], min: Vec3::splat(-1.0), max: Vec3::ONE, values }))?;
    eprintln!("wrote {out}");
    Ok(())
}
