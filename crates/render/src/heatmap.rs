//! A grid archive as a heat map (as pyribs's `grid_archive_heatmap`): the
//! first two measures on the axes, one rectangle per cell coloured by its
//! objective (viridis; empty cells white), a colour bar beside it. An
//! archive of more measures shows, in each cell of the first two, the best
//! objective over the rest; of one, a single row.

use plotters::prelude::*;

/// A heat map to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct Heatmap {
    /// Title above the map.
    pub title: String,
    /// The x axis's measure.
    pub x_label: String,
    /// The y axis's measure (empty for a one-measure archive).
    pub y_label: String,
    /// Cells along x and y.
    pub bins: (u64, u64),
    /// `(min, max)` along x and y.
    pub ranges: ((f64, f64), (f64, f64)),
    /// Occupied cells: (x cell, y cell, objective).
    pub cells: Vec<(u64, u64, f64)>,
    /// Image size in pixels.
    pub size: (u32, u32),
}

/// Viridis at `t` in [0, 1] (matplotlib's, linearly between 9 of its
/// stops).
pub fn viridis(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 9] = [
        (68, 1, 84),
        (71, 44, 122),
        (59, 81, 139),
        (44, 113, 142),
        (33, 144, 141),
        (39, 173, 129),
        (92, 200, 99),
        (170, 220, 50),
        (253, 231, 37),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let mix = |a: u8, b: u8| (a as f64 + (b as f64 - a as f64) * f).round() as u8;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Draws `map` and returns the PNG bytes.
pub fn heatmap_png(map: &Heatmap) -> Result<Vec<u8>, String> {
    crate::plot::font();
    let (w, h) = map.size;
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let (lo, hi) = map
        .cells
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| {
            (a.min(c.2), b.max(c.2))
        });
    let (lo, hi) = if lo.is_finite() {
        (lo, hi.max(lo + 1e-12))
    } else {
        (0.0, 1.0)
    };
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let (left, right) = root.split_horizontally(w.saturating_sub(130));
        let ((x0, x1), (y0, y1)) = map.ranges;
        let (nx, ny) = (map.bins.0.max(1), map.bins.1.max(1));
        let mut chart = ChartBuilder::on(&left)
            .caption(&map.title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(map.x_label.as_str())
            .y_desc(map.y_label.as_str())
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(|e| e.to_string())?;
        let (dx, dy) = ((x1 - x0) / nx as f64, (y1 - y0) / ny as f64);
        chart
            .draw_series(map.cells.iter().map(|&(i, j, f)| {
                let a = (x0 + i as f64 * dx, y0 + j as f64 * dy);
                let b = (a.0 + dx, a.1 + dy);
                Rectangle::new([a, b], viridis((f - lo) / (hi - lo)).filled())
            }))
            .map_err(|e| e.to_string())?;
        // The colour bar.
        let mut bar = ChartBuilder::on(&right)
            .margin_top(44)
            .margin_bottom(56)
            .margin_right(12)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..1.0, lo..hi)
            .map_err(|e| e.to_string())?;
        bar.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc("objective")
            .y_label_formatter(&|v| {
                if hi - lo >= 10.0 {
                    format!("{v:.0}")
                } else {
                    format!("{v:.3}")
                }
            })
            .label_style(("sans-serif", 12))
            .axis_desc_style(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
        let steps = 100;
        bar.draw_series((0..steps).map(|k| {
            let a = lo + (hi - lo) * k as f64 / steps as f64;
            let b = lo + (hi - lo) * (k + 1) as f64 / steps as f64;
            Rectangle::new(
                [(0.0, a), (1.0, b)],
                viridis(k as f64 / (steps - 1) as f64).filled(),
            )
        }))
        .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    crate::png_file::encode_rgb(w, h, &buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends_and_middle() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(0.5), RGBColor(33, 144, 141));
        assert_eq!(viridis(f64::NAN), RGBColor(68, 1, 84));
    }

    #[test]
    fn a_map_draws() {
        let map = Heatmap {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            bins: (4, 3),
            ranges: ((0.0, 1.0), (0.0, 1.0)),
            cells: vec![(0, 0, 1.0), (3, 2, 5.0)],
            size: (400, 300),
        };
        let png = heatmap_png(&map).unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }
}
