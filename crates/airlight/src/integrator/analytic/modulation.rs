//! What multiplies the attenuation along a piece of a ray: the phase
//! function, a spot's falloff, a quad light's cosine, a sphere light's
//! near-field factor; and the medium's numbers.

use super::lights::{ViewSegment, sphere_factor};
use super::{Analytic, Emission, MODULATED_POINTS, PointEmitter, quadrature};
use crate::integrator::analytic::closed_form::Glow;
use crate::light::spot_falloff;
use crate::medium::{Medium, henyey_greenstein};
use glam::DVec3;
use std::f64::consts::FRAC_PI_4;

impl Analytic {
    /// What multiplies the attenuation on the piece around `x`: None if the
    /// piece is dark (outside a spot's cone, behind a quad light; shadows
    /// are the caller's),
    /// Some(Some(m)) if phase·m is the constant m there, Some(None) if it
    /// varies (weighted_mean takes it).
    pub(super) fn modulation_class(&self, k: &MediumConsts, x: DVec3, e: &PointEmitter) -> Option<Option<f64>> {
        let to = e.position - x;
        let dist = to.length();
        if dist == 0.0 {
            return None;
        }
        let wi = to / dist;
        let mut varies = k.g != 0.0;
        match e.emission {
            Emission::Isotropic => {}
            Emission::Spot { .. } => {
                let f = emission_factor(&e.emission, wi);
                if f <= 0.0 {
                    return None;
                }
                varies |= f < 1.0;
            }
            Emission::Cosine { .. } => {
                if emission_factor(&e.emission, wi) <= 0.0 {
                    return None;
                }
                varies = true;
            }
            Emission::Sphere { .. } => varies = true,
        }
        Some(if varies { None } else { Some(henyey_greenstein(0.0, 0.0) as f64) })
    }

    /// Σ w e(θ) m(θ) / Σ w e(θ) over [ta, tb] per channel, with e the
    /// attenuation e^{−σt (t + r)} and m = phase · emission factor, by
    /// Gauss–Legendre in θ in panels of at most π/4.
    pub(super) fn weighted_mean(
        &self,
        k: &MediumConsts,
        glows: &[Glow; 3],
        segment: &ViewSegment,
        (ta, tb): (f64, f64),
        e: &PointEmitter,
    ) -> [f64; 3] {
        let ViewSegment { o, d, .. } = *segment;
        let g0 = &glows[0];
        let (a, b) = (g0.angle(ta), g0.angle(tb));
        let panels = ((b - a) / FRAC_PI_4).ceil().max(1.0) as usize;
        let width = (b - a) / panels as f64;
        let rule = quadrature::gl16();
        debug_assert_eq!(rule.nodes.len(), MODULATED_POINTS);
        let (mut num, mut den) = ([0.0; 3], [0.0; 3]);
        for panel in 0..panels {
            let start = a + width * panel as f64;
            for (x, w) in rule.nodes.iter().zip(&rule.weights) {
                let theta = start + width * x;
                let t = g0.t_at_angle(theta);
                let to = e.position - (o + d * t);
                let wi = to.normalize();
                let phase = henyey_greenstein((-d).dot(wi) as f32, k.g) as f64;
                let m = phase * emission_factor(&e.emission, wi);
                for c in 0..k.channels {
                    let att = if glows[c].sigma_t > 0.0 { glows[c].attenuation_at_angle(theta) } else { 1.0 };
                    let m = match e.emission {
                        Emission::Sphere { radius } => m * sphere_factor(to.length(), radius, glows[c].sigma_t),
                        _ => m,
                    };
                    num[c] += w * att * m;
                    den[c] += w * att;
                }
            }
        }
        std::array::from_fn(|c| if den[c] > 0.0 { num[c] / den[c] } else { 0.0 })
    }
}

/// The emitter's intensity factor toward −wi (wi: unit, from the point to
/// the emitter): the spot's falloff, the cosine of a quad light, or 1.
pub(super) fn emission_factor(emission: &Emission, wi: DVec3) -> f64 {
    match *emission {
        Emission::Isotropic => 1.0,
        Emission::Spot { axis, cos_outer, cos_inner, cone, start, profile } => {
            let cos = -wi.dot(axis);
            if cos < cos_outer {
                0.0
            } else if cos >= cos_inner {
                1.0
            } else {
                spot_falloff(profile, cos as f32, cone, start) as f64
            }
        }
        Emission::Cosine { normal } => (-wi.dot(normal)).max(0.0),
        Emission::Sphere { .. } => 1.0,
    }
}

/// The medium's numbers in f64; `channels` is 1 when σt is grey.
pub(super) struct MediumConsts {
    pub(super) sigma_t: [f64; 3],
    pub(super) channels: usize,
    pub(super) g: f32,
}

impl MediumConsts {
    pub(super) fn new(m: &Medium) -> Self {
        let st = m.sigma_t().as_dvec3();
        let grey = st.x == st.y && st.y == st.z;
        MediumConsts { sigma_t: [st.x, st.y, st.z], channels: if grey { 1 } else { 3 }, g: m.g }
    }
}
