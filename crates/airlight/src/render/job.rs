//! A render job: what one render computes (its mode, which samples of
//! which rows, its AOVs, its worker threads) and the rules every front end
//! obeys: which modes go together, the bounds of shards and tiles, the
//! memory each mode holds, and how many threads it may start. The CLI's
//! `render` and `gi`, the viewer, `study` and the Python package describe
//! their renders as a [`RenderRequest`] and get a checked [`RenderJob`], so
//! the rules are written once, here.

use super::aov::Aov;
use crate::film::FilmSettings;
use crate::film::partial::piece;
use crate::integrator::IntegratorKind;
use crate::memory::MemoryError;
use crate::scene::RenderSettings;
use std::ops::Range;

/// Most worker threads a render starts: spawning tens of thousands takes
/// minutes before any work starts.
pub const MAX_THREADS: u32 = 4096;

/// How a render takes its samples and what it keeps of them, which sets
/// its memory ([`RenderMode::bytes`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RenderMode {
    /// All samples in one go ([`crate::render::render`]): each tile's sums
    /// live only while it renders; the image and its encoded file (measured
    /// at 2048²: 19.8 bytes a pixel in all).
    Image,
    /// Passes of 1, 1, 2, 4, … samples ([`crate::render::Progressive`]),
    /// every pixel's sums kept for a variance, checkpoints or an error
    /// target: the accumulator, the image, a variance image and an encoded
    /// file (measured at 2048²: 137 bytes a pixel in all). A pass that may
    /// be `cancellable` (the study's) adds into sums of its own first, so
    /// that a cancelled pass adds nothing.
    Progressive { cancellable: bool },
    /// A part of a render, a shard of the samples or a tile of rows
    /// ([`crate::render::accumulate`]), kept as sums for a merge (measured
    /// at 2048²: 121–122 bytes a pixel in all).
    Partial,
    /// Adaptive sampling ([`crate::render::adaptive`]): the accumulator,
    /// which holds the pilot and then every sample; while planning, each
    /// pixel's noise twice (f64 each) and its count; then the image and its
    /// encoded file (measured at 2048²: 135 bytes a pixel in all).
    Adaptive,
}

impl RenderMode {
    /// Bytes a render of `pixels` pixels in this mode holds at its peak,
    /// with an image's worth to spare for the rest (tiles under way,
    /// encoders' buffers). Files are encoded straight to disk.
    pub fn bytes(self, pixels: u64) -> u64 {
        let sums = crate::film::ACCUMULATOR_BYTES_PER_PIXEL as u64;
        let image = size_of::<crate::Rgb>() as u64;
        let per_pixel = match self {
            RenderMode::Image => 2 * image,
            RenderMode::Partial => sums + 2 * image,
            RenderMode::Progressive { cancellable: false } => sums + 4 * image,
            RenderMode::Progressive { cancellable: true } => 2 * sums + 4 * image,
            RenderMode::Adaptive => sums + 2 * 8 + 4 + 2 * image,
        };
        pixels.saturating_mul(per_pixel)
    }

    /// Refuses a render of the film's size in this mode that would not fit
    /// in memory ([`crate::memory::check`]).
    pub fn check_memory(self, film: &FilmSettings) -> Result<(), MemoryError> {
        let what = format!("a {}×{} render", film.width, film.height);
        crate::memory::check(what, self.bytes(film.pixels()))
    }
}

/// What a front end asks of a render, before it is checked.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderRequest {
    /// Only part k of n of each pixel's samples (0 ≤ k < n).
    pub shard: Option<(u32, u32)>,
    /// Only band k of n of the image's rows (0 ≤ k < n).
    pub tile: Option<(u32, u32)>,
    /// Render in passes (progressive output, an error target).
    pub passes: bool,
    /// Passes that may be cancelled part way (a deadline), each adding
    /// into sums of its own first so that a cancelled one adds nothing.
    pub cancellable: bool,
    /// Also the estimated variance of each pixel's mean (rendered in
    /// passes).
    pub variance: bool,
    /// The AOVs to write beside the image.
    pub aovs: Vec<Aov>,
    /// Worker threads; None for one a core.
    pub threads: Option<u32>,
}

/// A checked request: how it renders, which samples of which rows.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderJob {
    pub mode: RenderMode,
    /// The samples of each pixel rendered (numbered across passes).
    pub samples: Range<u64>,
    /// The rows rendered.
    pub rows: Range<u32>,
    pub aovs: Vec<Aov>,
    pub variance: bool,
    /// Worker threads; 0 for one a core (rayon's default).
    pub threads: usize,
}

