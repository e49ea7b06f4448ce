//! The error measures that `airlight compare` prints, and error maps.

use super::Image;
use crate::Rgb;

/// Differences between an image and a reference, over all pixels and channels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageError {
    /// √(mean (a − b)²)
    pub rmse: f64,
    /// mean (a − b)² / (b² + 0.01): the relative MSE of Rousselle, Knaus and
    /// Zwicker (2011), ε = 0.01 keeping dark pixels from dominating.
    pub rel_mse: f64,
    /// mean |a − b|
    pub mae: f64,
    /// max |a − b|
    pub max: f64,
    /// √(Σ (a − b)² / Σ b²): the RMSE relative to the reference's RMS. The
    /// "relative RMSE" that tests and benchmarks quote.
    pub rel_rmse: f64,
}

/// Compares `image` against `reference`; None if their sizes differ.
pub fn compare(image: &Image, reference: &Image) -> Option<ImageError> {
    if image.width != reference.width || image.height != reference.height {
        return None;
    }
    let (mut se, mut rel, mut abs, mut max, mut ref2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (a, b) in image.pixels.iter().zip(&reference.pixels) {
        for c in 0..3 {
            let (a, b) = (a[c] as f64, b[c] as f64);
            let d = a - b;
            se += d * d;
            rel += d * d / (b * b + 0.01);
            abs += d.abs();
            max = max.max(d.abs());
            ref2 += b * b;
        }
    }
    let n = (image.pixels.len() * 3).max(1) as f64;
    Some(ImageError {
        rmse: (se / n).sqrt(),
        rel_mse: rel / n,
        mae: abs / n,
        max,
        rel_rmse: if ref2 > 0.0 {
            (se / ref2).sqrt()
        } else if se == 0.0 {
            0.0
        } else {
            f64::INFINITY
        },
    })
}

/// An error map: |a − b| averaged over channels, scaled so that `scale`
/// maps to white.
pub fn error_map(image: &Image, reference: &Image, scale: f32) -> Image {
    let pixels = image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, b)| Rgb::splat(((*a - *b).abs().element_sum() / 3.0) / scale.max(1e-30)))
        .collect();
    Image { width: image.width, height: image.height, pixels }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compare_measures_known_differences() {
        let a = Image { width: 2, height: 1, pixels: vec![Rgb::splat(1.0), Rgb::splat(0.0)] };
        let b = Image { width: 2, height: 1, pixels: vec![Rgb::splat(1.0), Rgb::splat(0.5)] };
        let e = compare(&a, &b).unwrap();
        assert!((e.rmse - (0.125f64).sqrt()).abs() < 1e-12);
        assert!((e.mae - 0.25).abs() < 1e-12);
        assert_eq!(e.max, 0.5);
        assert!((e.rel_mse - 0.5 * 0.25 / 0.26).abs() < 1e-12);
        assert!((e.rel_rmse - (0.75f64 / 3.75).sqrt()).abs() < 1e-12);
        assert!(compare(&a, &Image::new(1, 1)).is_none());
    }
}
