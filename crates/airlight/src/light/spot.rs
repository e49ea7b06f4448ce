//! The edge of a spot light's cone.

/// How a spot light's intensity falls between `falloff_start` and `cone_angle`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SpotProfile {
    /// pbrt-v4: smoothstep of cos θ between cos(cone_angle) and cos(falloff_start).
    #[default]
    Smoothstep,
    /// Mitsuba 3: linear in the angle θ.
    Linear,
}

/// The fraction of a spot light's intensity emitted at angle θ from its axis,
/// given cos θ. 1 inside `falloff_start`, 0 outside `cone_angle` (half angles,
/// radians); equal angles give a hard edge.
///
/// Smoothstep is pbrt-v4's SpotLight::I: t = (cos θ − cos cone)/(cos start −
/// cos cone), t²(3 − 2t). Linear is Mitsuba 3's spot: (cone − θ)/(cone − start).
pub fn spot_falloff(profile: SpotProfile, cos_theta: f32, cone_angle: f32, falloff_start: f32) -> f32 {
    let cos_cone = cone_angle.cos();
    if cos_theta < cos_cone {
        return 0.0;
    }
    if falloff_start >= cone_angle {
        return 1.0;
    }
    match profile {
        SpotProfile::Smoothstep => {
            let cos_start = falloff_start.cos();
            let t = ((cos_theta - cos_cone) / (cos_start - cos_cone)).clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        }
        SpotProfile::Linear => {
            let theta = cos_theta.clamp(-1.0, 1.0).acos();
            ((cone_angle - theta) / (cone_angle - falloff_start)).clamp(0.0, 1.0)
        }
    }
}
