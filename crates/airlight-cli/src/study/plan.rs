//! The ladder a study climbs: every integrator the user asked for, at a few
//! settings around the scene's own (raymarch steps, analytic light steps
//! and shadows, lights' attenuation models), each rendered progressively
//! at 1, 2, 4, … samples per pixel.

use super::data::{NotRun, Transport};
use airlight::integrator::{Estimate, IntegratorDesc, IntegratorKind, MAX_LIGHT_STEPS, MAX_STEPS};
use airlight::light::{AttenuationModel, Light};
use airlight::scene::Scene;

/// One curve of the study: an integrator at one setting.
#[derive(Clone, Debug)]
pub struct SeriesPlan {
    /// Safe in file names: `raymarch_steps25`.
    pub id: String,
    pub label: String,
    pub kind: IntegratorKind,
    pub setting: String,
    pub desc: IntegratorDesc,
    /// Every point, spot and sphere light switched to this falloff.
    pub attenuation: Option<AttenuationModel>,
    pub transport: Transport,
}

pub const ATTENUATION_MODELS: [(AttenuationModel, &str); 6] = [
    (AttenuationModel::Physical, "physical"),
    (AttenuationModel::Sphere, "sphere"),
    (AttenuationModel::Cutoff, "cutoff"),
    (AttenuationModel::WindowTan, "window_tan"),
    (AttenuationModel::WindowRational, "window_rational"),
    (AttenuationModel::WindowUe4, "window_ue4"),
];

/// Which transport an integrator computes: single-scattering methods are
/// measured against path at max_depth 1, the others against the scene's;
/// None for a debug view, which estimates no light and is not studied.
pub fn transport(kind: IntegratorKind, desc: &IntegratorDesc) -> Option<Transport> {
    match kind.estimate() {
        Estimate::Direct | Estimate::SingleScattering => Some(Transport::Single),
        Estimate::Full if kind == IntegratorKind::Path && desc.path.max_depth == 1 => Some(Transport::Single),
        Estimate::Full => Some(Transport::Full),
        Estimate::DebugView => None,
    }
}

/// A quarter, the same and four times `v`, within [1, max], without repeats.
fn around(v: u32, max: u32) -> Vec<u32> {
    let mut out: Vec<u32> = [v / 4, v, v.saturating_mul(4)].into_iter().map(|x| x.clamp(1, max)).collect();
    out.dedup();
    out
}

/// The series to run for `kinds`, in order (the path tracers first: the
/// others' speed ratios are measured against them), and the variants that
/// cannot be made, with the reason.
pub fn ladder(scene: &Scene, base: &IntegratorDesc, kinds: &[IntegratorKind]) -> (Vec<SeriesPlan>, Vec<NotRun>) {
    let mut plans = Vec::new();
    let mut refused = Vec::new();
    let mut push = |kind: IntegratorKind, id: String, setting: String, desc: IntegratorDesc| {
        let label = if setting.is_empty() { kind.name().to_string() } else { format!("{kind}, {setting}") };
        if let Some(transport) = transport(kind, &desc) {
            plans.push(SeriesPlan { id, label, kind, setting, desc, attenuation: None, transport });
        }
    };
    let medium = scene.medium().is_some();
    // Every integrator there is, the path tracer first.
    let mut order = IntegratorKind::ALL.to_vec();
    order.sort_by_key(|k| *k != IntegratorKind::Path);
    for kind in order {
        if !kinds.contains(&kind) {
            continue;
        }
        if kind.estimate() == Estimate::DebugView {
            let reason = "a view of the scene's geometry, not an estimate of its light: nothing to measure";
            refused.push(NotRun { label: kind.name().into(), reason: reason.into() });
            continue;
        }
        let desc = base.with_kind(kind);
        match kind {
            IntegratorKind::Path => {
                let depth = desc.path.max_depth;
                push(kind, "path".into(), format!("max_depth {depth}"), desc);
                if depth > 1 {
                    let mut single = desc;
                    single.path.max_depth = 1;
                    push(kind, "path_depth1".into(), "max_depth 1".into(), single);
                }
            }
            IntegratorKind::Raymarch => {
                for steps in around(desc.raymarch.steps, MAX_STEPS) {
                    let mut d = desc;
                    d.raymarch.steps = steps;
                    push(kind, format!("raymarch_steps{steps}"), format!("steps {steps}"), d);
                }
            }
            IntegratorKind::Analytic => {
                // Light steps only matter for line, quad and triangle
                // lights in a medium.
                let area = scene
                    .lights()
                    .iter()
                    .any(|l| matches!(l, Light::Line { .. } | Light::Quad { .. } | Light::Triangle { .. }));
                let own = desc.analytic.light_steps;
                let steps = if medium && area { around(own, MAX_LIGHT_STEPS) } else { vec![own] };
                let shadows = desc.analytic.shadows;
                let mut variants: Vec<(bool, u32)> = steps.into_iter().map(|s| (shadows, s)).collect();
                if medium {
                    variants.push((!shadows, own));
                }
                for (shadows, light_steps) in variants {
                    let mut d = desc;
                    d.analytic.shadows = shadows;
                    d.analytic.light_steps = light_steps;
                    let s = if shadows { "shadows, " } else { "" };
                    let id = format!("analytic_{}ls{light_steps}", if shadows { "shadows_" } else { "" });
                    push(kind, id, format!("{s}light_steps {light_steps}"), d);
                }
            }
            _ => push(kind, kind.name().into(), String::new(), desc),
        }
    }
    if kinds.contains(&IntegratorKind::Raymarch) {
        attenuation_variants(scene, base, &mut plans, &mut refused);
    }
    (plans, refused)
}

