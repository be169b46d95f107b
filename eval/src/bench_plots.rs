//! The plots of `strandlight bench` (plotters): per map and mode, error against frame
//! milliseconds on log-log axes, one plot for relative RMSE and one for HDR-FLIP, as PNG and SVG.
//! The SRBF default, its one-at-a-time variations, the median-cut curve and the reference are
//! marked, and the equal-error speed-up is written on the plot. Text uses the Hack font that
//! egui ships (`epaint_default_fonts`), so a machine without system fonts draws the same PNG.

use crate::bench::{EnvLitResult, Point};
use anyhow::Context;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Once;

/// Which points' labels belong to a plotted series.
type LabelFilter<'a> = &'a dyn Fn(&str) -> bool;

const WIDTH: u32 = 720;
const HEIGHT: u32 = 480;

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // A font that fails to register leaves plotters without text: the plot is still drawn.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::HACK_REGULAR,
        );
    });
}

/// Which error a plot shows.
#[derive(Clone, Copy)]
pub enum Metric {
    RelativeRmse,
    HdrFlip,
    /// Against the path-traced ground truth (where the report has one).
    TruthRelativeRmse,
    TruthHdrFlip,
}

impl Metric {
    /// Every metric a result can be drawn with: against the ground truth only where it has one.
    pub fn of_result(r: &EnvLitResult) -> Vec<Metric> {
        let mut metrics = vec![Metric::RelativeRmse, Metric::HdrFlip];
        if r.truth.is_some() {
            metrics.extend([Metric::TruthRelativeRmse, Metric::TruthHdrFlip]);
        }
        metrics
    }

    fn of(self, p: &Point) -> f64 {
        match self {
            Metric::RelativeRmse => p.relative_rmse,
            Metric::HdrFlip => p.hdr_flip,
            Metric::TruthRelativeRmse => p.truth.map_or(f64::NAN, |t| t.relative_rmse),
            Metric::TruthHdrFlip => p.truth.map_or(f64::NAN, |t| t.hdr_flip),
        }
    }

    fn name(self) -> &'static str {
        match self {
            Metric::RelativeRmse => "relative RMSE vs the DOM reference",
            Metric::HdrFlip => "HDR-FLIP vs the DOM reference",
            Metric::TruthRelativeRmse => "relative RMSE vs the path-traced truth",
            Metric::TruthHdrFlip => "HDR-FLIP vs the path-traced truth",
        }
    }

    pub fn file_tag(self) -> &'static str {
        match self {
            Metric::RelativeRmse => "rmse",
            Metric::HdrFlip => "flip",
            Metric::TruthRelativeRmse => "truth-rmse",
            Metric::TruthHdrFlip => "truth-flip",
        }
    }

    /// Whether the DOM reference has an error of its own under this metric.
    fn against_truth(self) -> bool {
        matches!(self, Metric::TruthRelativeRmse | Metric::TruthHdrFlip)
    }

    fn speedup(self, r: &EnvLitResult) -> Option<f64> {
        match self {
            Metric::RelativeRmse => r.speedup_equal_rmse,
            Metric::HdrFlip => r.speedup_equal_flip,
            Metric::TruthRelativeRmse => r.speedup_equal_rmse_truth,
            Metric::TruthHdrFlip => r.speedup_equal_flip_truth,
        }
    }
}

