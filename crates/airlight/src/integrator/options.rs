//! What an integrator is built from: its kind and each integrator's own
//! options, each with its defaults and its checks, and the one function that
//! builds them ([`IntegratorDesc::build`]).
//!
//! A scene file's `[render]` table may hold options of several integrators
//! (`steps` for raymarch, `bounces` for radiosity, …) and the command line
//! may pick another integrator than the file names, so a description keeps
//! the options of every integrator and `kind` says which one is built.
//!
//! Every option is declared once, in [`INTEGRATOR_OPTIONS`]: key, kind of
//! value with its bounds, doc line and the integrators that read it. The
//! scene file, the command line and Python set options through it, and
//! [`IntegratorDesc::validate`] checks by it.

use super::analytic::{AnalyticOptions, LightQuadrature};
use super::{
    AmbientOcclusion, AmbientOcclusionOptions, Analytic, Direct, Integrator, IntegratorKind, PathTracer,
    RadiosityIntegrator, Raymarch, Sampling, Stochastic,
};
use crate::options::{Checked, NumberRange, OptionSpec, OptionValue, ValueKind, set_named};
use crate::radiosity::{RadiosityError, RadiosityOptions};
use crate::scene::Scene;

pub use crate::options::OptionError;

/// Most march samples per ray (`steps`).
pub const MAX_STEPS: u32 = 1 << 20;
/// Most points per dimension over a line or quad light (`light_steps`).
pub const MAX_LIGHT_STEPS: u32 = 4096;
/// Most scattering events of a path (`max_depth`).
pub const MAX_DEPTH: u32 = 1 << 16;
/// Most radiosity bounces (`bounces`).
pub const MAX_BOUNCES: u32 = 1024;

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

