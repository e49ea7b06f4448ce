//! `airlight submit slurm`: one render cut into shards × tiles × frames, run
//! as a Slurm job array (task → one `airlight render --shard --tile
//! --frame`), and a merge job that starts when every task has succeeded
//! (`--dependency=afterok`). The job scripts are written into a work folder
//! beside the output, so that a failed task can be run again alone
//! (`sbatch --array=K WORK/render.sh`) and the merge after it
//! (`sbatch WORK/merge.sh`).

#[cfg(test)]
mod fuzz;

use crate::render::{RenderArgs, numbered, prepare};
use clap::Parser;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

#[derive(clap::Args)]
pub struct SlurmArgs {
    /// Scene file (TOML).
    scene: PathBuf,
    /// The merged image, .exr or .png (with --frames, numbered as `render
    /// --frames` numbers them); may be given more than once.
    #[arg(short, long = "output", value_name = "OUT", required = true)]
    output: Vec<PathBuf>,
    /// Contiguous ranges of samples per pixel, one task each.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    shards: u32,
    /// Bands of rows, one task each (times the shards).
    #[arg(long, value_name = "M", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    tiles: u32,
    /// Frames of the light animation, one task each (times shards × tiles).
    #[arg(long, value_name = "F", value_parser = clap::value_parser!(u32).range(1..))]
    frames: Option<u32>,
    /// Slurm partition (default: the cluster's default).
    #[arg(long)]
    partition: Option<String>,
    /// CPUs per task; each task renders with that many threads.
    #[arg(long, value_name = "C", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    cpus_per_task: u32,
    /// Time limit per task, in Slurm's form (e.g. 30, 1:00:00, 2-0).
    #[arg(long, value_name = "T")]
    time: Option<String>,
    /// Block until the merge ends; exit non-zero, naming the failed tasks,
    /// if any task or the merge fails.
    #[arg(long)]
    wait: bool,
    /// Options for every `airlight render` task (after `--`), e.g.
    /// `-- --spp 4096 --integrator path`.
    #[arg(last = true, value_name = "RENDER OPTIONS")]
    render: Vec<String>,
}

/// `airlight render` options, parsed as the command line parses them.
#[derive(Parser)]
#[command(name = "airlight render")]
struct RenderCommand {
    #[command(flatten)]
    args: RenderArgs,
}

/// Options that submit sets on every task itself.
const OWN: [&str; 10] = [
    "-o",
    "--output",
    "--shard",
    "--tile",
    "--frame",
    "--frames",
    "--threads",
    "--progressive",
    "--target-error",
    "--variance",
];

