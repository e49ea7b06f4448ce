//! The viewer's window (minifb): reads keys and the mouse into
//! [`Controls`], moves the camera and the lights, runs a frame of the
//! [`Engine`] and shows it, with the frame time, samples and integrator in
//! the title.
//!
//! Keys: W/A/S/D move, Q/E down/up, left-drag looks, wheel or +/− change
//! the speed; Tab selects a light, the arrows and PageUp/PageDown move it,
//! Space plays the scene's light keyframes; 1/2/3 pick preview, raymarch or
//! stochastic; F12 saves the image (EXR and PNG); Esc quits.

use super::engine::{Engine, Mode};
use super::headless::Start;
use super::input::{Controls, FlyCamera, nudge};
use airlight::film::Tonemap;
use airlight::film::{self, Image};
use glam::{Vec2, Vec3};
use minifb::{Key, KeyRepeat, MouseButton, MouseMode, Window, WindowOptions};
use std::path::{Path, PathBuf};
use std::time::Instant;

pub struct Options {
    /// Seconds per pass of the light keyframes.
    pub period: f32,
    /// Render at half size while moving when full size is too slow.
    pub dynamic: bool,
    /// Where F12 saves.
    pub out: PathBuf,
}

/// Frame time above which moving frames are rendered at half size.
const BUDGET_MS: f64 = 1000.0 / 30.0;

pub fn run(engine: &mut Engine, start: &Start, options: &Options) -> Result<(), String> {
    let (w, h) = engine.full_size();
    let (w, h) = (w as usize, h as usize);
    let mut window = Window::new("airlight view", w, h, WindowOptions::default())
        .map_err(|e| format!("cannot open a window ({e}); without a display, use --headless"))?;
    // Caps the polling rate when idle; rendering is slower than this anyway.
    window.set_target_fps(120);
    let mut fly = FlyCamera::from_camera(&start.camera, (0.15 * engine.scene.bounds().1).max(0.05));
    let mut lights = start.lights.clone();
    let movable: Vec<usize> = (0..lights.len()).filter(|&i| lights[i].position().is_some()).collect();
    let mut selected = 0;
    let (mut playing, mut time) = (false, 0.0f32);
    let mut buffer = vec![0u32; w * h];
    let lut = Lut::new(engine.scene.settings().film.exposure, engine.scene.settings().film.tonemap);
    let mut last = Instant::now();
    let mut mouse_prev: Option<(f32, f32)> = None;
    let mut full_ms = 0.0;
    let mut status = String::new();
    while window.is_open() {
        let now = Instant::now();
        let dt = (now - last).as_secs_f32().min(0.25);
        last = now;
        let pressed = window.get_keys_pressed(KeyRepeat::No);
        if pressed.contains(&Key::Escape) {
            break;
        }
        let axis = |pos: Key, neg: Key| (window.is_key_down(pos) as i32 - window.is_key_down(neg) as i32) as f32;
        let mut c = Controls {
            walk: Vec3::new(axis(Key::D, Key::A), axis(Key::E, Key::Q), axis(Key::W, Key::S)),
            ..Default::default()
        };
        let mut save = false;
        for key in &pressed {
            match key {
                Key::Key1 => engine.set_mode(Mode::Preview),
                Key::Key2 => engine.set_mode(Mode::Raymarch),
                Key::Key3 => engine.set_mode(Mode::Stochastic),
                Key::Tab if !movable.is_empty() => selected = (selected + 1) % movable.len(),
                Key::Space => playing = !playing,
                Key::Equal | Key::NumPadPlus => c.speed_steps += 1.0,
                Key::Minus | Key::NumPadMinus => c.speed_steps -= 1.0,
                Key::F12 => save = true,
                _ => {}
            }
        }
        if let Some((_, y)) = window.get_scroll_wheel() {
            c.speed_steps += y.signum();
        }
        let mouse = window.get_mouse_pos(MouseMode::Pass);
        if window.get_mouse_down(MouseButton::Left)
            && let (Some(p), Some(q)) = (mouse, mouse_prev)
        {
            c.drag = Vec2::new(p.0 - q.0, p.1 - q.1);
        }
        mouse_prev = mouse;
        let mut moving = fly.apply(&c, dt);

        let arrows = Vec3::new(axis(Key::Right, Key::Left), axis(Key::PageUp, Key::PageDown), axis(Key::Up, Key::Down));
        if arrows != Vec3::ZERO
            && let Some(&i) = movable.get(selected)
            && let Some(p) = lights[i].position()
        {
            lights[i] = lights[i].moved_to(nudge(p, &fly, arrows, dt));
            playing = false;
            moving = true;
        }
        if playing {
            time = (time + dt / options.period).fract();
            for (i, path) in start.paths.iter().enumerate() {
                if let Some(path) = path {
                    lights[i] = lights[i].moved_to(path.at(time));
                    moving = true;
                }
            }
        }
        engine.set_camera(fly.camera());
        engine.set_lights(&lights);
        engine.set_scale(if options.dynamic && moving && full_ms > BUDGET_MS { 2 } else { 1 });
        let stats = engine.frame();
        if engine.size() == engine.full_size() && stats.samples == 1 {
            full_ms = stats.total().as_secs_f64() * 1e3;
        }
        if save {
            status = match save_image(&engine.image(), engine, &options.out) {
                Ok(name) => format!("saved {name}"),
                Err(e) => format!("not saved: {e}"),
            };
            eprintln!("{status}");
        }
        if stats.added > 0 {
            show(&engine.image(), &mut buffer, w, h, &lut);
        }
        let selected_text = match movable.len() {
            0 => "no movable light".to_string(),
            n => format!("light {}/{n}", selected + 1),
        };
        let (rw, rh) = engine.size();
        window.set_title(&format!(
            "airlight view | {} | {:.1} ms/frame (GI {:.1}, image {:.1}) | {} spp | {rw}×{rh} | {selected_text}{} | speed {:.2} {status}",
            engine.mode().name(),
            dt * 1e3,
            stats.radiosity.as_secs_f64() * 1e3,
            stats.image.as_secs_f64() * 1e3,
            engine.samples(),
            if playing { " (playing)" } else { "" },
            fly.speed,
        ));
        window.update_with_buffer(&buffer, w, h).map_err(|e| format!("cannot show the frame: {e}"))?;
    }
    Ok(())
}

