//! The study's table: its figures as the page and the terminal print them,
//! and the speed ratios filled in from the reference path tracers' rungs.

use super::data::{Row, Series, Study, Transport};
use super::ratio::speed_ratio;

/// Colours of the series, in order (Tableau 10, then darker shades).
pub const PALETTE: [(u8, u8, u8); 14] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
    (57, 59, 121),
    (99, 121, 57),
    (140, 109, 49),
    (132, 60, 57),
];

pub fn colour(index: usize) -> (u8, u8, u8) {
    PALETTE[index % PALETTE.len()]
}

/// The id of the series a series is measured against for its speed ratio:
/// path at the same transport.
pub fn reference_id(study: &Study, series: &Series) -> &'static str {
    if series.transport == Transport::Single && study.has_single_truth() { "path_depth1" } else { "path" }
}

/// Fills in what every row's figures imply as the study stands: its speed
/// ratio from the reference's rungs, and whether its error is close to the
/// truth's own.
pub fn fill_derived(study: &mut Study) {
    let references: Vec<(String, Vec<(f64, f64)>)> = study
        .series
        .iter()
        .filter(|s| s.id == "path" || s.id == "path_depth1")
        .map(|s| (s.id.clone(), s.rows.iter().map(|r| (r.seconds, r.error.rel_rmse)).collect()))
        .collect();
    for i in 0..study.series.len() {
        let id = reference_id(study, &study.series[i]);
        let reference = references.iter().find(|(r, _)| r == id).map(|(_, points)| points.as_slice());
        let noise = study.truth_for(study.series[i].transport).map_or(0.0, |t| t.estimated_error);
        for row in &mut study.series[i].rows {
            row.near_truth_noise = row.error.rel_rmse < 2.0 * noise;
            let ratio = reference.and_then(|points| speed_ratio(points, row.seconds, row.error.rel_rmse));
            row.speed_ratio = ratio.map(|r| r.0);
            row.ratio_extrapolated = ratio.is_some_and(|r| r.1);
        }
    }
}

/// Four significant figures (scientific below 0.001).
pub fn figure(v: f64) -> String {
    if !v.is_finite() {
        return if v.is_nan() { "—".into() } else { "∞".into() };
    }
    if v == 0.0 {
        return "0".into();
    }
    if v.abs() < 1e-3 {
        return format!("{v:.3e}");
    }
    significant(v, 4)
}

/// `v` with `digits` significant digits, counted after rounding (0.99996
/// is 1.000, not 1.0000).
fn significant(v: f64, digits: i32) -> String {
    let decimals = |x: f64| (digits - 1 - x.abs().log10().floor() as i32).max(0) as usize;
    let d = decimals(v);
    let rounded: f64 = format!("{v:.d$}").parse().unwrap_or(v);
    let d = decimals(rounded).min(d);
    format!("{v:.d$}")
}

pub fn seconds(v: f64) -> String {
    if v < 10.0 { format!("{v:.3}") } else { format!("{v:.1}") }
}

pub fn ratio(row: &Row) -> String {
    match row.speed_ratio {
        Some(r) => format!("{}{}×", if row.ratio_extrapolated { "~" } else { "" }, figure_short(r)),
        None => "—".into(),
    }
}

/// Three significant figures, for ratios.
fn figure_short(v: f64) -> String {
    if !v.is_finite() || v <= 0.0 {
        return figure(v);
    }
    significant(v, 3)
}

/// The table for a terminal: one line per rung.
pub fn terminal(study: &Study) -> String {
    let single = study.has_single_truth();
    let mut lines = vec![{
        let mut head = vec!["series".to_string(), "spp".into(), "time s".into(), "rel RMSE".into()];
        if single {
            head.push("vs full".into());
        }
        head.push("speed vs path".into());
        head
    }];
    for s in &study.series {
        for (i, row) in s.rows.iter().enumerate() {
            let mut line = vec![
                if i == 0 { s.label.clone() } else { String::new() },
                row.spp.to_string(),
                seconds(row.seconds),
                format!("{}{}", figure(row.error.rel_rmse), if row.near_truth_noise { "*" } else { "" }),
            ];
            if single {
                line.push(row.error_full.map_or("".into(), |e| figure(e.rel_rmse)));
            }
            line.push(ratio(row));
            lines.push(line);
        }
    }
    let columns = lines[0].len();
    let widths: Vec<usize> =
        (0..columns).map(|c| lines.iter().map(|l| l[c].chars().count()).max().unwrap_or(0)).collect();
    let mut out = String::new();
    for line in &lines {
        let cells: Vec<String> = line
            .iter()
            .enumerate()
            .map(|(c, v)| if c == 0 { format!("{v:<w$}", w = widths[c]) } else { format!("{v:>w$}", w = widths[c]) })
            .collect();
        out.push_str(cells.join("  ").trim_end());
        out.push('\n');
    }
    if study.series.iter().flat_map(|s| &s.rows).any(|r| r.near_truth_noise) {
        out.push_str("* below twice the truth's estimated error: much of it may be the truth's own noise\n");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_keep_four_significant_digits() {
        assert_eq!(figure(0.123456), "0.1235");
        assert_eq!(figure(12.3456), "12.35");
        assert_eq!(figure(1234.5), "1234");
        assert_eq!(figure(0.00123456), "0.001235");
        assert_eq!(figure(0.000123456), "1.235e-4");
        assert_eq!(figure(0.0), "0");
        assert_eq!(figure(f64::INFINITY), "∞");
        assert_eq!(figure_short(12.345), "12.3");
        assert_eq!(figure_short(0.5), "0.500");
        assert_eq!(figure_short(0.99999), "1.00");
        assert_eq!(figure(9.99996), "10.00");
    }
}
