//! Where an evolution's time goes, and what more workers would make of it:
//! a [`Tracer`] records every piece of work of a run (each lane's `ask`,
//! each candidate's evaluation, each `tell`, with its duration, its thread
//! and the batch it ran in), and a [`Schedule`] replays that work on any
//! number of workers under the run's own dependencies — a lane's
//! generations one after another, a generation's evaluations after its
//! `ask` and before its `tell`, and every worker waiting for the slowest
//! lane at the end of each batch (`animats evolve` ends one only to save a
//! checkpoint, every `--checkpoint-every` seconds) — to predict the run's wall time. `animats evolve --schedule` prints the
//! prediction for 1 to 64 workers from a run on the cores at hand.
//!
//! The replay is greedy list scheduling (Graham's): a free worker takes the
//! ready piece that comes first in the order the run's own scheduler would
//! reach it — the lane that has done the fewest generations of its batch,
//! then the lowest lane, then the order its generation started its
//! evaluations (the longest first where the problem can guess their
//! costs, as bodies' sizes let it; else the candidates' order). Its makespan `T(W)`
//! lies between `max(work / W, critical path)` and `work / W + critical
//! path` (Graham, 1969); the tests check both. It models no contention
//! (memory bandwidth, frequency scaling): the prediction is what the
//! dependencies and the measured durations allow.

use std::sync::Mutex;
use std::time::Instant;

/// What a piece of work was.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Piece {
    /// The optimiser asking for a generation (what is left of it beside
    /// its children's making, where that is recorded apart).
    Ask,
    /// Child `k`'s making (a body's variation and checks), in parallel
    /// within the ask, after its serial part.
    Vary(usize),
    /// Candidate `k`'s evaluation.
    Evaluate(usize),
    /// The optimiser told the generation's outcomes (and the log row).
    Tell,
}

/// One piece of work of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Work {
    /// Its lane.
    pub lane: usize,
    /// Its generation (the lane's, 0-based).
    pub generation: u64,
    /// What it was.
    pub piece: Piece,
    /// The batch (the run's `advance` call) it ran in, 0-based.
    pub batch: usize,
    /// The rayon thread that ran it (0 outside a pool).
    pub thread: usize,
    /// When it started, s after the tracer was made.
    pub start: f64,
    /// How long it took, s.
    pub seconds: f64,
    /// An evaluation's place in the order its generation started them (its
    /// longest first, where the problem can tell); 0 for the rest.
    pub position: usize,
}

/// Records a run's work as it happens (many threads at once).
#[derive(Debug)]
pub struct Tracer {
    origin: Instant,
    work: Mutex<Vec<Work>>,
    batch: Mutex<usize>,
}

impl Default for Tracer {
    fn default() -> Self {
        Tracer {
            origin: Instant::now(),
            work: Mutex::new(Vec::new()),
            batch: Mutex::new(0),
        }
    }
}

impl Tracer {
    /// Records a piece that started at `began`.
    pub fn done(&self, lane: usize, generation: u64, piece: Piece, began: Instant) {
        self.record(lane, generation, piece, 0, began);
    }

    /// `piece`, begun at `began`, has just ended; `apart` s of it were
    /// recorded as other pieces (its children's making), and are left out.
    pub fn done_part(
        &self,
        lane: usize,
        generation: u64,
        piece: Piece,
        began: Instant,
        apart: f64,
    ) {
        let seconds = (began.elapsed().as_secs_f64() - apart).max(0.0);
        self.push(lane, generation, piece, 0, began, seconds);
    }

    /// `piece` took `seconds`, measured by whoever ran it.
    pub fn done_seconds(&self, lane: usize, generation: u64, piece: Piece, seconds: f64) {
        self.push(lane, generation, piece, 0, Instant::now(), seconds);
    }

    /// Candidate `k`'s evaluation, begun at `began`, the `position`-th its
    /// generation started, has just ended.
    pub fn done_evaluation(
        &self,
        lane: usize,
        generation: u64,
        k: usize,
        position: usize,
        began: Instant,
    ) {
        self.record(lane, generation, Piece::Evaluate(k), position, began);
    }

