//! PNG line charts shaped like the thesis' figures, drawn with `plotters` into an RGB buffer
//! and written with `image`. Text is drawn with a bundled DejaVu Sans through `ab_glyph`, so no
//! system fonts are needed.

use std::path::{Path, PathBuf};
use std::sync::Once;

use anyhow::{anyhow, Result};
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

const FONT: &str = "sans-serif";
static FONT_BYTES: &[u8] = include_bytes!("fonts/DejaVuSans.ttf");

fn register_font() -> Result<()> {
    static ONCE: Once = Once::new();
    let mut result = Ok(());
    ONCE.call_once(|| {
        result = plotters::style::register_font(FONT, FontStyle::Normal, FONT_BYTES)
            .map_err(|_| anyhow!("the bundled plot font cannot be read"));
    });
    result
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Style {
    /// A line (many points, e.g. one per degree).
    Line,
    /// A line with a dot at every point.
    LinePoints,
    /// A dashed horizontal reference (e.g. the base tracer beside grid resolutions).
    Dashed,
    /// Crosses only (published values).
    Crosses,
}

/// One data series of a chart.
#[derive(Debug, Clone)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub style: Style,
    /// Index into the palette.
    pub color: usize,
}

impl Series {
    pub fn new(
        name: impl Into<String>,
        points: Vec<(f64, f64)>,
        style: Style,
        color: usize,
    ) -> Series {
        Series {
            name: name.into(),
            points,
            style,
            color,
        }
    }
}

/// One panel: title, axis labels and series.
#[derive(Debug, Clone, Default)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    /// Fixed x range; default: the data's.
    pub x_range: Option<(f64, f64)>,
    /// A logarithmic y axis (for series that differ by orders of magnitude).
    pub log_y: bool,
    /// A logarithmic x axis: drawn as log10 x, labelled with x.
    pub log_x: bool,
    /// The x values are exponents of 10 (what `log_x` becomes when drawn).
    x_exponent: bool,
}

impl Chart {
    /// A panel with linear axes fitted to the data.
    pub fn new(
        title: impl Into<String>,
        x_label: &str,
        y_label: &str,
        series: Vec<Series>,
    ) -> Chart {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series,
            ..Chart::default()
        }
    }

    /// The same panel with a logarithmic y axis.
    pub fn log_y(self) -> Chart {
        Chart {
            log_y: true,
            ..self
        }
    }

    /// The same panel with a logarithmic x axis.
    pub fn log_x(self) -> Chart {
        Chart {
            log_x: true,
            ..self
        }
    }

    /// The same panel with the x axis from `lo` to `hi`.
    pub fn x_range(self, lo: f64, hi: f64) -> Chart {
        Chart {
            x_range: Some((lo, hi)),
            ..self
        }
    }
}

/// A PNG of one or more panels side by side, and its caption in the report.
#[derive(Debug, Clone)]
pub struct Figure {
    /// The file name, relative to the output folder.
    pub file: PathBuf,
    pub caption: String,
    /// Width and height of each panel in pixels.
    pub panel: (u32, u32),
    pub charts: Vec<Chart>,
}

impl Figure {
    pub fn new(file: &str, caption: &str, panel: (u32, u32), charts: Vec<Chart>) -> Figure {
        Figure {
            file: file.into(),
            caption: caption.into(),
            panel,
            charts,
        }
    }

    /// Draw the figure into the output folder `out`.
    pub fn save(&self, out: &Path) -> Result<()> {
        save(
            &out.join(&self.file),
            self.panel.0,
            self.panel.1,
            &self.charts,
        )
    }

    /// The markdown that shows it: `![caption](file)`.
    pub fn markdown(&self) -> String {
        format!("![{}]({})\n", self.caption, self.file.display())
    }
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 0),
];

/// The colour of palette entry `i` (black is the last: published values).
pub const BLACK_INDEX: usize = PALETTE.len() - 1;

fn color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Axis numbers: 1.2G, 350M, 12k, 2.5.
pub fn si(v: f64) -> String {
    let a = v.abs();
    if a > 0.0 && a < 0.01 {
        return format!("{v:.0e}");
    }
    let (d, s) = if a >= 1e9 {
        (1e9, "G")
    } else if a >= 1e6 {
        (1e6, "M")
    } else if a >= 1e4 {
        (1e3, "k")
    } else {
        (1.0, "")
    };
    let x = v / d;
    let digits = if x.abs() >= 100.0 {
        0
    } else if x.abs() >= 10.0 {
        1
    } else {
        2
    };
    let mut t = format!("{x:.digits$}");
    if t.contains('.') {
        t = t.trim_end_matches('0').trim_end_matches('.').to_string();
    }
    if t == "-0" {
        t = "0".into();
    }
    format!("{t}{s}")
}

