//! `render --aov`: the first-hit outputs (albedo, normal, depth), the
//! variance and the in-scattered light, written as layers of the render's
//! EXR images.

use airlight::aov::{Aov, SurfaceAovs, in_scattered_aov, surface_aovs};
use airlight::film::Image;
use airlight::integrator::Integrator;
use airlight::scene::Scene;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The AOVs `--aov` names (one value, a comma-separated list).
#[derive(Clone, Debug)]
pub struct AovList(pub Vec<Aov>);

pub fn parse_list(list: &str) -> Result<AovList, String> {
    Aov::parse_list(list).map(AovList)
}

pub fn is_exr(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Refuses AOVs that no output would hold (the library's render job
/// checks the rest).
pub fn check(aovs: &[Aov], outputs: &[PathBuf]) -> Result<(), String> {
    if !aovs.is_empty() && !outputs.iter().any(|o| is_exr(o)) {
        return Err("--aov: the AOVs are layers of an EXR image: give an output ending in .exr (-o NAME.exr)".into());
    }
    Ok(())
}

/// The layers one frame's EXR images carry.
pub struct Layers {
    aovs: Vec<Aov>,
    surface: Option<SurfaceAovs>,
    in_scattered: Option<Image>,
}

impl Layers {
    pub fn none() -> Self {
        Layers { aovs: Vec::new(), surface: None, in_scattered: None }
    }

    /// The first-hit outputs of the frame, over the camera rays of its
    /// samples `samples`, when any is asked for.
    pub fn of_frame(
        scene: &Scene,
        integrator: &dyn Integrator,
        pool: &rayon::ThreadPool,
        aovs: &[Aov],
        samples: Range<u64>,
    ) -> Self {
        let surface = aovs
            .iter()
            .any(|a| matches!(a, Aov::Albedo | Aov::Normal | Aov::Depth))
            .then(|| pool.install(|| surface_aovs(scene, integrator.stratified(), samples.clone())));
        // A second pass over the render's own samples (as costly as the
        // render): checked to be possible in `check`.
        let in_scattered = aovs
            .contains(&Aov::Inscatter)
            .then(|| pool.install(|| in_scattered_aov(scene, integrator, samples)))
            .flatten();
        Layers { aovs: aovs.to_vec(), surface, in_scattered }
    }

    pub fn wants_variance(&self) -> bool {
        self.aovs.contains(&Aov::Variance)
    }

    /// The named channels to write beside R, G, B, with the variance so
    /// far (infinite until two samples are in); None without AOVs.
    pub fn channels(&self, variance: Option<&Image>) -> Option<Vec<(&'static str, Vec<f32>)>> {
        if self.aovs.is_empty() {
            return None;
        }
        let mut out = Vec::new();
        for &aov in &self.aovs {
            let values = match (aov, &self.surface, variance) {
                (Aov::Variance, _, Some(v)) => (0..3).map(|c| v.pixels.iter().map(|p| p[c]).collect()).collect(),
                (Aov::Variance, _, None) => continue,
                (Aov::Inscatter, _, _) => match &self.in_scattered {
                    Some(image) => (0..3).map(|c| image.pixels.iter().map(|p| p[c]).collect()).collect(),
                    None => continue,
                },
                (_, Some(surface), _) => surface.channels(aov).unwrap_or_default(),
                (_, None, _) => continue,
            };
            out.extend(aov.channels().iter().copied().zip(values));
        }
        Some(out)
    }
}
