//! The module's rayon pool, made again in a forked child.
//!
//! A process forked from one whose rayon pool has started (`multiprocessing`'s "fork"
//! start method, the default on Linux before Python 3.14, and so `ProcessPoolExecutor`)
//! inherits the pool's state but none of its threads: work handed to that pool waits for
//! ever. Every parallel computation of the module therefore runs in this pool, which
//! belongs to the process that made it: a process with another id (a forked child) makes
//! its own and leaves the inherited one alone (dropping it would signal threads that are
//! not there).

use pyo3::prelude::*;
use std::sync::{Arc, Mutex};

/// The pool and the id of the process that made it.
static POOL: Mutex<Option<(u32, Arc<rayon::ThreadPool>)>> = Mutex::new(None);

/// This process's pool (None when no thread can be started: the work runs on the caller).
fn current() -> Option<Arc<rayon::ThreadPool>> {
    let pid = std::process::id();
    let mut slot = POOL.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((owner, pool)) = slot.as_ref()
        && *owner == pid
    {
        return Some(pool.clone());
    }
    if let Some(inherited) = slot.take() {
        std::mem::forget(inherited);
    }
    // as many threads as rayon's global pool would have: RAYON_NUM_THREADS, else the cores
    let pool = rayon::ThreadPoolBuilder::new().thread_name(|i| format!("pdeshape-py-{i}")).build().ok().map(Arc::new);
    *slot = pool.clone().map(|p| (pid, p));
    pool
}

/// Runs `f` without the GIL in this process's pool (its parallel loops run there).
pub fn detached<T: Send>(py: Python<'_>, f: impl FnOnce() -> T + Send) -> T {
    let pool = current();
    py.detach(move || match pool {
        Some(p) => p.install(f),
        None => f(),
    })
}
