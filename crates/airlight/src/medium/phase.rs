//! Phase functions, normalised over the sphere.

use std::f32::consts::PI;

/// The isotropic phase function, 1/4π.
pub const fn isotropic() -> f32 {
    1.0 / (4.0 * PI)
}

/// Henyey–Greenstein as pbrt-v4 writes it (docs/scene-format.md):
/// p = (1 − g²) / (4π (1 + g² + 2g cos θ)^1.5), with cos θ between the two
/// directions both pointing away from the scattering point, so g > 0 favours
/// light continuing forward (cos θ = −1).
#[inline]
pub fn henyey_greenstein(cos_theta: f32, g: f32) -> f32 {
    if g == 0.0 {
        return isotropic();
    }
    let denom = 1.0 + g * g + 2.0 * g * cos_theta;
    (1.0 - g * g) / (4.0 * PI * denom * denom.max(1e-12).sqrt())
}

/// Draws cos θ (between wo and wi, both pointing away) from the
/// Henyey–Greenstein distribution, by inverting its CDF (pbrt-v4,
/// SampleHenyeyGreenstein); the pdf is henyey_greenstein(cos θ, g).
pub fn sample_henyey_greenstein_cos(g: f32, u: f32) -> f32 {
    if g.abs() < 1e-3 {
        return 1.0 - 2.0 * u;
    }
    let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u);
    (-(1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hg_samples_follow_the_density() {
        // Histogram of cos θ in 20 bins against the integral of the density
        // over each bin (2π ∫ p dμ, by Simpson), for several g.
        for g in [-0.7f32, 0.0, 0.4, 0.9] {
            let bins = 20;
            let mut counts = vec![0usize; bins];
            let mut s = crate::sampling::Sampler::for_pixel(2, 0, 0);
            let n = 400_000;
            for _ in 0..n {
                let mu = sample_henyey_greenstein_cos(g, s.next());
                counts[(((mu + 1.0) * 0.5 * bins as f32) as usize).min(bins - 1)] += 1;
            }
            for (b, &count) in counts.iter().enumerate() {
                let (a, c) = (-1.0 + 2.0 * b as f64 / bins as f64, -1.0 + 2.0 * (b + 1) as f64 / bins as f64);
                let k = 200;
                let h = (c - a) / k as f64;
                let mut sum = 0.0;
                for i in 0..=k {
                    let w = if i == 0 || i == k {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    sum += w * henyey_greenstein((a + i as f64 * h) as f32, g) as f64;
                }
                let expected = 2.0 * std::f64::consts::PI * sum * h / 3.0 * n as f64;
                let sigma = expected.sqrt().max(1.0);
                assert!(
                    (count as f64 - expected).abs() < 5.0 * sigma + 1e-3 * expected,
                    "g {g} bin {b}: {count} vs {expected:.0}"
                );
            }
        }
    }
}
