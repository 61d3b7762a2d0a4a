//! Plots a person reads: every PNG talus writes, with a title, labelled axes in SI
//! units, and a legend or colour bar where there is more than one thing to tell apart.
//!
//! `plotters` draws into an RGB buffer (its bitmap backend), its text is rasterised by
//! `ab_glyph` in DejaVu Sans (embedded by the `dejavu` crate, so no system font or
//! fontconfig is needed), and `png` encodes the buffer. Three kinds of figure cover
//! what talus plots:
//!
//! - [`LineChart`]: curves against a common axis (drum torque over time, porosity
//!   profiles);
//! - [`LogChart`]: points and curves on log–log axes (errors against cost or step);
//! - [`HeatMap`]: a scalar on rectangular cells with a colour bar, and curves drawn over
//!   it (the drum's velocity field with the rim and the free surface).

mod chart;
mod heat_map;
mod log_chart;

use std::io;
use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;

pub use chart::{LineChart, Series};
pub use heat_map::{Cell, HeatMap};
pub use log_chart::{LogChart, PointSet};

/// The font family every text of a plot is set in.
const FONT: &str = "sans-serif";

/// The font family, registered with plotters on first use (DejaVu Sans).
fn font() -> &'static str {
    static REGISTERED: OnceLock<()> = OnceLock::new();
    REGISTERED.get_or_init(|| {
        // The embedded file is a valid TrueType font; a failure here is a build error
        // of this crate, not something a user could cause.
        plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular())
            .map_err(|_| ())
            .expect("DejaVu Sans is a valid font");
    });
    FONT
}

/// A drawing area over an RGB buffer.
type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Draws `draw` on a white canvas of `size` pixels and writes it to `path` as PNG
/// (8-bit RGB).
fn render(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&Area<'_>) -> Result<(), String>,
) -> io::Result<()> {
    let mut rgb = vec![255u8; 3 * size.0 as usize * size.1 as usize];
    {
        let area = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        draw(&area).map_err(io::Error::other)?;
        area.present()
            .map_err(|e| io::Error::other(e.to_string()))?;
    }
    write_png(path, size, &rgb)
}

/// Encodes an RGB buffer as PNG.
fn write_png(path: &Path, (width, height): (u32, u32), rgb: &[u8]) -> io::Result<()> {
    let file = io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(io::Error::other)?;
    writer.write_image_data(rgb).map_err(io::Error::other)?;
    writer.finish().map_err(io::Error::other)
}

/// A plotters error as text.
fn drawing<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> String {
    format!("drawing a plot: {e}")
}

