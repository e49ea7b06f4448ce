//! `airlight study` as a user runs it: the report and every image it names
//! are there, its figures are what `airlight compare` says of the written
//! images (the independent check), Monte Carlo curves fall with time, and
//! Ctrl-C leaves a report of what was finished.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn airlight(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_airlight")).current_dir(dir).args(args).output().unwrap()
}

fn scene(name: &str) -> String {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    path.to_str().unwrap().to_string()
}

/// Every `src="…"` of the page.
fn sources(html: &str) -> Vec<String> {
    html.split("src=\"").skip(1).map(|s| s[..s.find('"').unwrap()].to_string()).collect()
}

/// `airlight compare`'s figures, by name.
fn compare(dir: &Path, image: &str, truth: &str) -> Vec<(String, f64)> {
    let out = airlight(dir, &["compare", image, truth]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    ["rmse", "rel_mse", "mae", "max", "rel_rmse"]
        .iter()
        .map(|key| {
            let line = text.lines().find(|l| l.starts_with(&format!("{key}: "))).unwrap();
            (key.to_string(), line[key.len() + 2..].parse().unwrap())
        })
        .collect()
}

/// The relative RMSE the page shows in row `exr`'s cell of `class`.
fn shown(html: &str, exr: &str, class: &str) -> f64 {
    let row = &html[html.find(&format!("data-exr=\"{exr}\"")).unwrap()..];
    let row = &row[..row.find("</tr>").unwrap()];
    let cell = &row[row.find(&format!("class=\"{class}\">")).unwrap() + class.len() + 9..];
    cell[..cell.find('<').unwrap()].parse().unwrap()
}

#[test]
fn the_report_holds_every_image_and_the_figures_compare_gives() {
    let dir = tempfile::tempdir().unwrap();
    let out = airlight(
        dir.path(),
        &[
            "study",
            &scene("spheres_spot_fog.toml"),
            "--width",
            "24",
            "--height",
            "18",
            "--time-budget",
            "12",
            "--truth-error",
            "0.03",
            "--integrators",
            "path,raymarch,stochastic,analytic",
            "-o",
            "report",
            "--json",
            "study.json",
            "--quiet",
        ],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("speed vs path") && stdout.contains("stochastic"), "the table on the terminal: {stdout}");
    let report = dir.path().join("report");
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    let study: Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("study.json")).unwrap()).unwrap();
    assert_eq!(study["state"], "finished");
    for src in sources(&html) {
        assert!(report.join(&src).is_file(), "the page shows {src}, which is missing");
    }
    assert!(sources(&html).iter().any(|s| s == "plot.svg"));
    // Height fog: analytic refuses, and the page says why.
    let refused = study["not_run"].as_array().unwrap();
    assert!(refused.iter().any(|n| n["reason"].as_str().unwrap().contains("homogeneous medium")), "{refused:?}");
    assert!(html.contains("needs a homogeneous medium"));
    // Every row's figures are those of `airlight compare` of its image
    // against the truth, as written.
    let truth_of = |transport: &str| if transport == "single" { "truth_single.exr" } else { "truth.exr" };
    let mut rows = 0;
    for series in study["series"].as_array().unwrap() {
        let own = truth_of(series["transport"].as_str().unwrap());
        for row in series["rows"].as_array().unwrap() {
            let exr = row["exr"].as_str().unwrap();
            for (key, value) in compare(&report, exr, own) {
                assert_eq!(row["error"][&key].as_f64(), Some(value), "{exr} {key}");
            }
            let rel = row["error"]["rel_rmse"].as_f64().unwrap();
            assert!((shown(&html, exr, "rel") / rel - 1.0).abs() < 1e-3, "{exr}: the page's figure");
            if !row["error_full"].is_null() {
                for (key, value) in compare(&report, exr, "truth.exr") {
                    assert_eq!(row["error_full"][&key].as_f64(), Some(value), "{exr} {key} vs full");
                }
                let full = row["error_full"]["rel_rmse"].as_f64().unwrap();
                assert!((shown(&html, exr, "full") / full - 1.0).abs() < 1e-3);
            }
            rows += 1;
        }
    }
    assert!(rows >= 10, "{rows} rows");
    // A Monte Carlo integrator's error falls as its time grows: its last
    // rung well below its first, and the log–log trend downward.
    let stochastic = study["series"].as_array().unwrap().iter().find(|s| s["id"] == "stochastic").unwrap();
    let points: Vec<(f64, f64)> = stochastic["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["seconds"].as_f64().unwrap().ln(), r["error"]["rel_rmse"].as_f64().unwrap().ln()))
        .collect();
    assert!(points.len() >= 3, "{points:?}");
    assert!(points.windows(2).all(|w| w[1].0 > w[0].0), "time grows rung by rung");
    assert!(points[points.len() - 1].1 < points[0].1 + 0.5f64.ln(), "{points:?}");
    let n = points.len() as f64;
    let (mx, my) = (points.iter().map(|p| p.0).sum::<f64>() / n, points.iter().map(|p| p.1).sum::<f64>() / n);
    let slope = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    assert!(slope < -0.1, "log–log slope {slope}");
}