    fn record(&self, lane: usize, generation: u64, piece: Piece, position: usize, began: Instant) {
        let seconds = began.elapsed().as_secs_f64();
        self.push(lane, generation, piece, position, began, seconds);
    }

    fn push(
        &self,
        lane: usize,
        generation: u64,
        piece: Piece,
        position: usize,
        began: Instant,
        seconds: f64,
    ) {
        let start = began.duration_since(self.origin).as_secs_f64();
        let batch = *self.batch.lock().unwrap_or_else(|p| p.into_inner());
        let w = Work {
            lane,
            generation,
            piece,
            batch,
            thread: rayon::current_thread_index().unwrap_or(0),
            start,
            seconds,
            position,
        };
        self.work.lock().unwrap_or_else(|p| p.into_inner()).push(w);
    }

    /// The next pieces belong to the next batch.
    pub fn next_batch(&self) {
        *self.batch.lock().unwrap_or_else(|p| p.into_inner()) += 1;
    }

    /// Everything recorded, in a fixed order (batch, lane, generation,
    /// piece), whatever order the threads finished in.
    pub fn schedule(&self) -> Schedule {
        let mut work = self.work.lock().unwrap_or_else(|p| p.into_inner()).clone();
        work.sort_by(|a, b| {
            (a.batch, a.lane, a.generation, a.piece).cmp(&(b.batch, b.lane, b.generation, b.piece))
        });
        Schedule { work }
    }
}

/// A run's recorded work, to replay.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    /// Every piece, ordered by (batch, lane, generation, piece).
    pub work: Vec<Work>,
}

/// One lane-generation of a batch, as the replay sees it.
struct Step {
    lane: usize,
    /// Its rank among the lane's generations in the batch.
    rank: u64,
    ask: f64,
    /// Its children's making, each.
    varies: Vec<f64>,
    /// Its evaluations' durations, in the order the run started them.
    evaluations: Vec<f64>,
    tell: f64,
}

impl Schedule {
    /// The sum of every piece's duration, s: one worker's wall time.
    pub fn work_seconds(&self) -> f64 {
        self.work.iter().map(|w| w.seconds).sum()
    }

    /// The longest chain of dependent pieces, s (batch barriers included
    /// when `barriers`): no number of workers is faster.
    pub fn critical_path(&self, barriers: bool) -> f64 {
        let mut total = 0.0;
        let mut lanes: std::collections::BTreeMap<usize, f64> = Default::default();
        for batch in self.batches() {
            let mut in_batch: std::collections::BTreeMap<usize, f64> = Default::default();
            for s in batch {
                let longest = s.evaluations.iter().cloned().fold(0.0, f64::max);
                let child = s.varies.iter().cloned().fold(0.0, f64::max);
                *in_batch.entry(s.lane).or_default() += s.ask + child + longest + s.tell;
            }
            if barriers {
                total += in_batch.values().cloned().fold(0.0, f64::max);
            } else {
                for (lane, t) in in_batch {
                    *lanes.entry(lane).or_default() += t;
                }
            }
        }
        if barriers {
            total
        } else {
            lanes.values().cloned().fold(0.0, f64::max)
        }
    }

