//! How light falls off with distance: the physical law, and the curves of
//! real-time rendering that bring a light's reach to a finite range, after
//! Tom Madams, "Light Attenuation" and "Improved Light Attenuation" (2011).
//!
//! Normalisation. A light of intensity I (a sphere light of radius r and
//! radiance L has I = π r² L) and radius r gives, on a surface facing it at
//! distance d from its surface (D = d + r from its centre),
//! E = E₀ · f(d) with E₀ = I / r², the irradiance at its surface. Every curve
//! f below is 1 at d = 0. The physical law is f = r² / D² = 1/(d/r + 1)²,
//! which is Madams's finding: its attenuation curve for a sphere of radius
//! r is the inverse-square law measured from the centre, in units of r
//! (k_c = 1, k_l = 2/r, k_q = 1/r²).

/// Which falloff a point, spot or sphere light uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AttenuationModel {
    /// Inverse square from the centre; a sphere light is integrated exactly
    /// (sampled over the cone it subtends), with soft shadows.
    #[default]
    Physical,
    /// Madams's 1/(d/r + 1)², evaluated as a point at the centre (for a
    /// sphere light: no horizon clipping, hard shadows).
    Sphere,
    /// Madams's bias and scale: (f − c)/(1 − c), c = I_c/E₀, clamped at 0,
    /// reaching 0 at d_max = r(√(E₀/I_c) − 1).
    Cutoff,
    /// f(d') with d' = (2 d_max/π) tan(π d/(2 d_max)) (Madams's tan window;
    /// its constant 2.1 is replaced by 2 d_max/π so that d' ≈ d near the light).
    WindowTan,
    /// f(d') with d' = d / (1 − (d/d_max)²) (Madams's rational window).
    WindowRational,
    /// Karis (2013), Unreal Engine 4: saturate(1 − (d/d_max)⁴)² / ((d/r)² + 1),
    /// distance in light radii (with r = 1 it is his formula).
    WindowUe4,
}

/// A light's falloff: its model, the radius that sets the curve's scale,
/// and its range (d_max, from the light's surface; infinite for the
/// physical and sphere models).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attenuation {
    pub model: AttenuationModel,
    pub radius: f32,
    pub range: f32,
    /// c = I_c / E₀ for the cutoff model, else 0.
    pub relative_cutoff: f32,
}

impl Default for Attenuation {
    fn default() -> Self {
        Attenuation::PHYSICAL
    }
}

impl Attenuation {
    /// The physical law, with no range.
    pub const PHYSICAL: Attenuation =
        Attenuation { model: AttenuationModel::Physical, radius: 0.1, range: f32::INFINITY, relative_cutoff: 0.0 };

    /// A falloff for a light of `radius` and surface irradiance `e0` (I/r²);
    /// `cutoff` is the irradiance I_c below which light is dropped, and
    /// `range` (d_max) overrides the range it implies. Windows need one of
    /// the two.
    pub fn new(
        model: AttenuationModel,
        radius: f32,
        e0: f32,
        cutoff: Option<f32>,
        range: Option<f32>,
    ) -> Result<Self, String> {
        let relative_cutoff = cutoff.map_or(0.0, |c| if e0 > 0.0 { c / e0 } else { 1.0 });
        let from_cutoff = cutoff.map(|_| cutoff_range(radius, relative_cutoff));
        let range = match model {
            AttenuationModel::Physical | AttenuationModel::Sphere => f32::INFINITY,
            AttenuationModel::Cutoff => {
                if cutoff.is_none() {
                    return Err("the cutoff model needs `cutoff` (an irradiance threshold)".into());
                }
                from_cutoff.unwrap()
            }
            _ => range.or(from_cutoff).ok_or("a window needs `range` (d_max) or `cutoff`")?,
        };
        Ok(Attenuation { model, radius, range, relative_cutoff })
    }

    /// The same light's falloff under another model, keeping its radius and
    /// cutoff (or, without a cutoff, its range).
    pub fn with_model(&self, model: AttenuationModel) -> Result<Self, String> {
        let cutoff = (self.relative_cutoff > 0.0).then_some(self.relative_cutoff);
        let range = self.range.is_finite().then_some(self.range);
        // With E₀ = 1 the cutoff is the relative one.
        Attenuation::new(model, self.radius, 1.0, cutoff, range)
    }

    /// f(d) for distance d from the light's surface: 1 at d = 0.
    pub fn factor(&self, d: f32) -> f32 {
        let d = d.max(0.0);
        let r = self.radius;
        match self.model {
            AttenuationModel::Physical | AttenuationModel::Sphere => sphere_falloff(d, r),
            AttenuationModel::Cutoff => cutoff_falloff(d, r, self.relative_cutoff),
            AttenuationModel::WindowTan => window_tan(d, r, self.range),
            AttenuationModel::WindowRational => window_rational(d, r, self.range),
            AttenuationModel::WindowUe4 => window_ue4(d, r, self.range),
        }
    }

