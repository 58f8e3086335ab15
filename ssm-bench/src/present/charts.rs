//! Every chart `ssm` draws, with plotters, each to PNG (text in the bundled Ubuntu Light) and SVG:
//! the time-against-error plot of `ssm sweep` (any x axis, y logarithmic, the Pareto front
//! marked) and the per-pass chart of `ssm compare` (where each technique's frame time goes).

use anyhow::{Context, Result, bail};
use plotters::prelude::*;

use super::work::short;
use crate::stats::pareto_front;

/// One point of a plot.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotPoint {
    /// The series it belongs to (its technique and the varied values not on the x axis).
    pub series: String,
    /// Position.
    pub x: f64,
    /// Position.
    pub y: f64,
    /// A short label drawn beside it.
    pub label: String,
}

/// What the plot's axes show.
#[derive(Clone, Debug)]
pub struct PlotAxes {
    /// x axis caption.
    pub x_label: String,
    /// y axis caption.
    pub y_label: String,
    /// Logarithmic x.
    pub log_x: bool,
    /// Mark the Pareto front of (x, y), both to be minimised (time against error).
    pub pareto: bool,
}

/// Draws the points, one line per series, y logarithmic, the Pareto front as a
/// dashed line when asked, into `png` and `svg`.
///
/// # Errors
/// Drawing or file errors, or no finite point.
pub fn plot(points: &[PlotPoint], axes: &PlotAxes, title: &str, png: &std::path::Path, svg: &std::path::Path) -> Result<()> {
    register_plot_font();
    draw(&BitMapBackend::new(png, (1000, 700)).into_drawing_area(), points, axes, title)
        .with_context(|| format!("drawing {}", png.display()))?;
    draw(&SVGBackend::new(svg, (1000, 700)).into_drawing_area(), points, axes, title)
        .with_context(|| format!("drawing {}", svg.display()))?;
    Ok(())
}

/// The font for PNG text; SVG text is drawn by whatever opens the file.
fn register_plot_font() {
    static FONT: std::sync::Once = std::sync::Once::new();
    FONT.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    });
}

/// What a per-pass chart measures: milliseconds ([`PassMeasure::MILLISECONDS`]) or a count of work.
#[derive(Clone, Copy, Debug)]
pub struct PassMeasure {
    /// The x axis caption: what the shares are of.
    pub share_of: &'static str,
    /// The frame's total as written beside a bar's name: `12.3 ms`, `4.56 M texel reads`.
    pub total: fn(f64) -> String,
}

impl PassMeasure {
    /// GPU time per pass.
    pub const MILLISECONDS: Self = Self { share_of: "share of the frame's GPU time, %", total: |ms| format!("{ms:.1} ms") };
    /// Texel reads per pass, as the techniques' shaders count them.
    pub const TEXEL_READS: Self =
        Self { share_of: "share of the frame's counted texel reads, %", total: |n| format!("{} texel reads", short(n)) };
    /// Vertex, fragment and compute invocations per pass (pipeline statistics).
    pub const INVOCATIONS: Self =
        Self { share_of: "share of the frame's counted invocations, %", total: |n| format!("{} invocations", short(n)) };
}

/// Where each technique's frame goes: one bar per technique (`(label, passes)`, each pass
/// `(name, amount)`, in `measure`'s unit), its passes stacked as shares of its frame so that a
/// 10 ms technique and a 10 s one read alike; the frame's total is in the bar's label, a pass's
/// name in its segment when the segment is wide enough. Written to `png` and `svg`.
///
/// # Errors
/// Drawing or file errors, or no bar with a positive total.
pub fn pass_chart(
    bars: &[(String, Vec<(String, f64)>)],
    title: &str,
    measure: PassMeasure,
    png: &std::path::Path,
    svg: &std::path::Path,
) -> Result<()> {
    let bars: Vec<&(String, Vec<(String, f64)>)> =
        bars.iter().filter(|(_, passes)| passes.iter().map(|(_, ms)| ms.max(0.0)).sum::<f64>() > 0.0).collect();
    if bars.is_empty() {
        bail!("no technique with a positive total");
    }
    register_plot_font();
    let height = 120 + 76 * bars.len() as u32;
    draw_pass_chart(&BitMapBackend::new(png, (1000, height)).into_drawing_area(), &bars, title, measure)
        .with_context(|| format!("drawing {}", png.display()))?;
    draw_pass_chart(&SVGBackend::new(svg, (1000, height)).into_drawing_area(), &bars, title, measure)
        .with_context(|| format!("drawing {}", svg.display()))?;
    Ok(())
}