pub fn slurm(args: SlurmArgs) -> Result<(), String> {
    if let Some(own) =
        args.render.iter().find(|a| OWN.iter().any(|o| a.as_str() == *o || a.starts_with(&format!("{o}="))))
    {
        return Err(format!("`{own}` is set by submit for each task; give it to submit, not after `--`"));
    }
    for tool in ["sbatch", "scontrol"] {
        if !on_path(tool) {
            return Err(format!("`{tool}` is not on PATH: submit slurm needs Slurm's client commands"));
        }
    }
    let exe = std::env::current_exe().map_err(|e| format!("cannot find the airlight binary: {e}"))?;
    let scene = absolute(&args.scene)?;
    let outputs: Vec<PathBuf> = args.output.iter().map(|o| absolute(o)).collect::<Result<_, _>>()?;
    // Check everything a task would check, with the largest shard and tile
    // numbers, before submitting anything.
    let mut check = vec!["render".to_string(), scene.display().to_string()];
    check.extend(args.render.iter().cloned());
    check.extend(["--shard".into(), format!("{}/{}", args.shards - 1, args.shards)]);
    check.extend(["--tile".into(), format!("{}/{}", args.tiles - 1, args.tiles)]);
    if let Some(f) = args.frames {
        check.extend(["--frames".into(), f.to_string(), "--frame".into(), (f - 1).to_string()]);
    }
    check.extend(["-o".into(), "check.exr".into()]);
    let parsed = RenderCommand::try_parse_from(&check).map_err(|e| format!("the render options: {e}"))?;
    let (file, _, _) = prepare(&parsed.args)?;
    // The merged images, checked now rather than when the merge runs: each
    // a .png or .exr, none over the scene, its files or each other.
    for out in &outputs {
        if !out
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| matches!(e.to_ascii_lowercase().as_str(), "png" | "exr"))
        {
            return Err(format!("cannot write `{}`: the output must end in .png or .exr", out.display()));
        }
    }
    crate::outputs::check_render(Some(&scene), file.scene.files(), &outputs, None, args.frames)?;

    check_sbatch_values(&args)?;
    let work = work_folder(&outputs[0]);
    let (parts, logs) = (work.join("parts"), work.join("logs"));
    check_log_folder(&logs)?;
    for dir in [&work, &parts, &logs] {
        // A folder that is a symbolic link would put the scripts and parts
        // wherever it points.
        if std::fs::symlink_metadata(dir).is_ok_and(|m| m.file_type().is_symlink()) {
            return Err(format!(
                "`{}` is a symbolic link: submit writes its work folder only as a real folder",
                dir.display()
            ));
        }
        std::fs::create_dir_all(dir).map_err(|e| format!("cannot create `{}`: {e}", dir.display()))?;
    }
    let tasks = args.shards as u64 * args.tiles as u64 * args.frames.unwrap_or(1) as u64;
    let render_script = work.join("render.sh");
    let merge_script = work.join("merge.sh");
    write_script(&render_script, &render_sh(&args, &exe, &scene, &parts, &logs))?;
    write_script(&merge_script, &merge_sh(&args, &exe, &outputs, &parts, &logs))?;

    let array = sbatch(&[format!("--array=0-{}", tasks - 1)], &render_script)?;
    let merge = sbatch(&[format!("--dependency=afterok:{array}"), "--kill-on-invalid-dep=yes".into()], &merge_script)?;
    println!(
        "render job array {array}: {tasks} tasks ({} shards × {} tiles × {} frames)",
        args.shards,
        args.tiles,
        args.frames.unwrap_or(1)
    );
    println!("merge job {merge}: after every task succeeds");
    println!("work folder: {} (scripts, parts/, logs/)", work.display());
    println!(
        "a failed task K runs again alone with `sbatch --array=K {}`, then the merge with `sbatch {}`",
        render_script.display(),
        merge_script.display()
    );
    if args.wait {
        wait(&array, &merge, &args, &logs)?;
        println!("done: {}", outputs.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "));
    }
    Ok(())
}

/// `OUT.slurm/` beside the first output.
fn work_folder(output: &Path) -> PathBuf {
    let stem = output.file_stem().unwrap_or_default().to_string_lossy();
    output.with_file_name(format!("{stem}.slurm"))
}

fn absolute(path: &Path) -> Result<PathBuf, String> {
    std::path::absolute(path).map_err(|e| format!("`{}`: {e}", path.display()))
}

fn on_path(tool: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|paths| std::env::split_paths(&paths).any(|d| d.join(tool).is_file()))
}

/// A word for a shell script: single-quoted.
fn quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// Refuses a partition or time limit that could not stand alone on an
/// `#SBATCH` line: sbatch reads those lines itself, and a line break in a
/// value would start a shell command of its own.
fn check_sbatch_values(args: &SlurmArgs) -> Result<(), String> {
    let check = |option: &str, value: &Option<String>, allowed: &dyn Fn(char) -> bool, form: &str| match value {
        Some(v) if v.is_empty() || !v.chars().all(allowed) => Err(format!("--{option} {v:?}: expected {form}")),
        _ => Ok(()),
    };
    let partition = |c: char| c.is_ascii_alphanumeric() || "_-.,".contains(c);
    check(
        "partition",
        &args.partition,
        &partition,
        "a partition name (letters, digits, `_`, `-`, `.`; `,` between names)",
    )?;
    let time = |c: char| c.is_ascii_digit() || ":-".contains(c);
    check("time", &args.time, &time, "a time limit in Slurm's form (minutes, M:S, H:M:S, D-H, D-H:M or D-H:M:S)")
}

