//! `airlight merge`: partial renders (from `render --shard/--tile`) added up
//! into the image one render of all the samples gives, bit for bit.

use crate::outputs::Output;
use airlight::film::partial::{self, Partial};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct MergeArgs {
    /// Partial renders (EXR files written by `airlight render --shard K/N`
    /// or `--tile K/N`) that together hold every sample of every pixel once.
    #[arg(required = true, value_name = "PARTS")]
    parts: Vec<PathBuf>,
    /// Output image, .exr or .png; may be given more than once.
    #[arg(short, long = "output", value_name = "OUT", required = true)]
    output: Vec<PathBuf>,
    /// Also write the estimated variance of each pixel's mean as an EXR.
    #[arg(long, value_name = "VAR.exr")]
    variance: Option<PathBuf>,
    /// No summary.
    #[arg(long, short)]
    quiet: bool,
}

pub fn merge(args: MergeArgs) -> Result<(), String> {
    for out in &args.output {
        match out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("png" | "exr") => {}
            _ => return Err(format!("cannot write `{}`: the output must end in .png or .exr", out.display())),
        }
    }
    if let Some(v) = &args.variance
        && !v.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        return Err(format!("cannot write `{}`: the variance is written as .exr", v.display()));
    }
    // Every output checked against the parts and each other, and its
    // folder, before any part is read.
    let outputs: Vec<Output> = args.output.iter().map(|path| Output { option: "-o", path }).collect();
    let variance = args.variance.iter().map(|path| Output { option: "--variance", path });
    let outputs: Vec<Output> = outputs.into_iter().chain(variance).collect();
    let inputs: Vec<&Path> = args.parts.iter().map(PathBuf::as_path).collect();
    crate::outputs::check(&outputs, &inputs)?;
    let mut parts = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        let part = Partial::read(path).map_err(|why| format!("{}: {why}", path.display()))?;
        parts.push((path.display().to_string(), part));
    }
    // Every check is made before anything is written.
    let (header, sums) = partial::merge(&parts)?;
    let image = sums.image();
    for out in &args.output {
        image
            .save_with(out, header.exposure, header.tonemap)
            .map_err(|e| format!("cannot write `{}`: {e}", out.display()))?;
    }
    if let Some(path) = &args.variance {
        sums.variance().save(path).map_err(|e| format!("cannot write `{}`: {e}", path.display()))?;
    }
    if !args.quiet {
        let frame = header.frame.map(|(k, n)| format!(", frame {k} of {n}")).unwrap_or_default();
        eprintln!(
            "merged {} parts: {}×{}, {} spp{frame} → {}",
            parts.len(),
            header.width,
            header.height,
            header.spp,
            args.output.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
        );
    }
    Ok(())
}
