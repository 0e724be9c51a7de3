//! Pools whose threads keep to their own processors. A world split over
//! threads forks and joins a few times a step; left to itself, the system
//! often runs both threads of a pool on one processor for a hundred steps
//! at a time (we suppose because a woken thread is placed beside the one
//! that woke it; the probe saw only where they ran), and the second
//! thread then gains less than it could (allpairs-1000 on two threads: 1.63–
//! 1.65× one thread unpinned, 1.89–1.91× pinned, measured 2026-11-25). Pinning changes speed only, never results.
//!
//! Thread `i` of a pool of `n` is pinned to the `i`-th processor the
//! process may use, and only when it may use at least `n` (a pool larger
//! than the machine, or a process already confined to fewer processors by
//! `taskset` or a container, is left alone). `ANIMATS_PIN_THREADS=0` turns
//! it off. Linux only; elsewhere the threads are left to the system.
//!
//! It pays where the steps run inside the pool (`pool.install(|| for _ in
//! … { world.step(dt) })`, as `animats bench` runs them). Stepping a world
//! from a thread outside the pool (the CLI's `simulate`), which hands each
//! step to the pool and waits, measured 4–16 % slower pinned on a cloth
//! on the floor, so the CLI pins its global pool only when asked
//! (`ANIMATS_PIN_THREADS=1`).

/// A rayon pool of `threads` threads, each pinned to its own processor
/// (see the module's documentation).
pub fn pinned_pool(threads: usize) -> Result<rayon::ThreadPool, rayon::ThreadPoolBuildError> {
    pinned(threads).build()
}

/// A builder of a pool of `threads` threads, each pinned as it starts.
fn pinned(threads: usize) -> rayon::ThreadPoolBuilder {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .start_handler(move |i| {
            pin_thread(i, threads);
        })
}

/// Makes rayon's global pool a pinned one, of `RAYON_NUM_THREADS` threads
/// or else one per processor (rayon's own default). An error if the global
/// pool already exists. (`animats` calls it when `ANIMATS_PIN_THREADS=1`.)
pub fn pin_global_pool() -> Result<(), rayon::ThreadPoolBuildError> {
    let threads = std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|s| s.parse::<usize>().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    pinned(threads).build_global()
}

/// Whether pinning is turned off (`ANIMATS_PIN_THREADS=0`).
fn turned_off() -> bool {
    std::env::var_os("ANIMATS_PIN_THREADS").is_some_and(|v| v == "0")
}

/// Pins the calling thread, thread `i` of a pool of `n`, to the `i`-th
/// processor this thread may use, if it may use at least `n` and `n > 1`.
/// True if it did.
#[cfg(target_os = "linux")]
pub fn pin_thread(i: usize, n: usize) -> bool {
    if n < 2 || i >= n || turned_off() {
        return false;
    }
    let Some(allowed) = allowed().filter(|a| a.len() >= n) else {
        return false;
    };
    // SAFETY: `cpu_set_t` is plain bits (all zeros is the empty set); the
    // call reads only the set passed, for the calling thread.
    unsafe {
        let mut one: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(allowed[i], &mut one);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &one) == 0
    }
}

/// The processors the calling thread may use (`None` if the system will
/// not say).
#[cfg(target_os = "linux")]
fn allowed() -> Option<Vec<usize>> {
    // SAFETY: `cpu_set_t` is plain bits (all zeros is the empty set); the
    // call writes only the set passed, for the calling thread.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return None;
        }
        Some(
            (0..libc::CPU_SETSIZE as usize)
                .filter(|&c| libc::CPU_ISSET(c, &set))
                .collect(),
        )
    }
}

/// Elsewhere the threads are left to the system.
#[cfg(not(target_os = "linux"))]
pub fn pin_thread(_i: usize, _n: usize) -> bool {
    let _ = turned_off;
    false
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    /// The processors the calling thread may use.
    fn allowed() -> Vec<usize> {
        super::allowed().expect("sched_getaffinity answers")
    }

    /// Each thread of a pinned pool may then use its own processor and no
    /// other, the `i`-th of those the process may use; a pool of one
    /// thread, or of more threads than processors, is left alone.
    #[test]
    fn a_pinned_pools_threads_each_keep_to_their_own_processor() {
        let all = allowed();
        if all.len() >= 2 && !turned_off() {
            let pool = pinned_pool(2).unwrap();
            let seen = pool.broadcast(|ctx| (ctx.index(), allowed()));
            for (i, mine) in seen {
                assert_eq!(mine, vec![all[i]], "thread {i}");
            }
        }
        let one = pinned_pool(1).unwrap();
        assert_eq!(one.install(allowed), all);
        let many = pinned_pool(all.len() + 1).unwrap();
        assert_eq!(many.install(allowed), all);
        // Pinning a thread spawned here leaves this one as it was.
        let pinned = std::thread::spawn(|| pin_thread(0, 2)).join().unwrap();
        assert_eq!(pinned, all.len() >= 2 && !turned_off());
        assert_eq!(allowed(), all);
    }
}
