//! Cooperative cancellation of long computations.
//!
//! A caller that may give up on a computation (the editor, whose requests have a time
//! limit) runs it with [`run`] and a shared flag. The solvers, tabulations and meshing
//! loops of this crate call [`checkpoint`] between units of work (a mode, a row of a grid,
//! a sweep): once the flag is raised, the next checkpoint unwinds the computation — on the
//! calling thread and on every worker of the pool [`run`] made for it — and [`run`] returns
//! [`Cancelled`]. Unwinding drops every buffer on the way, so the memory and the cores are
//! free when [`run`] returns.
//!
//! Outside [`run`] (the CLI, library users) a checkpoint reads one thread-local and does
//! nothing. The unwind uses `resume_unwind`, which does not call the panic hook: a
//! cancellation prints nothing.
//!
//! ```
//! use pdeshape_core::cancel::{self, Cancelled};
//! use std::sync::{Arc, atomic::{AtomicBool, Ordering}};
//! let flag = Arc::new(AtomicBool::new(false));
//! let f2 = flag.clone();
//! let r = cancel::run(&flag, 1, move || {
//!     for i in 0.. {
//!         if i == 10 { f2.store(true, Ordering::Relaxed); }
//!         cancel::checkpoint();
//!     }
//! });
//! assert_eq!(r, Err(Cancelled));
//! assert_eq!(cancel::run(&Arc::new(AtomicBool::new(false)), 1, || 7), Ok(7));
//! ```

use std::cell::RefCell;
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// The computation was cancelled.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("cancelled")]
pub struct Cancelled;

thread_local! {
    static FLAG: RefCell<Option<Arc<AtomicBool>>> = const { RefCell::new(None) };
}

/// True when the computation running on this thread has been cancelled.
#[inline]
pub fn is_cancelled() -> bool {
    FLAG.with(|f| f.borrow().as_ref().is_some_and(|f| f.load(Ordering::Relaxed)))
}

/// Unwinds the current computation when it has been cancelled (see the module docs).
#[inline]
pub fn checkpoint() {
    if is_cancelled() {
        resume_unwind(Box::new(Cancelled));
    }
}

/// Sets this thread's flag for the guard's lifetime.
struct Scoped(Option<Arc<AtomicBool>>);

impl Scoped {
    fn set(flag: &Arc<AtomicBool>) -> Self {
        Scoped(FLAG.with(|f| f.replace(Some(flag.clone()))))
    }
}

impl Drop for Scoped {
    fn drop(&mut self) {
        let old = self.0.take();
        FLAG.with(|f| *f.borrow_mut() = old);
    }
}

/// Runs `f` on the calling thread with a rayon pool of `threads` workers (its parallel
/// loops run there) under `flag`: when the flag is raised, `f` stops at its next
/// checkpoint and `run` returns `Err(Cancelled)`. Other panics propagate unchanged.
pub fn run<T: Send>(flag: &Arc<AtomicBool>, threads: usize, f: impl FnOnce() -> T + Send) -> Result<T, Cancelled> {
    let worker_flag = flag.clone();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .thread_name(|i| format!("pdeshape-solve-{i}"))
        .start_handler(move |_| FLAG.with(|f| *f.borrow_mut() = Some(worker_flag.clone())))
        .build();
    let _guard = Scoped::set(flag);
    let out = match pool {
        Ok(pool) => catch_unwind(AssertUnwindSafe(|| pool.install(f))),
        // no threads to be had: run on this thread alone
        Err(_) => catch_unwind(AssertUnwindSafe(f)),
    };
    match out {
        Ok(v) => Ok(v),
        Err(payload) if payload.is::<Cancelled>() => Err(Cancelled),
        Err(payload) => resume_unwind(payload),
    }
}

/// Runs `f` as [`run`] does, with a deadline `limit` from now: a watchdog thread raises the
/// flag then, and `f` stops at its next checkpoint (`Err(Cancelled)`). The CLI's and
/// Python's time limits.
pub fn within<T: Send>(
    limit: std::time::Duration,
    threads: usize,
    f: impl FnOnce() -> T + Send,
) -> Result<T, Cancelled> {
    let flag = Arc::new(AtomicBool::new(false));
    let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
    let watchdog = {
        let flag = flag.clone();
        std::thread::spawn(move || {
            if let Err(std::sync::mpsc::RecvTimeoutError::Timeout) = done_rx.recv_timeout(limit) {
                flag.store(true, Ordering::SeqCst);
            }
        })
    };
    let r = run(&flag, threads, f);
    drop(done_tx);
    let _ = watchdog.join();
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// A loop that would run for ever stops at the deadline; one that ends first returns.
    #[test]
    fn within_stops_at_the_deadline() {
        let t = std::time::Instant::now();
        let r = within(std::time::Duration::from_millis(200), 1, || {
            loop {
                checkpoint();
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
        });
        assert_eq!(r, Err::<(), _>(Cancelled));
        assert!(t.elapsed() < std::time::Duration::from_secs(5), "{:?}", t.elapsed());
        assert_eq!(within(std::time::Duration::from_secs(60), 1, || 7), Ok(7));
    }

    #[test]
    fn parallel_loops_stop_on_every_worker() {
        let flag = Arc::new(AtomicBool::new(false));
        let done = Arc::new(std::sync::atomic::AtomicUsize::new(0));
        let (f2, d2) = (flag.clone(), done.clone());
        let r = run(&flag, 2, move || {
            (0..1_000_000u64).into_par_iter().for_each(|i| {
                if i == 1000 {
                    f2.store(true, Ordering::Relaxed);
                }
                checkpoint();
                d2.fetch_add(1, Ordering::Relaxed);
            })
        });
        assert_eq!(r, Err(Cancelled));
        // every worker stopped soon after the flag: far fewer items than the loop has
        assert!(done.load(Ordering::Relaxed) < 500_000, "{}", done.load(Ordering::Relaxed));
        // the flag is gone from this thread after run
        assert!(!is_cancelled());
    }

    #[test]
    fn other_panics_propagate() {
        let flag = Arc::new(AtomicBool::new(false));
        let r = catch_unwind(AssertUnwindSafe(|| run(&flag, 1, || panic!("boom"))));
        assert!(r.is_err());
        assert!(!is_cancelled());
    }
}
