//! The viewer's frame loop, shared by the window and the headless mode: it
//! takes the camera and the lights of the frame, relights the radiosity
//! solution when the lights moved, and renders more samples into a running
//! mean, starting over whenever anything changed.

use airlight::film::{Accumulator, Image, PixelSum};
use airlight::integrator::{Integrator, IntegratorDesc, IntegratorKind};
use airlight::preview::{Fill, FirstSample, Preview};
use airlight::radiosity::Radiosity;
use airlight::render::{RenderObserver, accumulate_into};
use airlight::{Camera, Scene, SceneFile, light::Light};
use rayon::prelude::*;
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
    /// The scene file's integrator options (steps, sampling, bounces, …).
    pub integrators: IntegratorDesc,
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
    /// The running mean's samples (see [`Samples`]).
    accumulator: Samples,
    samples: u32,
    lights_dirty: bool,
    /// Whether the camera moved since the last frame.
    camera_moved: bool,
    /// The preview's first sample, kept while the camera stands still.
    first: FirstSample,
}

/// The samples of the running mean. A frame with a single sample per
/// pixel, all a moving camera ever gets, is kept as rendered: its per-pixel
/// sums (about 100 bytes a pixel, 24 MB at 640×360) would be made, zeroed
/// and thrown away at every frame. A moving camera's is made with the
/// preview's sparse lookups ([`Fill::Sparse`]), and made again exactly
/// when the camera stops, before samples are added to it.
enum Samples {
    None,
    First(Image, Fill),
    Sums(Accumulator),
}

/// The samples so far as sums of a `width`×`height` image, taken out of
/// `samples` (a size change, or no samples yet, starts from none).
fn take_sums(samples: &mut Samples, (width, height): (u32, u32)) -> Accumulator {
    match std::mem::replace(samples, Samples::None) {
        Samples::Sums(sums) if sums.size() == (width, height) => sums,
        Samples::First(image, _) if (image.width, image.height) == (width, height) => sums_of(&image),
        _ => Accumulator::new(width, height),
    }
}

/// The sums of a one-sample image, as the renderer's accumulator holds them.
fn sums_of(image: &Image) -> Accumulator {
    let mut sums = Accumulator::new(image.width, image.height);
    sums.pixels_mut().par_iter_mut().zip(&image.pixels).for_each(|(sum, &p)| sum.add(p));
    sums
}

impl Engine {
    /// Compiles the scene's radiosity (the costly step: once) and renders at
    /// `width`×`height`. A scene that cannot be compiled (too many patches)
    /// is still viewed, without indirect light; `solution_note` says why.
    pub fn new(file: SceneFile, width: u32, height: u32, mode: Mode) -> Engine {
        let SceneFile { mut scene, integrator: integrators } = file;
        (scene.settings_mut().film.width, scene.settings_mut().film.height) = (width, height);
        let (solution, solution_note) = match Radiosity::compile(&scene, &integrators.radiosity) {
            Ok(s) => (Some(s), None),
            Err(e) => (None, Some(format!("no indirect light: {e}"))),
        };
        Engine {
            first: FirstSample::new(&scene),
            scene,
            integrators,
            solution,
            solution_note,
            mode,
            full: (width, height),
            scale: 1,
            batch: 4,
            max_spp: 1024,
            accumulator: Samples::None,
            samples: 0,
            lights_dirty: false,
            camera_moved: false,
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
        (self.scene.settings().film.width, self.scene.settings().film.height)
    }

    pub fn full_size(&self) -> (u32, u32) {
        self.full
    }

    fn restart(&mut self) {
        self.samples = 0;
        self.accumulator = Samples::None;
    }

    pub fn set_mode(&mut self, mode: Mode) {
        if mode != self.mode {
            self.mode = mode;
            self.restart();
        }
    }

    pub fn set_camera(&mut self, camera: Camera) {
        if camera != *self.scene.camera() {
            self.scene.set_camera(camera);
            self.camera_moved = true;
            self.restart();
        }
    }

    /// Moves the lights (same number and order as the scene's).
    pub fn set_lights(&mut self, lights: &[Light]) {
        if lights != self.scene.lights() {
            self.scene.set_lights(lights);
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
            let s = self.scene.settings_mut();
            s.film.width = (self.full.0 / scale).max(1);
            s.film.height = (self.full.1 / scale).max(1);
            self.restart();
        }
    }

    /// One frame: relight if the lights moved (the preview needs it; the
    /// other integrators relight on their own), then add samples: one after
    /// a change, then doubling up to `batch` per frame, until `max_spp`.
    /// The samples are numbered across frames, so once the camera stands
    /// still the running mean is the same image as one render of that many
    /// samples (a moving camera's frames interpolate the indirect light).
    pub fn frame(&mut self) -> FrameStats {
        let mut stats = FrameStats::default();
        let moving = std::mem::take(&mut self.camera_moved);
        if !moving && matches!(self.accumulator, Samples::First(_, Fill::Sparse)) {
            // The camera stopped: its first sample again, exactly.
            self.restart();
        }
        if self.lights_dirty
            && self.mode == Mode::Preview
            && let Some(solution) = &mut self.solution
        {
            let t = Instant::now();
            solution.update(&self.scene, self.integrators.radiosity.bounces);
            stats.radiosity = t.elapsed();
            self.lights_dirty = false;
        }
        let count = self.samples.max(1).min(self.batch.max(1)).min(self.max_spp.saturating_sub(self.samples));
        if count > 0 {
            let t = Instant::now();
            let size = self.size();
            match self.mode {
                Mode::Preview => {
                    let preview = Preview::new(
                        &self.scene,
                        self.solution.as_ref(),
                        self.integrators.analytic,
                        self.integrators.raymarch,
                    );
                    if self.samples == 0 && count == 1 {
                        // The same samples as rendering sample 0, from hits
                        // kept while the camera stands still; while it
                        // moves, with the indirect light interpolated.
                        let fill = if moving { Fill::Sparse } else { Fill::Exact };
                        let image = self.first.render(&self.scene, self.solution.as_ref(), &preview, fill);
                        self.accumulator = Samples::First(image, fill);
                        self.samples = 1;
                        stats.image = t.elapsed();
                        stats.added = 1;
                        stats.samples = 1;
                        return stats;
                    }
                    // Taken only now: a first-sample frame keeps no sums.
                    let mut sums = take_sums(&mut self.accumulator, size);
                    self.add_samples(&preview, count, &mut sums);
                    self.accumulator = Samples::Sums(sums);
                }
                Mode::Raymarch | Mode::Stochastic => {
                    let kind =
                        if self.mode == Mode::Raymarch { IntegratorKind::Raymarch } else { IntegratorKind::Stochastic };
                    // Progressive refinement wants jittered march samples.
                    let mut desc = self.integrators.with_kind(kind);
                    desc.raymarch.jitter = true;
                    let mut sums = take_sums(&mut self.accumulator, size);
                    if let Ok(integrator) = desc.build(&self.scene) {
                        self.add_samples(integrator.as_ref(), count, &mut sums);
                    }
                    self.accumulator = Samples::Sums(sums);
                }
            }
            self.samples += count;
            stats.image = t.elapsed();
        }
        stats.added = count;
        stats.samples = self.samples;
        stats
    }

    /// The preview integrator for the scene's current lights.
    pub fn preview(&self) -> Preview<'_> {
        Preview::new(&self.scene, self.solution.as_ref(), self.integrators.analytic, self.integrators.raymarch)
    }