/// Refuses a log folder that an `#SBATCH --output=` line could not hold
/// as it is: sbatch splits those lines at white space and reads quotes and
/// backslashes itself, and a line break would end the line. (`%`, Slurm's
/// file-name patterns, is escaped as `%%` instead.)
fn check_log_folder(logs: &Path) -> Result<(), String> {
    let text = logs.to_str().ok_or_else(|| format!("`{}` is not UTF-8: job scripts cannot name it", logs.display()))?;
    match text.chars().find(|c| c.is_whitespace() || c.is_control() || "\"'\\`$".contains(*c)) {
        Some(c) => Err(format!(
            "the work folder `{}` holds {c:?}, which an #SBATCH line cannot hold: give an output in a folder \
             whose path has no white space, quotes, backslashes, `$` or backticks",
            logs.display()
        )),
        None => Ok(()),
    }
}

/// A log file's path for an `#SBATCH --output=` line: `%` doubled, since
/// Slurm reads `%A`, `%a`, `%j` … as patterns (`pattern` adds its own).
fn log_path(logs: &Path, pattern: &str) -> String {
    format!("{}/{pattern}", logs.display().to_string().replace('%', "%%"))
}

/// The #SBATCH lines every job shares (so that a task run again alone with
/// `sbatch --array=K render.sh` gets them too); every value was checked
/// ([`check_sbatch_values`], [`check_log_folder`]).
fn sbatch_lines(args: &SlurmArgs, name: &str, log: &str) -> String {
    let mut s = format!("#SBATCH --job-name={name}\n#SBATCH --output={log}\n");
    if let Some(p) = &args.partition {
        let _ = writeln!(s, "#SBATCH --partition={p}");
    }
    if let Some(t) = &args.time {
        let _ = writeln!(s, "#SBATCH --time={t}");
    }
    s
}

/// The array task's script: task number → shard, tile, frame.
fn render_sh(args: &SlurmArgs, exe: &Path, scene: &Path, parts: &Path, logs: &Path) -> String {
    let (n, m) = (args.shards, args.tiles);
    let mut s = String::from("#!/bin/bash\n");
    s += &sbatch_lines(args, "airlight-render", &log_path(logs, "render-%A_%a.log"));
    let _ = writeln!(s, "#SBATCH --cpus-per-task={}", args.cpus_per_task);
    s += "# Task K renders shard K % N, tile (K / N) % M, frame K / (N M).\n";
    s += "set -euo pipefail\n";
    s += "task=${SLURM_ARRAY_TASK_ID:?run this script as a Slurm array task}\n";
    let _ = writeln!(s, "shard=$(( task % {n} ))\ntile=$(( task / {n} % {m} ))\nframe=$(( task / {} ))", n * m);
    let mut command = vec![
        quote(&exe.display().to_string()),
        "render".into(),
        quote(&scene.display().to_string()),
        "--shard".into(),
        format!("\"$shard/{n}\""),
        "--tile".into(),
        format!("\"$tile/{m}\""),
    ];
    if let Some(f) = args.frames {
        command.extend(["--frames".into(), f.to_string(), "--frame".into(), "\"$frame\"".into()]);
    }
    command.extend(["--threads".into(), "\"${SLURM_CPUS_PER_TASK:-1}\"".into()]);
    command.extend(args.render.iter().map(|a| quote(a)));
    command.extend(["-o".into(), format!("{}/\"t${{tile}}_s${{shard}}.exr\"", quote(&parts.display().to_string()))]);
    let _ = writeln!(s, "exec {}", command.join(" "));
    s
}

/// The part files of one frame (named as `render --frames` numbers them).
fn part_files(args: &SlurmArgs, parts: &Path, frame: Option<u32>) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for tile in 0..args.tiles {
        for shard in 0..args.shards {
            let file = parts.join(format!("t{tile}_s{shard}.exr"));
            files.push(match frame {
                Some(k) => numbered(&file, k),
                None => file,
            });
        }
    }
    files
}

/// The merge job's script: one `airlight merge` per frame, naming every part.
fn merge_sh(args: &SlurmArgs, exe: &Path, outputs: &[PathBuf], parts: &Path, logs: &Path) -> String {
    let mut s = String::from("#!/bin/bash\n");
    s += &sbatch_lines(args, "airlight-merge", &log_path(logs, "merge-%j.log"));
    s += "set -euo pipefail\n";
    let frames: Vec<Option<u32>> = match args.frames {
        Some(f) => (0..f).map(Some).collect(),
        None => vec![None],
    };
    for frame in frames {
        let mut command = vec![quote(&exe.display().to_string()), "merge".into()];
        command.extend(part_files(args, parts, frame).iter().map(|p| quote(&p.display().to_string())));
        for out in outputs {
            let out = match frame {
                Some(k) => numbered(out, k),
                None => out.clone(),
            };
            command.extend(["-o".into(), quote(&out.display().to_string())]);
        }
        let _ = writeln!(s, "{}", command.join(" "));
    }
    s
}

