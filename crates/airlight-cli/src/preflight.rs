//! What the commands check and say before (and while) they work: memory a
//! render will need, scenes that can only be black, runs that would take
//! longer than anyone means them to, images with broken pixels.

use airlight::Image;
use airlight::integrator::Integrator;
use airlight::render::RenderMode;
use airlight::scene::Scene;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Most frames one run renders (`render --frames`, `gi --frames`, `view
/// --headless --frames`): 2²⁰, about 10 hours of 30 fps video.
pub const MAX_FRAMES: u32 = 1 << 20;

/// Most worker threads (`--threads`), as the library's render job allows.
pub const MAX_THREADS: u32 = airlight::render::MAX_THREADS;

/// Refuses a render whose image and sums would not fit in memory.
pub fn render_memory(scene: &Scene, mode: RenderMode) -> Result<(), String> {
    mode.check_memory(&scene.settings().film).map_err(|e| format!("{e}: make the image smaller (--width, --height)"))
}

/// Prints a warning when every frame of `scene` will be black, and one for
/// each thing the scene asked for that Airlight does not do yet.
pub fn warn_if_dark(scene: &Scene, sees_medium: bool) {
    if let Some(why) = scene.darkness(sees_medium) {
        eprintln!("warning: {why}");
    }
    for note in scene.notes() {
        eprintln!("warning: {note}");
    }
}

/// Refuses an image with pixels that are not finite numbers: measures over
/// them would be NaN or infinite, or (max) silently skip them.
pub fn finite_pixels(image: &Image, path: &std::path::Path) -> Result<(), String> {
    let mut broken = image.pixels.iter().enumerate().filter(|(_, p)| !p.is_finite());
    let Some((first, p)) = broken.next() else {
        return Ok(());
    };
    let count = 1 + broken.count();
    let (x, y) = (first as u32 % image.width.max(1), first as u32 / image.width.max(1));
    Err(format!(
        "`{}` has {count} pixel{} that are not finite numbers (NaN or infinite), the first at ({x}, {y}): {} {} {}; \
         the measures would be meaningless",
        path.display(),
        if count == 1 { "" } else { "s" },
        p.x,
        p.y,
        p.z
    ))
}

/// Samples in [`probe`]: a 4×4 grid of pixels, one sample each.
const PROBE: u32 = 4;

/// Times one sample of each of 16 pixels spread over the image and, when
/// the whole run (`frames` frames of every pixel at the scene's spp, on
/// `threads` threads) would take more than [`Forecast::LONG`] at that
/// pace, says so: before the first tile, which at millions of samples per
/// pixel may itself take hours, reports any progress.
pub fn probe(scene: &Scene, integrator: &dyn Integrator, threads: usize, frames: u32, what: &str) -> Option<String> {
    let s = scene.settings();
    let start = Instant::now();
    for i in 0..PROBE * PROBE {
        let (x, y) =
            ((2 * (i % PROBE) + 1) * s.film.width / (2 * PROBE), (2 * (i / PROBE) + 1) * s.film.height / (2 * PROBE));
        airlight::render::pixel_sum(scene, integrator, x, y, 0..1);
    }
    let per_sample = start.elapsed().as_secs_f64() / (PROBE * PROBE) as f64;
    let samples = s.film.width as f64 * s.film.height as f64 * s.spp as f64 * frames as f64;
    let projected = per_sample * samples / threads.max(1) as f64;
    (projected > Forecast::LONG.as_secs_f64()).then(|| {
        format!(
            "warning: by a probe of {} samples, {what} will take about {} on {threads} threads (stop it with Ctrl-C)",
            PROBE * PROBE,
            human(projected)
        )
    })
}

/// A run's projected length, from its pace so far: once a few seconds in,
/// it warns (once) when the whole run would take more than [`Forecast::LONG`].
pub struct Forecast {
    start: Instant,
    total: u64,
    what: String,
    state: Mutex<(u64, bool)>,
}

impl Forecast {
    /// Runs projected longer than this are warned about.
    pub const LONG: Duration = Duration::from_secs(3600);
    /// The pace is measured over at least this long before a projection.
    const SETTLE: Duration = Duration::from_secs(2);

    /// A run of `total` units of work (pixel samples, frames), described
    /// by `what`; `warned`: the warning was already given (by [`probe`]).
    pub fn new(total: u64, what: impl Into<String>, warned: bool) -> Self {
        Forecast { start: Instant::now(), total, what: what.into(), state: Mutex::new((0, warned)) }
    }

    /// Counts `done` more units; returns the warning when it is time to give it.
    pub fn advance(&self, done: u64) -> Option<String> {
        let mut state = self.state.lock().ok()?;
        state.0 += done;
        let elapsed = self.start.elapsed();
        if state.1 || elapsed < Self::SETTLE || state.0 == 0 {
            return None;
        }
        let projected = elapsed.as_secs_f64() * self.total as f64 / state.0 as f64;
        if projected < Self::LONG.as_secs_f64() {
            return None;
        }
        state.1 = true;
        Some(format!(
            "warning: at its pace so far, {} will take about {} (stop it with Ctrl-C)",
            self.what,
            human(projected)
        ))
    }
}

/// Seconds as the largest unit that keeps the figure ≥ 1: "3.2 days".
pub fn human(seconds: f64) -> String {
    let units = [(365.25 * 86400.0, "years"), (86400.0, "days"), (3600.0, "hours"), (60.0, "minutes")];
    for (size, name) in units {
        if seconds >= size {
            return format!("{:.1} {name}", seconds / size);
        }
    }
    format!("{seconds:.0} s")
}

#[cfg(test)]
mod tests {
    use super::*;
    use airlight::Rgb;

    #[test]
    fn nan_pixels_are_counted_and_located() {
        let mut image = Image::new(3, 2);
        assert_eq!(finite_pixels(&image, "a.exr".as_ref()), Ok(()));
        image.pixels[4] = Rgb::new(f32::NAN, 0.0, 1.0);
        image.pixels[5] = Rgb::splat(f32::INFINITY);
        let e = finite_pixels(&image, "a.exr".as_ref()).unwrap_err();
        assert!(
            e.starts_with("`a.exr` has 2 pixels that are not finite numbers (NaN or infinite), the first at (1, 1)")
        );
    }

    #[test]
    fn a_run_projected_past_an_hour_is_warned_about_once() {
        let f = Forecast {
            start: Instant::now() - Duration::from_secs(10),
            ..Forecast::new(1_000_000, "this render", false)
        };
        assert_eq!(
            f.advance(1_000),
            Some("warning: at its pace so far, this render will take about 2.8 hours (stop it with Ctrl-C)".into())
        );
        assert_eq!(f.advance(1_000), None);
        let quick = Forecast { start: Instant::now() - Duration::from_secs(10), ..Forecast::new(1_000, "that", false) };
        assert_eq!(quick.advance(500), None);
        assert_eq!(human(3.0 * 86400.0), "3.0 days");
        assert_eq!(human(42.0), "42 s");
    }
}
