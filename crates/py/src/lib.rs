//! `animats._animats`: the Python bindings. Thin: each class wraps a Rust
//! type of the libraries and translates arrays and errors; the logic lives
//! in `animats-scene`, `animats-creatures` and `animats-evolve`. The Python
//! package (`python/animats/`) re-exports these and adds the Gymnasium
//! environments and the Ray distribution.
//!
//! - `scene.rs`: `load`, `Scene`, `World`, `Snapshot`.
//! - `evaluate.rs`: `evaluate`, `Evaluator` (in parallel, the GIL released).
//! - `optimise.rs`: `Optimiser`, `Evolution` (`animats evolve`'s run).
//! - `env.rs`: `Env`, `VecEnv` (what the Gymnasium wrappers step).

use pyo3::prelude::*;

/// mimalloc for the module's own blocks, as in the `animats` command:
/// evaluations on many threads then share no cache lines
/// (docs/DESIGN.md, "Threads").
#[global_allocator]
static ALLOC: mimalloc::MiMalloc = mimalloc::MiMalloc;

mod env;
mod evaluate;
mod optimise;
mod scene;

pyo3::create_exception!(
    _animats,
    SceneError,
    pyo3::exceptions::PyValueError,
    "A scene file that cannot be read or built; the message names the file, line, entry and field."
);

/// A Rust error message as a Python `ValueError`.
pub(crate) fn value_error(e: impl std::fmt::Display) -> PyErr {
    pyo3::exceptions::PyValueError::new_err(e.to_string())
}

/// A simulation or evaluation failure as a Python `RuntimeError`.
pub(crate) fn runtime_error(e: impl std::fmt::Display) -> PyErr {
    pyo3::exceptions::PyRuntimeError::new_err(e.to_string())
}

/// A scene error as `animats.SceneError`.
pub(crate) fn scene_error(e: impl std::fmt::Display) -> PyErr {
    SceneError::new_err(e.to_string())
}

/// Locks `m` without holding the GIL while it waits: the thread that holds
/// it may be working with the GIL released (a long `World.step`) and need
/// the GIL back before it can let go, which a waiter that kept the GIL
/// would never give (the two would wait for each other for ever). Ctrl-C
/// stops the wait (`KeyboardInterrupt`).
pub(crate) fn lock<'a, T: Send>(
    m: &'a std::sync::Mutex<T>,
    what: &str,
) -> PyResult<std::sync::MutexGuard<'a, T>> {
    use std::sync::TryLockError;
    use std::time::Duration;
    // Asked again after 50 µs, then twice as long each time up to 10 ms: a
    // short wait ends soon, a long one takes the GIL only 100 times a second.
    let mut pause = Duration::from_micros(50);
    loop {
        match m.try_lock() {
            Ok(guard) => return Ok(guard),
            Err(TryLockError::Poisoned(_)) => {
                return Err(runtime_error(format!(
                    "the {what} was poisoned by an earlier failure"
                )))
            }
            Err(TryLockError::WouldBlock) => Python::attach(|py| {
                py.detach(|| std::thread::sleep(pause));
                py.check_signals()
            })?,
        }
        pause = (pause * 2).min(Duration::from_millis(10));
    }
}

/// How long a long call works with the GIL released before it takes the
/// GIL back to let Python handle a signal (Ctrl-C raises
/// `KeyboardInterrupt` in at most about this long).
pub(crate) const SLICE: std::time::Duration = std::time::Duration::from_millis(100);

/// Runs `work` on `pool` (the global pool for `None`) while this thread,
/// the GIL released, waits for it and takes the GIL back every [`SLICE`]
/// to let Python handle signals: on Ctrl-C it sets `stop`, which `work`
/// is to heed by ending early, waits for it to end and raises
/// `KeyboardInterrupt`.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    pool: &Option<rayon::ThreadPool>,
    stop: &std::sync::atomic::AtomicBool,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    py.detach(|| match pool {
        Some(p) => p.in_place_scope(|s| wait_for(s, stop, work)),
        None => rayon::in_place_scope(|s| wait_for(s, stop, work)),
    })
}

/// [`interruptible`] in the scope `s`.
fn wait_for<'scope, T: Send + 'scope>(
    s: &rayon::Scope<'scope>,
    stop: &std::sync::atomic::AtomicBool,
    work: impl FnOnce() -> T + Send + 'scope,
) -> PyResult<T> {
    use std::sync::atomic::Ordering;
    use std::sync::mpsc::{channel, RecvTimeoutError};
    let (tx, rx) = channel();
    s.spawn(move |_| {
        // (The receiver is gone only after a Ctrl-C.)
        let _ = tx.send(work());
    });
    loop {
        match rx.recv_timeout(SLICE) {
            Ok(out) => return Ok(out),
            Err(RecvTimeoutError::Timeout) => {
                if let Err(e) = Python::attach(|py| py.check_signals()) {
                    stop.store(true, Ordering::Relaxed);
                    // The scope waits for `work` to end.
                    return Err(e);
                }
            }
            // `work` panicked: the scope passes the panic on.
            Err(RecvTimeoutError::Disconnected) => return Err(runtime_error("the work panicked")),
        }
    }
}

/// A rayon pool of `threads` threads, or `None` for the global pool (every
/// core).
pub(crate) fn pool(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    match threads {
        None => Ok(None),
        Some(0) => Err(value_error("threads must be at least 1")),
        Some(n) if n > 4096 => Err(value_error(format!("threads: {n} is too many"))),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map(Some)
            .map_err(runtime_error),
    }
}

/// A numpy array's elements in C order: borrowed when it is contiguous,
/// copied otherwise.
pub(crate) fn elements<'a, D: numpy::ndarray::Dimension>(
    a: &'a numpy::PyReadonlyArray<'_, f64, D>,
) -> std::borrow::Cow<'a, [f64]> {
    match a.as_slice() {
        Ok(s) => std::borrow::Cow::Borrowed(s),
        Err(_) => std::borrow::Cow::Owned(a.as_array().iter().copied().collect()),
    }
}

/// Runs `f` on `pool` (or the global pool).
pub(crate) fn on<T: Send>(pool: &Option<rayon::ThreadPool>, f: impl FnOnce() -> T + Send) -> T {
    match pool {
        Some(p) => p.install(f),
        None => f(),
    }
}

#[pymodule]
fn _animats(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("CPU_FEATURES", animats_engine::cpu::required_features())?;
    use animats_creatures::roobot::{params::BOUNDS, HopParams};
    m.add("ROOBOT_INITIAL", HopParams::INITIAL.0.to_vec())?;
    m.add(
        "ROOBOT_BOUNDS",
        BOUNDS.iter().map(|(a, b)| vec![*a, *b]).collect::<Vec<_>>(),
    )?;
    m.add_function(wrap_pyfunction!(scene::load, m)?)?;
    m.add_function(wrap_pyfunction!(scene::parse, m)?)?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<scene::World>()?;
    m.add_class::<scene::Snapshot>()?;
    m.add_function(wrap_pyfunction!(evaluate::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::evaluate_scenes, m)?)?;
    m.add_class::<evaluate::Evaluator>()?;
    m.add_class::<optimise::Optimiser>()?;
    m.add_class::<optimise::Evolution>()?;
    m.add_class::<env::Env>()?;
    m.add_class::<env::VecEnv>()?;
    Ok(())
}
