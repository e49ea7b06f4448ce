//! What an integrator is built from: its kind and each integrator's own
//! options, each with its defaults and its checks, and the one function that
//! builds them ([`IntegratorDesc::build`]).
//!
//! A scene file's `[render]` table may hold options of several integrators
//! (`steps` for raymarch, `bounces` for radiosity, …) and the command line
//! may pick another integrator than the file names, so a description keeps
//! the options of every integrator and `kind` says which one is built.

use super::analytic::{AnalyticOptions, LightQuadrature};
use super::{
    Analytic, Direct, Integrator, IntegratorKind, PathTracer, RadiosityIntegrator, Raymarch, Sampling, Stochastic,
};
use crate::radiosity::RadiosityError;
use crate::scene::Scene;
use crate::scene::desc::{FieldError, RenderDesc, parse_name, render_count};

/// Most march samples per ray (`steps`).
pub const MAX_STEPS: u32 = 1 << 20;
/// Most points per dimension over a line or quad light (`light_steps`).
pub const MAX_LIGHT_STEPS: u32 = 4096;
/// Most scattering events of a path (`max_depth`).
pub const MAX_DEPTH: u32 = 1 << 16;
/// Most radiosity bounces (`bounces`).
pub const MAX_BOUNCES: u32 = 1024;

/// An option whose value is out of bounds: its key (as the scene file
/// spells it) and what was expected.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{key} {message}")]
pub struct OptionError {
    pub key: &'static str,
    pub message: String,
}

impl OptionError {
    fn new(key: &'static str, message: impl Into<String>) -> Self {
        OptionError { key, message: message.into() }
    }
}

/// Why an integrator could not be built, or relit.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum IntegratorError {
    #[error(transparent)]
    Option(#[from] OptionError),
    /// The integrator has no way to render something the scene holds; the
    /// reason names it and the integrator to use instead.
    #[error("{reason}")]
    Unsupported { integrator: IntegratorKind, reason: String },
    #[error(transparent)]
    Radiosity(#[from] RadiosityError),
}

fn count_in(key: &'static str, value: u32, min: u32, max: u32) -> Result<(), OptionError> {
    if (min..=max).contains(&value) {
        Ok(())
    } else {
        Err(OptionError::new(key, format!("must be an integer from {min} to {max}, got {value}")))
    }
}

/// `raymarch`: a shadow ray from each of `steps` samples along the ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RaymarchOptions {
    /// March samples per ray.
    pub steps: u32,
    /// Offset the samples by a random fraction of a step per pixel sample
    /// (else each sample sits at its segment's middle).
    pub jitter: bool,
}

impl Default for RaymarchOptions {
    fn default() -> Self {
        RaymarchOptions { steps: 64, jitter: true }
    }
}

impl RaymarchOptions {
    pub fn validate(&self) -> Result<(), OptionError> {
        count_in("steps", self.steps, 1, MAX_STEPS)
    }
}

impl AnalyticOptions {
    pub fn validate(&self) -> Result<(), OptionError> {
        count_in("light_steps", self.light_steps, 1, MAX_LIGHT_STEPS)
    }
}

/// `stochastic`: how the point on the camera segment is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StochasticOptions {
    pub sampling: Sampling,
    /// Stratify each pixel's samples (Owen-scrambled Sobol').
    pub stratify: bool,
}

impl Default for StochasticOptions {
    fn default() -> Self {
        StochasticOptions { sampling: Sampling::default(), stratify: true }
    }
}

/// `path`: the volumetric path tracer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathOptions {
    /// Most scattering events; 1 is direct light on surfaces plus single
    /// scattering in the medium.
    pub max_depth: u32,
    /// Draw each bounce's light sample and scattering direction from the
    /// pixel's Owen-scrambled Sobol' points rather than independently.
    pub stratify: bool,
    /// Let the paths of neighbouring pixels (a batch's groups of eight)
    /// share what they gather beyond their second vertex, in scenes
    /// without a medium (`integrator/path/reuse.rs`).
    pub reuse: bool,
}

impl Default for PathOptions {
    fn default() -> Self {
        PathOptions { max_depth: 8, stratify: true, reuse: false }
    }
}