fn draw_pass_chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    bars: &[&(String, Vec<(String, f64)>)],
    title: &str,
    measure: PassMeasure,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    area.fill(&WHITE).map_err(chart_error)?;
    let totals: Vec<f64> = bars.iter().map(|(_, passes)| passes.iter().map(|(_, ms)| ms.max(0.0)).sum()).collect();
    let names: Vec<String> = bars.iter().zip(&totals).map(|((label, _), total)| format!("{label} ({})", (measure.total)(*total))).collect();
    let count = bars.len();
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 22))
        .margin(20)
        .x_label_area_size(40)
        .y_label_area_size(230)
        // Shifted by 0.15 so that the labels plotters puts at k + 0.5 sit at the bars' centres, the
        // bars being in the upper part of their slots to leave room for the names under them.
        .build_cartesian_2d(0.0..100.0, -0.15..count as f64 - 0.15)
        .map_err(chart_error)?;
    chart
        .configure_mesh()
        .disable_y_mesh()
        .x_desc(measure.share_of)
        .label_style(("sans-serif", 15))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_labels(count * 2 + 1)
        .y_label_formatter(&|y| {
            // Labels at the bars' middles (k + 0.5), top bar first.
            let slot = y - y.floor();
            let index = count.checked_sub(1 + y.floor() as usize);
            match index {
                Some(index) if (slot - 0.5).abs() < 1e-6 => names[index].clone(),
                _ => String::new(),
            }
        })
        .draw()
        .map_err(chart_error)?;
    for (index, ((_, passes), total)) in bars.iter().zip(&totals).enumerate() {
        let top = (count - index) as f64 - 0.27;
        let bottom = (count - 1 - index) as f64 + 0.27;
        let mut start = 0.0;
        // Passes too narrow for their name are named under the bar, each after a swatch of its colour.
        let (mut key_cursor, mut key_line) = (0.0, 0.0);
        for (k, (pass, ms)) in passes.iter().enumerate() {
            let share = 100.0 * ms.max(0.0) / total;
            let colour = Palette99::pick(k).to_rgba();
            chart
                .draw_series(std::iter::once(Rectangle::new([(start, bottom), (start + share, top)], colour.filled())))
                .map_err(chart_error)?;
            // The pass's name inside its segment, when about 7 pixels a character fit (1% ≈ 7.2 pixels here).
            if share * 7.2 > 7.0 * pass.len() as f64 + 8.0 {
                let label = Text::new(pass.clone(), (start + 0.5, (top + bottom) / 2.0), ("sans-serif", 13).into_font().color(&BLACK));
                chart.draw_series(std::iter::once(label)).map_err(chart_error)?;
            } else {
                let key = format!("{pass} {share:.0}%");
                // About 6 pixels a character at 12 pixels, 7.2 pixels a percent; a second line when the first is full.
                let key_width = (6.0 * key.len() as f64 + 26.0) / 7.2;
                if key_cursor > 0.0 && key_cursor + key_width > 100.0 {
                    (key_cursor, key_line) = (0.0, key_line + 1.0);
                }
                let key_top = bottom - 0.04 - 0.19 * key_line;
                let key_bottom = key_top - 0.15;
                let swatch = Rectangle::new([(key_cursor, key_bottom), (key_cursor + 1.4, key_top)], colour.filled());
                chart.draw_series(std::iter::once(swatch)).map_err(chart_error)?;
                let text = Text::new(key.clone(), (key_cursor + 1.9, key_top + 0.02), ("sans-serif", 12).into_font().color(&BLACK));
                chart.draw_series(std::iter::once(text)).map_err(chart_error)?;
                key_cursor += key_width;
            }
            start += share;
        }
    }
    area.present().map_err(chart_error)?;
    Ok(())
}