fn range(values: impl Iterator<Item = f64>, from_zero: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if from_zero {
        lo = lo.min(0.0);
    }
    if hi - lo <= f64::EPSILON * hi.abs().max(1.0) {
        let pad = hi.abs().max(1.0) * 0.1;
        return (lo - pad, hi + pad);
    }
    (lo, hi + 0.08 * (hi - lo))
}

fn draw_panel(area: &DrawingArea<BitMapBackend<'_>, Shift>, chart: &Chart) -> Result<()> {
    if chart.log_x {
        return draw_panel(area, &log10_x(chart));
    }
    let points = || chart.series.iter().flat_map(|s| s.points.iter());
    let (x0, x1) = chart.x_range.unwrap_or_else(|| {
        let (lo, hi) = range(points().map(|p| p.0), false);
        // no extra headroom on x
        let hi = if hi > lo { lo + (hi - lo) / 1.08 } else { hi };
        (lo, hi)
    });
    let positive: Vec<f64> = points()
        .map(|p| p.1)
        .filter(|y| *y > 0.0 && y.is_finite())
        .collect();
    if chart.log_y && !positive.is_empty() {
        let lo = positive.iter().cloned().fold(f64::INFINITY, f64::min) / 1.6;
        let hi = positive.iter().cloned().fold(f64::NEG_INFINITY, f64::max) * 1.6;
        draw_on(area, chart, x0..x1, (lo..hi).log_scale())
    } else {
        let (y0, y1) = range(points().map(|p| p.1), true);
        draw_on(area, chart, x0..x1, y0..y1)
    }
}

/// `chart` with its x values replaced by their log10 (points at x ≤ 0 dropped), to be drawn on
/// a linear axis labelled with 10^x: what `log_x` asks for.
fn log10_x(chart: &Chart) -> Chart {
    let series = chart.series.iter().map(|s| Series {
        points: s
            .points
            .iter()
            .filter(|p| p.0 > 0.0)
            .map(|&(x, y)| (x.log10(), y))
            .collect(),
        ..s.clone()
    });
    Chart {
        series: series.collect(),
        x_range: chart.x_range.map(|(lo, hi)| (lo.log10(), hi.log10())),
        x_label: format!("{} (log scale)", chart.x_label),
        log_x: false,
        x_exponent: true,
        ..chart.clone()
    }
}

fn draw_on<Y>(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    chart: &Chart,
    x: std::ops::Range<f64>,
    y: Y,
) -> Result<()>
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let err = |e: &dyn std::fmt::Display| anyhow!("drawing the chart {:?}: {e}", chart.title);
    let mut c = ChartBuilder::on(area)
        .caption(&chart.title, (FONT, 17))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d(x, y)
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc(chart.x_label.as_str())
        .y_desc(if chart.log_y {
            format!("{} (log scale)", chart.y_label)
        } else {
            chart.y_label.clone()
        })
        .axis_desc_style((FONT, 14))
        .label_style((FONT, 12))
        .x_label_formatter(&|v| match chart.x_exponent {
            true => si(10f64.powf(*v)),
            false => si(*v),
        })
        .y_label_formatter(&|v| si(*v))
        .light_line_style(if chart.log_y {
            WHITE
        } else {
            RGBColor(235, 235, 235)
        })
        .draw()
        .map_err(|e| err(&e))?;
    for s in &chart.series {
        draw_series::<Y>(&mut c, s).map_err(|e| err(&e))?;
    }
    if chart.series.iter().any(|s| !s.name.is_empty()) {
        let corner = legend_corner::<Y>(&c, chart);
        c.configure_series_labels()
            .label_font((FONT, 12))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .position(corner)
            .draw()
            .map_err(|e| err(&e))?;
    }
    Ok(())
}

/// A chart's plotting context with an f64 x axis and the y axis `Y`.
type Context<'a, 'b, Y> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<RangedCoordf64, <Y as AsRangedCoord>::CoordDescType>,
>;

/// Draw one series in its style, with its legend entry.
fn draw_series<Y>(
    c: &mut Context<'_, '_, Y>,
    s: &Series,
) -> Result<(), DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>>
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: Ranged<ValueType = f64>,
{
    let col = color(s.color);
    let line = col.stroke_width(2);
    let points = s.points.iter().copied();
    let legend_line = move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], line);
    match s.style {
        Style::Line | Style::LinePoints => {
            c.draw_series(LineSeries::new(points, line))?
                .label(&s.name)
                .legend(legend_line);
            if s.style == Style::LinePoints {
                c.draw_series(s.points.iter().map(|&p| Circle::new(p, 3, col.filled())))?;
            }
        }
        Style::Dashed => {
            c.draw_series(DashedLineSeries::new(points, 8, 5, line))?
                .label(&s.name)
                .legend(legend_line);
        }
        Style::Crosses => {
            c.draw_series(points.map(|p| Cross::new(p, 7, col.stroke_width(3))))?
                .label(&s.name)
                .legend(move |(x, y)| Cross::new((x + 9, y), 5, line));
        }
    }
    Ok(())
}