    /// The batches, each a list of lane-generations in (lane, generation)
    /// order.
    fn batches(&self) -> Vec<Vec<Step>> {
        // Each step's evaluations as (position, seconds), put in order below.
        let mut started: Vec<Vec<Vec<(usize, usize, f64)>>> = Vec::new();
        let mut out: Vec<Vec<Step>> = Vec::new();
        let mut last: Option<(usize, usize, u64)> = None;
        let mut rank: std::collections::BTreeMap<(usize, usize), u64> = Default::default();
        for w in &self.work {
            if out.len() <= w.batch {
                out.resize_with(w.batch + 1, Vec::new);
                started.resize_with(w.batch + 1, Vec::new);
            }
            let key = (w.batch, w.lane, w.generation);
            if last != Some(key) {
                let r = rank.entry((w.batch, w.lane)).or_default();
                out[w.batch].push(Step {
                    lane: w.lane,
                    rank: *r,
                    ask: 0.0,
                    varies: Vec::new(),
                    evaluations: Vec::new(),
                    tell: 0.0,
                });
                started[w.batch].push(Vec::new());
                *r += 1;
                last = Some(key);
            }
            let (Some(step), Some(evaluations)) =
                (out[w.batch].last_mut(), started[w.batch].last_mut())
            else {
                continue;
            };
            match w.piece {
                Piece::Ask => step.ask += w.seconds,
                Piece::Vary(_) => step.varies.push(w.seconds),
                Piece::Evaluate(k) => evaluations.push((w.position, k, w.seconds)),
                Piece::Tell => step.tell += w.seconds,
            }
        }
        for (steps, started) in out.iter_mut().zip(started) {
            for (step, mut evaluations) in steps.iter_mut().zip(started) {
                evaluations.sort_by_key(|&(position, k, _)| (position, k));
                step.evaluations = evaluations.into_iter().map(|e| e.2).collect();
            }
        }
        out
    }

    /// The predicted wall time on `workers` workers, s: every batch
    /// replayed by greedy list scheduling, each ending when its slowest
    /// lane does (`barriers`, as `animats evolve` runs today) or the whole
    /// run as one batch (lanes never waiting for each other).
    pub fn makespan(&self, workers: usize, barriers: bool) -> f64 {
        let workers = workers.max(1);
        if barriers {
            self.batches().iter().map(|b| replay(b, workers, 0)).sum()
        } else {
            replay(&self.as_one_batch(), workers, 0)
        }
    }

    /// [`Schedule::makespan`] without barriers had each lane asked for its
    /// next generation as soon as the last was made, while it was still
    /// evaluated, and told it after the last (its parents drawn from the
    /// archive as it was a generation earlier: a different search, which
    /// MAP-Elites's stateless emitters allow): a generation's slowest
    /// evaluation no longer holds up the next one's.
    pub fn makespan_overlapped(&self, workers: usize) -> f64 {
        replay(&self.as_one_batch(), workers.max(1), 1)
    }

    /// The critical path of [`Schedule::makespan_overlapped`], s.
    pub fn critical_path_overlapped(&self) -> f64 {
        let mut ends: std::collections::BTreeMap<usize, (f64, f64, f64)> = Default::default();
        let mut path = 0.0f64;
        for s in self.as_one_batch() {
            // (made, told, told the generation before) of the lane's last.
            let (made, told, told_before) = ends.get(&s.lane).copied().unwrap_or((0.0, 0.0, 0.0));
            let child = s.varies.iter().cloned().fold(0.0, f64::max);
            let longest = s.evaluations.iter().cloned().fold(0.0, f64::max);
            let now_made = made.max(told_before) + s.ask + child;
            let now_told = (now_made + longest).max(told) + s.tell;
            ends.insert(s.lane, (now_made, now_told, told));
            path = path.max(now_told);
        }
        path
    }

    /// Every batch's lane-generations as one batch, each lane's in order.
    fn as_one_batch(&self) -> Vec<Step> {
        let mut all: Vec<Step> = Vec::new();
        let mut done: std::collections::BTreeMap<usize, u64> = Default::default();
        for b in self.batches() {
            for mut s in b {
                let d = done.entry(s.lane).or_default();
                s.rank = *d;
                *d += 1;
                all.push(s);
            }
        }
        all.sort_by_key(|s| (s.lane, s.rank));
        all
    }
}

