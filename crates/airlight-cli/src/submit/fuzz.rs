//! Fuzzing the job scripts (with the library fuzzers' seeded generator): 10,000 submissions with hostile names (spaces,
//! quotes, `$()`, backticks, `;`, `%`, newlines, backslashes, globs) for
//! the binary, the scene, the outputs, the work folder, the render options,
//! the partition and the time limit. Each pair of scripts that the checks
//! let through is run by bash, as Slurm would run it, with the commands
//! replaced by a print of the words bash hands them: every word must come
//! out exactly as given, no other command may run (PATH is empty, and no
//! file may appear), and every `#SBATCH` line must hold exactly its value.
//! One bash process runs them all. A million in an ignored test
//! (`cargo test -p airlight-cli --bin airlight scripts -- --ignored`;
//! `AIRLIGHT_FUZZ_INPUTS` sets the count).

use super::*;
use crate::mutate::Rng;

/// A name a hostile user might give: plain letters mixed with what a
/// shell or sbatch would read.
fn hostile(rng: &mut Rng) -> String {
    const PIECES: [&str; 24] = [
        "a",
        "b",
        "x",
        " ",
        "'",
        "\"",
        "$",
        "$(touch INJ)",
        "`touch INJ`",
        ";",
        "\n",
        "%",
        "%j",
        "\\",
        "*",
        "?",
        "~",
        "#",
        "!",
        "{a,b}",
        "&",
        "|",
        ">INJ",
        "é",
    ];
    pieces(rng, &PIECES)
}

/// A name the work folder's `#SBATCH --output=` line can hold (no white
/// space, quotes, backslashes, `$` or backticks), still full of what a
/// shell would read.
fn hostile_folder(rng: &mut Rng) -> String {
    const PIECES: [&str; 16] = ["a", "b", "x", ";", "%", "%j", "*", "?", "~", "#", "!", "{a,b}", "&", "|", ">INJ", "é"];
    pieces(rng, &PIECES)
}

fn pieces(rng: &mut Rng, pieces: &[&str]) -> String {
    let len = 1 + rng.below(6);
    (0..len).map(|_| *rng.pick(pieces)).collect()
}

/// A partition or time limit: a valid one, or a hostile one.
fn sbatch_value(rng: &mut Rng, valid: &[&str]) -> Option<String> {
    match rng.below(4) {
        0 => None,
        1 | 2 => Some(rng.pick(valid).to_string()),
        _ => Some(hostile(rng)),
    }
}

/// One submission's arguments and paths (beside `root`, where bash runs).
struct Input {
    args: SlurmArgs,
    exe: PathBuf,
    scene: PathBuf,
    outputs: Vec<PathBuf>,
    parts: PathBuf,
    logs: PathBuf,
}

fn input(seed: u64, root: &Path) -> Input {
    let mut rng = Rng(seed);
    // The work folder is named after the first output: mostly one its
    // #SBATCH line can hold, so that most inputs reach bash.
    let folder_name = |rng: &mut Rng| if rng.below(8) == 0 { hostile(rng) } else { hostile_folder(rng) };
    let folder = root.join(folder_name(&mut rng));
    let outputs: Vec<PathBuf> = (0..1 + rng.below(2))
        .map(|k| folder.join(format!("{}.exr", if k == 0 { folder_name(&mut rng) } else { hostile(&mut rng) })))
        .collect();
    let work = work_folder(&outputs[0]);
    let args = SlurmArgs {
        scene: folder.join(format!("{}.toml", hostile(&mut rng))),
        output: outputs.clone(),
        shards: 1 + rng.below(3) as u32,
        tiles: 1 + rng.below(3) as u32,
        frames: rng.below(2).eq(&0).then(|| 1 + rng.below(3) as u32),
        partition: sbatch_value(&mut rng, &["debug", "gpu-a100", "p.1,p.2"]),
        cpus_per_task: 1,
        time: sbatch_value(&mut rng, &["30", "1:00:00", "2-0"]),
        wait: false,
        render: (0..rng.below(4)).map(|_| hostile(&mut rng)).collect(),
    };
    Input {
        exe: root.join(hostile(&mut rng)).join("airlight"),
        scene: args.scene.clone(),
        outputs,
        parts: work.join("parts"),
        logs: work.join("logs"),
        args,
    }
}

