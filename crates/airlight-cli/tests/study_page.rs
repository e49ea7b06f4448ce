//! The study's page in a real browser: headless Chromium takes a
//! screenshot, which must show a page (not blank), the table (its header's
//! colour) and the plot above it (the series' colours). Needs `chromium`
//! (`apt-get install -y chromium`); skipped without it, except under
//! AIRLIGHT_CI=1.

mod common;

use std::path::Path;
use std::process::Command;

/// The table header's background (report.rs's STYLE).
const HEADER: [u8; 3] = [0x2b, 0x4c, 0x7e];
/// The first two series' colours (table.rs's PALETTE): path and path at max_depth 1.
const SERIES: [[u8; 3]; 2] = [[31, 119, 180], [255, 127, 14]];

fn near(p: &[u8], c: [u8; 3], tolerance: i32) -> bool {
    (0..3).all(|i| (p[i] as i32 - c[i] as i32).abs() <= tolerance)
}

#[test]
fn the_page_shows_the_table_and_the_plot_in_chromium() {
    if !common::tools_present(
        "the_page_shows_the_table_and_the_plot_in_chromium",
        &["chromium"],
        "apt-get install -y chromium",
    ) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell_box.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_airlight"))
        .current_dir(dir.path())
        .args(["study", scene.to_str().unwrap(), "--width", "16", "--height", "16", "--time-budget", "6"])
        .args(["--truth-error", "0.05", "--integrators", "path,direct", "-o", "report", "--quiet"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let page = dir.path().join("report/index.html");
    let shot = dir.path().join("shot.png");
    let profile = tempfile::tempdir().unwrap();
    let browser = Command::new("chromium")
        .args(["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run"])
        .args(["--disable-background-networking", "--disable-component-update", "--disable-sync"])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(format!("--screenshot={}", shot.display()))
        .arg("--window-size=1200,2000")
        .arg(format!("file://{}", page.display()))
        .output()
        .unwrap();
    assert!(shot.is_file(), "no screenshot: {}", String::from_utf8_lossy(&browser.stderr));
    let image = image::open(&shot).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (1200, 2000));
    let pixels: Vec<&[u8]> = image.pixels().map(|p| &p.0[..]).collect();
    // Not blank: much that is not white, and many colours.
    let inked = pixels.iter().filter(|p| !near(p, [255, 255, 255], 8)).count();
    assert!(inked > pixels.len() / 20, "{inked} of {} pixels are not white", pixels.len());
    let mut colours: Vec<[u8; 3]> = pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(colours.len() > 200, "{} colours", colours.len());
    // The table: a band of its header's colour.
    let row = |y: u32| (0..1200).filter(|&x| near(&image.get_pixel(x, y).0, HEADER, 6)).count();
    let header = (0..2000).find(|&y| row(y) > 300).expect("no table header on the page");
    // The plot, above the table: both series' colours drawn there.
    for colour in SERIES {
        let drawn = (0..header)
            .flat_map(|y| (0..1200).map(move |x| (x, y)))
            .filter(|&(x, y)| near(&image.get_pixel(x, y).0, colour, 40))
            .count();
        assert!(drawn > 150, "{drawn} pixels of {colour:?} above the table (y < {header})");
    }
}