/// Greedy list scheduling of one batch's lane-generations on `workers`
/// workers; the makespan, s. A lane's generation is asked once the one
/// before it is made (asked, its children made) and the one `lag` before
/// that is told (`lag` 0: a generation asked after the last is told, as
/// every optimiser runs today; 1: while the last is still evaluated, its
/// parents from the archive as it was a generation earlier), and told
/// after its evaluations and the generation before it.
fn replay(steps: &[Step], workers: usize, lag: usize) -> f64 {
    use std::cmp::Reverse;
    use std::collections::{BTreeSet, BinaryHeap};
    // A task: (step index, what). Ready tasks are ordered as the run's
    // scheduler reaches them: fewest generations done, lane, then piece.
    #[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
    enum What {
        Ask,
        Vary(usize),
        Evaluate(usize),
        Tell,
    }
    /// A task's place in the order the run's scheduler reaches it.
    type Key = (u64, usize, What, usize);
    let order = |i: usize, what: What| -> Key { (steps[i].rank, steps[i].lane, what, i) };
    // Each lane's steps in order, and each step's place among them.
    let mut lanes: Vec<Vec<usize>> = Vec::new();
    let mut place: Vec<(usize, usize)> = vec![(0, 0); steps.len()];
    {
        let mut by_lane: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
        for (i, s) in steps.iter().enumerate() {
            by_lane.entry(s.lane).or_default().push(i);
        }
        for list in by_lane.into_values() {
            let mut sorted = list;
            sorted.sort_by_key(|&i| steps[i].rank);
            for (j, &i) in sorted.iter().enumerate() {
                place[i] = (lanes.len(), j);
            }
            lanes.push(sorted);
        }
    }
    let n = steps.len();
    let (mut asked, mut made, mut told) = (vec![false; n], vec![false; n], vec![false; n]);
    let (mut evaluated, mut telling) = (vec![false; n], vec![false; n]);
    let mut ready: BTreeSet<Key> = BTreeSet::new();
    // Generation `j` of lane `l` is asked if it can be.
    let try_ask = |ready: &mut BTreeSet<Key>,
                   asked: &mut [bool],
                   made: &[bool],
                   told: &[bool],
                   l: usize,
                   j: usize| {
        let Some(&i) = lanes[l].get(j) else { return };
        let after_made = j == 0 || made[lanes[l][j - 1]];
        let after_told = j < 1 + lag || told[lanes[l][j - 1 - lag]];
        if !asked[i] && after_made && after_told {
            asked[i] = true;
            ready.insert(order(i, What::Ask));
        }
    };
    // Generation `j` of lane `l` is told if it can be.
    let try_tell = |ready: &mut BTreeSet<Key>,
                    telling: &mut [bool],
                    evaluated: &[bool],
                    told: &[bool],
                    l: usize,
                    j: usize| {
        let Some(&i) = lanes[l].get(j) else { return };
        if !telling[i] && evaluated[i] && (j == 0 || told[lanes[l][j - 1]]) {
            telling[i] = true;
            ready.insert(order(i, What::Tell));
        }
    };
    for l in 0..lanes.len() {
        try_ask(&mut ready, &mut asked, &made, &told, l, 0);
    }
    // Running tasks by end time (ties by order, for determinism).
    let mut running: BinaryHeap<Reverse<(u64, Key)>> = BinaryHeap::new();
    let mut left: Vec<usize> = steps.iter().map(|s| s.evaluations.len()).collect();
    let mut unmade: Vec<usize> = steps.iter().map(|s| s.varies.len()).collect();
    let (mut now, mut free) = (0.0f64, workers);
    // Time in integer nanoseconds inside the heap, so that it orders totally.
    let nanos = |t: f64| (t * 1e9).round() as u64;
    loop {
        while free > 0 {
            let Some(&task) = ready.iter().next() else {
                break;
            };
            ready.remove(&task);
            let (_, _, what, i) = task;
            let seconds = match what {
                What::Ask => steps[i].ask,
                What::Vary(k) => steps[i].varies[k],
                What::Evaluate(k) => steps[i].evaluations[k],
                What::Tell => steps[i].tell,
            };
            running.push(Reverse((nanos(now + seconds), task)));
            free -= 1;
        }
        let Some(Reverse((end, (_, _, what, i)))) = running.pop() else {
            break;
        };
        now = end as f64 * 1e-9;
        free += 1;
        let (l, j) = place[i];
        // Step i is made: its evaluations (or, with none, its tell) become
        // ready, and so may the next generation's ask.
        let made_now = match what {
            What::Ask => {
                for k in 0..steps[i].varies.len() {
                    ready.insert(order(i, What::Vary(k)));
                }
                steps[i].varies.is_empty()
            }
            What::Vary(_) => {
                unmade[i] -= 1;
                unmade[i] == 0
            }
            What::Evaluate(_) => {
                left[i] -= 1;
                if left[i] == 0 {
                    evaluated[i] = true;
                    try_tell(&mut ready, &mut telling, &evaluated, &told, l, j);
                }
                false
            }
            What::Tell => {
                told[i] = true;
                try_tell(&mut ready, &mut telling, &evaluated, &told, l, j + 1);
                try_ask(&mut ready, &mut asked, &made, &told, l, j + 1 + lag);
                false
            }
        };
        if made_now {
            made[i] = true;
            if steps[i].evaluations.is_empty() {
                evaluated[i] = true;
                try_tell(&mut ready, &mut telling, &evaluated, &told, l, j);
            }
            for k in 0..steps[i].evaluations.len() {
                ready.insert(order(i, What::Evaluate(k)));
            }
            try_ask(&mut ready, &mut asked, &made, &told, l, j + 1);
        }
    }
    now
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A piece of a made-up run (an evaluation's position its candidate).
    fn made_up(lane: usize, generation: u64, batch: usize, piece: Piece, seconds: f64) -> Work {
        Work {
            lane,
            generation,
            piece,
            batch,
            thread: 0,
            start: 0.0,
            seconds,
            position: match piece {
                Piece::Evaluate(k) => k,
                _ => 0,
            },
        }
    }

    /// A made-up run: `lanes` lanes, `generations` each in batches of
    /// `per_batch`, `population` candidates of uneven length.
    fn run(lanes: usize, generations: u64, per_batch: u64, population: usize) -> Schedule {
        let mut work = Vec::new();
        for g in 0..generations {
            for lane in 0..lanes {
                let batch = (g / per_batch) as usize;
                let w = |piece, seconds| made_up(lane, g, batch, piece, seconds);
                work.push(w(Piece::Ask, 0.001));
                for k in 0..population {
                    let s = 0.01 * (1.0 + ((lane * 7 + k * 3 + g as usize) % 5) as f64);
                    work.push(w(Piece::Evaluate(k), s));
                }
                work.push(w(Piece::Tell, 0.002));
            }
        }
        let mut s = Schedule { work };
        s.work.sort_by(|a, b| {
            (a.batch, a.lane, a.generation, a.piece).cmp(&(b.batch, b.lane, b.generation, b.piece))
        });
        s
    }

    #[test]
    fn the_replay_starts_evaluations_in_the_run_s_order() {
        // One generation of three evaluations, 1, 1 and 2 s, on two
        // workers: in the candidates' order the long one starts last (3 s);
        // started first, as the run starts its longest (2 s).
        let at = |k: usize, position: usize, seconds: f64| Work {
            position,
            ..made_up(0, 0, 0, Piece::Evaluate(k), seconds)
        };
        let s = |positions: [usize; 3]| Schedule {
            work: vec![
                at(0, positions[0], 1.0),
                at(1, positions[1], 1.0),
                at(2, positions[2], 2.0),
            ],
        };
        assert_eq!(s([0, 1, 2]).makespan(2, true), 3.0);
        assert_eq!(s([1, 2, 0]).makespan(2, true), 2.0);
        assert_eq!(s([1, 2, 0]).makespan(1, true), 4.0);
    }

    #[test]
    fn children_made_within_an_ask_are_replayed_in_parallel() {
        // An ask of 0.1 s serial and four children of 1 s each, then two
        // evaluations of 1 s: 6.1 s on one worker, 0.1 + 2 + 1 on two,
        // 0.1 + 1 + 1 on four; the critical path 0.1 + 1 + 1.
        let piece = |piece, seconds| made_up(0, 0, 0, piece, seconds);
        let mut work = vec![piece(Piece::Ask, 0.1)];
        work.extend((0..4).map(|k| piece(Piece::Vary(k), 1.0)));
        work.extend((0..2).map(|k| piece(Piece::Evaluate(k), 1.0)));
        let s = Schedule { work };
        for (workers, wall) in [(1, 6.1), (2, 3.1), (4, 2.1)] {
            assert!((s.makespan(workers, true) - wall).abs() < 1e-9, "{workers}");
        }
        assert!((s.critical_path(true) - 2.1).abs() < 1e-12);
        assert!((s.work_seconds() - 6.1).abs() < 1e-12);
    }

    #[test]
    fn the_replay_keeps_within_grahams_bounds() {
        let s = run(6, 12, 4, 12);
        let work = s.work_seconds();
        for barriers in [true, false] {
            let path = s.critical_path(barriers);
            // One worker: the sum of the work, to rounding.
            assert!((s.makespan(1, barriers) - work).abs() < 1e-6);
            for w in [2, 3, 4, 8, 16, 64, 1000] {
                let t = s.makespan(w, barriers);
                let lower = (work / w as f64).max(path);
                // Graham: each batch is within work/W + its path.
                let batches = 3.0;
                let upper = work / w as f64 + path + batches * 1e-6;
                assert!(
                    t >= lower - 1e-6 && t <= upper,
                    "{w}: {lower} ≤ {t} ≤ {upper}"
                );
            }
            // Unbounded workers: the critical path.
            assert!((s.makespan(10_000, barriers) - path).abs() < 1e-6);
        }
        // Barriers only cost.
        assert!(s.makespan(16, false) <= s.makespan(16, true) + 1e-9);
        // The replay is a pure function of the schedule.
        assert_eq!(s.makespan(7, true), s.makespan(7, true));
    }

    #[test]
    fn overlapped_generations_fill_the_wait_for_the_slowest() {
        // One lane, two generations of evaluations 2, 1, 1 and 1 s (asks
        // and tells take no time), on two workers: one after the other each
        // takes 3 s (the long one beside two short, then the last short
        // alone), 6 s; overlapped, the second starts in the first's idle
        // second: 10 s of work in 5. Unbounded: the long ones side by side.
        let mut work = Vec::new();
        for g in 0..2 {
            work.push(made_up(0, g, 0, Piece::Ask, 0.0));
            for (k, seconds) in [2.0, 1.0, 1.0, 1.0].into_iter().enumerate() {
                work.push(made_up(0, g, 0, Piece::Evaluate(k), seconds));
            }
            work.push(made_up(0, g, 0, Piece::Tell, 0.0));
        }
        let s = Schedule { work };
        assert_eq!(s.makespan(2, false), 6.0);
        assert_eq!(s.makespan_overlapped(2), 5.0);
        assert_eq!(s.makespan_overlapped(1), 10.0);
        assert_eq!(s.critical_path_overlapped(), 2.0);
        assert_eq!(s.makespan_overlapped(100), 2.0);
        assert_eq!(s.critical_path(false), 4.0);
    }

    #[test]
    fn the_overlapped_replay_keeps_within_grahams_bounds() {
        let s = run(3, 12, 4, 12);
        let (work, path) = (s.work_seconds(), s.critical_path_overlapped());
        assert!(path < s.critical_path(false));
        assert!((s.makespan_overlapped(1) - work).abs() < 1e-6);
        for w in [2, 3, 4, 8, 16, 64] {
            let t = s.makespan_overlapped(w);
            let lower = (work / w as f64).max(path);
            assert!(
                t >= lower - 1e-6 && t <= work / w as f64 + path + 1e-6,
                "{w}: {lower} ≤ {t}"
            );
        }
        assert!((s.makespan_overlapped(10_000) - path).abs() < 1e-6);
    }
}
