//! Which [`Layout`] a run's batches take on a GPU. Neither layout is the
//! faster for every kind of creature (on an H200, 2026-11-30: the state
//! in the thread's own memory ran the roobot 29 % faster and the
//! jellyfish 2.3×, in the batch's arrays the walker 20 % faster and
//! bodies of mixed sizes 39 %; docs/GPU.md), and both give the same bits.
//! So, unless `ANIMATS_GPU_LAYOUT` fixes one, a run tries each on one
//! batch, in turn, after a first batch that warms the GPU, and keeps the
//! one that took less time per simulated creature-second for the rest:
//! an evolution's first three generations measure it.

use crate::Layout;

/// The layouts tried, in the order they are tried (a tie keeps the first).
const ORDER: [Layout; 2] = [Layout::Local, Layout::Batch];

/// A run's choice of layout: fixed, or learned from its first batches.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LayoutChoice {
    fixed: Option<Layout>,
    /// Whether a batch has run: the first is not timed (it pays for the
    /// kernel's first launch, loading it onto the GPU, whichever layout).
    warm: bool,
    /// Each layout tried, with its seconds per simulated creature-second.
    tried: Vec<(Layout, f64)>,
}

impl LayoutChoice {
    /// A choice fixed to `layout`, or (`None`) learned.
    pub fn new(fixed: Option<Layout>) -> LayoutChoice {
        LayoutChoice {
            fixed,
            warm: false,
            tried: Vec::new(),
        }
    }

    /// The layout for the next batch: the fixed one, else the first not yet
    /// tried, else the one that took the least time.
    pub fn next(&self) -> Layout {
        if let Some(l) = self.fixed {
            return l;
        }
        if let Some(&l) = ORDER
            .iter()
            .find(|l| !self.tried.iter().any(|(t, _)| t == *l))
        {
            return l;
        }
        self.tried
            .iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(Layout::default(), |t| t.0)
    }

    /// A batch in `layout` took `seconds` to simulate `simulated`
    /// creature-seconds. Learned while the layout is untried, but for the
    /// run's first batch (a batch that simulated nothing teaches nothing
    /// either); when the last is learned, a line saying what was measured
    /// and chosen.
    pub fn record(&mut self, layout: Layout, seconds: f64, simulated: f64) -> Option<String> {
        if !std::mem::replace(&mut self.warm, true) {
            return None;
        }
        if self.fixed.is_some()
            || self.tried.iter().any(|(t, _)| *t == layout)
            || !(simulated > 0.0 && seconds.is_finite() && seconds >= 0.0)
        {
            return None;
        }
        self.tried.push((layout, seconds / simulated));
        if self.tried.len() < ORDER.len() {
            return None;
        }
        let each: Vec<String> = self
            .tried
            .iter()
            .map(|(l, c)| format!("{l:?} {:.3} ms", 1e3 * c))
            .collect();
        Some(format!(
            "GPU layout: {} of GPU time per simulated creature-second: {:?} for the rest of the run",
            each.join(", "),
            self.next()
        ))
    }
}

/// `ANIMATS_GPU_LAYOUT`: unset, empty or `auto` learns the layout;
/// `local` or `batch` fixes it; anything else is refused by name.
pub fn layout_from_env() -> Result<Option<Layout>, String> {
    parse_layout(std::env::var("ANIMATS_GPU_LAYOUT").ok().as_deref())
}

/// [`layout_from_env`] from the variable's value (`None`: unset).
pub fn parse_layout(v: Option<&str>) -> Result<Option<Layout>, String> {
    match v.map(str::trim) {
        None | Some("") | Some("auto") => Ok(None),
        Some("local") => Ok(Some(Layout::Local)),
        Some("batch") => Ok(Some(Layout::Batch)),
        Some(other) => Err(format!(
            "ANIMATS_GPU_LAYOUT: auto, local or batch, got {other:?}"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_layout_is_tried_once_then_the_faster_kept() {
        let mut c = LayoutChoice::new(None);
        assert_eq!(c.next(), Layout::Local);
        // The first batch warms the GPU: not timed, Local again next.
        assert_eq!(c.record(Layout::Local, 90.0, 1000.0), None);
        assert_eq!(c.next(), Layout::Local);
        assert_eq!(c.record(Layout::Local, 2.0, 1000.0), None);
        assert_eq!(c.next(), Layout::Batch);
        let line = c.record(Layout::Batch, 1.5, 1000.0).unwrap();
        assert_eq!(c.next(), Layout::Batch);
        assert!(
            line.contains("Local 2.000 ms") && line.contains("Batch 1.500 ms"),
            "{line}"
        );
        assert!(line.ends_with("Batch for the rest of the run"), "{line}");
        // Later batches teach nothing more: the choice stays.
        assert_eq!(c.record(Layout::Batch, 100.0, 1.0), None);
        assert_eq!(c.record(Layout::Local, 0.0, 1.0), None);
        assert_eq!(c.next(), Layout::Batch);
    }

    #[test]
    fn the_slower_per_simulated_second_loses_whatever_the_batch_s_size() {
        // Batch took less time, but for a tenth of the simulation.
        let mut c = LayoutChoice::new(None);
        c.record(Layout::Local, 1.0, 1.0);
        c.record(Layout::Local, 10.0, 10_000.0);
        c.record(Layout::Batch, 2.0, 1_000.0);
        assert_eq!(c.next(), Layout::Local);
        // A tie keeps the first tried.
        let mut c = LayoutChoice::new(None);
        c.record(Layout::Local, 9.0, 1.0);
        c.record(Layout::Local, 1.0, 1.0);
        c.record(Layout::Batch, 1.0, 1.0);
        assert_eq!(c.next(), Layout::Local);
    }

    #[test]
    fn a_batch_that_simulated_nothing_is_tried_again() {
        let mut c = LayoutChoice::new(None);
        c.record(Layout::Local, 1.0, 1.0);
        assert_eq!(c.record(Layout::Local, 0.1, 0.0), None);
        assert_eq!(c.record(Layout::Local, f64::NAN, 1.0), None);
        assert_eq!(c.next(), Layout::Local);
        assert_eq!(c.record(Layout::Local, 1.0, 1.0), None);
        assert_eq!(c.next(), Layout::Batch);
    }

    #[test]
    fn a_fixed_layout_stays_and_learns_nothing() {
        let mut c = LayoutChoice::new(Some(Layout::Batch));
        assert_eq!(c.next(), Layout::Batch);
        assert_eq!(c.record(Layout::Batch, 1.0, 1.0), None);
        assert_eq!(c.record(Layout::Batch, 1.0, 1.0), None);
        assert_eq!(c.record(Layout::Local, 1.0, 1.0), None);
        assert_eq!(c.next(), Layout::Batch);
    }

    #[test]
    fn the_knob_takes_auto_local_and_batch_and_names_what_it_refuses() {
        assert_eq!(parse_layout(None), Ok(None));
        assert_eq!(parse_layout(Some("auto")), Ok(None));
        assert_eq!(parse_layout(Some(" local ")), Ok(Some(Layout::Local)));
        assert_eq!(parse_layout(Some("batch")), Ok(Some(Layout::Batch)));
        let e = parse_layout(Some("Local")).unwrap_err();
        assert!(
            e.contains("ANIMATS_GPU_LAYOUT") && e.contains("Local"),
            "{e}"
        );
    }
}
