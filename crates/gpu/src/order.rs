//! A batch's scenes in order of size. A GPU runs a warp's 32 threads in
//! step, so a warp of creatures of unlike sizes waits, at each of a
//! step's loops over particles and springs, for its largest: random
//! bodies of 2 to 40 particles keep about half of its threads idle there.
//! Packed in order of size (particles, then springs; a stable sort, so a
//! population of one shape keeps its order), neighbours in a warp do like
//! work. Each creature is evaluated alone, so the order changes no bit of
//! any result: they are handed back in the order they came.
//!
//! Opt-in until measured on a GPU: `ANIMATS_GPU_SORT=1`
//! ([`sort_from_env`]), read by [`crate::Device::open`]; `bench/gpu.sh
//! tune` compares both orders.

use animats_scene::evaluate::Evaluation;
use animats_scene::Scene;

/// A scene's size as a GPU thread's loops see it: particles, then springs.
pub fn size(scene: &Scene) -> (usize, usize) {
    world_size(&scene.world)
}

/// [`size`] of a world.
pub fn world_size(world: &animats_engine::World) -> (usize, usize) {
    (world.len(), world.forces().springs.len())
}

/// The indices of `keys` in increasing order of key, equal keys in their
/// own order.
pub fn by_size<K: Ord + Copy>(keys: &[K]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..keys.len()).collect();
    order.sort_by_key(|&i| keys[i]);
    order
}

/// `items`, the answers for `order`'s indices in that order, put back in
/// the indices' own order (`items[k]` answers index `order[k]`).
pub fn restored<T>(items: Vec<T>, order: &[usize]) -> Result<Vec<T>, String> {
    if items.len() != order.len() {
        return Err(format!(
            "{} answers for {} scenes",
            items.len(),
            order.len()
        ));
    }
    let mut slots: Vec<Option<T>> = (0..order.len()).map(|_| None).collect();
    for (item, &i) in items.into_iter().zip(order) {
        let slot = slots
            .get_mut(i)
            .ok_or_else(|| format!("index {i} out of {}", order.len()))?;
        if slot.replace(item).is_some() {
            return Err(format!("index {i} answered twice"));
        }
    }
    slots
        .into_iter()
        .enumerate()
        .map(|(i, s)| s.ok_or_else(|| format!("index {i} not answered")))
        .collect()
}

/// `scenes` evaluated by `evaluate` (a batch's runner: packs and
/// evaluates them, answering in the order given) in order of size when
/// `sort`, the answers handed back in the scenes' own order.
pub fn evaluate_in_order(
    scenes: &[&Scene],
    sort: bool,
    evaluate: impl FnOnce(&[&Scene]) -> Result<Vec<Evaluation>, String>,
) -> Result<Vec<Evaluation>, String> {
    if !sort {
        return evaluate(scenes);
    }
    let keys: Vec<(usize, usize)> = scenes.iter().map(|s| size(s)).collect();
    let order = by_size(&keys);
    let sorted: Vec<&Scene> = order.iter().map(|&i| scenes[i]).collect();
    restored(evaluate(&sorted)?, &order)
}

/// The share of a warp's lanes that do work in a loop over each
/// creature's `sizes` (its particles, say), creatures in warps of 32 in
/// the order given, averaged over the warps: a warp loops as often as its
/// largest creature, each lane idle once its own creature is done. 1 for
/// creatures of one size; what order by size raises for unlike ones (a
/// model of divergence, no measurement of a GPU).
pub fn warp_busy(sizes: &[usize]) -> f64 {
    let warps = sizes.chunks(32);
    let n = warps.len().max(1) as f64;
    warps
        .map(|w| {
            let most = w.iter().copied().max().unwrap_or(0).max(1);
            w.iter().sum::<usize>() as f64 / (32 * most) as f64
        })
        .sum::<f64>()
        / n
}

/// `ANIMATS_GPU_SORT`: unset, empty or `0` leaves a batch in its order,
/// `1` packs it in order of size; anything else is refused by name.
pub fn sort_from_env() -> Result<bool, String> {
    parse_sort(std::env::var("ANIMATS_GPU_SORT").ok().as_deref())
}

/// [`sort_from_env`] from the variable's value (`None`: unset).
pub fn parse_sort(v: Option<&str>) -> Result<bool, String> {
    match v.map(str::trim) {
        None | Some("") | Some("0") => Ok(false),
        Some("1") => Ok(true),
        Some(other) => Err(format!(
            "ANIMATS_GPU_SORT: 1 (batches in order of size) or 0, got {other:?}"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_order_is_by_size_and_stable_and_restoring_inverts_it() {
        let keys = [(5, 9), (2, 1), (5, 3), (2, 1), (40, 0), (5, 3)];
        let order = by_size(&keys);
        assert_eq!(order, vec![1, 3, 2, 5, 0, 4]);
        let answers: Vec<(usize, usize)> = order.iter().map(|&i| keys[i]).collect();
        assert_eq!(restored(answers, &order).unwrap(), keys.to_vec());
        // One shape: the order it came in.
        assert_eq!(by_size(&[(7, 9); 5]), vec![0, 1, 2, 3, 4]);
        assert_eq!(by_size::<(usize, usize)>(&[]), Vec::<usize>::new());
    }

    #[test]
    fn a_warp_is_busy_as_its_sizes_against_its_largest() {
        assert_eq!(warp_busy(&[7; 64]), 1.0);
        // One warp of 31 creatures of 1 and one of 32: (31 + 32) / (32 × 32).
        let mut sizes = vec![1; 31];
        sizes.push(32);
        assert_eq!(warp_busy(&sizes), 63.0 / 1024.0);
        // 1, 32, 1, 32, …: each warp (16 + 16 × 32) / (32 × 32); in
        // order, a warp of ones and a warp of 32s, both full.
        let mut two: Vec<usize> = (0..64).map(|k| if k % 2 == 0 { 1 } else { 32 }).collect();
        assert_eq!(warp_busy(&two), 528.0 / 1024.0);
        two.sort();
        assert_eq!(warp_busy(&two), 1.0);
        // A last warp of fewer than 32 counts its empty lanes as idle.
        assert_eq!(warp_busy(&[4; 16]), 0.5);
        assert_eq!(warp_busy(&[]), 0.0);
    }

    #[test]
    fn answers_that_do_not_match_the_order_are_refused() {
        assert!(restored(vec![1, 2], &[0])
            .unwrap_err()
            .contains("2 answers for 1"));
        assert!(restored(vec![1, 2], &[1, 1]).unwrap_err().contains("twice"));
        assert!(restored(vec![1, 2], &[0, 2])
            .unwrap_err()
            .contains("out of 2"));
    }

    #[test]
    fn the_knob_takes_0_and_1_and_names_what_it_refuses() {
        assert_eq!(parse_sort(None), Ok(false));
        assert_eq!(parse_sort(Some("")), Ok(false));
        assert_eq!(parse_sort(Some("0")), Ok(false));
        assert_eq!(parse_sort(Some(" 1 ")), Ok(true));
        for bad in ["yes", "2", "-1", "true"] {
            let e = parse_sort(Some(bad)).unwrap_err();
            assert!(e.contains("ANIMATS_GPU_SORT") && e.contains(bad), "{e}");
        }
    }
}