/// `[lo, hi]` of finite values widened by 5 % on each side (and to a unit width when
/// all values are equal), or `[0, 1]` when there is none.
fn padded_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return (0.0, 1.0);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1e-12)
    };
    (lo - pad, hi + pad)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An RGB PNG read back: (width, height, pixels).
    fn read(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
        let file = std::fs::File::open(path).unwrap();
        let mut reader = png::Decoder::new(io::BufReader::new(file))
            .read_info()
            .unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        let pixels = buf[..info.buffer_size()]
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2]])
            .collect();
        (info.width, info.height, pixels)
    }

    fn scratch(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("talus-plot-{}-{name}", std::process::id()))
    }

    #[test]
    fn a_line_is_drawn_where_its_values_map_and_the_title_is_set_in_text() {
        let path = scratch("line.png");
        let mut chart = LineChart::new("A flat line", "x (m)", "y (-)")
            .with("y = 0.25", vec![(0.0, 0.25), (1.0, 0.25)]);
        chart.y_range = Some((0.0, 1.0));
        chart.write_png(&path).unwrap();
        let (width, height, pixels) = read(&path);
        let _ = std::fs::remove_file(&path);
        assert_eq!((width, height), (800, 500));
        let blue = chart::PALETTE[0];
        let rows: Vec<u32> = (0..pixels.len())
            .filter(|&k| pixels[k] == [blue.0, blue.1, blue.2])
            .map(|k| k as u32 / width)
            .collect();
        // A line 2 px wide spanning most of the plot's width, a quarter of the way up
        // the plot area (its top below the title, its bottom above the x labels).
        assert!(rows.len() > 2 * 500, "{} pixels of the line", rows.len());
        let (lo, hi) = (rows.iter().min().unwrap(), rows.iter().max().unwrap());
        assert!(hi - lo <= 3, "rows {lo}..{hi}");
        let (top, bottom) = (12 + 30, 500 - 12 - 48);
        let expected = bottom as f64 - 0.25 * (bottom - top) as f64;
        assert!((*lo as f64 - expected).abs() < 15.0, "{lo} vs {expected}");
        // Text: dark pixels in the title strip.
        let dark = pixels[..40 * width as usize]
            .iter()
            .filter(|p| p.iter().all(|&c| c < 90))
            .count();
        assert!(dark > 100, "{dark} dark pixels in the title");
    }

    #[test]
    fn a_heat_map_colours_its_cells_by_value_and_greys_the_empty_ones() {
        let path = scratch("heat.png");
        let cells = [(0.0, Some(0.0)), (1.0, Some(2.0)), (2.0, None)]
            .into_iter()
            .map(|(x, value)| Cell {
                x: (x, x + 1.0),
                y: (0.0, 3.0),
                value,
            })
            .collect();
        HeatMap {
            title: "Three cells".into(),
            x_label: "x (m)".into(),
            y_label: "y (m)".into(),
            value_label: "value (1)".into(),
            extent: (0.0, 3.0),
            cells,
            overlays: Vec::new(),
        }
        .write_png(&path)
        .unwrap();
        let (_, _, pixels) = read(&path);
        let _ = std::fs::remove_file(&path);
        let count = |c: [u8; 3]| pixels.iter().filter(|p| **p == c).count();
        // Each cell is a third of a ~540 px square plot: the low end of viridis (the
        // cell at 0), its high end (the cell at the largest value) and grey.
        let third = 540 * 540 / 3;
        assert!(
            count([68, 1, 84]) > third * 9 / 10,
            "{}",
            count([68, 1, 84])
        );
        assert!(
            count([254, 232, 37]) > third * 9 / 10,
            "{}",
            count([254, 232, 37])
        );
        assert!(count([215, 215, 215]) > third * 9 / 10);
    }

    #[test]
    fn log_chart_points_map_by_decades() {
        let path = scratch("log.png");
        let mut chart = LogChart::new("Two points", "cost (s)", "error (1)");
        let colour = RGBColor(214, 39, 40);
        chart.sets.push(PointSet {
            name: "points".into(),
            points: vec![(1.0, 1e-4), (100.0, 1e-2), (0.0, 1.0)],
            colour,
            joined: false,
            marker: 4,
        });
        chart.write_png(&path).unwrap();
        let (width, height, pixels) = read(&path);
        let _ = std::fs::remove_file(&path);
        assert_eq!((width, height), (800, 560));
        // Two markers (the point at x = 0 cannot be drawn on a log axis), the second
        // up and to the right of the first by the same distance on both axes' scales.
        let at: Vec<(u32, u32)> = (0..pixels.len())
            .filter(|&k| pixels[k] == [colour.0, colour.1, colour.2])
            .map(|k| (k as u32 % width, k as u32 / width))
            .collect();
        let (left, right): (Vec<_>, Vec<_>) = at.iter().partition(|p| p.0 < width / 2);
        assert!(
            left.len() > 20 && right.len() > 20,
            "{} {}",
            left.len(),
            right.len()
        );
        let mean = |v: &[&(u32, u32)]| {
            let n = v.len() as f64;
            (
                v.iter().map(|p| p.0 as f64).sum::<f64>() / n,
                v.iter().map(|p| p.1 as f64).sum::<f64>() / n,
            )
        };
        let (a, b) = (mean(&left), mean(&right));
        assert!(b.0 > a.0 + 300.0 && b.1 < a.1 - 200.0, "{a:?} {b:?}");
    }

    #[test]
    fn ranges_are_padded_and_never_empty() {
        assert_eq!(padded_range([0.0, 10.0].into_iter()), (-0.5, 10.5));
        assert_eq!(padded_range([2.0, 2.0].into_iter()), (1.0, 3.0));
        assert_eq!(padded_range([f64::NAN].into_iter()), (0.0, 1.0));
        assert_eq!(padded_range(std::iter::empty()), (0.0, 1.0));
    }
}
