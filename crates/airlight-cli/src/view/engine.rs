//! The viewer's frame loop, shared by the window and the headless mode: it
//! takes the camera and the lights of the frame, relights the radiosity
//! solution when the lights moved, and renders more samples into a running
//! mean, starting over whenever anything changed.

use airlight::film::Image;
use airlight::integrator::{Integrator, Raymarch, Stochastic};
use airlight::preview::{FirstSample, Preview, set_lights};
use airlight::radiosity::Radiosity;
use airlight::render::{RenderObserver, render_samples};
use airlight::{Camera, Scene, light::Light};
use glam::DVec3;
use std::time::{Duration, Instant};

/// The integrators the number keys pick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Key 1: direct light + radiosity indirect + analytic glow.
    Preview,
    /// Key 2: the ray-marching integrator (the scene's `steps`).
    Raymarch,
    /// Key 3: the stochastic single-scattering integrator.
    Stochastic,
}

impl Mode {
    pub const ALL: [Mode; 3] = [Mode::Preview, Mode::Raymarch, Mode::Stochastic];

    pub fn name(self) -> &'static str {
        match self {
            Mode::Preview => "preview",
            Mode::Raymarch => "raymarch",
            Mode::Stochastic => "stochastic",
        }
    }

    pub fn parse(s: &str) -> Result<Mode, String> {
        Mode::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("unknown viewer integrator `{s}`; expected preview, raymarch or stochastic"))
    }
}

/// What one call of [`Engine::frame`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Relighting the radiosity solution (zero when the lights stood still).
    pub radiosity: Duration,
    /// Rendering this frame's samples and adding them in.
    pub image: Duration,
    /// Samples per pixel rendered this frame (0 once `max_spp` is reached).
    pub added: u32,
    /// Samples per pixel in the running mean after this frame.
    pub samples: u32,
}

impl FrameStats {
    pub fn total(&self) -> Duration {
        self.radiosity + self.image
    }
}

/// The viewer's renderer: a scene whose camera and lights change between
/// frames, its radiosity solution, and the running mean of the samples
/// rendered since the last change.
pub struct Engine {
    pub scene: Scene,
    solution: Option<Radiosity>,
    /// Why there is no solution, when there is none.
    pub solution_note: Option<String>,
    mode: Mode,
    full: (u32, u32),
    scale: u32,
    /// Most samples a still frame adds (passes double up to this).
    pub batch: u32,
    /// Accumulation stops here.
    pub max_spp: u32,
    sum: Vec<DVec3>,
    samples: u32,
    lights_dirty: bool,
    /// The preview's first sample, kept while the camera stands still.
    first: FirstSample,
}

impl Engine {
    /// Compiles the scene's radiosity (the costly step: once) and renders at
    /// `width`×`height`. A scene that cannot be compiled (too many patches)
    /// is still viewed, without indirect light; `solution_note` says why.
    pub fn new(mut scene: Scene, width: u32, height: u32, mode: Mode) -> Engine {
        (scene.settings.width, scene.settings.height) = (width, height);
        let (solution, solution_note) = match Radiosity::compile(&scene) {
            Ok(s) => (Some(s), None),
            Err(e) => (None, Some(format!("no indirect light: {e}"))),
        };
        Engine {
            first: FirstSample::new(&scene),
            scene,
            solution,
            solution_note,
            mode,
            full: (width, height),
            scale: 1,
            batch: 4,
            max_spp: 1024,
            sum: Vec::new(),
            samples: 0,
            lights_dirty: false,
        }
    }

    pub fn solution(&self) -> Option<&Radiosity> {
        self.solution.as_ref()
    }

    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Samples per pixel in the running mean.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// The size frames are rendered at now.
    pub fn size(&self) -> (u32, u32) {
        (self.scene.settings.width, self.scene.settings.height)
    }

    pub fn full_size(&self) -> (u32, u32) {
        self.full
    }

    fn restart(&mut self) {
        self.samples = 0;
        self.sum.clear();
    }

    pub fn set_mode(&mut self, mode: Mode) {
        if mode != self.mode {
            self.mode = mode;
            self.restart();
        }
    }

    pub fn set_camera(&mut self, camera: Camera) {
        if camera != self.scene.camera {
            self.scene.camera = camera;
            self.restart();
        }
    }

    /// Moves the lights (same number and order as the scene's).
    pub fn set_lights(&mut self, lights: &[Light]) {
        if lights != self.scene.lights.as_slice() {
            set_lights(&mut self.scene, lights);
            self.lights_dirty = true;
            self.restart();
        }
    }

    /// Renders at 1/`scale` of the full size in each direction (dynamic
    /// resolution while moving); 1 is full size.
    pub fn set_scale(&mut self, scale: u32) {
        let scale = scale.max(1);
        if scale != self.scale {
            self.scale = scale;
            let s = &mut self.scene.settings;
            s.width = (self.full.0 / scale).max(1);
            s.height = (self.full.1 / scale).max(1);
            self.restart();
        }
    }