impl Default for AnalyticOptions {
    fn default() -> Self {
        AnalyticOptions { shadows: false, light_steps: 16, quadrature: LightQuadrature::Gauss }
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
    pub ambient_occlusion: AmbientOcclusionOptions,
}

impl Default for IntegratorDesc {
    fn default() -> Self {
        IntegratorDesc::new(IntegratorKind::Direct)
    }
}

/// One integrator option: its declaration and the integrators that read it.
pub struct IntegratorOption {
    pub spec: OptionSpec<IntegratorDesc>,
    /// The integrators whose images depend on it.
    pub takes: &'static [IntegratorKind],
}

use IntegratorKind::{Analytic as AnalyticKind, Path as PathKind, Radiosity as RadiosityKind};
use IntegratorKind::{Raymarch as RaymarchKind, Stochastic as StochasticKind};

/// A count as an option value.
fn count(n: u32) -> OptionValue {
    OptionValue::Int(n as i128)
}

/// The key of the option that names the integrator: the one option every
/// integrator takes, and the one front ends give a place of its own
/// (Python's first argument).
pub const INTEGRATOR_KEY: &str = "integrator";

/// Every integrator option, in the order the docs list them.
pub const INTEGRATOR_OPTIONS: &[IntegratorOption] = &[
    IntegratorOption {
        spec: OptionSpec {
            key: INTEGRATOR_KEY,
            kind: ValueKind::Name(&IntegratorKind::NAMES),
            unit: "",
            doc: "The integrator that renders the image.",
            default_doc: Some("raymarch if the scene has a medium, else direct"),
            get: |d| OptionValue::Text(d.kind.name().into()),
            set: |d, v| set_named(&mut d.kind, v),
        },
        takes: &IntegratorKind::ALL,
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "steps",
            kind: ValueKind::Count { min: 1, max: MAX_STEPS as u64 },
            unit: "",
            doc: "March samples per camera ray, each with a shadow ray to each light.",
            default_doc: None,
            get: |d| count(d.raymarch.steps),
            set: |d, v| d.raymarch.steps = v.count() as u32,
        },
        takes: &[RaymarchKind, RadiosityKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "jitter",
            kind: ValueKind::Bool,
            unit: "",
            doc: "Offset the march samples by a random fraction of a step (else at each step's middle).",
            default_doc: None,
            get: |d| OptionValue::Bool(d.raymarch.jitter),
            set: |d, v| d.raymarch.jitter = v.bool(),
        },
        takes: &[RaymarchKind, RadiosityKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "shadows",
            kind: ValueKind::Bool,
            unit: "",
            doc: "Volumetric shadows: integrate only the lit intervals of each ray.",
            default_doc: None,
            get: |d| OptionValue::Bool(d.analytic.shadows),
            set: |d, v| d.analytic.shadows = v.bool(),
        },
        takes: &[AnalyticKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "light_steps",
            kind: ValueKind::Count { min: 1, max: MAX_LIGHT_STEPS as u64 },
            unit: "",
            doc: "Points per dimension over line, quad and triangle lights.",
            default_doc: None,
            get: |d| count(d.analytic.light_steps),
            set: |d, v| d.analytic.light_steps = v.count() as u32,
        },
        takes: &[AnalyticKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "light_quadrature",
            kind: ValueKind::Name(&["gauss", "uniform"]),
            unit: "",
            doc: "How points are placed over a light: Gauss–Legendre nodes, or equal steps (Packard's).",
            default_doc: None,
            get: |d| OptionValue::Text(d.analytic.quadrature.name().into()),
            set: |d, v| set_named(&mut d.analytic.quadrature, v),
        },
        takes: &[AnalyticKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "sampling",
            kind: ValueKind::Name(&["uniform", "equiangular", "mis"]),
            unit: "",
            doc: "How the point on the camera segment is drawn.",
            default_doc: None,
            get: |d| OptionValue::Text(d.stochastic.sampling.name().into()),
            set: |d, v| set_named(&mut d.stochastic.sampling, v),
        },
        takes: &[StochasticKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "stratify",
            kind: ValueKind::Bool,
            unit: "",
            doc: "Draw each pixel's samples from Owen-scrambled Sobol' points rather than independently.",
            default_doc: None,
            get: |d| OptionValue::Bool(d.stochastic.stratify && d.path.stratify),
            set: |d, v| {
                d.stochastic.stratify = v.bool();
                d.path.stratify = v.bool();
            },
        },
        takes: &[StochasticKind, PathKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "max_depth",
            kind: ValueKind::Count { min: 1, max: MAX_DEPTH as u64 },
            unit: "",
            doc: "Most scattering events of a path; 1 is direct light and single scattering.",
            default_doc: None,
            get: |d| count(d.path.max_depth),
            set: |d, v| d.path.max_depth = v.count() as u32,
        },
        takes: &[PathKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "reuse",
            kind: ValueKind::Bool,
            unit: "",
            doc: "Neighbouring pixels' paths share what they gather beyond their second vertex (no medium).",
            default_doc: None,
            get: |d| OptionValue::Bool(d.path.reuse),
            set: |d, v| d.path.reuse = v.bool(),
        },
        takes: &[PathKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "bounces",
            kind: ValueKind::Count { min: 1, max: MAX_BOUNCES as u64 },
            unit: "",
            doc: "Bounces of indirect light.",
            default_doc: None,
            get: |d| count(d.radiosity.bounces),
            set: |d, v| d.radiosity.bounces = v.count() as u32,
        },
        takes: &[RadiosityKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "patch_size",
            kind: ValueKind::Number(NumberRange::Positive),
            unit: "world units",
            doc: "Side length surfaces are cut into patches of.",
            default_doc: Some("1/32 of the bounded geometry's largest extent"),
            get: |d| d.radiosity.patch_size.map_or(OptionValue::Default, OptionValue::real),
            set: |d, v| {
                d.radiosity.patch_size = match v {
                    Checked::Default => None,
                    v => Some(v.number() as f32),
                };
            },
        },
        takes: &[RadiosityKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "link_threshold",
            kind: ValueKind::Number(NumberRange::NonNegative),
            unit: "",
            doc: "A patch links to a whole cluster whose form factor estimate A/(π d²) is below this; 0 links every pair.",
            default_doc: None,
            get: |d| OptionValue::real(d.radiosity.link_threshold),
            set: |d, v| d.radiosity.link_threshold = v.number() as f32,
        },
        takes: &[RadiosityKind],
    },
    IntegratorOption {
        spec: OptionSpec {
            key: "ao_distance",
            kind: ValueKind::Number(NumberRange::Positive),
            unit: "world units",
            doc: "How far a direction from a surface must be open to count as open.",
            default_doc: None,
            get: |d| OptionValue::real(d.ambient_occlusion.distance),
            set: |d, v| d.ambient_occlusion.distance = v.number() as f32,
        },
        takes: &[IntegratorKind::AmbientOcclusion],
    },
];

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
            ambient_occlusion: AmbientOcclusionOptions::default(),
        }
    }

    /// The same description with another kind.
    pub fn with_kind(mut self, kind: IntegratorKind) -> Self {
        self.kind = kind;
        self
    }

    /// The declaration of option `key`, if it is an integrator option.
    pub fn option(key: &str) -> Option<&'static IntegratorOption> {
        INTEGRATOR_OPTIONS.iter().find(|o| o.spec.key == key)
    }

    /// Sets option `key` to `value`, checked by its declaration.
    /// None when no integrator has an option `key`.
    pub fn set(&mut self, key: &str, value: &OptionValue) -> Option<Result<(), OptionError>> {
        Self::option(key).map(|o| o.spec.apply(self, value))
    }

    /// Checks every option by its declaration, whichever integrator is
    /// chosen (a scene file's options must be valid even when the command
    /// line picks another).
    pub fn validate(&self) -> Result<(), OptionError> {
        INTEGRATOR_OPTIONS.iter().try_for_each(|o| o.spec.validate(self))
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
            IntegratorKind::AmbientOcclusion => Box::new(AmbientOcclusion::new(self.ambient_occlusion)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_option_is_checked_by_its_declaration() {
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

    #[test]
    fn each_option_reads_back_what_it_was_set_to_and_knows_its_names() {
        crate::options::check_declarations(INTEGRATOR_OPTIONS.iter().map(|o| &o.spec));
    }

    #[test]
    fn every_integrator_but_direct_takes_an_option_of_its_own() {
        for kind in IntegratorKind::ALL {
            let own = INTEGRATOR_OPTIONS.iter().filter(|o| o.spec.key != INTEGRATOR_KEY && o.takes.contains(&kind));
            assert_eq!(own.count() == 0, kind == IntegratorKind::Direct, "{kind}");
        }
    }
}