/// 8-bit sRGB of linear values after exposure and tone curve, by table:
/// one lookup per channel instead of a `powf`.
struct Lut {
    scale: f32,
    tonemap: Tonemap,
    table: Vec<u8>,
}

impl Lut {
    const SIZE: usize = 4096;

    fn new(exposure: f32, tonemap: Tonemap) -> Lut {
        let table = (0..Self::SIZE).map(|i| film::to_srgb8(i as f32 / (Self::SIZE - 1) as f32)).collect();
        Lut { scale: exposure.exp2(), tonemap, table }
    }

    fn get(&self, linear: f32) -> u32 {
        let t = film::tone(linear * self.scale, self.tonemap);
        self.table[(t * (Self::SIZE - 1) as f32 + 0.5) as usize] as u32
    }
}

/// Fills the window's 0RGB buffer from `image`, stretched (nearest pixel)
/// when it was rendered smaller.
fn show(image: &Image, buffer: &mut [u32], w: usize, h: usize, lut: &Lut) {
    let (iw, ih) = (image.width as usize, image.height as usize);
    for y in 0..h {
        let sy = y * ih / h;
        for x in 0..w {
            let p = image.pixels[sy * iw + x * iw / w];
            buffer[y * w + x] = (lut.get(p.x) << 16) | (lut.get(p.y) << 8) | lut.get(p.z);
        }
    }
}

/// Writes `dir/airlight-view-NNNN.exr` and `.png` with the first number not
/// taken; each file is written whole or not at all (`Image::write`).
fn save_image(image: &Image, engine: &Engine, dir: &Path) -> Result<String, String> {
    let s = engine.scene.settings();
    let free = (1..10_000)
        .map(|n| dir.join(format!("airlight-view-{n:04}")))
        .find(|stem| !stem.with_extension("png").exists() && !stem.with_extension("exr").exists());
    let stem = free.ok_or_else(|| format!("no free airlight-view-NNNN name left in `{}`", dir.display()))?;
    for ext in ["exr", "png"] {
        let file = stem.with_extension(ext);
        image
            .save_with(&file, s.film.exposure, s.film.tonemap)
            .map_err(|e| format!("cannot write `{}`: {e}", file.display()))?;
    }
    Ok(format!("{}.exr and .png", stem.display()))
}
