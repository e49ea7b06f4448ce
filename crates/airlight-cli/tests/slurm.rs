//! `airlight submit slurm` on a real Slurm: a single-node cluster started by
//! tools/slurm-local.sh (Debian's slurmctld, slurmd, slurm-client and
//! munge, which .ci/run installs; starting it needs root). Without them the
//! test says so and is skipped, except under AIRLIGHT_CI=1.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tools() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools/slurm-local.sh")
}

/// Stops the cluster when dropped, if this test started it.
struct Cluster {
    started: bool,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        if self.started {
            let _ = Command::new(tools()).arg("stop").output();
        }
    }
}

fn cluster_up() -> bool {
    Command::new("scontrol").arg("ping").output().is_ok_and(|o| String::from_utf8_lossy(&o.stdout).contains("UP"))
}

fn airlight(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_airlight")).current_dir(dir).args(args).output().unwrap()
}

#[test]
fn submit_slurm_renders_shards_merges_them_and_names_a_failed_task() {
    let needed = ["sbatch", "scontrol", "scancel", "slurmctld", "slurmd", "munged"];
    let install = "apt-get install slurmctld slurmd slurm-client munge, as .ci/run does";
    if !common::tools_present("the Slurm test", &needed, install) {
        return;
    }
    let mut cluster = Cluster { started: false };
    if !cluster_up() {
        let out = Command::new(tools()).arg("start").output().unwrap();
        cluster.started = out.status.success();
        assert!(
            cluster.started,
            "tools/slurm-local.sh start failed (it needs root): {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/spheres_spot_fog.toml");
    let scene = scene.to_str().unwrap();
    let options = ["--width", "48", "--height", "36", "--spp", "8", "--steps", "24", "--quiet"];
    let single = airlight(d, &[&["render", scene, "-o", "single.exr"], &options[..]].concat());
    assert!(single.status.success(), "{}", String::from_utf8_lossy(&single.stderr));

    // Four shards, two tiles: eight tasks and a merge, the single render's bytes.
    let submit_as = |out: &str, shards: &str, tiles: &str| {
        let head = ["submit", "slurm", scene, "-o", out, "--shards", shards, "--tiles", tiles, "--wait", "--"];
        airlight(d, &[&head[..], &options[..]].concat())
    };
    let submit = |out: &str| submit_as(out, "4", "2");
    let ok = submit("ok.exr");
    assert!(ok.status.success(), "{}{}", String::from_utf8_lossy(&ok.stdout), String::from_utf8_lossy(&ok.stderr));
    assert_eq!(std::fs::read(d.join("ok.exr")).unwrap(), std::fs::read(d.join("single.exr")).unwrap());

    // A task that cannot write its part (a folder stands in its place):
    // the merge does not run, submit names the task and exits non-zero.
    let blocked = d.join("bad.slurm/parts/t1_s2.exr");
    std::fs::create_dir_all(&blocked).unwrap();
    let bad = submit("bad.exr");
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(!bad.status.success());
    assert!(stderr.contains("1 of 8 tasks failed, so the merge did not run: task 6 (shard 2/4, tile 1/2"), "{stderr}");
    assert!(!d.join("bad.exr").exists());

    // Run that task again alone, then the merge: the same image.
    std::fs::remove_dir(&blocked).unwrap();
    let work = d.join("bad.slurm");
    let rerun = Command::new("sbatch").args(["--wait", "--array=6"]).arg(work.join("render.sh")).output().unwrap();
    assert!(rerun.status.success(), "{}", String::from_utf8_lossy(&rerun.stderr));
    let merge = Command::new("sbatch").arg("--wait").arg(work.join("merge.sh")).output().unwrap();
    assert!(merge.status.success(), "{}", String::from_utf8_lossy(&merge.stderr));
    assert_eq!(std::fs::read(d.join("bad.exr")).unwrap(), std::fs::read(d.join("single.exr")).unwrap());

    // Names a shell or sbatch would read as syntax reach the scripts quoted
    // (or, for sbatch's own lines, with `%` escaped): the job runs, writes
    // exactly the file named, and runs nothing else.
    let odd = d.join("a;b&c|(d)%e%%f*g<h>");
    std::fs::create_dir(&odd).unwrap();
    let name = odd.join("o;x%j(1)&.exr");
    let ok = submit_as(name.to_str().unwrap(), "2", "1");
    assert!(ok.status.success(), "{}{}", String::from_utf8_lossy(&ok.stdout), String::from_utf8_lossy(&ok.stderr));
    assert_eq!(std::fs::read(&name).unwrap(), std::fs::read(d.join("single.exr")).unwrap());
    let logs: Vec<String> = std::fs::read_dir(odd.join("o;x%j(1)&.slurm/logs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(logs.iter().any(|l| l.starts_with("merge-")), "{logs:?}");
    // Names that no #SBATCH line can hold are refused before anything is
    // written or submitted, and nothing in them runs.
    let hostile =
        ["sp ace.exr", "o\ntouch INJ\n.exr", "$(touch INJ).exr", "`touch INJ`.exr", "q'uote.exr", "d\"quote.exr"];
    for out in hostile {
        let run = submit(out);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{out:?}: {stderr}");
        assert!(stderr.contains("which an #SBATCH line cannot hold"), "{out:?}: {stderr}");
    }
    for (option, value) in [("--partition", "debug\ntouch INJ"), ("--time", "10\ntouch INJ"), ("--time", "1;x")] {
        let run = airlight(d, &["submit", "slurm", scene, "-o", "p.exr", option, value]);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{option} {value:?}: {stderr}");
        assert!(stderr.contains(&format!("{option} ")), "{stderr}");
    }
    assert!(!d.join("INJ").exists() && !Path::new("INJ").exists(), "an injected command ran");
    // A job script that is a symbolic link is replaced, not written through.
    std::fs::create_dir(d.join("lnk.slurm")).unwrap();
    std::fs::write(d.join("victim.txt"), "keep me\n").unwrap();
    std::os::unix::fs::symlink(d.join("victim.txt"), d.join("lnk.slurm/render.sh")).unwrap();
    let ok = submit_as("lnk.exr", "2", "1");
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    assert_eq!(std::fs::read_to_string(d.join("victim.txt")).unwrap(), "keep me\n");
    use std::os::unix::fs::PermissionsExt;
    assert_eq!(std::fs::metadata(d.join("victim.txt")).unwrap().permissions().mode() & 0o111, 0);
    assert!(!std::fs::symlink_metadata(d.join("lnk.slurm/render.sh")).unwrap().file_type().is_symlink());
    // The scene as the output: refused now, not when the merge runs.
    let run = airlight(d, &["submit", "slurm", scene, "-o", scene]);
    assert_eq!(run.status.code(), Some(1), "{}", String::from_utf8_lossy(&run.stderr));
}
