//! The error-against-run-time plot (`docs/accuracy.svg`): log-log, one colour per scenario, every
//! (substep rate, iterations) setting as a point, the Pareto front connected, the defaults marked.

use plotters::prelude::*;

/// One setting of one scenario.
pub struct Point {
    pub wall: f64,
    pub error: f64,
    pub is_default: bool,
    pub on_front: bool,
}

pub struct Series {
    pub name: String,
    pub points: Vec<Point>,
}

const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

fn decade_bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    (10f64.powf(lo.log10().floor()), 10f64.powf(hi.log10().ceil()))
}

pub fn write_svg(path: &str, title: &str, series: &[Series]) -> Result<(), Box<dyn std::error::Error>> {
    let all = || series.iter().flat_map(|s| s.points.iter()).filter(|p| p.error > 0.0 && p.wall > 0.0);
    let (x0, x1) = decade_bounds(all().map(|p| p.wall));
    let (y0, y1) = decade_bounds(all().map(|p| p.error));
    let root = SVGBackend::new(path, (960, 640)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("wall-clock seconds per simulated second (median, single thread)")
        .y_desc("error / chain length")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()?;
    for (i, s) in series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let points: Vec<&Point> = s.points.iter().filter(|p| p.error > 0.0 && p.wall > 0.0).collect();
        chart.draw_series(points.iter().map(|p| Circle::new((p.wall, p.error), 3, colour.mix(0.5).filled())))?;
        let mut front: Vec<(f64, f64)> = points.iter().filter(|p| p.on_front).map(|p| (p.wall, p.error)).collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(front, colour.stroke_width(2)))?
            .label(format!("{} (line: Pareto front)", s.name))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
        chart.draw_series(points.iter().filter(|p| p.is_default).map(|p| {
            EmptyElement::at((p.wall, p.error))
                + TriangleMarker::new((0, 0), 9, colour.filled())
                + TriangleMarker::new((0, 0), 9, BLACK.stroke_width(1))
        }))?;
    }
    // A legend entry for the default marker.
    chart
        .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
        .label("triangle: default settings (240 Hz, 2 iterations)")
        .legend(|(x, y)| TriangleMarker::new((x + 10, y), 6, BLACK.filled()));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