/// The words `render.sh` must hand the binary as array task `task`.
fn render_words(i: &Input, task: u32) -> Vec<String> {
    let (n, m) = (i.args.shards, i.args.tiles);
    let (shard, tile, frame) = (task % n, task / n % m, task / (n * m));
    let mut words = vec![i.exe.display().to_string(), "render".into(), i.scene.display().to_string()];
    words.extend(["--shard".into(), format!("{shard}/{n}"), "--tile".into(), format!("{tile}/{m}")]);
    if let Some(f) = i.args.frames {
        words.extend(["--frames".into(), f.to_string(), "--frame".into(), frame.to_string()]);
    }
    words.extend(["--threads".into(), "1".into()]);
    words.extend(i.args.render.iter().cloned());
    words.extend(["-o".into(), format!("{}/t{tile}_s{shard}.exr", i.parts.display())]);
    words
}

/// The words of each of `merge.sh`'s commands, one per frame.
fn merge_words(i: &Input) -> Vec<Vec<String>> {
    let frames: Vec<Option<u32>> = match i.args.frames {
        Some(f) => (0..f).map(Some).collect(),
        None => vec![None],
    };
    frames
        .into_iter()
        .map(|frame| {
            let mut words = vec![i.exe.display().to_string(), "merge".into()];
            words.extend(part_files(&i.args, &i.parts, frame).iter().map(|p| p.display().to_string()));
            for out in &i.outputs {
                let out = frame.map_or(out.clone(), |k| numbered(out, k));
                words.extend(["-o".into(), out.display().to_string()]);
            }
            words
        })
        .collect()
}

/// The `#SBATCH` lines a script must have, and nothing else of that form.
fn check_sbatch_lines(script: &str, i: &Input, log: &str, job: &str) -> Result<(), String> {
    let mut want = vec![format!("--job-name={job}"), format!("--output={log}")];
    want.extend(i.args.partition.iter().map(|p| format!("--partition={p}")));
    want.extend(i.args.time.iter().map(|t| format!("--time={t}")));
    if job == "airlight-render" {
        want.push("--cpus-per-task=1".into());
    }
    let got: Vec<&str> = script.lines().filter_map(|l| l.strip_prefix("#SBATCH ")).collect();
    // sbatch splits these lines at white space: each must be one word.
    if got.len() != want.len() || got.iter().zip(&want).any(|(g, w)| g != w || g.contains(char::is_whitespace)) {
        return Err(format!("#SBATCH lines {got:?}, expected {want:?}"));
    }
    Ok(())
}

/// `merge.sh` with each command (a line that starts with the binary's
/// quoted path) printed as bash splits it into words instead of run:
/// `printf` in front, a record separator (0x1e, in no name) after. Lines are found outside single
/// quotes (a quoted name may hold a line break); outside them a backslash
/// escapes the next character, as in the `'\''` the scripts use.
fn printed(script: &str) -> String {
    let (mut out, mut quoted, mut escaped, mut line_start, mut command) = (String::new(), false, false, true, false);
    for c in script.chars() {
        if line_start && !quoted && c == '\'' {
            out.push_str("printf '%s\\0' ");
            command = true;
        }
        line_start = false;
        if c == '\n' && !quoted {
            if command {
                out.push_str("; printf '\\036'");
                command = false;
            }
            line_start = true;
        }
        if c == '\'' && !escaped {
            quoted = !quoted;
        }
        escaped = !quoted && !escaped && c == '\\';
        out.push(c);
    }
    out
}