    /// Whether the light reaches a point at distance d from its surface.
    #[inline]
    pub fn reaches(&self, d: f32) -> bool {
        d < self.range
    }
}

/// Madams's sphere-light attenuation, 1/(d/r + 1)² = r²/(d + r)².
#[inline]
pub fn sphere_falloff(d: f32, r: f32) -> f32 {
    let x = d / r + 1.0;
    1.0 / (x * x)
}

/// Madams's range for a cutoff c = I_c/E₀: where 1/(d/r + 1)² = c.
pub fn cutoff_range(r: f32, relative_cutoff: f32) -> f32 {
    if relative_cutoff <= 0.0 {
        return f32::INFINITY;
    }
    (r * ((1.0 / relative_cutoff).sqrt() - 1.0)).max(0.0)
}

/// Madams's bias and scale: (f − c)/(1 − c), clamped at 0.
#[inline]
pub fn cutoff_falloff(d: f32, r: f32, c: f32) -> f32 {
    if c >= 1.0 {
        return 0.0;
    }
    ((sphere_falloff(d, r) - c) / (1.0 - c)).max(0.0)
}

/// The tan window: f(d') with d' = (2 d_max/π) tan(π d/(2 d_max)); 0 from d_max on.
#[inline]
pub fn window_tan(d: f32, r: f32, d_max: f32) -> f32 {
    if d >= d_max {
        return 0.0;
    }
    let scale = 2.0 * d_max / std::f32::consts::PI;
    sphere_falloff(scale * (d / scale).tan(), r)
}

/// The rational window: f(d') with d' = d/(1 − (d/d_max)²); 0 from d_max on.
#[inline]
pub fn window_rational(d: f32, r: f32, d_max: f32) -> f32 {
    if d >= d_max {
        return 0.0;
    }
    let x = d / d_max;
    sphere_falloff(d / (1.0 - x * x), r)
}

/// Karis's window in light radii: saturate(1 − (d/d_max)⁴)² / ((d/r)² + 1).
#[inline]
pub fn window_ue4(d: f32, r: f32, d_max: f32) -> f32 {
    let x = d / d_max;
    let w = (1.0 - x * x * x * x).clamp(0.0, 1.0);
    let q = d / r;
    w * w / (q * q + 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    const WINDOWS: [AttenuationModel; 4] = [
        AttenuationModel::Cutoff,
        AttenuationModel::WindowTan,
        AttenuationModel::WindowRational,
        AttenuationModel::WindowUe4,
    ];

    #[test]
    fn every_curve_is_one_at_the_surface_and_windows_end_flat_at_their_range() {
        let (r, e0) = (0.5f32, 100.0f32);
        for model in WINDOWS {
            let a = Attenuation::new(model, r, e0, Some(0.05), None).unwrap();
            assert!((a.factor(0.0) - 1.0).abs() < 1e-6, "{model:?}");
            let d_max = a.range;
            assert!(
                (d_max - r * ((e0 / 0.05f32).sqrt() - 1.0)).abs() < 1e-3 * d_max,
                "{model:?}: range from Madams's formula"
            );
            // Value 0 at d_max, and the derivative there by a one-sided
            // difference: ~0 (cutoff's is not, which is Madams's point).
            assert_eq!(a.factor(d_max), 0.0);
            let h = 1e-3 * d_max;
            let slope = (a.factor(d_max) - a.factor(d_max - h)) / h;
            let scale = 1.0 / r; // the curves' slope at d = 0 is about −2/r
            if model == AttenuationModel::Cutoff {
                assert!(slope.abs() > 1e-6 * scale, "cutoff keeps a kink: {slope}");
            } else {
                assert!(slope.abs() < 1e-3 * scale, "{model:?}: slope {slope} at d_max");
            }
            // Monotone between.
            let mut last = a.factor(0.0);
            for i in 1..=1000 {
                let v = a.factor(d_max * i as f32 / 1000.0);
                assert!(v <= last + 1e-7, "{model:?} rises at step {i}");
                last = v;
            }
        }
    }

    #[test]
    fn physical_curve_is_inverse_square_from_the_centre() {
        let r = 0.3f32;
        for d in [0.0f32, 0.1, 1.0, 7.5] {
            let expected = r * r / ((d + r) * (d + r));
            assert!((sphere_falloff(d, r) / expected - 1.0).abs() < 1e-6);
        }
        assert_eq!(Attenuation::PHYSICAL.range, f32::INFINITY);
    }

    #[test]
    fn windows_need_a_range() {
        assert!(Attenuation::new(AttenuationModel::WindowTan, 1.0, 1.0, None, None).is_err());
        assert!(Attenuation::new(AttenuationModel::Cutoff, 1.0, 1.0, None, Some(3.0)).is_err());
        let a = Attenuation::new(AttenuationModel::WindowRational, 1.0, 1.0, None, Some(3.0)).unwrap();
        assert_eq!(a.range, 3.0);
        assert!(a.reaches(2.9) && !a.reaches(3.0));
    }
}