/// Raymarch (at the scene's steps) with every light that has a falloff
/// switched to each other model the lights accept.
fn attenuation_variants(scene: &Scene, base: &IntegratorDesc, plans: &mut Vec<SeriesPlan>, refused: &mut Vec<NotRun>) {
    let lights: Vec<(&Light, _)> = scene.lights().iter().filter_map(|l| Some((l, l.attenuation()?))).collect();
    if lights.is_empty() {
        return;
    }
    let desc = base.with_kind(IntegratorKind::Raymarch);
    let steps = desc.raymarch.steps;
    for (model, name) in ATTENUATION_MODELS {
        if lights.iter().all(|(_, a)| a.model == model) {
            continue; // the scene's own
        }
        let label = format!("raymarch, steps {steps}, attenuation {name}");
        let reason = if model == AttenuationModel::Sphere
            && lights.iter().all(|(l, a)| a.model == AttenuationModel::Physical && !matches!(l, Light::Sphere { .. }))
        {
            // attenuation.rs: for a point or spot light both give 1/D².
            Some("the same law as physical for point and spot lights (1/d² from the centre)".to_string())
        } else {
            lights.iter().find_map(|(_, a)| a.with_model(model).err())
        };
        match reason {
            Some(reason) => refused.push(NotRun { label, reason }),
            None => plans.push(SeriesPlan {
                id: format!("raymarch_steps{steps}_{name}"),
                label,
                kind: IntegratorKind::Raymarch,
                setting: format!("steps {steps}, attenuation {name}"),
                desc,
                attenuation: Some(model),
                transport: Transport::Single,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The analytic series of a foggy scene lit by `light`: their light steps.
    fn analytic_light_steps(light: Light) -> Vec<u32> {
        use airlight::prelude::*;
        let scene = SceneBuilder::new()
            .size(8, 8)
            .camera(Camera::look_at(vec3(0.0, 1.0, -5.0), vec3(0.0, 1.0, 0.0), Vec3::Y, 40.0))
            .material("white", Material::diffuse(Rgb::splat(0.8)))
            .object(Shape::sphere(vec3(0.0, 1.0, 0.0), 1.0), "white")
            .light(light)
            .medium(Medium::homogeneous(Rgb::splat(0.01), Rgb::splat(0.1), 0.0))
            .build()
            .unwrap();
        let desc = IntegratorDesc::new(IntegratorKind::Analytic);
        let (plans, _) = ladder(&scene, &desc, &[IntegratorKind::Analytic]);
        plans
            .iter()
            .filter(|p| p.desc.analytic.shadows == desc.analytic.shadows)
            .map(|p| p.desc.analytic.light_steps)
            .collect()
    }

    #[test]
    fn light_steps_vary_for_lights_with_an_extent_only() {
        use airlight::prelude::{Rgb, vec3};
        let own = IntegratorDesc::new(IntegratorKind::Analytic).analytic.light_steps;
        let spread = around(own, MAX_LIGHT_STEPS);
        assert!(spread.len() > 1);
        let colour = Rgb::splat(5.0);
        let (a, b, c) = (vec3(-1.0, 3.0, 0.0), vec3(0.0, 3.0, 1.0), vec3(1.0, 3.0, 0.0));
        assert_eq!(analytic_light_steps(Light::triangle(a, b, c, colour)), spread);
        assert_eq!(analytic_light_steps(Light::quad(a, b - a, c - a, colour)), spread);
        assert_eq!(analytic_light_steps(Light::line(a, c, colour)), spread);
        assert_eq!(analytic_light_steps(Light::point(a, colour)), [own]);
    }

    #[test]
    fn settings_spread_around_the_scenes_own() {
        assert_eq!(around(64, MAX_STEPS), [16, 64, 256]);
        assert_eq!(around(2, MAX_STEPS), [1, 2, 8]);
        assert_eq!(around(1, 1), [1]);
        assert_eq!(around(4096, 4096), [1024, 4096]);
    }
}
