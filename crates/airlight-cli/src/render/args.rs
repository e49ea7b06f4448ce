//! What `airlight render`'s command line says: its arguments, checked as
//! clap parses them, and the scene file with their overrides applied.

use crate::load::load;
use crate::options::OptionFlags;
use airlight::SceneFile;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct RenderArgs {
    /// Scene file (TOML). Without one, the built-in demo scene.
    pub(super) scene: Option<PathBuf>,
    /// Output image, .png or .exr; may be given more than once.
    /// Default: airlight.png for the demo, else the scene's name with .png.
    #[arg(short, long = "output", value_name = "OUT")]
    pub(super) output: Vec<PathBuf>,
    /// Render in passes of 1, 1, 2, 4, ... samples per pixel up to spp,
    /// rewriting the output after each pass.
    #[arg(long)]
    pub(super) progressive: bool,
    /// Stop once the estimated relative error of the image (√(Σ variance of
    /// the pixel means / Σ mean²)) is below E, or at spp; implies
    /// --progressive. The estimate is close for independent samples, high
    /// for stratified ones (stochastic), and low while rare bright samples
    /// (fireflies) are still missing.
    #[arg(long, value_name = "E", value_parser = parse_target_error)]
    pub(super) target_error: Option<f64>,
    /// Also write the estimated variance of each pixel's mean (per channel)
    /// as an EXR; implies --progressive.
    #[arg(long, value_name = "OUT.exr")]
    pub(super) variance: Option<PathBuf>,
    /// Render N frames of the scene's light animation (lights with
    /// keyframes), frame k at time k/(N − 1), each output numbered:
    /// NAME_0000.png, NAME_0001.png, ...
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=crate::preflight::MAX_FRAMES as i64))]
    pub(super) frames: Option<u32>,
    /// With --frames N: only frame K (0 ≤ K < N), named as --frames names it.
    #[arg(long, value_name = "K", requires = "frames")]
    pub(super) frame: Option<u32>,
    /// Only the K-th of N contiguous ranges of each pixel's samples
    /// (0 ≤ K < N), written as a partial EXR for `airlight merge`.
    #[arg(long, value_name = "K/N", value_parser = parse_part)]
    pub(super) shard: Option<(u32, u32)>,
    /// Only the K-th of N bands of rows (0 ≤ K < N), written as a partial
    /// EXR for `airlight merge`; combines with --shard.
    #[arg(long, value_name = "K/N", value_parser = parse_part)]
    pub(super) tile: Option<(u32, u32)>,
    /// With --progressive: continue the render whose samples so far are kept
    /// beside the output (NAME.partial.exr, rewritten after every pass); the
    /// finished image is the one an uninterrupted render gives, bit for bit.
    #[arg(long, requires = "progressive")]
    pub(super) resume: bool,
    /// Falloff for every point, spot and sphere light: physical, sphere,
    /// cutoff, window_tan, window_rational, window_ue4 (each keeps its cutoff).
    #[arg(long, value_parser = parse_attenuation)]
    pub(super) attenuation: Option<airlight::light::AttenuationModel>,
    /// A medium instead of the scene's (a glTF file has none): the keys of
    /// a scene file's `[medium]` as `key=value` pairs separated by commas,
    /// e.g. `sigma_s=0.05,sigma_a=0.01,g=0.3`, `sigma_s=[0.1,0.1,0.2]` or
    /// `type="height",sigma_s=0.2,falloff=0.5`; `none` for no medium.
    #[arg(long, value_name = "KEY=VALUE,...", value_parser = parse_medium)]
    pub(super) medium: Option<MediumOption>,
    /// The sky's radiance instead of the scene's (a uniform sky, or the
    /// scale of its environment map): a number or `[r,g,b]` (≥ 0); `none`
    /// for no sky.
    #[arg(long, value_name = "RADIANCE", value_parser = parse_sky)]
    pub(super) sky: Option<airlight::Rgb>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=crate::preflight::MAX_THREADS as i64))]
    pub(super) threads: Option<u32>,
    /// Also write, as layers of each .exr output, what the camera's first
    /// hits are: a comma-separated list of albedo, normal, depth and
    /// variance (variance implies --progressive); and inscatter, the
    /// medium's light alone (raymarch, analytic, stochastic)
    #[arg(long, value_name = "LIST", value_parser = crate::aovs::parse_list)]
    pub(super) aov: Option<crate::aovs::AovList>,
    #[command(flatten)]
    pub(super) options: OptionFlags,
    /// Denoise the image with Intel Open Image Denoise, guided by the first
    /// hits' albedo and normal (`pip install pyoidn` provides the library,
    /// or set AIRLIGHT_OIDN to it); not with --shard or --tile, whose sums
    /// are merged first.
    #[arg(long)]
    pub(super) denoise: bool,
    /// No progress bar or summary.
    #[arg(long, short)]
    pub(super) quiet: bool,
}