fn chart_error(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("{e}")
}

fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    points: &[PlotPoint],
    axes: &PlotAxes,
    title: &str,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let usable: Vec<&PlotPoint> =
        points.iter().filter(|p| p.x.is_finite() && p.y.is_finite() && p.y > 0.0 && (!axes.log_x || p.x > 0.0)).collect();
    if usable.is_empty() {
        bail!("no finite point to plot");
    }
    let (x_min, x_max) = usable.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.x), hi.max(p.x)));
    let (y_min, y_max) = usable.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
    area.fill(&WHITE).map_err(chart_error)?;
    let mut builder = ChartBuilder::on(area);
    builder.caption(title, ("sans-serif", 24)).margin(20).x_label_area_size(50).y_label_area_size(70);
    let y_low = y_min / 1.5;
    let y_high_for = |x_fraction: &dyn Fn(f64) -> f64| legend_room(&usable, y_low, y_max, x_fraction, axes.pareto);
    if axes.log_x {
        let (x_low, x_high) = (x_min / 1.5, x_max * 1.5);
        let (y_high, legend) = y_high_for(&|x: f64| (x / x_low).ln() / (x_high / x_low).ln());
        // The ticks chosen here: plotters' own log ticks start at the first power of ten inside the
        // range, so an axis within one decade got that one label, or none.
        let y_range = (y_low..y_high).log_scale().with_key_points(log_key_points(y_low, y_high));
        let x_range = (x_low..x_high).log_scale().with_key_points(log_key_points(x_low, x_high));
        let chart = builder.build_cartesian_2d(x_range, y_range).map_err(chart_error)?;
        draw_series(chart, &usable, axes, legend, false)
    } else {
        let pad = ((x_max - x_min) * 0.08).max(1e-6);
        let (x_low, x_high) = (x_min - pad, x_max + pad);
        let (y_high, legend) = y_high_for(&|x: f64| (x - x_low) / (x_high - x_low));
        let y_range = (y_low..y_high).log_scale().with_key_points(log_key_points(y_low, y_high));
        let integers = usable.iter().all(|p| p.x.fract() == 0.0);
        let chart = builder.build_cartesian_2d(x_low..x_high, y_range).map_err(chart_error)?;
        draw_series(chart, &usable, axes, legend, integers)
    }
}

/// Ticks of a log axis from `low` to `high`: 1, 2 and 5 times each power of ten inside, and 3 as
/// well when the range spans less than two decades (few ticks otherwise).
fn log_key_points(low: f64, high: f64) -> Vec<f64> {
    if !(low > 0.0 && high > low && high.is_finite()) {
        return Vec::new();
    }
    let mantissas: &[f64] = if high / low < 100.0 { &[1.0, 2.0, 3.0, 5.0] } else { &[1.0, 2.0, 5.0] };
    let (first, last) = (low.log10().floor() as i32, high.log10().ceil() as i32);
    (first..=last).flat_map(|power| mantissas.iter().map(move |m| m * 10f64.powi(power))).filter(|v| *v >= low && *v <= high).collect()
}