#[test]
fn ctrl_c_leaves_a_report_of_what_was_finished() {
    let dir = tempfile::tempdir().unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_airlight"))
        .current_dir(dir.path())
        .args(["study", &scene("cornell_box.toml"), "--width", "16", "--height", "16", "--truth-error", "0.05"])
        .args(["--time-budget", "600", "--integrators", "path,direct", "-o", "report", "--json", "s.json"])
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let json = dir.path().join("s.json");
    let start = Instant::now();
    // Until the ladder has finished a few rungs.
    loop {
        let rows =
            std::fs::read_to_string(&json).ok().and_then(|t| serde_json::from_str::<Value>(&t).ok()).map_or(0, |v| {
                v["series"].as_array().map_or(0, |s| s.iter().map(|s| s["rows"].as_array().unwrap().len()).sum())
            });
        if rows >= 3 {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(120), "no rungs after two minutes");
        std::thread::sleep(Duration::from_millis(50));
    }
    let kill = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains("stopped by Ctrl-C"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let report = dir.path().join("report");
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    assert!(html.contains("Stopped by Ctrl-C"));
    let study: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(study["state"], "stopped");
    for src in sources(&html) {
        assert!(report.join(&src).is_file(), "{src}");
    }
    for series in study["series"].as_array().unwrap() {
        for row in series["rows"].as_array().unwrap() {
            assert!(report.join(row["exr"].as_str().unwrap()).is_file());
        }
    }
    // Nothing half-written is left behind.
    let names: Vec<String> =
        std::fs::read_dir(&report).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into()).collect();
    assert!(names.iter().all(|n| !n.contains(".tmp-")), "{names:?}");
}

#[test]
fn bad_options_give_clear_errors_before_any_render() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("full").with_extension("txt"), "x").unwrap();
    let cornell = scene("cornell_box.toml");
    let cases: [(&[&str], &str); 11] = [
        (&["--time-budget", "0"], "number of seconds"),
        (&["--time-budget", "nan"], "number of seconds"),
        (&["--truth-error", "1.5"], "relative error"),
        (&["--integrators", "path,magic"], "unknown integrator"),
        (&["--threads", "5000"], "4096"),
        (&["--width", "70000"], "65536"),
        (&["-o", "."], "not empty"),
        (&["--json", "missing/s.json", "-o", "r"], "cannot write"),
        (&["--json", &cornell, "-o", "r"], "would replace an input"),
        (&["--json", "r/index.html", "-o", "r"], "are the same file"),
        (&["--json", "r", "-o", "r"], "it is a folder"),
    ];
    for (args, expected) in cases {
        let out = airlight(dir.path(), &[&["study", &cornell, "--quiet"][..], args].concat());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        // Refused before any render: no report folder is left behind.
        assert!(!dir.path().join("r").exists(), "{args:?} left r/");
    }
    // Images that would not fit in memory (here a 64 MB limit) are refused
    // up front, with the size that would.
    let out = Command::new(env!("CARGO_BIN_EXE_airlight"))
        .current_dir(dir.path())
        .env("AIRLIGHT_MEMORY_LIMIT", "64M")
        .args(["study", &cornell, "--width", "2000", "--height", "2000", "--time-budget", "5", "-o", "r", "--quiet"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains("2000×2000 study needs about"), "{stderr}");
    assert!(!dir.path().join("r").exists());
    let out = airlight(dir.path(), &["study", "no-such.toml"]);
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("no-such.toml"));
}

#[test]
fn a_budget_too_small_for_anything_leaves_no_report() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell_box.toml");
    let args = ["study", &cornell, "--width", "64", "--height", "64", "--time-budget", "0.001", "-o", "r", "--quiet"];
    let out = airlight(dir.path(), &args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains("give a larger --time-budget"), "{stderr}");
    assert!(!dir.path().join("r").exists(), "an empty report was left: {stderr}");
    // An earlier report in the folder is left as it was.
    std::fs::create_dir(dir.path().join("r")).unwrap();
    std::fs::write(dir.path().join("r/index.html"), "earlier").unwrap();
    let out = airlight(dir.path(), &args);
    assert!(!out.status.success());
    assert_eq!(std::fs::read_to_string(dir.path().join("r/index.html")).unwrap(), "earlier");
}
