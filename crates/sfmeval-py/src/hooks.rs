//! What a call does around the core's work: the thread pool of `threads=`, the progress
//! callback, and stopping on Ctrl-C.
//!
//! The core has no cancel flag; its [`Progress`] hooks are where a front end hears from it.
//! [`run`] does the work on a worker thread while the calling thread, without the GIL, wakes
//! every 50 ms to run Python's signal handlers (`PyErr_CheckSignals`, which only the main
//! thread can: Ctrl-C) with the GIL taken briefly. [`Hooks`] calls the `progress` callback
//! (each stage's start and end, and every 1 % of its work). When either raises (Ctrl-C's
//! `KeyboardInterrupt`, or the callback's own exception), the exception is kept and the next
//! hook the core calls (at most 1 % of a stage later) unwinds out of the core with
//! [`std::panic::resume_unwind`] (no panic message; rayon carries it to the worker's top);
//! [`run`] catches exactly that and raises the exception. The core's state is dropped on the
//! way out; nothing of the call survives.

use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use sfmeval::progress::{Progress, Stage};

use crate::{Failure, InputError};

/// The unwinding payload of a stop asked for from Python.
struct Stopped;

/// Progress hooks of one call.
pub(crate) struct Hooks {
    callback: Option<Py<PyAny>>,
    stopped: AtomicBool,
    stage: Mutex<Option<Stage>>,
    total: AtomicU64,
    done: AtomicU64,
    next_call: AtomicU64,
    error: Mutex<Option<PyErr>>,
}

impl Hooks {
    fn new(callback: Option<Py<PyAny>>) -> Hooks {
        Hooks {
            callback,
            stopped: AtomicBool::new(false),
            stage: Mutex::new(None),
            total: AtomicU64::new(0),
            done: AtomicU64::new(0),
            next_call: AtomicU64::new(u64::MAX),
            error: Mutex::new(None),
        }
    }

    /// Keeps `e` (the first one) and asks the core to stop at its next hook.
    fn stop_with(&self, e: PyErr) {
        if let Ok(mut slot) = self.error.lock() {
            slot.get_or_insert(e);
        }
        self.stopped.store(true, Ordering::SeqCst);
    }

    /// Calls the callback with `fraction` (taking the GIL); unwinds with [`Stopped`] when a
    /// stop was asked for or the callback raises.
    fn poll(&self, fraction: f64) {
        if let Some(cb) = &self.callback
            && !self.stopped.load(Ordering::SeqCst)
        {
            let label = self
                .stage
                .lock()
                .ok()
                .and_then(|s| s.map(Stage::label))
                .unwrap_or("");
            if let Err(e) = Python::attach(|py| cb.call1(py, (label, fraction)).map(drop)) {
                self.stop_with(e);
            }
        }
        if self.stopped.load(Ordering::SeqCst) {
            resume_unwind(Box::new(Stopped));
        }
    }

    fn step(total: u64) -> u64 {
        (total / 100).max(1)
    }
}

impl Progress for Hooks {
    fn start(&self, stage: Stage, total: u64) {
        if let Ok(mut s) = self.stage.lock() {
            *s = Some(stage);
        }
        self.total.store(total, Ordering::Relaxed);
        self.done.store(0, Ordering::Relaxed);
        self.next_call.store(Hooks::step(total), Ordering::Relaxed);
        self.poll(0.0);
    }

    fn advance(&self, n: u64) {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        let next = self.next_call.load(Ordering::Relaxed);
        if done < next {
            return;
        }
        let total = self.total.load(Ordering::Relaxed);
        // one caller per 1 % step: the thread that moves the mark (the end is `finish`'s)
        if done < total
            && self
                .next_call
                .compare_exchange(
                    next,
                    done + Hooks::step(total),
                    Ordering::Relaxed,
                    Ordering::Relaxed,
                )
                .is_ok()
        {
            self.poll(done as f64 / total as f64);
        }
    }

    fn finish(&self) {
        self.next_call.store(u64::MAX, Ordering::Relaxed);
        self.poll(1.0);
    }
}

/// Runs `work` without the GIL on a worker thread, in a pool of `threads` workers when given
/// (else rayon's global pool: every core), with [`Hooks`] calling `progress`; the calling
/// thread runs Python's signal handlers meanwhile. Ctrl-C or a raising callback stop it.
pub(crate) fn run<T: Send>(
    py: Python<'_>,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
    work: impl FnOnce(&dyn Progress) -> Result<T, Failure> + Send,
) -> PyResult<T> {
    let pool = match threads {
        Some(0) => return Err(InputError::new_err("threads: must be at least 1")),
        Some(n) => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| InputError::new_err(format!("threads: {e}")))?,
        ),
        None => None,
    };
    let hooks = Hooks::new(progress);
    let outcome = py.detach(|| {
        let caller = std::thread::current();
        let (hooks, pool, caller) = (&hooks, &pool, &caller);
        std::thread::scope(|scope| {
            // the main thread's stack size, as the CLI runs the core on
            let worker = std::thread::Builder::new()
                .name("sfmeval".into())
                .stack_size(8 << 20)
                .spawn_scoped(scope, move || {
                    let outcome = catch_unwind(AssertUnwindSafe(|| match pool {
                        Some(p) => p.install(|| work(hooks)),
                        None => work(hooks),
                    }));
                    caller.unpark();
                    outcome
                })
                .map_err(|e| {
                    PyErr::from(Failure::Input(anyhow::anyhow!(
                        "cannot start a thread: {e}"
                    )))
                })?;
            while !worker.is_finished() {
                std::thread::park_timeout(Duration::from_millis(50));
                if let Err(e) = Python::attach(|py| py.check_signals()) {
                    hooks.stop_with(e);
                }
            }
            Ok::<_, PyErr>(worker.join())
        })
    })?;
    // a Ctrl-C that came after the core's last hook is raised all the same (its handler ran)
    let raised = hooks.error.lock().ok().and_then(|mut e| e.take());
    match (outcome, raised) {
        (Ok(Ok(_)), Some(e)) => Err(e),
        (Ok(Ok(result)), None) => result.map_err(PyErr::from),
        (Ok(Err(payload)) | Err(payload), raised) if payload.is::<Stopped>() => {
            Err(raised.unwrap_or_else(|| PyKeyboardInterrupt::new_err(())))
        }
        (Ok(Err(payload)) | Err(payload), _) => resume_unwind(payload),
    }
}
