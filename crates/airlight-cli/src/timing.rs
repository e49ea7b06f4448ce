//! Where a render's time went, for its closing line: the image's samples
//! apart from writing the outputs, so that a render's speed can be compared
//! with another renderer's without the cost of the file formats.

use std::time::{Duration, Instant};

/// Time spent so far in each part of a render command.
#[derive(Default)]
pub struct Timing {
    /// Rendering the samples into the image (every pass, every frame).
    image: Duration,
    /// Rendering the AOV layers (the camera's first hits).
    pub layers: Duration,
    /// Writing images, variance and samples-so-far files (encoding and
    /// compressing included).
    writing: Duration,
}

impl Timing {
    /// Runs `render`, counting its time as the image's.
    pub fn image<T>(&mut self, render: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = render();
        self.image += start.elapsed();
        out
    }

    /// Runs `render`, whose writing (timed by the `Timing` it is given)
    /// counts as writing and the rest as the image's: passes that write
    /// their outputs between them.
    pub fn image_writing<T>(&mut self, render: impl FnOnce(&mut Timing) -> T) -> T {
        let start = Instant::now();
        let mut inner = Timing::default();
        let out = render(&mut inner);
        self.writing += inner.writing;
        self.image += start.elapsed().saturating_sub(inner.writing);
        out
    }

    /// Runs `write`, counting its time as writing outputs.
    pub fn writing<T>(&mut self, write: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = write();
        self.writing += start.elapsed();
        out
    }

    /// "T (image I, writing W, setup S)" for a command that took
    /// `total`: setup is the rest (building the integrator, radiosity's
    /// solve among it, the preflight probe, moving lights between frames);
    /// the AOV layers are named when there were any.
    pub fn summary(&self, total: Duration) -> String {
        let setup = total.saturating_sub(self.image + self.layers + self.writing);
        // Three decimals below a second, where the comparisons with other
        // renderers (tools/mitsuba_compare.py) are.
        let s = |d: Duration| match d.as_secs_f64() {
            t if t < 1.0 => format!("{t:.3} s"),
            t => format!("{t:.2} s"),
        };
        let layers = if self.layers.is_zero() { String::new() } else { format!(", AOV layers {}", s(self.layers)) };
        format!("{} (image {}{layers}, writing {}, setup {})", s(total), s(self.image), s(self.writing), s(setup))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_parts_add_up_to_the_total() {
        let ms = Duration::from_millis;
        let mut timing = Timing { image: ms(400), layers: Duration::ZERO, writing: ms(190) };
        assert_eq!(timing.summary(ms(611)), "0.611 s (image 0.400 s, writing 0.190 s, setup 0.021 s)");
        timing.layers = ms(1500);
        assert_eq!(
            timing.summary(ms(2100)),
            "2.10 s (image 0.400 s, AOV layers 1.50 s, writing 0.190 s, setup 0.010 s)"
        );
        let counted = timing.image(|| 7);
        assert_eq!(counted, 7, "the closure's result is passed on");
    }
}