    /// Adds the next `count` samples of every pixel into `sums`, in place:
    /// no pass-sized accumulator to fault in and merge each frame.
    fn add_samples(&self, integrator: &dyn Integrator, count: u32, sums: &mut Accumulator) {
        let first = self.samples as u64;
        accumulate_into(&self.scene, integrator, first..first + count as u64, sums, &RenderObserver::none());
    }

    /// The running mean at the current render size (black before the
    /// first frame).
    pub fn image(&self) -> Image {
        match &self.accumulator {
            Samples::None => Image::new(self.size().0, self.size().1),
            // Each pixel as the accumulator would give it, without making one.
            Samples::First(image, _) => {
                Image { pixels: image.pixels.par_iter().map(|&p| PixelSum::of_one(p).mean()).collect(), ..*image }
            }
            Samples::Sums(sums) => sums.image(),
        }
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
        let file = SceneFile::from_toml_str(super::super::DEFAULT_SCENE, None).unwrap();
        let mut e = Engine::new(file, 32, 18, Mode::Preview);
        e.batch = 4;
        e
    }

    /// The engine's scene, at its size, rendered with `spp` samples: what
    /// its running mean must equal.
    fn reference(spp: u32) -> Scene {
        let mut scene = SceneFile::from_toml_str(super::super::DEFAULT_SCENE, None).unwrap().scene;
        let s = scene.settings_mut();
        (s.film.width, s.film.height, s.spp) = (32, 18, spp);
        scene
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
        let scene = reference(8);
        let preview = e.preview();
        let once = airlight::render(&scene, &preview, &RenderObserver::none());
        // One accumulator under both: the same bits.
        assert_eq!(e.image(), once);
    }

    #[test]
    fn a_first_frame_kept_as_an_image_is_the_one_sample_render_and_refines_the_same() {
        let mut scene = reference(1);
        let mut e = engine();
        e.frame();
        assert!(matches!(e.accumulator, Samples::First(_, Fill::Exact)));
        let once = airlight::render(&scene, &e.preview(), &RenderObserver::none());
        assert_eq!(e.image(), once);
        e.frame();
        scene.settings_mut().spp = 2;
        assert_eq!(e.image(), airlight::render(&scene, &e.preview(), &RenderObserver::none()));
    }

    #[test]
    fn a_moving_camera_interpolates_and_a_stopped_one_renders_its_first_sample_again_exactly() {
        let mut e = engine();
        e.frame();
        let mut camera = *e.scene.camera();
        for step in 1..=2 {
            camera.position.x += 0.05 * step as f32;
            e.set_camera(camera);
            let stats = e.frame();
            assert_eq!((stats.added, stats.samples), (1, 1));
            assert!(matches!(e.accumulator, Samples::First(_, Fill::Sparse)));
        }
        let mut scene = reference(1);
        scene.set_camera(camera);
        let exact = airlight::render(&scene, &e.preview(), &RenderObserver::none());
        // Stopped: sample 0 again, exactly, then the running mean refines.
        e.set_camera(camera);
        let stats = e.frame();
        assert_eq!((stats.added, stats.samples), (1, 1));
        assert!(matches!(e.accumulator, Samples::First(_, Fill::Exact)));
        assert_eq!(e.image(), exact);
        e.frame();
        scene.settings_mut().spp = 2;
        assert_eq!(e.image(), airlight::render(&scene, &e.preview(), &RenderObserver::none()));
    }

    #[test]
    fn moving_a_light_relights_and_starts_over_while_a_still_one_does_not() {
        let mut e = engine();
        e.frame();
        e.frame();
        let same = e.scene.lights().to_vec();
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
