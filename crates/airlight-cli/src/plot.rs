//! A small line plot with axes, ticks and a legend, written as a PNG: enough
//! to compare attenuation curves without a plotting library.

use airlight::Rgb;
use airlight::film::Image;
use font8x8::UnicodeFonts;

pub struct Series {
    pub label: String,
    pub color: Rgb,
    pub points: Vec<(f32, f32)>,
}

pub struct Plot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_max: f32,
    /// The y axis spans [y_min, y_max]; with `log_y`, in powers of ten
    /// (10^y_min to 10^y_max), values at or below 10^y_min on the bottom.
    pub y_min: f32,
    pub y_max: f32,
    pub log_y: bool,
    pub series: Vec<Series>,
}

const W: u32 = 900;
const H: u32 = 560;
const LEFT: f32 = 90.0;
const RIGHT: f32 = 24.0;
const TOP: f32 = 50.0;
const BOTTOM: f32 = 70.0;
const TEXT: u32 = 2; // font scale: 16-pixel characters

struct Canvas(Image);

impl Canvas {
    fn set(&mut self, x: i64, y: i64, c: Rgb) {
        if x >= 0 && y >= 0 && (x as u32) < W && (y as u32) < H {
            self.0.pixels[(y as u32 * W + x as u32) as usize] = c;
        }
    }

    /// A line `width` pixels thick, by stepping along its longer axis.
    fn line(&mut self, (x0, y0): (f32, f32), (x1, y1): (f32, f32), c: Rgb, width: i64) {
        let steps = (x1 - x0).abs().max((y1 - y0).abs()).ceil().max(1.0) as i64;
        for i in 0..=steps {
            let t = i as f32 / steps as f32;
            let (x, y) = (x0 + (x1 - x0) * t, y0 + (y1 - y0) * t);
            for dx in 0..width {
                for dy in 0..width {
                    self.set(x.round() as i64 + dx - width / 2, y.round() as i64 + dy - width / 2, c);
                }
            }
        }
    }

    fn text(&mut self, x: f32, y: f32, s: &str, c: Rgb) {
        for (i, ch) in s.chars().enumerate() {
            let Some(glyph) = font8x8::BASIC_FONTS.get(ch) else { continue };
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..8 {
                    if bits & (1 << col) != 0 {
                        for sy in 0..TEXT {
                            for sx in 0..TEXT {
                                let px = x as i64 + ((i as u32 * 8 + col) * TEXT + sx) as i64;
                                let py = y as i64 + (row as u32 * TEXT + sy) as i64;
                                self.set(px, py, c);
                            }
                        }
                    }
                }
            }
        }
    }
}

fn text_width(s: &str) -> f32 {
    (s.chars().count() as u32 * 8 * TEXT) as f32
}

/// A tick spacing of 1, 2 or 5 times a power of ten giving about `count`
/// ticks; `max` positive and finite (else the spacing is `max` itself).
fn tick_step(max: f32, count: f32) -> f32 {
    let raw = max / count;
    if !(raw.is_normal() && raw > 0.0) {
        return max;
    }
    // In f64: a power of ten near f32's ends (1e-40, 1e38) would round to 0 or ∞.
    let power = 10f64.powf((raw as f64).log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0].into_iter().map(|m| m * power).find(|s| *s >= raw as f64).unwrap_or(10.0 * power);
    step as f32
}