    /// One frame: relight if the lights moved (the preview needs it; the
    /// other integrators relight on their own), then add samples: one after
    /// a change, then doubling up to `batch` per frame, until `max_spp`.
    /// The samples are numbered across frames, so the running mean is the
    /// same image as one render of that many samples.
    pub fn frame(&mut self) -> FrameStats {
        let mut stats = FrameStats::default();
        if self.lights_dirty
            && self.mode == Mode::Preview
            && let Some(solution) = &mut self.solution
        {
            let t = Instant::now();
            solution.update_with(&self.scene, &self.scene.lights, self.scene.settings.bounces);
            stats.radiosity = t.elapsed();
            self.lights_dirty = false;
        }
        let count = self.samples.max(1).min(self.batch.max(1)).min(self.max_spp.saturating_sub(self.samples));
        if count > 0 {
            let t = Instant::now();
            let s = &self.scene.settings;
            let image = match self.mode {
                Mode::Preview => {
                    let preview = Preview::new(&self.scene, self.solution.as_ref());
                    if self.samples == 0 && count == 1 {
                        // The same image as rendering sample 0, from
                        // hits kept while the camera stands still.
                        self.first.render(&self.scene, self.solution.as_ref(), &preview)
                    } else {
                        self.render(&preview, count)
                    }
                }
                Mode::Raymarch => self.render(&Raymarch { steps: s.steps, jitter: true }, count),
                Mode::Stochastic => self.render(&Stochastic { sampling: s.sampling, stratify: s.stratify }, count),
            };
            if self.sum.len() != image.pixels.len() {
                self.sum = vec![DVec3::ZERO; image.pixels.len()];
            }
            for (acc, p) in self.sum.iter_mut().zip(&image.pixels) {
                *acc += p.as_dvec3() * count as f64;
            }
            self.samples += count;
            stats.image = t.elapsed();
        }
        stats.added = count;
        stats.samples = self.samples;
        stats
    }

    fn render(&self, integrator: &dyn Integrator, count: u32) -> Image {
        render_samples(&self.scene, integrator, self.samples as u64, count, &RenderObserver::none())
    }

    /// The running mean at the current render size (black before the
    /// first frame).
    pub fn image(&self) -> Image {
        let (w, h) = self.size();
        let n = self.samples.max(1) as f64;
        let mut image = Image::new(w, h);
        for (p, s) in image.pixels.iter_mut().zip(&self.sum) {
            *p = (*s / n).as_vec3();
        }
        image
    }

    #[cfg(test)]
    /// Whether moved lights still wait for the solution to be relit (the
    /// preview relights on its next frame).
    pub fn lights_pending(&self) -> bool {
        self.lights_dirty
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use airlight::prelude::*;

    fn engine() -> Engine {
        let scene = airlight::scene::from_toml_str(super::super::DEFAULT_SCENE, None).unwrap();
        let mut e = Engine::new(scene, 32, 18, Mode::Preview);
        e.batch = 4;
        e
    }

    #[test]
    fn still_frames_accumulate_one_then_doubling_up_to_the_batch_then_stop() {
        let mut e = engine();
        e.max_spp = 12;
        let added: Vec<u32> = (0..6).map(|_| e.frame().added).collect();
        assert_eq!(added, [1, 1, 2, 4, 4, 0]);
        assert_eq!(e.samples(), 12);
    }

    #[test]
    fn the_running_mean_is_the_same_as_one_render_of_that_many_samples() {
        let mut e = engine();
        for _ in 0..4 {
            e.frame();
        }
        assert_eq!(e.samples(), 8);
        let mut scene = airlight::scene::from_toml_str(super::super::DEFAULT_SCENE, None).unwrap();
        (scene.settings.width, scene.settings.height, scene.settings.spp) = (32, 18, 8);
        let preview = Preview::new(&scene, e.solution());
        let once = airlight::render::render_with(&scene, &preview, &RenderObserver::none());
        let mean = e.image();
        for (a, b) in mean.pixels.iter().zip(&once.pixels) {
            assert!((*a - *b).abs().max_element() <= 1e-5 * b.max_element().max(1.0), "{a} vs {b}");
        }
    }

    #[test]
    fn moving_a_light_relights_and_starts_over_while_a_still_one_does_not() {
        let mut e = engine();
        e.frame();
        e.frame();
        let same = e.scene.lights.clone();
        e.set_lights(&same);
        assert_eq!(e.samples(), 2);
        assert!(!e.lights_pending());
        let moved: Vec<Light> = same.iter().map(|l| l.moved_to(vec3(1.0, 5.4, 1.0))).collect();
        e.set_lights(&moved);
        assert_eq!(e.samples(), 0);
        let stats = e.frame();
        assert!(stats.radiosity > Duration::ZERO);
        assert_eq!(stats.added, 1);
        assert!(!e.lights_pending());
    }

    #[test]
    fn scaling_renders_smaller_and_changing_mode_starts_over() {
        let mut e = engine();
        e.frame();
        e.set_scale(2);
        assert_eq!(e.size(), (16, 9));
        e.frame();
        assert_eq!(e.image().width, 16);
        e.set_mode(Mode::Raymarch);
        assert_eq!(e.samples(), 0);
        e.frame();
        assert!(e.image().mean().max_element() > 0.0);
        e.set_scale(1);
        assert_eq!(e.size(), (32, 18));
    }
}
