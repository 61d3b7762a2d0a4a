//! Line charts: curves against a common horizontal axis.

use std::io;
use std::path::Path;

use plotters::prelude::*;

use super::{drawing, font, padded_range, render};

/// One curve of a [`LineChart`].
#[derive(Clone, Debug)]
pub struct Series {
    /// The legend's text.
    pub name: String,
    /// Points in drawing order; non-finite ones break the curve.
    pub points: Vec<(f64, f64)>,
    /// Line colour.
    pub colour: RGBColor,
}

/// Curves against a common axis, with a title, axis labels (name and unit) and a
/// legend when there is more than one curve. The axes span the data with 5 % to
/// spare, or the ranges given.
pub struct LineChart {
    /// Above the plot.
    pub title: String,
    /// Horizontal axis: quantity and unit, e.g. "time (s)".
    pub x_label: String,
    /// Vertical axis: quantity and unit.
    pub y_label: String,
    /// The curves, drawn in order.
    pub series: Vec<Series>,
    /// Vertical range, when the data's own is not wanted (a fraction in [0, 1]).
    pub y_range: Option<(f64, f64)>,
    /// Where the legend goes (where the curves leave room).
    pub legend: SeriesLabelPosition,
}

/// Colours of successive curves (Tableau 10's first four).
pub const PALETTE: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
];

impl LineChart {
    /// A chart without curves.
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        LineChart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            y_range: None,
            legend: SeriesLabelPosition::UpperRight,
        }
    }

    /// Adds a curve in the next colour of the palette.
    pub fn with(mut self, name: &str, points: Vec<(f64, f64)>) -> Self {
        let colour = PALETTE[self.series.len() % PALETTE.len()];
        self.series.push(Series {
            name: name.into(),
            points,
            colour,
        });
        self
    }

    /// Writes the chart as a PNG of 800 × 500 pixels.
    pub fn write_png(&self, path: &Path) -> io::Result<()> {
        render(path, (800, 500), |area| {
            area.fill(&WHITE).map_err(drawing)?;
            let points = || self.series.iter().flat_map(|s| s.points.iter());
            let x = padded_range(points().map(|p| p.0));
            let y = self
                .y_range
                .unwrap_or_else(|| padded_range(points().map(|p| p.1)));
            let mut chart = ChartBuilder::on(area)
                .caption(&self.title, (font(), 22))
                .margin(12)
                .x_label_area_size(48)
                .y_label_area_size(80)
                .build_cartesian_2d(x.0..x.1, y.0..y.1)
                .map_err(drawing)?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .label_style((font(), 14))
                .axis_desc_style((font(), 16))
                .light_line_style(RGBColor(246, 246, 246))
                .draw()
                .map_err(drawing)?;
            for s in &self.series {
                // A curve is broken where a value is missing.
                for run in s
                    .points
                    .split(|p| !(p.0.is_finite() && p.1.is_finite()))
                    .filter(|run| !run.is_empty())
                {
                    chart
                        .draw_series(LineSeries::new(
                            run.iter().copied(),
                            s.colour.stroke_width(2),
                        ))
                        .map_err(drawing)?;
                }
                let colour = s.colour;
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        Vec::<(f64, f64)>::new(),
                        colour,
                    )))
                    .map_err(drawing)?
                    .label(&s.name)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(2))
                    });
            }
            if self.series.len() > 1 {
                chart
                    .configure_series_labels()
                    .label_font((font(), 14))
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .position(self.legend.clone())
                    .draw()
                    .map_err(drawing)?;
            }
            Ok(())
        })
    }
}