/// The chart every plot draws on: frame ms against error, both axes logarithmic.
type LogChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// Error against ms for one map and mode, drawn on any plotters backend.
fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    r: &EnvLitResult,
    metric: Metric,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let measured: Vec<&Point> = r
        .points
        .iter()
        .filter(|p| p.family != "reference")
        .collect();
    let reference = r.points.iter().find(|p| p.family == "reference");
    let reference_point = reference
        .filter(|_| metric.against_truth())
        .map(|p| (p.ms, metric.of(p).max(1e-4)));
    let ((lo_ms, hi_ms), (lo_e, hi_e)) = axis_ranges(r, &measured, reference, metric);
    let title = format!("{} ({}): {}", r.map, r.mode, metric.name());
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(
            (lo_ms * 0.7..hi_ms * 1.4).log_scale(),
            (lo_e * 0.7..hi_e * 1.4).log_scale(),
        )
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    chart
        .configure_mesh()
        .x_desc("frame ms")
        .y_desc(metric.name())
        .x_labels(8)
        .y_labels(10)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.2}"))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let baseline_family = r
        .points
        .iter()
        .find(|p| p.is_baseline())
        .map_or("median cut", |p| p.family.as_str());
    draw_baseline(&mut chart, &measured, metric, baseline_family)?;
    draw_srbf_series(&mut chart, &measured, metric)?;
    if let Some(default) = measured.iter().find(|p| p.label.starts_with("default")) {
        draw_default(&mut chart, default, r, metric, baseline_family)?;
    }
    if let (Some(reference), Some(at)) = (reference, reference_point) {
        // Against the ground truth the DOM reference has an error of its own: a point.
        chart
            .draw_series([Rectangle::new(
                [(at.0 / 1.08, at.1 / 1.08), (at.0 * 1.08, at.1 * 1.08)],
                BLACK.filled(),
            )])
            .map_err(|e| anyhow::anyhow!("{e:?}"))?
            .label(format!("DOM reference, {} lights", reference.lights))
            .legend(|(x, y)| Rectangle::new([(x + 5, y - 4), (x + 13, y + 4)], BLACK.filled()));
    } else if let Some(reference) = reference {
        // The reference has no error of its own: drawn as a vertical line at its cost.
        chart
            .draw_series(LineSeries::new(
                [(reference.ms, lo_e * 0.7), (reference.ms, hi_e * 1.4)],
                BLACK.mix(0.5).stroke_width(1),
            ))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?
            .label(format!("reference, {} lights", reference.lights))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK.mix(0.5)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 12))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    root.present().map_err(|e| anyhow::anyhow!("{e:?}"))?;
    Ok(())
}

/// The (ms, error) spans the axes must cover: every point's cost, including the reference's;
/// every measured point's error, and the reference's where it has one under `metric` (against
/// the ground truth). Errors are floored at 10⁻⁴ so that the log axis never meets a zero.
fn axis_ranges(
    r: &EnvLitResult,
    measured: &[&Point],
    reference: Option<&Point>,
    metric: Metric,
) -> ((f64, f64), (f64, f64)) {
    let (mut lo_ms, mut hi_ms) = (f64::INFINITY, 0.0f64);
    let (mut lo_e, mut hi_e) = (f64::INFINITY, 0.0f64);
    for p in &r.points {
        lo_ms = lo_ms.min(p.ms);
        hi_ms = hi_ms.max(p.ms);
    }
    for p in measured
        .iter()
        .copied()
        .chain(reference.filter(|_| metric.against_truth()))
    {
        let e = metric.of(p).max(1e-4);
        lo_e = lo_e.min(e);
        hi_e = hi_e.max(e);
    }
    ((lo_ms, hi_ms), (lo_e, hi_e))
}

/// The (ms, error) points of one series, in order of cost: the measured points of `family`
/// whose label `label` accepts.
fn series(
    measured: &[&Point],
    metric: Metric,
    family: &str,
    label: LabelFilter,
) -> Vec<(f64, f64)> {
    let mut v: Vec<(f64, f64)> = measured
        .iter()
        .filter(|p| p.family == family && label(&p.label))
        .map(|p| (p.ms, metric.of(p).max(1e-4)))
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    v
}

/// The baseline (median cut, or whichever family the report marks as baseline) as a red curve
/// over its light counts.
fn draw_baseline<DB: DrawingBackend>(
    chart: &mut LogChart<'_, DB>,
    measured: &[&Point],
    metric: Metric,
    baseline_family: &str,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let baseline = series(measured, metric, baseline_family, &|_| true);
    chart
        .draw_series(LineSeries::new(baseline.clone(), RED.stroke_width(2)))
        .map_err(|e| anyhow::anyhow!("{e:?}"))?
        .label(format!("{baseline_family} (light count)"))
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], RED.stroke_width(2)));
    chart
        .draw_series(baseline.iter().map(|&p| Circle::new(p, 4, RED.filled())))
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    Ok(())
}