/// Writes a job script whole, executable, never through a symbolic link
/// at `path` (the link is replaced; what it pointed to is untouched).
fn write_script(path: &Path, text: &str) -> Result<(), String> {
    use std::io::Write;
    use std::os::unix::fs::PermissionsExt;
    airlight::film::write_atomically_with(path, |file| {
        file.write_all(text.as_bytes())?;
        // On the open file: a mode set by path would follow a link.
        file.set_permissions(std::fs::Permissions::from_mode(0o755))
    })
    .map_err(|e| format!("cannot write `{}`: {e}", path.display()))
}

/// Submits `script` with `options`; the job id.
fn sbatch(options: &[String], script: &Path) -> Result<String, String> {
    let out = Command::new("sbatch")
        .arg("--parsable")
        .args(options)
        .arg(script)
        .output()
        .map_err(|e| format!("cannot run sbatch: {e}"))?;
    if !out.status.success() {
        return Err(format!("sbatch {} failed: {}", script.display(), String::from_utf8_lossy(&out.stderr).trim()));
    }
    // `--parsable` prints "id" or "id;cluster".
    let text = String::from_utf8_lossy(&out.stdout);
    let id = text.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(format!("sbatch printed no job id: `{}`", text.trim()));
    }
    Ok(id)
}

/// The state of a job (or of each task of an array): (task id, state).
fn job_states(id: &str) -> Result<Vec<(Option<u32>, String)>, String> {
    let out = Command::new("scontrol")
        .args(["show", "job", id, "--oneliner"])
        .output()
        .map_err(|e| format!("cannot run scontrol: {e}"))?;
    if !out.status.success() {
        return Err(format!("scontrol show job {id}: {}", String::from_utf8_lossy(&out.stderr).trim()));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    Ok(text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let field = |name: &str| {
                line.split_whitespace().find_map(|w| w.strip_prefix(name).and_then(|v| v.strip_prefix('=')))
            };
            let task = field("ArrayTaskId").and_then(|t| t.parse().ok());
            (task, field("JobState").unwrap_or("UNKNOWN").to_string())
        })
        .collect())
}

const FAILED: [&str; 7] = ["FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY", "BOOT_FAIL", "DEADLINE"];

/// Polls the array and the merge until the merge ends or a task fails.
fn wait(array: &str, merge: &str, args: &SlurmArgs, logs: &Path) -> Result<(), String> {
    loop {
        let tasks = job_states(array)?;
        let failed: Vec<u32> =
            tasks.iter().filter(|(_, s)| FAILED.contains(&s.as_str())).filter_map(|(t, _)| *t).collect();
        let running =
            tasks.iter().any(|(_, s)| matches!(s.as_str(), "PENDING" | "RUNNING" | "CONFIGURING" | "COMPLETING"));
        if !failed.is_empty() && !running {
            let _ = Command::new("scancel").arg(merge).output();
            let (n, m) = (args.shards, args.tiles);
            let names: Vec<String> = failed
                .iter()
                .map(|&k| {
                    let frame = args.frames.map(|f| format!(", frame {} of {f}", k / (n * m))).unwrap_or_default();
                    format!(
                        "task {k} (shard {}/{n}, tile {}/{m}{frame}; log {})",
                        k % n,
                        k / n % m,
                        logs.join(format!("render-{array}_{k}.log")).display()
                    )
                })
                .collect();
            return Err(format!(
                "{} of {} tasks failed, so the merge did not run: {}",
                failed.len(),
                tasks.len(),
                names.join("; ")
            ));
        }
        if let Some((_, state)) = job_states(merge)?.first() {
            match state.as_str() {
                "COMPLETED" => return Ok(()),
                s if FAILED.contains(&s) => {
                    return Err(format!(
                        "the merge job {merge} ended {s}: see {}",
                        logs.join(format!("merge-{merge}.log")).display()
                    ));
                }
                _ => {}
            }
        }
        std::thread::sleep(Duration::from_millis(500));
    }
}