impl RenderRequest {
    /// Checks the request against the render's settings and integrator:
    /// the modes that do not go together, the bounds of shards, tiles and
    /// threads, and AOVs the integrator cannot give. The messages name
    /// what was asked in words every front end shares.
    pub fn check(&self, settings: &RenderSettings, integrator: IntegratorKind) -> Result<RenderJob, String> {
        let threads = match self.threads {
            None => 0,
            Some(n) if (1..=MAX_THREADS).contains(&n) => n as usize,
            Some(n) => return Err(format!("threads must be an integer from 1 to {MAX_THREADS}, got {n}")),
        };
        let part = |what: &str, part: Option<(u32, u32)>, total: u64, unit: &str| match part {
            None => Ok(0..total),
            Some((k, n)) if k >= n => Err(format!("{what} {k}/{n}: a part k of n needs 0 ≤ k < n")),
            Some((k, n)) if n as u64 > total => {
                Err(format!("{what} {k}/{n}: the render has only {total} {unit}, so at most {total} {what}s"))
            }
            Some((k, n)) => Ok(piece(total, k as u64, n as u64)),
        };
        let samples = part("shard", self.shard, settings.spp as u64, "samples per pixel")?;
        let rows = part("tile", self.tile, settings.film.height as u64, "rows")?;
        let rows = rows.start as u32..rows.end as u32;
        let partial = self.shard.is_some() || self.tile.is_some();
        let variance = self.variance || self.aovs.contains(&Aov::Variance);
        let passes = self.passes || self.cancellable || variance;
        if partial && !self.aovs.is_empty() {
            return Err("AOVs: a shard or tile holds part of the samples as sums; render the AOVs with the merged \
                        image's settings, without a shard or tile"
                .into());
        }
        if partial && passes {
            return Err("a shard or tile renders a fixed part of the samples: it does not go with passes, an error \
                        target or a variance (merge the parts, then compare)"
                .into());
        }
        if variance && settings.spp < 2 {
            return Err("a variance needs at least 2 samples per pixel (spp)".into());
        }
        if settings.adaptive && (partial || passes) {
            return Err("adaptive sampling renders in one go, its counts set by a pilot pass: it does not go with a \
                        shard, a tile, passes, an error target or a variance"
                .into());
        }
        if self.aovs.contains(&Aov::Inscatter) {
            if !integrator.separates_in_scattering() {
                let those: Vec<&str> =
                    IntegratorKind::ALL.into_iter().filter(|k| k.separates_in_scattering()).map(|k| k.name()).collect();
                return Err(format!(
                    "the inscatter AOV: the {integrator} integrator does not separate the medium's light; use {}",
                    crate::options::one_of(&those)
                ));
            }
            if settings.adaptive {
                // The layer is drawn with a uniform render's samples, so the
                // image minus it would no longer be the surfaces' light
                // sample for sample.
                return Err("the inscatter AOV is drawn with the samples of a uniform render: it does not go with \
                            adaptive sampling"
                    .into());
            }
        }
        let mode = if partial {
            RenderMode::Partial
        } else if passes {
            RenderMode::Progressive { cancellable: self.cancellable }
        } else if settings.adaptive {
            RenderMode::Adaptive
        } else {
            RenderMode::Image
        };
        Ok(RenderJob { mode, samples, rows, aovs: self.aovs.clone(), variance, threads })
    }
}

impl RenderJob {
    /// Whether the job renders a part of the image for a merge.
    pub fn partial(&self) -> bool {
        self.mode == RenderMode::Partial
    }

    /// The job's worker threads.
    pub fn thread_pool(&self) -> Result<rayon::ThreadPool, String> {
        pool(self.threads)
    }
}

fn pool(threads: usize) -> Result<rayon::ThreadPool, String> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("airlight-{i}"))
        .build()
        .map_err(|e| format!("cannot start worker threads: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(spp: u32, adaptive: bool) -> RenderSettings {
        let mut s = RenderSettings { spp, adaptive, ..RenderSettings::default() };
        s.film.height = 10;
        s
    }

    #[test]
    fn each_request_gets_its_mode_and_its_part() {
        let s = settings(8, false);
        let check = |r: RenderRequest| r.check(&s, IntegratorKind::Raymarch).unwrap();
        assert_eq!(check(RenderRequest::default()).mode, RenderMode::Image);
        let job = check(RenderRequest { shard: Some((1, 4)), tile: Some((0, 2)), ..Default::default() });
        assert_eq!((job.mode, job.samples, job.rows), (RenderMode::Partial, 2..4, 0..5));
        let job = check(RenderRequest { aovs: vec![Aov::Variance], ..Default::default() });
        assert_eq!(job.mode, RenderMode::Progressive { cancellable: false });
        assert!(job.variance);
        let adaptive = RenderRequest::default().check(&settings(8, true), IntegratorKind::Path).unwrap();
        assert_eq!(adaptive.mode, RenderMode::Adaptive);
    }

    #[test]
    fn modes_that_do_not_go_together_are_refused() {
        let s = settings(8, false);
        let refused = |r: RenderRequest, s: &RenderSettings, kind, phrase: &str| {
            let e = r.check(s, kind).unwrap_err();
            assert!(e.contains(phrase), "{e}");
        };
        use IntegratorKind::*;
        let shard = RenderRequest { shard: Some((0, 2)), ..Default::default() };
        refused(RenderRequest { passes: true, ..shard.clone() }, &s, Raymarch, "does not go with passes");
        refused(RenderRequest { aovs: vec![Aov::Albedo], ..shard.clone() }, &s, Raymarch, "without a shard");
        refused(RenderRequest { shard: Some((0, 9)), ..Default::default() }, &s, Raymarch, "at most 8 shards");
        refused(RenderRequest { tile: Some((3, 3)), ..Default::default() }, &s, Raymarch, "0 ≤ k < n");
        refused(shard, &settings(8, true), Path, "adaptive sampling renders in one go");
        refused(RenderRequest { variance: true, ..Default::default() }, &settings(1, false), Path, "at least 2");
        let inscatter = RenderRequest { aovs: vec![Aov::Inscatter], ..Default::default() };
        refused(inscatter.clone(), &s, Path, "use raymarch, analytic or stochastic");
        refused(inscatter, &settings(8, true), Raymarch, "does not go with adaptive");
        refused(RenderRequest { threads: Some(0), ..Default::default() }, &s, Path, "from 1 to 4096");
    }

    #[test]
    fn each_mode_holds_at_least_the_image() {
        for mode in [
            RenderMode::Image,
            RenderMode::Partial,
            RenderMode::Progressive { cancellable: false },
            RenderMode::Progressive { cancellable: true },
            RenderMode::Adaptive,
        ] {
            assert!(mode.bytes(1000) >= 1000 * size_of::<crate::Rgb>() as u64, "{mode:?}");
        }
        assert!(RenderMode::Partial.bytes(1) > RenderMode::Image.bytes(1));
    }
}
