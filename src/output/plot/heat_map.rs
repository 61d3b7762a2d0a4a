//! Heat maps: a scalar on rectangular cells, coloured by viridis, with a colour bar,
//! and curves drawn over it.

use std::io;
use std::path::Path;

use plotters::prelude::*;
use plotters::style::colors::colormaps::{ColorMap, ViridisRGB};

use super::{Area, Series, drawing, font, render};

/// One cell of a [`HeatMap`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    /// Horizontal extent.
    pub x: (f64, f64),
    /// Vertical extent.
    pub y: (f64, f64),
    /// The value, or `None` for a cell with no data (drawn light grey).
    pub value: Option<f64>,
}

/// A scalar on cells with its colour bar. The plot keeps the axes' aspect ratio (one
/// metre is as long across as up), so a circle stays a circle.
#[derive(Clone, Debug)]
pub struct HeatMap {
    /// Above the plot.
    pub title: String,
    /// Horizontal axis: quantity and unit.
    pub x_label: String,
    /// Vertical axis: quantity and unit.
    pub y_label: String,
    /// The colour bar's quantity and unit.
    pub value_label: String,
    /// The square region shown: `[lo, hi]` on both axes.
    pub extent: (f64, f64),
    /// The cells, drawn first.
    pub cells: Vec<Cell>,
    /// Curves drawn over the cells, named in a legend.
    pub overlays: Vec<Series>,
}

/// Height of the title strip, pixels.
const TITLE: u32 = 44;
/// Size of the square plot with its axes, and the colour bar's width, pixels.
const PLOT: u32 = 640;
const BAR: u32 = 150;
/// Space for the tick labels and axis names.
const X_LABELS: u32 = 48;
const Y_LABELS: u32 = 80;
const MARGIN: u32 = 10;

impl HeatMap {
    /// The range of the colour scale: 0 (or the smallest value, if negative) to the
    /// largest value.
    fn value_range(&self) -> (f64, f64) {
        let values = self
            .cells
            .iter()
            .filter_map(|c| c.value)
            .filter(|v| v.is_finite());
        let (lo, hi) = values.fold((0.0f64, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        if hi > lo { (lo, hi) } else { (lo, lo + 1.0) }
    }

    /// Writes the map as a PNG.
    pub fn write_png(&self, path: &Path) -> io::Result<()> {
        // The plot's drawing box is square: its width less the y labels equals its
        // height less the x labels.
        let left_width = PLOT + Y_LABELS - X_LABELS;
        let size = (left_width + BAR, PLOT + TITLE);
        render(path, size, |area| {
            area.fill(&WHITE).map_err(drawing)?;
            let (title, body) = area.split_vertically(TITLE);
            title.titled(&self.title, (font(), 22)).map_err(drawing)?;
            let (plot, bar) = body.split_horizontally(left_width);
            let range = self.value_range();
            self.draw_map(&plot, range)?;
            self.draw_bar(&bar, range)
        })
    }

    fn draw_map(&self, area: &Area<'_>, (lo, hi): (f64, f64)) -> Result<(), String> {
        let (a, b) = self.extent;
        let mut chart = ChartBuilder::on(area)
            .margin(MARGIN)
            .x_label_area_size(X_LABELS - MARGIN)
            .y_label_area_size(Y_LABELS - MARGIN)
            .build_cartesian_2d(a..b, a..b)
            .map_err(drawing)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .label_style((font(), 14))
            .axis_desc_style((font(), 16))
            .draw()
            .map_err(drawing)?;
        let colour = |c: &Cell| match c.value {
            Some(v) if v.is_finite() => ViridisRGB.get_color_normalized(v, lo, hi),
            _ => RGBColor(215, 215, 215),
        };
        chart
            .draw_series(
                self.cells
                    .iter()
                    .map(|c| Rectangle::new([(c.x.0, c.y.0), (c.x.1, c.y.1)], colour(c).filled())),
            )
            .map_err(drawing)?;
        for s in &self.overlays {
            let colour = s.colour;
            chart
                .draw_series(LineSeries::new(
                    s.points.iter().copied(),
                    colour.stroke_width(2),
                ))
                .map_err(drawing)?
                .label(&s.name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(2))
                });
        }
        if !self.overlays.is_empty() {
            chart
                .configure_series_labels()
                .label_font((font(), 14))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperLeft)
                .draw()
                .map_err(drawing)?;
        }
        Ok(())
    }

    fn draw_bar(&self, area: &Area<'_>, (lo, hi): (f64, f64)) -> Result<(), String> {
        let mut bar = ChartBuilder::on(area)
            .margin(MARGIN)
            .margin_right(3 * MARGIN)
            .x_label_area_size(X_LABELS - MARGIN)
            .y_label_area_size(Y_LABELS)
            .build_cartesian_2d(0.0..1.0, lo..hi)
            .map_err(drawing)?;
        bar.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc(&self.value_label)
            .label_style((font(), 14))
            .axis_desc_style((font(), 16))
            .draw()
            .map_err(drawing)?;
        const STEPS: usize = 256;
        let dv = (hi - lo) / STEPS as f64;
        bar.draw_series((0..STEPS).map(|k| {
            let v = lo + k as f64 * dv;
            Rectangle::new(
                [(0.0, v), (1.0, v + dv)],
                ViridisRGB
                    .get_color_normalized(v + 0.5 * dv, lo, hi)
                    .filled(),
            )
        }))
        .map_err(drawing)?;
        Ok(())
    }
}
