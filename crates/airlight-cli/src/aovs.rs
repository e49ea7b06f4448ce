//! `render --aov`: the first-hit outputs (albedo, normal, depth), the
//! variance and the in-scattered light, written as layers of the render's
//! EXR images.

use airlight::aov::{Aov, SurfaceAovs, in_scattered_aov, surface_aovs};
use airlight::denoise::Denoiser;
use airlight::film::Image;
use airlight::integrator::Integrator;
use airlight::scene::Scene;
use std::borrow::Cow;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

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
    /// `--denoise`: the library, which the first hits' albedo and normal guide.
    denoiser: Option<Arc<Denoiser>>,
}

/// Where `--denoise` looks for Open Image Denoise: `AIRLIGHT_OIDN` (the
/// library or its folder), a pip-installed `pyoidn`'s copy (as the
/// `python3` on the path finds it), and the system's library path.
pub fn oidn_candidates() -> Vec<PathBuf> {
    let mut candidates: Vec<PathBuf> = std::env::var_os("AIRLIGHT_OIDN").map(PathBuf::from).into_iter().collect();
    let script = "import os, pyoidn; print(os.path.join(os.path.dirname(pyoidn.__file__), 'oidn', 'lib'))";
    if let Ok(out) =
        std::process::Command::new("python3").args(["-c", script]).stderr(std::process::Stdio::null()).output()
        && out.status.success()
    {
        let folder = String::from_utf8_lossy(&out.stdout).trim().to_string();
        if !folder.is_empty() {
            candidates.push(PathBuf::from(folder));
        }
    }
    candidates.push(PathBuf::from(airlight::denoise::LIBRARY));
    candidates
}

impl Layers {
    pub fn none() -> Self {
        Layers { aovs: Vec::new(), surface: None, in_scattered: None, denoiser: None }
    }

    /// The image to write: `image`, denoised when `--denoise` asked.
    pub fn finish<'a>(&self, image: &'a Image) -> Result<Cow<'a, Image>, String> {
        match (&self.denoiser, &self.surface) {
            (Some(denoiser), Some(s)) => denoiser.denoise(image, Some((&s.albedo, &s.normal))).map(Cow::Owned),
            (Some(denoiser), None) => denoiser.denoise(image, None).map(Cow::Owned),
            _ => Ok(Cow::Borrowed(image)),
        }
    }

    /// The first-hit outputs of the frame, over the camera rays of its
    /// samples `samples`, when any is asked for.
    pub fn of_frame(
        scene: &Scene,
        integrator: &dyn Integrator,
        pool: &rayon::ThreadPool,
        aovs: &[Aov],
        samples: Range<u64>,
        denoiser: Option<Arc<Denoiser>>,
    ) -> Self {
        let surface = (denoiser.is_some() || aovs.iter().any(|a| matches!(a, Aov::Albedo | Aov::Normal | Aov::Depth)))
            .then(|| pool.install(|| surface_aovs(scene, integrator.stratified(), samples.clone())));
        // A second pass over the render's own samples (as costly as the
        // render): checked to be possible in `check`.
        let in_scattered = aovs
            .contains(&Aov::Inscatter)
            .then(|| pool.install(|| in_scattered_aov(scene, integrator, samples)))
            .flatten();
        Layers { aovs: aovs.to_vec(), surface, in_scattered, denoiser }
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