/// The corner of the plotting area the data covers least, for the legend.
fn legend_corner<Y>(
    c: &ChartContext<'_, BitMapBackend<'_>, Cartesian2d<RangedCoordf64, Y::CoordDescType>>,
    chart: &Chart,
) -> SeriesLabelPosition
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: Ranged<ValueType = f64>,
{
    let (xr, yr) = c.plotting_area().get_pixel_range();
    let (w, h) = ((xr.end - xr.start) as f64, (yr.end - yr.start) as f64);
    // points along every drawn segment, in pixels relative to the plotting area
    let mut px = Vec::new();
    for s in &chart.series {
        let p: Vec<(f64, f64)> = s
            .points
            .iter()
            .map(|&q| {
                let (x, y) = c.backend_coord(&q);
                ((x - xr.start) as f64 / w, (y - yr.start) as f64 / h)
            })
            .collect();
        px.extend(p.iter().copied());
        if s.style != Style::Crosses {
            for seg in p.windows(2) {
                px.extend((1..20).map(|i| {
                    let t = i as f64 / 20.0;
                    (
                        seg[0].0 + t * (seg[1].0 - seg[0].0),
                        seg[0].1 + t * (seg[1].1 - seg[0].1),
                    )
                }));
            }
        }
    }
    let count = |right: bool, bottom: bool| {
        px.iter()
            .filter(|(x, y)| {
                (if right { *x > 0.6 } else { *x < 0.4 })
                    && (if bottom { *y > 0.6 } else { *y < 0.4 })
            })
            .count()
    };
    [
        (count(true, true), SeriesLabelPosition::LowerRight),
        (count(true, false), SeriesLabelPosition::UpperRight),
        (count(false, false), SeriesLabelPosition::UpperLeft),
        (count(false, true), SeriesLabelPosition::LowerLeft),
    ]
    .into_iter()
    .min_by_key(|(n, _)| *n)
    .map(|(_, pos)| pos)
    .unwrap_or(SeriesLabelPosition::LowerRight)
}

/// Draw `charts` side by side, each `panel_w`×`panel_h` pixels, into a PNG at `path`.
pub fn save(path: &Path, panel_w: u32, panel_h: u32, charts: &[Chart]) -> Result<()> {
    register_font()?;
    let (w, h) = (panel_w * charts.len().max(1) as u32, panel_h);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let panels = root.split_evenly((1, charts.len().max(1)));
        for (area, chart) in panels.iter().zip(charts) {
            draw_panel(area, chart)?;
        }
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).ok_or_else(|| anyhow!("plot buffer size"))?;
    gpgpu_rt::output::write_file(path, |w| gpgpu_rt::output::encode_image(&img, path, w))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn si_labels() {
        assert_eq!(si(0.0), "0");
        assert_eq!(si(2.5), "2.5");
        assert_eq!(si(1_200_000_000.0), "1.2G");
        assert_eq!(si(350_000_000.0), "350M");
        assert_eq!(si(12_000.0), "12k");
        assert_eq!(si(360.0), "360");
        assert_eq!(si(0.001), "1e-3");
    }

    #[test]
    fn chart_renders_text_and_lines_without_system_fonts() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.png");
        let chart = Chart {
            title: "Fig. 19".into(),
            x_label: "angle".into(),
            y_label: "FPS".into(),
            series: vec![
                Series::new(
                    "a",
                    (0..360)
                        .map(|x| (x as f64, 2.0 + (x as f64 / 40.0).sin()))
                        .collect(),
                    Style::Line,
                    0,
                ),
                Series::new("published", vec![(180.0, 2.5)], Style::Crosses, BLACK_INDEX),
            ],
            x_range: Some((0.0, 360.0)),
            ..Chart::default()
        };
        let log = Chart {
            log_y: true,
            ..chart.clone()
        };
        save(&path, 400, 300, &[chart, log]).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (800, 300));
        // the blue series and black text/axes are there
        let blue = img.pixels().filter(|p| p.0 == [31, 119, 180]).count();
        let dark = img.pixels().filter(|p| p.0.iter().all(|&c| c < 80)).count();
        assert!(blue > 300, "{blue} series pixels");
        assert!(dark > 500, "{dark} text/axis pixels");
    }
}