impl PathOptions {
    pub fn validate(&self) -> Result<(), OptionError> {
        count_in("max_depth", self.max_depth, 1, MAX_DEPTH)
    }
}

/// Default of [`RadiosityOptions::link_threshold`].
pub const DEFAULT_LINK_THRESHOLD: f32 = 0.02;

/// `radiosity`: patches, links and bounces. In a medium its camera rays
/// are marched with the raymarch options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadiosityOptions {
    /// Side length (world units) surfaces are cut into patches of; None
    /// picks 1/32 of the largest extent of the bounded geometry.
    pub patch_size: Option<f32>,
    /// Bounces of indirect light (1 = one bounce, as in Madams technique).
    pub bounces: u32,
    /// A patch links to a whole cluster instead of its children when the
    /// cluster's estimated form factor A/(π d²) is below this; 0 links
    /// every patch to every patch it sees (the O(N²) solution).
    pub link_threshold: f32,
}

impl Default for RadiosityOptions {
    fn default() -> Self {
        RadiosityOptions { patch_size: None, bounces: 1, link_threshold: DEFAULT_LINK_THRESHOLD }
    }
}

impl RadiosityOptions {
    pub fn validate(&self) -> Result<(), OptionError> {
        count_in("bounces", self.bounces, 1, MAX_BOUNCES)?;
        if let Some(p) = self.patch_size
            && !(p.is_finite() && p > 0.0)
        {
            return Err(OptionError::new("patch_size", format!("must be a positive number, got {p}")));
        }
        let t = self.link_threshold;
        if !(t.is_finite() && t >= 0.0) {
            return Err(OptionError::new("link_threshold", format!("must be a finite number ≥ 0, got {t}")));
        }
        Ok(())
    }
}

/// Which integrator to build, with the options of every integrator (see
/// the module documentation). `Default` is `direct` with every default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegratorDesc {
    pub kind: IntegratorKind,
    pub raymarch: RaymarchOptions,
    pub analytic: AnalyticOptions,
    pub stochastic: StochasticOptions,
    pub path: PathOptions,
    pub radiosity: RadiosityOptions,
}

impl Default for IntegratorDesc {
    fn default() -> Self {
        IntegratorDesc::new(IntegratorKind::Direct)
    }
}

impl IntegratorDesc {
    /// `kind` with every option at its default.
    pub fn new(kind: IntegratorKind) -> Self {
        IntegratorDesc {
            kind,
            raymarch: RaymarchOptions::default(),
            analytic: AnalyticOptions::default(),
            stochastic: StochasticOptions::default(),
            path: PathOptions::default(),
            radiosity: RadiosityOptions::default(),
        }
    }

    /// The same description with another kind.
    pub fn with_kind(mut self, kind: IntegratorKind) -> Self {
        self.kind = kind;
        self
    }

    /// Checks every option, whichever integrator is chosen (a scene file's
    /// options must be valid even when the command line picks another).
    pub fn validate(&self) -> Result<(), OptionError> {
        self.raymarch.validate()?;
        self.analytic.validate()?;
        self.path.validate()?;
        self.radiosity.validate()
    }

    /// Builds the integrator `kind` names for `scene`: the one place
    /// integrators are made. Fails on an option out of bounds, or when the
    /// integrator cannot render what the scene holds (the reason says what
    /// and what to use instead).
    pub fn build(&self, scene: &Scene) -> Result<Box<dyn Integrator>, IntegratorError> {
        self.validate()?;
        let unsupported = |reason: String| IntegratorError::Unsupported { integrator: self.kind, reason };
        Ok(match self.kind {
            IntegratorKind::Direct => Box::new(Direct),
            IntegratorKind::Raymarch => Box::new(Raymarch::new(self.raymarch)),
            IntegratorKind::Analytic => Box::new(Analytic::new(scene, self.analytic).map_err(unsupported)?),
            IntegratorKind::Stochastic => Box::new(Stochastic::new(self.stochastic)),
            IntegratorKind::Path => Box::new(PathTracer::new(self.path)),
            IntegratorKind::Radiosity => Box::new(RadiosityIntegrator::new(scene, self.radiosity, self.raymarch)?),
        })
    }
}