/// The SRBF method's one-at-a-time variations, one colour of triangles each.
///
/// Labels name what was changed ("8 lobes", "light maps, κ 1", "light maps 256²"); each
/// series is joined to the frame it varies: the default, or for the κ and size series Ren's
/// light-map frame ("light maps (κ 0.1, 512²)") where the report has one. Reports written
/// before the volume was the default label κ frames "κ 1", and vary the default.
fn draw_srbf_series<DB: DrawingBackend>(
    chart: &mut LogChart<'_, DB>,
    measured: &[&Point],
    metric: Metric,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let is_light_map_base: LabelFilter = &|l| l.starts_with("light maps (");
    let srbf_series: [(LabelFilter, RGBColor, &str); 8] = [
        (&|l| l.ends_with(" lobes"), BLUE, "SRBF: lobe count"),
        (
            is_light_map_base,
            RGBColor(90, 90, 90),
            "SRBF: light maps (Ren 2010)",
        ),
        (
            &|l| l.starts_with("κ") || l.starts_with("light maps, κ"),
            GREEN,
            "SRBF light maps: κ",
        ),
        (
            &|l| l.starts_with("light maps ") && l.ends_with('²'),
            MAGENTA,
            "SRBF light maps: size",
        ),
        (
            &|l| l == "visibility volume",
            RGBColor(0, 150, 110),
            "SRBF: visibility volume",
        ),
        (
            &|l| l.starts_with("adaptive"),
            CYAN,
            "SRBF: adaptive κ share (removed, in earlier reports)",
        ),
        (
            &|l| l.starts_with("lobe spread"),
            RGBColor(230, 120, 0),
            "SRBF: lobe spread (κ; removed, in earlier reports)",
        ),
        (
            &|l| l.starts_with("light-pass chord"),
            RGBColor(120, 80, 40),
            "SRBF: light-pass chord tolerance (removed, in earlier reports)",
        ),
    ];
    let light_map_base = series(measured, metric, "srbf", is_light_map_base);
    for (matches, colour, label) in srbf_series {
        let mut points = series(measured, metric, "srbf", matches);
        if points.is_empty() {
            continue; // not in this plan (or a report written before it)
        }
        let varies_light_maps = label.starts_with("SRBF light maps") && !light_map_base.is_empty();
        match varies_light_maps {
            true => points.extend(&light_map_base),
            false => points.extend(series(measured, metric, "srbf", &|l| {
                l.starts_with("default")
            })),
        }
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        let style = colour.stroke_width(1);
        chart
            .draw_series(
                points
                    .iter()
                    .map(|&p| TriangleMarker::new(p, 6, colour.filled())),
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?
            .label(label)
            .legend(move |(x, y)| TriangleMarker::new((x + 9, y), 6, style.filled()));
    }
    Ok(())
}

/// The SRBF default frame as a cross, its legend saying what it buys over the baseline: the
/// speed-up at equal error, or a lower bound where the baseline never reaches its error.
fn draw_default<DB: DrawingBackend>(
    chart: &mut LogChart<'_, DB>,
    default: &Point,
    r: &EnvLitResult,
    metric: Metric,
    baseline_family: &str,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let at = (default.ms, metric.of(default).max(1e-4));
    let note = match metric.speedup(r) {
        Some(s) => format!("SRBF default: {s:.1}× {baseline_family} at equal error"),
        None => match r.speedup_lower_bound() {
            Some((lights, bound)) => format!(
                "SRBF default: > {bound:.1}× {baseline_family} (its {lights} lights still less accurate)"
            ),
            None => "SRBF default".into(),
        },
    };
    chart
        .draw_series([Cross::new(at, 9, BLACK.stroke_width(3))])
        .map_err(|e| anyhow::anyhow!("{e:?}"))?
        .label(note)
        .legend(|(x, y)| Cross::new((x + 9, y), 6, BLACK.stroke_width(2)));
    Ok(())
}

/// Writes `STEM.png` and `STEM.svg` in `dir` (each atomically: a failed plot never leaves half
/// a file); returns the two paths.
pub fn plot(
    dir: &Path,
    stem: &str,
    r: &EnvLitResult,
    metric: Metric,
) -> anyhow::Result<[PathBuf; 2]> {
    register_font();
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let png = dir.join(format!("{stem}.png"));
    let svg = dir.join(format!("{stem}.svg"));
    let mut pixels = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
    draw(
        BitMapBackend::with_buffer(&mut pixels, (WIDTH, HEIGHT)).into_drawing_area(),
        r,
        metric,
    )
    .with_context(|| format!("plotting {}", png.display()))?;
    let description = format!(
        "strandlight bench: {} ({}), {}",
        r.map,
        r.mode,
        metric.name()
    );
    strandlight_tables::image_out::write_png_rgb8(&png, WIDTH, HEIGHT, &pixels, &description)?;
    let mut text = String::new();
    draw(
        SVGBackend::with_string(&mut text, (WIDTH, HEIGHT)).into_drawing_area(),
        r,
        metric,
    )
    .with_context(|| format!("plotting {}", svg.display()))?;
    strandlight_tables::atomic_write::write_atomically(&svg, |w| {
        std::io::Write::write_all(w, text.as_bytes())
    })
    .with_context(|| format!("writing {}", svg.display()))?;
    Ok([png, svg])
}
