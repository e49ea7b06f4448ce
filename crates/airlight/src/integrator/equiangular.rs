//! Equiangular sampling of a ray segment about a point (Kulla and Fajardo,
//! "Importance Sampling Techniques for Path Tracing in Participating Media",
//! EGSR 2012, section 4.1).
//!
//! For a point y at distance h from the ray's line, whose foot on the line is
//! at parameter t_c, the integrand's 1/r² = 1/(h² + (t − t_c)²) is sampled
//! exactly: substituting t = t_c + h·tan θ gives dt = h·dθ/cos²θ and
//! r² = h²/cos²θ, so dt/r² = dθ/h and θ uniform on [θa, θb] draws t with
//!
//!   pdf(t) = h / ((θb − θa)·(h² + (t − t_c)²)),  θa,b = atan((t0,1 − t_c)/h).
//!
//! Its integral over [t0, t1] is (atan((t1 − t_c)/h) − atan((t0 − t_c)/h))/(θb − θa)
//! = 1: the Monte Carlo twin of the closed-form atan of the airlight integral.
//!
//! For an extended light the integrand is bounded where the ray passes
//! through or near it, so h may be raised to a `spread` (any h > 0 gives a
//! normalised pdf, a truncated Cauchy distribution): the light's size.

use glam::Vec3;

/// The equiangular distribution of t on [t0, t1] about a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Equiangular {
    t0: f64,
    t1: f64,
    /// Parameter of the point's foot on the line.
    tc: f64,
    /// Distance of the point from the line (kept above a floor so the pdf
    /// stays finite when the point lies on the line).
    h: f64,
    /// tan θa = (t0 − t_c)/h.
    tan_a: f64,
    /// θb − θa.
    angle: f64,
}

impl Equiangular {
    /// The distribution for the ray o + t·d (d unit), t in [t0, t1], about
    /// `y`, with h no less than `spread`.
    pub fn new(o: Vec3, d: Vec3, y: Vec3, spread: f32, t0: f32, t1: f32) -> Self {
        let (o, d, y) = (o.as_dvec3(), d.as_dvec3(), y.as_dvec3());
        let tc = (y - o).dot(d);
        let (t0, t1) = (t0 as f64, t1 as f64);
        let floor = 1e-6 * (1.0 + (t1 - t0).abs() + tc.abs());
        let h = (o + d * tc - y).length().max(floor).max(spread as f64);
        // θb − θa in one atan2, by tan(θb − θa) = (B − A)/(1 + A·B) with
        // A, B = tan θa, b; B ≥ A puts it in [0, π) whatever the sign of
        // 1 + A·B. One transcendental call fewer than two atans, and no
        // cancellation when both angles are near ±π/2.
        let (tan_a, tan_b) = ((t0 - tc) / h, (t1 - tc) / h);
        let angle = (tan_b - tan_a).atan2(1.0 + tan_a * tan_b);
        Equiangular { t0, t1, tc, h, tan_a, angle }
    }

    /// The t drawn by u uniform in [0, 1): t = t_c + h·tan(θa + u·Δθ),
    /// expanded by the tangent's addition rule, so that θa itself is not
    /// needed.
    pub fn sample(&self, u: f32) -> f32 {
        let (sin, cos) = (u as f64 * self.angle).sin_cos();
        let tan_theta = (self.tan_a * cos + sin) / (cos - self.tan_a * sin);
        (self.tc + self.h * tan_theta).clamp(self.t0, self.t1) as f32
    }

    /// The density of t (0 outside [t0, t1]).
    pub fn pdf(&self, t: f32) -> f32 {
        let t = t as f64;
        if !(t >= self.t0 && t <= self.t1) || self.angle <= 0.0 {
            return 0.0;
        }
        let x = t - self.tc;
        (self.h / (self.angle * (self.h * self.h + x * x))) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Sampler;

    fn cases() -> Vec<Equiangular> {
        let o = Vec3::new(0.2, -0.1, 0.3);
        let d = Vec3::new(0.3, 0.2, 1.0).normalize();
        vec![
            Equiangular::new(o, d, Vec3::new(1.0, 1.0, 4.0), 0.0, 0.0, 10.0),
            // The point beside the start, behind it, close to the line, far
            // away; a spread wider than the distance to the line.
            Equiangular::new(o, d, o + Vec3::new(0.5, 0.0, 0.0), 0.0, 0.0, 5.0),
            Equiangular::new(o, d, o - d * 3.0 + Vec3::Y, 0.0, 0.0, 5.0),
            Equiangular::new(o, d, o + d * 2.0 + Vec3::X * 0.01, 0.0, 0.5, 4.0),
            Equiangular::new(o, d, Vec3::new(50.0, 20.0, -30.0), 0.0, 0.0, 3.0),
            Equiangular::new(o, d, o + d * 2.0 + Vec3::X * 0.01, 0.7, 0.5, 4.0),
        ]
    }

    /// Composite Simpson's rule with 2000 intervals.
    fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
        let n = 2000;
        let h = (b - a) / n as f64;
        let inner: f64 = (1..n).map(|k| (if k % 2 == 1 { 4.0 } else { 2.0 }) * f(a + k as f64 * h)).sum();
        (f(a) + f(b) + inner) * h / 3.0
    }

    #[test]
    fn pdf_integrates_to_one() {
        // Composite Simpson on a fine grid, independently of the atan form.
        for (i, e) in cases().iter().enumerate() {
            let (a, b) = (e.t0, e.t1);
            let n = 200_000;
            let h = (b - a) / n as f64;
            let mut sum = e.pdf(a as f32) as f64 + e.pdf(b as f32) as f64;
            for k in 1..n {
                sum += (if k % 2 == 1 { 4.0 } else { 2.0 }) * e.pdf((a + k as f64 * h) as f32) as f64;
            }
            let integral = sum * h / 3.0;
            assert!((integral - 1.0).abs() < 1e-3, "case {i}: {integral}");
            assert_eq!(e.pdf((b + 0.1) as f32), 0.0);
        }
    }

    #[test]
    fn samples_follow_the_pdf() {
        // Histogram of 400k samples in 40 bins against the pdf's integral
        // over each bin (Simpson): a χ² test.
        for (i, e) in cases().iter().enumerate() {
            let bins = 40;
            let n = 400_000;
            let mut counts = vec![0u32; bins];
            let mut s = Sampler::for_pixel(9, i as u64, 0);
            let width = (e.t1 - e.t0) / bins as f64;
            for _ in 0..n {
                let t = e.sample(s.next()) as f64;
                assert!(t >= e.t0 && t <= e.t1);
                counts[(((t - e.t0) / width) as usize).min(bins - 1)] += 1;
            }
            let mut chi2 = 0.0;
            let mut dof = 0;
            for (k, &c) in counts.iter().enumerate() {
                let p = simpson(|t| e.pdf(t as f32) as f64, e.t0 + k as f64 * width, e.t0 + (k + 1) as f64 * width);
                let expected = p * n as f64;
                if expected > 5.0 {
                    chi2 += (c as f64 - expected).powi(2) / expected;
                    dof += 1;
                }
            }
            // The 99.9% point of χ² with 39 degrees of freedom is about 72.
            assert!(dof >= 10 && chi2 < 72.0, "case {i}: χ² {chi2} over {dof} bins");
        }
    }
}