/// The scene file with the command line's overrides applied and checked.
pub(super) fn configure(args: &RenderArgs) -> Result<SceneFile, String> {
    let mut file = load(args.scene.as_deref())?;
    let mut settings = file.scene.settings().clone();
    args.options.apply(&mut settings, &mut file.integrator)?;
    *file.scene.settings_mut() = settings;
    if let Some(model) = args.attenuation {
        file.scene.set_attenuation_model(model).map_err(|e| format!("--attenuation: {e}"))?;
    }
    if let Some(MediumOption(medium)) = &args.medium {
        file.scene.set_medium(medium.clone()).map_err(|e| format!("--medium: {e}"))?;
    }
    if let Some(radiance) = args.sky {
        file.scene.set_sky(radiance);
    }
    Ok(file)
}

/// `--sky`: a radiance, a number or `[r,g,b]`, finite and ≥ 0; `none` is 0.
fn parse_sky(s: &str) -> Result<airlight::Rgb, String> {
    use airlight::options::OptionValue;
    let rgb = match OptionValue::parse_word(s) {
        OptionValue::Text(t) if t == "none" => return Ok(airlight::Rgb::ZERO),
        OptionValue::Int(n) => [n as f64; 3],
        OptionValue::Float(x) => [x; 3],
        OptionValue::List(v) if v.len() == 3 => [v[0], v[1], v[2]],
        _ => return Err(format!("`{s}` is not a radiance: a number, [r,g,b] or none")),
    };
    if rgb.iter().any(|c| !(c.is_finite() && *c >= 0.0 && *c <= f32::MAX as f64)) {
        return Err(format!("`{s}`: a radiance is finite and ≥ 0"));
    }
    Ok(airlight::Rgb::new(rgb[0] as f32, rgb[1] as f32, rgb[2] as f32))
}

/// `--medium`: a medium, or None for `none`.
#[derive(Clone, Debug)]
pub struct MediumOption(Option<airlight::medium::Medium>);

fn parse_medium(s: &str) -> Result<MediumOption, String> {
    if s.trim() == "none" {
        return Ok(MediumOption(None));
    }
    airlight::scene_file::medium_from_options(s).map(|m| MediumOption(Some(m)))
}

/// The image outputs: as given, or NAME.png after the scene file.
pub(super) fn output_paths(args: &RenderArgs) -> Result<Vec<PathBuf>, String> {
    let outputs = if args.output.is_empty() {
        vec![match &args.scene {
            Some(path) => PathBuf::from(path.file_stem().unwrap_or_default()).with_extension("png"),
            None => PathBuf::from("airlight.png"),
        }]
    } else {
        args.output.clone()
    };
    for out in &outputs {
        match out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("png" | "exr") => {}
            _ => {
                return Err(format!("cannot write `{}`: the output must end in .png or .exr", out.display()));
            }
        }
    }
    Ok(outputs)
}

fn parse_target_error(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(e) if e > 0.0 && e.is_finite() => Ok(e),
        _ => Err(format!("`{s}` is not a positive number (a relative error, e.g. 0.01)")),
    }
}

/// `K/N` with 0 ≤ K < N.
fn parse_part(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("`{s}` is not K/N with whole numbers 0 ≤ K < N (e.g. 2/8)");
    let (k, n) = s.split_once('/').ok_or_else(bad)?;
    let (k, n): (u32, u32) = (k.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
    if k < n { Ok((k, n)) } else { Err(bad()) }
}

fn parse_attenuation(s: &str) -> Result<airlight::light::AttenuationModel, String> {
    use airlight::light::AttenuationModel as M;
    Ok(match s {
        "physical" => M::Physical,
        "sphere" => M::Sphere,
        "cutoff" => M::Cutoff,
        "window_tan" => M::WindowTan,
        "window_rational" => M::WindowRational,
        "window_ue4" => M::WindowUe4,
        _ => {
            return Err(format!(
                "unknown attenuation `{s}`; expected physical, sphere, cutoff, window_tan, window_rational or window_ue4"
            ));
        }
    })
}
