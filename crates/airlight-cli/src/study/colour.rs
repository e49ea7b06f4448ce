//! Error maps in colour: |image − truth| per pixel (mean over channels) on
//! a logarithmic scale of three decades, [scale/1000, scale], through a
//! dark-to-bright ramp (matplotlib's "inferno", sampled at eight points),
//! so that both a good and a poor method show where their error lies. The
//! page draws the legend with the same stops.

use airlight::Rgb;
use airlight::film::Image;

/// Decades the scale spans below `scale`.
pub const DECADES: f64 = 3.0;

/// The ramp's stops, sRGB, from no error to `scale` and above.
const STOPS: [[u8; 3]; 8] = [
    [0, 0, 4],
    [40, 11, 84],
    [101, 21, 110],
    [159, 42, 99],
    [212, 72, 66],
    [245, 125, 21],
    [250, 193, 39],
    [252, 255, 164],
];

/// The ramp at t in [0, 1], sRGB in [0, 1] (interpolated in sRGB, as CSS
/// gradients are).
fn ramp(t: f64) -> [f64; 3] {
    let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    std::array::from_fn(|c| (a[c] as f64 + f * (b[c] as f64 - a[c] as f64)) / 255.0)
}

/// Where an absolute error falls on the scale: 0 at scale/1000 and below,
/// 1 at scale and above.
pub fn position(error: f64, scale: f64) -> f64 {
    if error.is_nan() || error <= 0.0 {
        return 0.0;
    }
    ((error / scale).log10() / DECADES + 1.0).clamp(0.0, 1.0)
}

fn srgb_to_linear(v: f64) -> f32 {
    (if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }) as f32
}

/// The colour map of |image − truth|. Images are of one size (the study
/// renders them so).
pub fn error_map(image: &Image, truth: &Image, scale: f64) -> Image {
    let pixels = image
        .pixels
        .iter()
        .zip(&truth.pixels)
        .map(|(a, b)| {
            let e = (*a - *b).abs().element_sum() as f64 / 3.0;
            let [r, g, b] = ramp(position(e, scale));
            Rgb::new(srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b))
        })
        .collect();
    // PNGs are written from linear values through the sRGB curve, which
    // gives back the ramp's colours.
    Image { width: image.width, height: image.height, pixels }
}

/// A CSS `linear-gradient` of the ramp, left to right.
pub fn css_gradient() -> String {
    let stops: Vec<String> = STOPS.iter().map(|[r, g, b]| format!("rgb({r},{g},{b})")).collect();
    format!("linear-gradient(to right, {})", stops.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;
    use airlight::film::to_srgb8;

    #[test]
    fn the_scale_is_logarithmic_over_three_decades() {
        assert_eq!(position(0.0, 2.0), 0.0);
        assert_eq!(position(f64::NAN, 2.0), 0.0);
        assert_eq!(position(0.002, 2.0), 0.0);
        assert!((position(0.02, 2.0) - 1.0 / 3.0).abs() < 1e-12);
        assert!((position(0.2, 2.0) - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(position(5.0, 2.0), 1.0);
    }

    #[test]
    fn map_pixels_come_out_as_the_ramps_colours() {
        let truth = Image { width: 2, height: 1, pixels: vec![Rgb::splat(1.0); 2] };
        let image = Image { width: 2, height: 1, pixels: vec![Rgb::splat(1.0), Rgb::splat(3.0)] };
        let map = error_map(&image, &truth, 1.0);
        let srgb = |p: Rgb| [to_srgb8(p.x), to_srgb8(p.y), to_srgb8(p.z)];
        assert_eq!(srgb(map.pixels[0]), STOPS[0]);
        assert_eq!(srgb(map.pixels[1]), STOPS[7]);
    }
}