impl IntegratorDesc {
    /// The integrator and options a scene file's `[render]` table names.
    /// Without an `integrator` key: `raymarch` when the scene has a medium
    /// (show the fog), else `direct`. Errors point at the value.
    pub fn from_render_desc(r: &RenderDesc, has_medium: bool) -> Result<IntegratorDesc, FieldError> {
        let default_kind = if has_medium { IntegratorKind::Raymarch } else { IntegratorKind::Direct };
        let mut d = IntegratorDesc::new(default_kind);
        if let Some(v) = &r.integrator {
            d.kind = parse_name(v, "render.integrator")?;
        }
        if let Some(v) = &r.steps {
            d.raymarch.steps = render_count(v, "steps", 1, MAX_STEPS)?;
        }
        if let Some(v) = r.jitter {
            d.raymarch.jitter = v;
        }
        if let Some(v) = r.shadows {
            d.analytic.shadows = v;
        }
        if let Some(v) = &r.light_steps {
            d.analytic.light_steps = render_count(v, "light_steps", 1, MAX_LIGHT_STEPS)?;
        }
        if let Some(v) = &r.light_quadrature {
            d.analytic.quadrature = parse_name(v, "render.light_quadrature")?;
        }
        if let Some(v) = &r.sampling {
            d.stochastic.sampling = parse_name(v, "render.sampling")?;
        }
        if let Some(v) = r.stratify {
            d.stochastic.stratify = v;
            d.path.stratify = v;
        }
        if let Some(v) = r.reuse {
            d.path.reuse = v;
        }
        if let Some(v) = &r.max_depth {
            d.path.max_depth = render_count(v, "max_depth", 1, MAX_DEPTH)?;
        }
        if let Some(v) = &r.bounces {
            d.radiosity.bounces = render_count(v, "bounces", 1, MAX_BOUNCES)?;
        }
        if let Some(v) = &r.patch_size {
            d.radiosity.patch_size = Some(*v.get_ref());
        }
        if let Some(v) = &r.link_threshold {
            d.radiosity.link_threshold = *v.get_ref();
        }
        // The checks each option type makes, placed at the key's value.
        d.validate().map_err(|e| {
            let span = match e.key {
                "patch_size" => r.patch_size.as_ref().map(|v| v.span()),
                "link_threshold" => r.link_threshold.as_ref().map(|v| v.span()),
                _ => None,
            };
            FieldError { span: span.unwrap_or(0..0), message: format!("render.{e}") }
        })?;
        Ok(d)
    }
}

impl Default for AnalyticOptions {
    fn default() -> Self {
        AnalyticOptions { shadows: false, light_steps: 16, quadrature: LightQuadrature::Gauss }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_option_is_checked_by_its_own_type() {
        let ok = IntegratorDesc::default();
        assert_eq!(ok.validate(), Ok(()));
        let cases: [(IntegratorDesc, &str); 6] = [
            (IntegratorDesc { raymarch: RaymarchOptions { steps: 0, jitter: true }, ..ok }, "steps"),
            (IntegratorDesc { analytic: AnalyticOptions { light_steps: 4097, ..ok.analytic }, ..ok }, "light_steps"),
            (IntegratorDesc { path: PathOptions { max_depth: 0, ..PathOptions::default() }, ..ok }, "max_depth"),
            (IntegratorDesc { radiosity: RadiosityOptions { bounces: 0, ..ok.radiosity }, ..ok }, "bounces"),
            (
                IntegratorDesc { radiosity: RadiosityOptions { link_threshold: -1.0, ..ok.radiosity }, ..ok },
                "link_threshold",
            ),
            (
                IntegratorDesc { radiosity: RadiosityOptions { patch_size: Some(f32::NAN), ..ok.radiosity }, ..ok },
                "patch_size",
            ),
        ];
        for (desc, key) in cases {
            let e = desc.validate().unwrap_err();
            assert_eq!(e.key, key, "{e}");
            assert!(e.to_string().starts_with(key), "{e}");
        }
    }
}
