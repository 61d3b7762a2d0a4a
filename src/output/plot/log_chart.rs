//! Points and curves on logarithmic axes: errors against cost or against a step.

use std::io;
use std::path::Path;

use plotters::prelude::*;

use super::{drawing, font, render};

/// One set of points of a [`LogChart`].
#[derive(Clone, Debug)]
pub struct PointSet {
    /// The legend's text.
    pub name: String,
    /// The points; those not positive on both axes cannot be drawn and are left out.
    pub points: Vec<(f64, f64)>,
    pub colour: RGBColor,
    /// Joined by a line in order (a front, a convergence curve), or scattered.
    pub joined: bool,
    /// Marker radius, px (0: none).
    pub marker: u32,
}

/// Sets of points on log–log axes with a title, axis labels and a legend, and
/// horizontal reference lines (a target).
pub struct LogChart {
    pub title: String,
    /// Horizontal axis: quantity and unit.
    pub x_label: String,
    /// Vertical axis: quantity and unit.
    pub y_label: String,
    pub sets: Vec<PointSet>,
    /// Horizontal lines: legend text and height.
    pub levels: Vec<(String, f64)>,
    /// Room above the highest point (for the legend to sit in), as a fraction of
    /// the points' span in decades.
    pub headroom: f64,
}

impl LogChart {
    /// A chart without points.
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        LogChart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            sets: Vec::new(),
            levels: Vec::new(),
            headroom: 0.1,
        }
    }

    /// Writes the chart as a PNG of 800 × 560 pixels.
    pub fn write_png(&self, path: &Path) -> io::Result<()> {
        let drawable =
            |p: &&(f64, f64)| p.0 > 0.0 && p.1 > 0.0 && p.0.is_finite() && p.1.is_finite();
        let all = || {
            self.sets
                .iter()
                .flat_map(|s| s.points.iter().filter(drawable))
        };
        // The points' span, widened to the power of ten below and by a fifth of a
        // decade above, `top` of its decades more above.
        let span = |values: &mut dyn Iterator<Item = f64>, top: f64| {
            let (lo, hi) = values.fold((f64::INFINITY, 0.0_f64), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
            if lo > hi {
                (0.1, 10.0)
            } else {
                // From a power of ten: plotters places a log axis's ticks from the
                // first power of ten in range on.
                // (a hair below it: 10^-2 computed is 0.010000000000000002).
                let floor = 10f64.powf((lo / 1.6).log10().floor()) * (1.0 - 1e-9);
                (floor, hi * 1.6 * (hi / lo).powf(top))
            }
        };
        let x = span(&mut all().map(|p| p.0), 0.0);
        let y = span(
            &mut all().map(|p| p.1).chain(self.levels.iter().map(|l| l.1)),
            self.headroom,
        );
        render(path, (800, 560), |area| {
            area.fill(&WHITE).map_err(drawing)?;
            let mut chart = ChartBuilder::on(area)
                .caption(&self.title, (font(), 22))
                .margin(12)
                .x_label_area_size(48)
                .y_label_area_size(80)
                .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
                .map_err(drawing)?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .x_labels(label_count(x))
                .y_labels(label_count(y))
                .x_label_formatter(&|v| label(*v, x))
                .y_label_formatter(&|v| label(*v, y))
                .label_style((font(), 14))
                .axis_desc_style((font(), 16))
                .light_line_style(RGBColor(246, 246, 246))
                .draw()
                .map_err(drawing)?;
            for (name, level) in &self.levels {
                chart
                    .draw_series(LineSeries::new(
                        [(x.0, *level), (x.1, *level)],
                        BLACK.stroke_width(1),
                    ))
                    .map_err(drawing)?
                    .label(name)
                    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], BLACK));
            }
            for s in &self.sets {
                let points: Vec<(f64, f64)> = s.points.iter().filter(drawable).copied().collect();
                let colour = s.colour;
                if s.joined {
                    chart
                        .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                        .map_err(drawing)?;
                }
                let marker = s.marker;
                chart
                    .draw_series(
                        points
                            .iter()
                            .map(move |&p| Circle::new(p, marker, colour.filled())),
                    )
                    .map_err(drawing)?
                    .label(&s.name)
                    .legend(move |(x, y)| Circle::new((x + 12, y), marker.max(3), colour.filled()));
            }
            chart
                .configure_series_labels()
                .label_font((font(), 14))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(drawing)
        })
    }
}

/// Labels to ask plotters for: enough for the mantissas 2 and 5 on a short axis,
/// few enough that a long one is labelled at every other power of ten.
fn label_count((lo, hi): (f64, f64)) -> usize {
    if hi / lo < 1e3 { 20 } else { 10 }
}

/// A tick label: plain for an axis of less than two decades, else a power of ten;
/// only at mantissas 1, 2 and 5, so that labels never crowd.
fn label(v: f64, (lo, hi): (f64, f64)) -> String {
    // The key points plotters hands over carry round-off (19.9999… for 20).
    let mantissa = v / 10f64.powf((v.log10() + 1e-6).floor());
    if ![1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-4) || !v.is_finite() {
        return String::new();
    }
    if hi / lo < 100.0 {
        format!("{v:.3}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{v:.0e}")
    }
}