/// Runs `count` inputs seeded from `base`.
fn fuzz_scripts(count: u64, base: u64) {
    let dir = tempfile::tempdir().unwrap();
    let (root, run) = (dir.path().join("root"), dir.path().join("run"));
    std::fs::create_dir_all(&run).unwrap();
    let mut driver = String::from("set -u\n");
    let mut expected = Vec::new();
    let (mut refused, mut accepted) = (0u64, 0u64);
    for k in 0..count {
        let i = input(base.wrapping_add(k), &root);
        let checked = check_sbatch_values(&i.args).and_then(|()| check_log_folder(&i.logs));
        if checked.is_err() {
            // A value that an #SBATCH line cannot hold as it is.
            refused += 1;
            continue;
        }
        accepted += 1;
        let render = render_sh(&i.args, &i.exe, &i.scene, &i.parts, &i.logs);
        let merge = merge_sh(&i.args, &i.exe, &i.outputs, &i.parts, &i.logs);
        let render_log = log_path(&i.logs, "render-%A_%a.log");
        check_sbatch_lines(&render, &i, &render_log, "airlight-render").unwrap();
        check_sbatch_lines(&merge, &i, &log_path(&i.logs, "merge-%j.log"), "airlight-merge").unwrap();
        let tasks = i.args.shards * i.args.tiles * i.args.frames.unwrap_or(1);
        let task = (base.wrapping_add(k) % tasks as u64) as u32;
        std::fs::write(run.join(format!("render{k}.sh")), &render).unwrap();
        std::fs::write(run.join(format!("merge{k}.sh")), printed(&merge)).unwrap();
        let _ = writeln!(
            driver,
            "( export SLURM_ARRAY_TASK_ID={task} SLURM_CPUS_PER_TASK=1; exec() {{ printf '%s\\0' \"$@\"; }}; \
             . ./render{k}.sh ) > render{k}.out 2>&1\n( . ./merge{k}.sh ) > merge{k}.out 2>&1"
        );
        expected.push((k, render_words(&i, task), merge_words(&i)));
    }
    std::fs::write(run.join("driver.sh"), driver).unwrap();
    // Found on this PATH; the scripts run with none, so that a command an
    // injection would start is not found.
    let paths = std::env::var_os("PATH").unwrap_or_default();
    let bash = std::env::split_paths(&paths).map(|d| d.join("bash")).find(|p| p.is_file()).expect("bash on PATH");
    let status = Command::new(bash).arg("driver.sh").current_dir(&run).env_clear().env("PATH", "").status();
    assert!(status.unwrap().success());
    for (k, render, merges) in &expected {
        let out = |name: String| String::from_utf8(std::fs::read(run.join(name)).unwrap()).unwrap();
        let text = out(format!("render{k}.out"));
        let words: Vec<&str> = text.split_terminator('\0').collect();
        assert_eq!(words, *render, "render.sh of input {k} (seed {})", base.wrapping_add(*k));
        let text = out(format!("merge{k}.out"));
        let lines: Vec<Vec<&str>> =
            text.split_terminator('\u{1e}').map(|l| l.split_terminator('\0').collect()).collect();
        let merges: Vec<Vec<&str>> = merges.iter().map(|m| m.iter().map(String::as_str).collect()).collect();
        assert_eq!(lines, merges, "merge.sh of input {k} (seed {})", base.wrapping_add(*k));
    }
    // No injected command ran: nothing but the scripts and their outputs.
    let stray: Vec<String> = std::fs::read_dir(&run)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !(n.ends_with(".sh") || n.ends_with(".out")))
        .collect();
    assert!(stray.is_empty(), "files made by the scripts: {stray:?}");
    eprintln!("fuzz job scripts: {count} inputs, {accepted} run by bash, {refused} refused");
}

#[test]
fn hostile_names_reach_every_command_as_given_and_run_nothing_else() {
    fuzz_scripts(10_000, 0x5106);
}

#[test]
#[ignore = "a million inputs: run by hand (BENCHMARKS.md); AIRLIGHT_FUZZ_INPUTS sets the count"]
fn a_million_hostile_scripts() {
    let count: u64 = std::env::var("AIRLIGHT_FUZZ_INPUTS").ok().and_then(|v| v.parse().ok()).unwrap_or(1_000_000);
    for batch in 0..count.div_ceil(10_000) {
        fuzz_scripts(10_000.min(count - batch * 10_000), 0xB16 + batch * 10_000);
    }
}