/// A log axis's tick label: only at 1, 2, 3 and 5 times a power of ten, since plotters puts a tick at
/// every integer multiple and, over less than a decade, their labels overprint.
fn log_tick(value: f64) -> String {
    if !(value > 0.0 && value.is_finite()) {
        return String::new();
    }
    let mantissa = value / 10f64.powf(value.log10().floor());
    if [1.0, 2.0, 3.0, 5.0, 10.0].iter().any(|m| (mantissa - m).abs() < 1e-6 * m) { compact(value) } else { String::new() }
}

/// A number with at most three significant decimals and no trailing zeros.
fn compact(value: f64) -> String {
    let text = if value.abs() >= 100.0 { format!("{value:.0}") } else { format!("{value:.3}") };
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_owned() } else { text }
}

/// A label's rectangle in pixels: left, top, right, bottom.
type LabelBox = (i32, i32, i32, i32);

/// Where to draw the label of the point at pixel `at`, relative to it: above and to the right,
/// or else below, higher or lower, whichever first overlaps no label in `placed` (which it joins).
fn label_offset(at: (i32, i32), label: &str, placed: &mut Vec<LabelBox>) -> (i32, i32) {
    // 13-pixel sans-serif: about 7 pixels a character.
    let (width, height) = (7 * i32::try_from(label.chars().count()).unwrap_or(i32::MAX / 8), 13);
    let candidates = [(8, -16), (8, 6), (8, -30), (8, 20)];
    let rectangle = |(dx, dy): (i32, i32)| (at.0 + dx, at.1 + dy, at.0 + dx + width, at.1 + dy + height);
    let overlaps = |a: LabelBox, b: &LabelBox| a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3;
    let chosen = candidates.into_iter().find(|offset| !placed.iter().any(|b| overlaps(rectangle(*offset), b))).unwrap_or(candidates[0]);
    placed.push(rectangle(chosen));
    chosen
}

/// The top of a log y axis from `y_low` that leaves the legend room, and where the legend goes: the
/// emptiest corner when one holds no point (the axis tops at 1.5× the largest value); otherwise the
/// axis grows upwards until the legend's height at the top right holds no point. A legend must
/// hide no measurement.
fn legend_room(points: &[&PlotPoint], y_low: f64, y_max: f64, x_fraction: &dyn Fn(f64) -> f64, pareto: bool) -> (f64, SeriesLabelPosition) {
    let y_high = y_max * 1.5;
    let (corner, crowded) = emptiest_corner(points, x_fraction, |y: f64| (y / y_low).ln() / (y_high / y_low).ln());
    if crowded == 0 {
        return (y_high, corner);
    }
    // The legend's share of the plot's height: a 22-pixel line per series (and the Pareto
    // front's), in a plot area of about 560 pixels.
    let mut entries = points.iter().map(|p| p.series.as_str()).collect::<Vec<_>>();
    entries.sort_unstable();
    entries.dedup();
    let share = legend_share(entries.len() + usize::from(pareto));
    (y_low * (y_max / y_low).powf(1.0 / (1.0 - share - 0.03)), SeriesLabelPosition::UpperRight)
}

/// The fraction of the plot's height a legend of `entries` lines takes.
fn legend_share(entries: usize) -> f64 {
    ((22 * entries + 16) as f64 / 560.0).min(0.45)
}

/// A linear axis's tick label; on an axis of integers (a light count), none between them.
fn linear_tick(value: f64, integers: bool) -> String {
    if integers && value.fract().abs() > 1e-9 { String::new() } else { compact(value) }
}

