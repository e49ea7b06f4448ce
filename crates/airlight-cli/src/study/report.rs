//! The study's page, `index.html`, with its plots and the JSON: rewritten
//! whole (atomically) after every finished rung, so whatever stops the
//! study leaves a page that shows what was finished. It uses no script and
//! loads nothing from elsewhere: it works offline.

use super::colour;
use super::data::{State, Study, Transport};
use super::plot::{self, Curve};
use super::table::{self, figure, seconds};
use airlight::film::write_atomically;
use std::fmt::Write;
use std::path::Path;

/// Writes the plots, then the page and the JSON that refer to them.
pub fn write(dir: &Path, study: &Study, json: Option<&Path>) -> Result<(), String> {
    let save = |path: &Path, text: &str| {
        write_atomically(path, text.as_bytes()).map_err(|e| format!("cannot write `{}`: {e}", path.display()))
    };
    for (file, transport) in plots(study) {
        let svg = plot_svg(study, transport)?;
        save(&dir.join(file), &svg)?;
    }
    save(&dir.join("index.html"), &html(study))?;
    if let Some(json) = json {
        let text = serde_json::to_string_pretty(study).map_err(|e| format!("cannot write the JSON: {e}"))?;
        save(json, &text)?;
    }
    Ok(())
}

/// The plots: against full transport, and against single scattering when
/// the scene asks for more than one event.
fn plots(study: &Study) -> Vec<(&'static str, Transport)> {
    let mut out = vec![("plot.svg", Transport::Full)];
    if study.has_single_truth() {
        out.push(("plot_single.svg", Transport::Single));
    }
    out
}

fn plot_svg(study: &Study, transport: Transport) -> Result<String, String> {
    let single = transport == Transport::Single;
    let curves: Vec<Curve> = study
        .series
        .iter()
        .enumerate()
        .filter(|(_, s)| !single || s.transport == Transport::Single)
        .map(|(i, s)| Curve {
            label: s.label.clone(),
            colour: table::colour(i),
            points: s
                .rows
                .iter()
                .map(|r| (r.seconds, if single { r.error } else { r.error_full.unwrap_or(r.error) }.rel_rmse))
                .collect(),
        })
        .collect();
    let truth = study.truth_for(transport);
    let title = match truth {
        Some(t) if single => format!("error against single scattering (path, max_depth {})", t.max_depth),
        Some(t) => format!("error against full transport (path, max_depth {})", t.max_depth),
        None => "error against the truth".into(),
    };
    plot::error_vs_time(&title, &curves, truth.map(|t| t.estimated_error))
}

/// Text for HTML.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

