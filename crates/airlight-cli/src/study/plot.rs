//! The error-versus-time plot, log–log, one curve per series, drawn by
//! plotters as SVG (its text left to the browser's fonts, so no font
//! library is built in).

use plotters::prelude::*;

pub struct Curve {
    pub label: String,
    pub colour: (u8, u8, u8),
    /// (seconds, relative RMSE), in the order measured.
    pub points: Vec<(f64, f64)>,
}

pub const SIZE: (u32, u32) = (900, 560);

/// A tick label: plain decimals down to 0.001, then powers of ten.
fn tick(v: f64) -> String {
    if (1e-3..1e5).contains(&v) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

/// The range on a log axis that holds `values` with a margin; a default
/// when there is nothing to hold.
fn log_range(values: impl Iterator<Item = f64>, default: (f64, f64)) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo > hi {
        return default;
    }
    let (lo, hi) = if hi / lo < 10.0 { ((lo * hi).sqrt() / 3.2, (lo * hi).sqrt() * 3.2) } else { (lo, hi) };
    (lo / 1.5, hi * 1.5)
}

/// The plot as an SVG document; `truth_error` draws a dashed line where
/// errors stop being resolved (the truth's own estimated error).
pub fn error_vs_time(title: &str, curves: &[Curve], truth_error: Option<f64>) -> Result<String, String> {
    let points = || curves.iter().flat_map(|c| c.points.iter().copied());
    let (x0, x1) = log_range(points().map(|p| p.0), (0.01, 10.0));
    let (y0, y1) = log_range(points().map(|p| p.1).chain(truth_error), (1e-3, 1.0));
    let mut svg = String::new();
    draw(&mut svg, title, curves, truth_error, (x0, x1), (y0, y1)).map_err(|e| format!("cannot draw the plot: {e}"))?;
    Ok(svg)
}

fn draw<'a>(
    svg: &'a mut String,
    title: &str,
    curves: &[Curve],
    truth_error: Option<f64>,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Result<(), Box<dyn std::error::Error + 'a>> {
    let root = SVGBackend::with_string(svg, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 16))
        .x_desc("time, seconds (build + render)")
        .y_desc("relative RMSE")
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .light_line_style(WHITE.mix(0.0))
        .draw()?;
    if let Some(e) = truth_error.filter(|e| e.is_finite() && *e > 0.0) {
        let grey = RGBColor(120, 120, 120);
        chart
            .draw_series(DashedLineSeries::new([(x0, e), (x1, e)], 6, 5, grey.stroke_width(1)))?
            .label("truth's estimated error")
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 22, y)], grey.stroke_width(1)));
    }
    for c in curves {
        let colour = RGBColor(c.colour.0, c.colour.1, c.colour.2);
        let points = c.points.iter().copied().filter(|(t, e)| *t > 0.0 && *e > 0.0 && e.is_finite());
        chart
            .draw_series(LineSeries::new(points, colour.stroke_width(2)).point_size(3))?
            .label(c.label.as_str())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 22, y)], colour.stroke_width(3)));
    }
    // Lower left: no method is both fast and exact, so curves stay clear of it.
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .label_font(("sans-serif", 16))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.4))
        .draw()?;
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_read_plainly() {
        assert_eq!(tick(0.1), "0.1");
        assert_eq!(tick(2.0), "2");
        assert_eq!(tick(0.005), "0.005");
        assert_eq!(tick(1e-4), "1e-4");
    }

    #[test]
    fn the_plot_draws_each_curve_in_its_colour_with_its_label() {
        let curves = [Curve { label: "path".into(), colour: (31, 119, 180), points: vec![(0.1, 0.3), (0.4, 0.15)] }];
        let svg = error_vs_time("t", &curves, Some(0.01)).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..50.min(svg.len())]);
        assert!(svg.contains("#1F77B4") || svg.contains("#1f77b4"), "the curve's colour");
        assert!(svg.contains("\npath\n"), "the legend's label");
        // Nothing to draw still gives a page's plot, not an error.
        assert!(error_vs_time("t", &[], None).unwrap().contains("<svg"));
    }
}
