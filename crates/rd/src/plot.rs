//! SVG rate-distortion curves: RMS error in units of 1e-4 of the bounding-box diagonal (the
//! papers' unit) against bits per original vertex, both on log scales, one line per
//! mode/stage, Draco's anchors as a dashed baseline when given.

use crate::draco::DracoPoint;
use crate::sweep::Point;
use plotters::prelude::*;

/// Draws the curves of `mesh` into an SVG string.
pub fn svg_plot(
    mesh: &str,
    points: &[Point],
    draco: Option<&[DracoPoint]>,
) -> Result<String, String> {
    let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for p in points
        .iter()
        .filter(|p| p.mesh == mesh && p.error.is_none())
    {
        let key = format!("{} {}", p.mode, p.stage);
        let xy = (p.bits_per_original_vertex(), p.e4(p.rms));
        if !(xy.0 > 0.0 && xy.1 > 0.0 && xy.0.is_finite() && xy.1.is_finite()) {
            continue;
        }
        match series.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(xy),
            None => series.push((key, vec![xy])),
        }
    }
    let mut draco_xy: Vec<(f64, f64)> = draco
        .unwrap_or(&[])
        .iter()
        .map(|d| (d.bpv, d.rms_pct * 100.0))
        .filter(|&(x, y)| x > 0.0 && y > 0.0)
        .collect();
    // Each series keeps the sweep's rate order, so a line joins consecutive rates.
    draco_xy.sort_by(|a, b| a.0.total_cmp(&b.0));
    let draco_xy = draco_xy;
    let all = series
        .iter()
        .flat_map(|(_, v)| v.iter())
        .chain(draco_xy.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.1, 10.0, 0.1, 10.0);
    }
    // Plot in log10 space with linear axes, so ticks fall inside ranges shorter than a
    // decade too; labels show the value itself.
    let (x0, x1, y0, y1) = (
        (x0 / 1.3).log10(),
        (x1 * 1.3).log10(),
        (y0 / 1.5).log10(),
        (y1 * 1.5).log10(),
    );
    let lg = |(x, y): (f64, f64)| (x.log10(), y.log10());
    let series: Vec<(String, Vec<(f64, f64)>)> = series
        .into_iter()
        .map(|(k, v)| (k, v.into_iter().map(lg).collect()))
        .collect();
    let draco_xy: Vec<(f64, f64)> = draco_xy.into_iter().map(lg).collect();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (800, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut chart = ChartBuilder::on(&root)
            .caption(format!("{mesh}: rate-distortion"), ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(48)
            .y_label_area_size(64)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_labels(12)
            .y_labels(12)
            .x_label_formatter(&|x| short(10f64.powf(*x)))
            .y_label_formatter(&|y| short(10f64.powf(*y)))
            .x_desc("bits per original vertex (log scale)")
            .y_desc("L2 (RMS) error, units of 1e-4 of the bbox diagonal (log scale)")
            .draw()
            .map_err(|e| e.to_string())?;
        for (i, (name, v)) in series.iter().enumerate() {
            let color = Palette99::pick(i).to_rgba();
            chart
                .draw_series(LineSeries::new(v.iter().copied(), color.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color));
            chart
                .draw_series(v.iter().map(|&xy| Circle::new(xy, 3, color.filled())))
                .map_err(|e| e.to_string())?;
        }
        if !draco_xy.is_empty() {
            let grey = RGBColor(90, 90, 90);
            chart
                .draw_series(DashedLineSeries::new(
                    draco_xy.iter().copied(),
                    6,
                    4,
                    grey.stroke_width(2),
                ))
                .map_err(|e| e.to_string())?
                .label("Draco (level 10, q = 6..14)")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], grey));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(svg)
}

/// Tick label with two significant digits.
fn short(x: f64) -> String {
    if x >= 100.0 {
        format!("{x:.0}")
    } else if x >= 10.0 {
        format!("{x:.1}")
    } else if x >= 1.0 {
        format!("{x:.2}")
    } else {
        format!("{x:.3}")
    }
}