const STYLE: &str = "body{font-family:sans-serif;margin:24px;max-width:1150px;color:#222}
h1{font-size:24px}h2{font-size:19px;margin-top:28px;border-bottom:1px solid #ccc}
.status{padding:8px 12px;background:#eef3fa;border-left:5px solid #2b4c7e}
.plot{width:100%;max-width:900px;border:1px solid #ddd}
table.results{border-collapse:collapse;font-size:14px}
table.results th{background:#2b4c7e;color:#fff;padding:5px 9px;text-align:right}
table.results th:first-child{text-align:left}
table.results td{padding:3px 9px;text-align:right;border-bottom:1px solid #eee}
table.results td:first-child{text-align:left}
table.results tr.first td{border-top:2px solid #bbb}
table.results tr.shown td{font-weight:bold}
.swatch{display:inline-block;width:14px;height:14px;margin-right:6px;vertical-align:middle}
.row{display:flex;gap:14px;align-items:flex-start;margin:14px 0;flex-wrap:wrap}
figure{margin:0}figcaption{font-size:13px;max-width:260px}
.row img{width:256px;image-rendering:pixelated;border:1px solid #ccc}
.legend{width:256px;height:14px;border:1px solid #999}
.ticks{display:flex;justify-content:space-between;width:260px;font-size:12px}
.note{font-size:14px;color:#444;max-width:900px}";

fn html(study: &Study) -> String {
    let mut h = String::new();
    let name = Path::new(&study.scene).file_name().map_or(study.scene.clone(), |n| n.to_string_lossy().into());
    let refresh = if study.state == State::Running { "<meta http-equiv=\"refresh\" content=\"10\">" } else { "" };
    let _ = write!(
        h,
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">{refresh}\
         <title>Airlight study: {}</title><style>{STYLE}</style></head><body>\n<h1>Airlight study of <code>{}</code></h1>\n",
        esc(&name),
        esc(&study.scene)
    );
    status(&mut h, study);
    h.push_str("<h2>Error against time</h2>\n");
    for (file, transport) in plots(study) {
        let what = if transport == Transport::Single { "single scattering" } else { "full transport" };
        let _ = writeln!(
            h,
            "<p><img class=\"plot\" src=\"{file}\" alt=\"relative RMSE against time, against {what}\"></p>"
        );
    }
    results(&mut h, study);
    truths(&mut h, study);
    gallery(&mut h, study);
    if !study.not_run.is_empty() {
        h.push_str("<h2>Not run</h2>\n<ul>\n");
        for n in &study.not_run {
            let _ = writeln!(h, "<li><b>{}</b>: {}</li>", esc(&n.label), esc(&n.reason));
        }
        h.push_str("</ul>\n");
    }
    notes(&mut h, study);
    h.push_str("</body></html>\n");
    h
}

fn status(h: &mut String, study: &Study) {
    let done = study.series.iter().filter(|s| s.stopped_by.is_some()).count();
    let state = match study.state {
        State::Running => format!("In progress (this page reloads every 10 s): {done} series finished so far"),
        State::Finished => "Finished".into(),
        State::Stopped => format!("Stopped by Ctrl-C: {done} series finished; what is shown was finished"),
    };
    let load = |l: Option<[f64; 3]>| l.map_or("unknown".into(), |[a, b, c]| format!("{a:.2} {b:.2} {c:.2}"));
    let _ = writeln!(
        h,
        "<p class=\"status\">{state} after {} s of a {} s time budget. {}×{} pixels, {} threads; \
         load averages (1, 5, 15 min) {} at the start, {} at the last update; Airlight {}.</p>",
        seconds(study.elapsed_seconds),
        seconds(study.time_budget_seconds),
        study.width,
        study.height,
        study.threads,
        load(study.load_average_start),
        load(study.load_average_now),
        esc(&study.airlight_version)
    );
}

fn results(h: &mut String, study: &Study) {
    let single = study.has_single_truth();
    h.push_str("<h2>Table</h2>\n<table class=\"results\"><tr><th>series</th><th>spp</th><th>time s</th>");
    let own = if single { "rel RMSE vs its truth" } else { "rel RMSE" };
    let _ = write!(h, "<th>{own}</th>");
    if single {
        h.push_str("<th>rel RMSE vs full transport</th>");
    }
    h.push_str("<th>speed vs path at equal error</th></tr>\n");
    for (i, s) in study.series.iter().enumerate() {
        let (r, g, b) = table::colour(i);
        for (k, row) in s.rows.iter().enumerate() {
            let class = match (k == 0, k + 1 == s.rows.len()) {
                (true, true) => " class=\"first shown\"",
                (true, false) => " class=\"first\"",
                (false, true) => " class=\"shown\"",
                _ => "",
            };
            let label = if k == 0 {
                format!("<span class=\"swatch\" style=\"background:rgb({r},{g},{b})\"></span>{}", esc(&s.label))
            } else {
                String::new()
            };
            let _ = write!(
                h,
                "<tr{class} data-exr=\"{}\"><td>{label}</td><td>{}</td><td>{}</td><td class=\"rel\">{}{}</td>",
                esc(&row.exr),
                row.spp,
                seconds(row.seconds),
                figure(row.error.rel_rmse),
                if row.near_truth_noise { "<sup>*</sup>" } else { "" }
            );
            if single {
                let full = row.error_full.map_or(String::new(), |e| figure(e.rel_rmse));
                let _ = write!(h, "<td class=\"full\">{full}</td>");
            }
            let _ = writeln!(h, "<td>{}</td></tr>", table::ratio(row));
        }
    }
    h.push_str("</table>\n");
    if study.series.iter().flat_map(|s| &s.rows).any(|r| r.near_truth_noise) {
        h.push_str(
            "<p class=\"note\">* below twice the truth's estimated error: much of it may be the truth's \
                    own noise, and the speed ratio there is not to be trusted.</p>\n",
        );
    }
}

fn truths(h: &mut String, study: &Study) {
    h.push_str("<h2>Ground truth</h2>\n<div class=\"row\">\n");
    for t in &study.truths {
        let what = if t.transport == Transport::Single { "single scattering" } else { "full transport" };
        let reached = if t.reached_target { "" } else { " (the time budget stopped it before the target)" };
        let _ = writeln!(
            h,
            "<figure><img src=\"{}\" alt=\"truth\"><figcaption>path, max_depth {} ({what}): {} spp in {} s, \
             estimated relative error {}{reached}; seed {}; linear image {}</figcaption></figure>",
            esc(&t.png),
            t.max_depth,
            t.spp,
            seconds(t.seconds),
            figure(t.estimated_error),
            t.seed,
            esc(&t.exr)
        );
    }
    if study.truths.len() == 2 {
        h.push_str(
            "<figure><img src=\"multiple_scattering.png\" alt=\"multiple scattering\"><figcaption>|full − single \
             scattering|: the light that single-scattering methods leave out (colour scale below)</figcaption></figure>\n",
        );
    }
    h.push_str("</div>\n");
}

fn legend(study: &Study) -> String {
    let s = study.error_map_scale;
    let ticks: Vec<String> = (0..=colour::DECADES as i32)
        .map(|k| format!("<span>{}</span>", figure(s * 10f64.powi(k - colour::DECADES as i32))))
        .collect();
    format!(
        "<figure><div class=\"legend\" style=\"background:{}\"></div><div class=\"ticks\">{}</div>\
         <figcaption>|image − truth|, mean over R, G, B, in radiance; logarithmic; {} is the truth's mean \
         value; black at or below {}</figcaption></figure>",
        colour::css_gradient(),
        ticks.join(""),
        figure(s),
        figure(s / 1000.0)
    )
}

fn gallery(h: &mut String, study: &Study) {
    h.push_str(
        "<h2>Images</h2>\n<p class=\"note\">Each series at its last rung, beside its truth, and its error \
                map against that truth. Colour scale of every map:</p>\n",
    );
    h.push_str(&legend(study));
    for s in study.series.iter().filter(|s| !s.rows.is_empty()) {
        let Some(truth) = study.truth_for(s.transport) else { continue };
        let last = &s.rows[s.rows.len() - 1];
        let _ = writeln!(
            h,
            "<div class=\"row\"><figure><img src=\"{}\" alt=\"truth\"><figcaption>truth (max_depth {})</figcaption></figure>\
             <figure><img src=\"{}\" alt=\"{}\"><figcaption><b>{}</b>: {} spp, {} s</figcaption></figure>\
             <figure><img src=\"{}\" alt=\"error map\"><figcaption>error map: relative RMSE {}</figcaption></figure></div>",
            esc(&truth.png),
            truth.max_depth,
            esc(&s.png),
            esc(&s.label),
            esc(&s.label),
            last.spp,
            seconds(last.seconds),
            esc(&s.error_png),
            figure(last.error.rel_rmse)
        );
    }
}

fn notes(h: &mut String, study: &Study) {
    let e = figure(study.truth_error_target);
    let _ = writeln!(
        h,
        "<h2>How this was measured</h2>\n<ul class=\"note\">\
<li><b>Truth</b>: <code>path</code> rendered progressively until its estimated relative error (from each pixel's \
sample variance) is below {e}, with its own seed, so its noise is independent of every image measured against it. \
Errors much below the truth's own estimated error (the dashed line) are not resolved.</li>\
<li><b>Which truth</b>: single-scattering methods (direct, raymarch, analytic, stochastic) against path at \
max_depth 1 — the method's own error — and, in the column <i>vs full transport</i>, against the scene's max_depth: \
that error adds what leaving out multiple scattering costs. Path and radiosity against full transport.</li>\
<li><b>Relative RMSE</b> = √(Σ(a − b)²/Σb²) over all pixels and channels, as <code>airlight compare</code> prints it \
(<code>rel_rmse</code>); every row's linear image is in <code>exr/</code> to check it.</li>\
<li><b>Time</b>: wall clock of building the integrator plus every pass up to that row, on all threads. Each \
series is rendered progressively, 1, 1, 2, 4, … samples per pixel; the image after each pass is the one a render \
at that spp gives, and its time is what that render would take.</li>\
<li><b>Speed vs path at equal error</b> = t_path(e)/t: t is the row's time and e its error, t_path(e) the time the \
path tracer of the same transport (its series in this table) needs to reach e, interpolated linearly in log–log \
between its rows, over the best error it had reached by each time; beyond its first or last row, extrapolated as \
error ∝ time^−½ (marked ~). Above 1 the method is faster than path tracing to the same error.</li>\
<li><b>Time budget</b>: the truths may take half of it (single scattering first, then full transport with \
what is left of that half); what is left is shared evenly by the series still to run, \
each taking over what earlier ones left. A series stops before a pass that would not fit in its share (a pass costs \
about as much as all before it); its first pass always runs, unless a probe (one sample of 16 pixels) finds \
that it would end past the budget. A pass under way at the budget's end is cancelled as its tiles finish, and lost.</li>\
<li>A series whose first image is the same, bit for bit, as an earlier one's is not continued (listed above).</li>\
</ul>"
    );
}