/// The corner of the plot whose region (a third of the width, two fifths of the height) holds the
/// fewest points, for the legend, so that it hides no measurement, and how many it holds.
/// `x_fraction` and `y_fraction` place a value in [0, 1] along the axes as drawn.
fn emptiest_corner(
    points: &[&PlotPoint],
    x_fraction: impl Fn(f64) -> f64,
    y_fraction: impl Fn(f64) -> f64,
) -> (SeriesLabelPosition, usize) {
    let corners = [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerLeft, false, false),
        (SeriesLabelPosition::LowerRight, true, false),
    ];
    let crowding = |right: bool, upper: bool| {
        points
            .iter()
            .filter(|p| {
                let (x, y) = (x_fraction(p.x), y_fraction(p.y));
                (if right { x > 0.66 } else { x < 0.34 }) && (if upper { y > 0.6 } else { y < 0.4 })
            })
            .count()
    };
    corners
        .into_iter()
        .map(|(corner, right, upper)| (corner, crowding(right, upper)))
        .min_by_key(|(_, count)| *count)
        .unwrap_or((SeriesLabelPosition::UpperRight, 0))
}

fn draw_series<'a, DB, X>(
    mut chart: ChartContext<
        'a,
        DB,
        Cartesian2d<X, plotters::coord::combinators::WithKeyPoints<plotters::coord::combinators::LogCoord<f64>>>,
    >,
    points: &[&PlotPoint],
    axes: &PlotAxes,
    legend: SeriesLabelPosition,
    integer_x: bool,
) -> Result<()>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(axes.x_label.as_str())
        .y_desc(axes.y_label.as_str())
        .label_style(("sans-serif", 15))
        // An axis of integers (a light count) is labelled at integers only.
        .x_label_formatter(&|v| if axes.log_x { log_tick(*v) } else { linear_tick(*v, integer_x) })
        .y_label_formatter(&|v| log_tick(*v))
        .draw()
        .map_err(chart_error)?;
    let mut series_names: Vec<&str> = Vec::new();
    for p in points {
        if !series_names.contains(&p.series.as_str()) {
            series_names.push(&p.series);
        }
    }
    // Pixel rectangles of the labels drawn so far, so that close points' labels do not overprint.
    let mut placed_labels: Vec<LabelBox> = Vec::new();
    for (index, name) in series_names.iter().enumerate() {
        let colour = Palette99::pick(index).mix(0.9);
        let mut series: Vec<&PlotPoint> = points.iter().copied().filter(|p| p.series == *name).collect();
        if !axes.pareto {
            series.sort_by(|a, b| a.x.total_cmp(&b.x));
        }
        chart
            .draw_series(LineSeries::new(series.iter().map(|p| (p.x, p.y)), colour.stroke_width(2)))
            .map_err(chart_error)?
            .label(name.to_string())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(3)));
        chart.draw_series(series.iter().map(|p| Circle::new((p.x, p.y), 5, colour.filled()))).map_err(chart_error)?;
        let offsets: Vec<(i32, i32)> =
            series.iter().map(|p| label_offset(chart.backend_coord(&(p.x, p.y)), &p.label, &mut placed_labels)).collect();
        chart
            .draw_series(series.iter().zip(offsets).map(|(p, offset)| {
                EmptyElement::at((p.x, p.y)) + Text::new(p.label.clone(), offset, ("sans-serif", 13).into_font().color(&BLACK))
            }))
            .map_err(chart_error)?;
    }
    if axes.pareto {
        let coordinates: Vec<(f64, f64)> = points.iter().map(|p| (p.x, p.y)).collect();
        let front = pareto_front(&coordinates);
        chart
            .draw_series(DashedLineSeries::new(front.iter().map(|&i| coordinates[i]), 6, 4, BLACK.stroke_width(1)))
            .map_err(chart_error)?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1)));
        chart.draw_series(front.iter().map(|&i| Circle::new(coordinates[i], 9, BLACK.stroke_width(2)))).map_err(chart_error)?;
    }
    chart
        .configure_series_labels()
        .position(legend)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()
        .map_err(chart_error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_label_one_two_three_and_five_and_labels_do_not_overprint() {
        assert_eq!([10.0, 20.0, 30.0, 50.0, 70.0, 100.0, 0.05, 0.06].map(log_tick), ["10", "20", "30", "50", "", "100", "0.05", ""]);
        assert_eq!(compact(0.1), "0.1");
        let mut placed = Vec::new();
        let first = label_offset((100, 100), "1024", &mut placed);
        let second = label_offset((104, 100), "2048", &mut placed);
        assert_ne!(first, second, "a point 4 pixels away gets its label elsewhere");
        assert_eq!(label_offset((400, 100), "4096", &mut placed), first);
    }

    #[test]
    fn the_pass_chart_labels_each_bar_with_its_frame_time() {
        let dir = std::env::temp_dir().join(format!("ssm-pass-chart-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (png, svg) = (dir.join("passes.png"), dir.join("passes.svg"));
        let bars = vec![
            ("fast".to_owned(), vec![("shadow_map".to_owned(), 1.0), ("filter".to_owned(), 3.0)]),
            ("slow".to_owned(), vec![("tiles".to_owned(), 900.0), ("filter".to_owned(), 100.0)]),
            ("untimed".to_owned(), Vec::new()),
        ];
        pass_chart(&bars, "title", PassMeasure::MILLISECONDS, &png, &svg).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("fast (4.0 ms)") && text.contains("slow (1000.0 ms)") && !text.contains("untimed"), "{text}");
        assert!(text.lines().any(|line| line.trim() == "tiles"), "a wide segment is named");
        assert!(pass_chart(&bars[2..], "title", PassMeasure::MILLISECONDS, &png, &svg).is_err(), "nothing timed");
        // In work: the same shares, the frame's count in the label and the axis naming the count.
        let reads = vec![("fast".to_owned(), vec![("shadow_map".to_owned(), 0.0), ("filter".to_owned(), 4_560_000.0)])];
        pass_chart(&reads, "title", PassMeasure::TEXEL_READS, &png, &svg).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("fast (4.560 M texel reads)") && text.contains("counted texel reads, %"), "{text}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn log_axes_get_round_ticks_even_within_a_decade() {
        assert_eq!(log_key_points(0.017, 0.1), vec![0.02, 0.03, 0.05, 0.1]);
        let wide = log_key_points(7.0, 5000.0);
        assert_eq!(wide.first().copied(), Some(10.0));
        assert!(wide.contains(&200.0) && wide.contains(&5000.0) && !wide.contains(&300.0), "{wide:?}");
        assert!(log_key_points(0.0, 1.0).is_empty());
    }

    #[test]
    fn an_axis_of_integers_is_labelled_at_integers_only() {
        assert_eq!(linear_tick(1.5, true), "");
        assert_eq!(linear_tick(2.0, true), "2");
        assert_eq!(linear_tick(1.5, false), "1.5");
    }

    #[test]
    fn the_legend_hides_no_point_even_when_every_corner_is_taken() {
        // Eight series over 1, 2 and 3 lights spread over two decades: every corner holds points.
        let points: Vec<PlotPoint> = (0..8)
            .flat_map(|series| {
                (1..=3).map(move |lights| PlotPoint {
                    series: format!("s{series}"),
                    x: f64::from(lights),
                    y: 10.0 * 1.9f64.powi(series) * f64::from(lights),
                    label: String::new(),
                })
            })
            .collect();
        let refs: Vec<&PlotPoint> = points.iter().collect();
        let (y_low, y_max) = (10.0 / 1.5, refs.iter().map(|p| p.y).fold(0.0, f64::max));
        let x_fraction = |x: f64| (x - 0.84) / 2.32;
        assert!(emptiest_corner(&refs, x_fraction, |y| (y / y_low).ln() / (y_max * 1.5 / y_low).ln()).1 > 0, "the case is crowded");
        let (y_high, corner) = legend_room(&refs, y_low, y_max, &x_fraction, false);
        assert_eq!(corner, SeriesLabelPosition::UpperRight);
        let top = 1.0 - legend_share(8);
        assert!(refs.iter().all(|p| (p.y / y_low).ln() / (y_high / y_low).ln() < top), "a point under the legend");
    }
}
