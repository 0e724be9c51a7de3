//! Line plots (the thesis's Figure 18: best fitness against generation, one
//! line per lane), drawn with plotters into a pixel buffer and encoded as
//! PNG. The font is embedded (DejaVu Sans), so no system fonts are needed.

use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Registers the embedded font (once).
pub(crate) fn font() {
    REGISTER.call_once(|| {
        // The embedded font is known-good; registration only fails on a bad font.
        let _ = register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// One named series of (x, y) points, drawn as a step line.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points in increasing x.
    pub points: Vec<(f64, f64)>,
}

/// A plot to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    /// Title above the plot.
    pub title: String,
    /// X axis label.
    pub x_label: String,
    /// Y axis label.
    pub y_label: String,
    /// The lines.
    pub series: Vec<Series>,
    /// Image size in pixels.
    pub size: (u32, u32),
}

const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// Draws `plot` as step lines (a value holds until the next point) and
/// returns the PNG bytes.
pub fn step_plot_png(plot: &Plot) -> Result<Vec<u8>, String> {
    font();
    let (w, h) = plot.size;
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        // Points that cannot be placed (NaN, infinite, beyond ±10³⁰⁰, where
        // the axis's padding would overflow) are left out: a fitness of
        // `inf` from a scene's weights must not make the axes infinite.
        let placed: Vec<Vec<(f64, f64)>> = plot
            .series
            .iter()
            .map(|s| {
                s.points
                    .iter()
                    .copied()
                    .filter(|&(x, y)| x.is_finite() && y.is_finite() && y.abs() <= 1e300)
                    .collect()
            })
            .collect();
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for &(x, y) in placed.iter().flatten() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        if !x0.is_finite() {
            (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
        }
        let pad = ((y1 - y0) * 0.05).max(1e-9);
        let mut chart = ChartBuilder::on(&root)
            .caption(&plot.title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d(x0..x1.max(x0 + 1.0), (y0 - pad)..(y1 + pad))
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(plot.x_label.as_str())
            .y_desc(plot.y_label.as_str())
            .label_style(("sans-serif", 14))
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| {
                if y.abs() < 1e9 {
                    format!("{y:.0}")
                } else {
                    format!("{y:.2e}")
                }
            })
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(|e| e.to_string())?;
        for (i, (s, points)) in plot.series.iter().zip(&placed).enumerate() {
            let colour = COLOURS[i % COLOURS.len()];
            let mut steps = Vec::with_capacity(2 * points.len());
            for (k, &(x, y)) in points.iter().enumerate() {
                if k > 0 {
                    steps.push((x, points[k - 1].1));
                }
                steps.push((x, y));
            }
            chart
                .draw_series(LineSeries::new(steps, colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(s.label.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    crate::png_file::encode_rgb(w, h, &buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lane whose fitness overflowed (a scene's weight of 1e308) once
    /// made plotters search for the axis's key points for ever.
    #[test]
    fn points_that_cannot_be_placed_are_left_out_and_the_plot_is_drawn() {
        for points in [
            vec![(1.0, f64::INFINITY), (2.0, f64::INFINITY)],
            vec![
                (1.0, 5.0),
                (2.0, f64::NAN),
                (3.0, f64::NEG_INFINITY),
                (4.0, 7.0),
            ],
            vec![(1.0, -1e308), (2.0, 1e308), (3.0, 1e300), (4.0, -1e300)],
            vec![(f64::NAN, 1.0), (f64::INFINITY, 2.0)],
        ] {
            let plot = Plot {
                title: "t".into(),
                x_label: "x".into(),
                y_label: "y".into(),
                series: vec![Series {
                    label: "s".into(),
                    points: points.clone(),
                }],
                size: (320, 200),
            };
            // On a thread of its own, so that a regression fails here
            // instead of hanging the tests.
            let (tx, rx) = std::sync::mpsc::channel();
            std::thread::spawn(move || {
                let _ = tx.send(step_plot_png(&plot));
            });
            let png = rx
                .recv_timeout(std::time::Duration::from_secs(60))
                .expect("the plot was not drawn within 60 s")
                .unwrap();
            assert_eq!(&png[..4], b"\x89PNG", "{points:?}");
        }
    }
}