/// `v` with as many decimals as `step` needs; in scientific notation when
/// that would be more than a few (spans of 1e-20, or beyond 1e6).
fn label(v: f32, step: f32) -> String {
    let magnitude = step.abs().log10();
    if !magnitude.is_finite() || !(-4.0..=6.0).contains(&magnitude) {
        return format!("{v:.1e}");
    }
    let decimals = (-magnitude.floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

impl Plot {
    /// The plot as an image; `x_max` and the y range must be finite and
    /// non-empty (else nothing sensible can be drawn: an error says so).
    pub fn render(&self) -> Result<Image, String> {
        if !(self.x_max.is_finite() && self.x_max > 0.0) {
            return Err(format!("the x axis must span a positive finite length, got 0 to {}", self.x_max));
        }
        if !(self.y_min.is_finite() && self.y_max.is_finite() && self.y_min < self.y_max) {
            return Err(format!("the y axis must span a finite range, got {} to {}", self.y_min, self.y_max));
        }
        Ok(self.draw())
    }

    fn draw(&self) -> Image {
        let mut c = Canvas(Image { width: W, height: H, pixels: vec![Rgb::ONE; (W * H) as usize] });
        let (x0, x1, y0, y1) = (LEFT, W as f32 - RIGHT, H as f32 - BOTTOM, TOP);
        let to_px = |x: f32, y: f32| {
            let y = if self.log_y { y.max(10f32.powf(self.y_min)).log10() } else { y }.clamp(self.y_min, self.y_max);
            (x0 + (x1 - x0) * x / self.x_max, y0 + (y1 - y0) * (y - self.y_min) / (self.y_max - self.y_min))
        };
        let grey = Rgb::splat(0.8);
        let black = Rgb::ZERO;
        for (axis_min, axis_max, vertical) in [(0.0, self.x_max, true), (self.y_min, self.y_max, false)] {
            let log = !vertical && self.log_y;
            let step = if log { 1.0 } else { tick_step(axis_max - axis_min, 6.0) };
            let mut v = axis_min;
            // At most a few dozen ticks, whatever rounding does to the steps.
            let mut ticks = 0;
            while v <= axis_max + (axis_max - axis_min) * 1e-4 && ticks < 40 {
                ticks += 1;
                if vertical {
                    let (px, _) = to_px(v, 0.0);
                    c.line((px, y0), (px, y1), grey, 1);
                    let s = label(v, step);
                    c.text(px - text_width(&s) / 2.0, y0 + 8.0, &s, black);
                } else {
                    let (_, py) = to_px(0.0, if log { 10f32.powf(v) } else { v });
                    c.line((x0, py), (x1, py), grey, 1);
                    let s = if log { format!("1e{v}") } else { label(v, step) };
                    c.text(x0 - text_width(&s) - 8.0, py - 8.0, &s, black);
                }
                v += step;
            }
        }
        c.line((x0, y0), (x1, y0), black, 2);
        c.line((x0, y0), (x0, y1), black, 2);
        c.text((x0 + x1 - text_width(&self.x_label)) / 2.0, H as f32 - 30.0, &self.x_label, black);
        c.text(8.0, 12.0, &self.y_label, black);
        c.text((W as f32 - text_width(&self.title)) / 2.0, 12.0, &self.title, black);
        for s in &self.series {
            for pair in s.points.windows(2) {
                let a = to_px(pair[0].0, pair[0].1);
                let b = to_px(pair[1].0, pair[1].1);
                c.line(a, b, s.color, 3);
            }
        }
        // Legend, top right.
        let widest = self.series.iter().map(|s| text_width(&s.label)).fold(0.0, f32::max);
        let lx = x1 - widest - 60.0;
        for (i, s) in self.series.iter().enumerate() {
            let ly = y1 + 12.0 + i as f32 * 22.0;
            c.line((lx, ly + 8.0), (lx + 36.0, ly + 8.0), s.color, 4);
            c.text(lx + 44.0, ly, &s.label, black);
        }
        c.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_numbers() {
        assert_eq!(tick_step(10.0, 5.0), 2.0);
        assert_eq!(tick_step(1.0, 6.0), 0.2);
        assert_eq!(tick_step(37.0, 6.0), 10.0);
        assert_eq!(label(0.4, 0.2), "0.4");
        assert_eq!(label(20.0, 10.0), "20");
        // Spans near f32's ends (attenuation --radius 1e-20, --cutoff 1e-45).
        assert_eq!(tick_step(1e-20, 6.0), 2e-21);
        assert_eq!(tick_step(3e38, 6.0), 5e37);
        assert_eq!(tick_step(0.0, 6.0), 0.0);
        assert_eq!(label(2e-21, 2e-21), "2.0e-21");
        assert_eq!(label(1e23, 2e22), "1.0e23");
    }

    #[test]
    fn a_plot_draws_its_series_in_their_colours() {
        let red = Rgb::new(1.0, 0.0, 0.0);
        let plot = Plot {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            x_max: 1.0,
            y_min: 0.0,
            y_max: 1.0,
            log_y: false,
            series: vec![Series { label: "line".into(), color: red, points: vec![(0.0, 0.5), (1.0, 0.5)] }],
        };
        let img = plot.render().unwrap();
        // The middle of the plot area at y = 0.5 is red.
        let (x, y) = ((LEFT + (W as f32 - RIGHT)) / 2.0, ((H as f32 - BOTTOM) + TOP) / 2.0);
        assert_eq!(img.pixel(x as u32, y as u32), red);
        assert_eq!(img.pixel(W - 2, H - 2), Rgb::ONE, "background");
    }
}
