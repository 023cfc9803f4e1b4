//! Tug 2's local problem on a helper thread: the paper's distributed
//! architecture has each tug solve its own problem (Du et al. 2022, section
//! 3.4), so within an ADMM iteration the two tug steps run at the same time.
//!
//! The helper is a thread made once (with the [`crate::Admm`]) that owns
//! nothing but a handle to tug 2's problem; each iteration the loop posts tug
//! 2's step data, takes tug 1's step itself, and collects tug 2's report and
//! predicted poses. Between iterations the helper waits briefly, yielding its
//! core (the ship's step takes tens of microseconds), then parks until the next
//! sample; the caller waits for tug 2's step the same way. The helper's
//! arithmetic is tug 2's own, so the results are bit-identical to the sequential
//! loop. A panic on the helper is raised again on the caller's thread; if the
//! thread cannot be made, tug 2 steps on the caller's thread.

use std::ops::{Deref, DerefMut};
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::costs::Waterway;
use crate::engine::ScpReport;
use crate::obstacle::Obstacle;
use crate::tug::{TowlinePull, TugState};
use crate::tug_mpc::{TugMpc, TugStepData};
use crate::HORIZON;
use towing_model::geometry::Lane;

/// A tug's predicted poses `g_i` of one iteration.
pub(crate) type Poses = [[f64; 3]; HORIZON];

/// The pose part of a tug's predicted states.
pub(crate) fn poses(tug: &TugMpc) -> Poses {
    tug.predicted().map(|x| [x[0], x[1], x[2]])
}

/// How long the helper waits (yielding) for the next step before it parks: longer than
/// the ship's step between two tug steps (about 70 us on the paper scenario),
/// short against the time between samples.
const SPIN: Duration = Duration::from_micros(300);

const IDLE: u8 = 0;
const POSTED: u8 = 1;
const DONE: u8 = 2;
const EXIT: u8 = 3;

/// The data of one tug step, owned (the obstacles copied into a buffer kept
/// between steps).
#[derive(Debug, Default)]
struct Job {
    state: TugState,
    pulls: [TowlinePull; HORIZON],
    reference: [[f64; 3]; HORIZON],
    lambda: [[f64; 3]; HORIZON],
    rho: f64,
    obstacles: Vec<Obstacle>,
    distance_cost_off: u64,
    own_ship: Option<Obstacle>,
    other_tug: Option<Obstacle>,
    /// The lane (cloned into the kept buffer) and the margins of the sample's waterway.
    waterway: Option<(Lane, [f64; 3])>,
}

impl Job {
    fn set(&mut self, d: &TugStepData<'_>) {
        self.state = d.state;
        self.pulls = d.pulls;
        self.reference = d.reference;
        self.lambda = d.lambda;
        self.rho = d.rho;
        self.obstacles.clear();
        self.obstacles.extend_from_slice(d.obstacles);
        self.distance_cost_off = d.distance_cost_off;
        self.own_ship = d.own_ship;
        self.other_tug = d.other_tug;
        // The lane is the run's, the same every step: copied only when it differs, so the
        // per-iteration hand-over allocates nothing.
        match (&mut self.waterway, d.waterway) {
            (Some((lane, margin)), Some(w)) => {
                if lane != w.lane {
                    lane.clone_from(w.lane);
                }
                *margin = w.margin;
            }
            (kept, w) => *kept = w.map(|w| (w.lane.clone(), w.margin)),
        }
    }

    fn data(&self) -> TugStepData<'_> {
        TugStepData {
            state: self.state,
            pulls: self.pulls,
            reference: self.reference,
            lambda: self.lambda,
            rho: self.rho,
            obstacles: &self.obstacles,
            distance_cost_off: self.distance_cost_off,
            own_ship: self.own_ship,
            other_tug: self.other_tug,
            waterway: self.waterway.as_ref().map(|(lane, margin)| Waterway {
                lane,
                margin: *margin,
            }),
        }
    }
}

type Outcome = std::thread::Result<(ScpReport, Poses)>;

/// What the caller and the helper share.
struct Shared {
    tug: Mutex<TugMpc>,
    job: Mutex<Job>,
    result: Mutex<Option<Outcome>>,
    state: AtomicU8,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A panic on the helper is raised again on the caller's thread; the data is
    // the last consistent state of the step, kept.
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Shared {
    /// The helper's loop: wait for a posted step, take it, report it.
    fn work(&self) {
        loop {
            let mut since = None;
            loop {
                match self.state.load(Ordering::Acquire) {
                    POSTED => break,
                    EXIT => return,
                    _ => {
                        let start = *since.get_or_insert_with(Instant::now);
                        if start.elapsed() < SPIN {
                            // Yield, not spin: on a busy machine (a master, other
                            // FMUs, a campaign's other runs) a spinning thread
                            // takes the core the posting thread needs.
                            std::thread::yield_now();
                        } else {
                            std::thread::park();
                        }
                    }
                }
            }
            let outcome = catch_unwind(AssertUnwindSafe(|| {
                let job = lock(&self.job);
                let mut tug = lock(&self.tug);
                let report = tug.step(&job.data());
                (report, poses(&tug))
            }));
            *lock(&self.result) = Some(outcome);
            self.state.store(DONE, Ordering::Release);
        }
    }
}

/// Tug 2's problem: here, or owned by a helper thread (module docs).
pub(crate) enum Tug2 {
    /// On the caller's thread, with the result of the step started.
    Here(Box<TugMpc>, Option<(ScpReport, Poses)>),
    /// On a helper thread.
    There(Helper),
}

/// The helper thread and what it shares with the caller.
pub(crate) struct Helper {
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for Tug2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Tug2::Here(tug, _) => f.debug_tuple("Here").field(tug).finish(),
            Tug2::There(h) => f
                .debug_struct("There")
                .field("tug", &*lock(&h.shared.tug))
                .finish_non_exhaustive(),
        }
    }
}

impl Tug2 {
    /// Tug 2's problem, on a helper thread when `parallel` and one can be made.
    pub(crate) fn new(tug: TugMpc, parallel: bool) -> Tug2 {
        if !parallel {
            return Tug2::Here(Box::new(tug), None);
        }
        let shared = Arc::new(Shared {
            tug: Mutex::new(tug),
            job: Mutex::new(Job::default()),
            result: Mutex::new(None),
            state: AtomicU8::new(IDLE),
        });
        let worker = Arc::clone(&shared);
        match std::thread::Builder::new()
            .name("towing-mpc tug 2".into())
            .spawn(move || worker.work())
        {
            Ok(thread) => Tug2::There(Helper {
                shared,
                thread: Some(thread),
            }),
            // No thread: the problem comes back to this one (the worker's handle
            // went with the failed spawn).
            Err(_) => match Arc::try_unwrap(shared) {
                Ok(s) => Tug2::Here(
                    Box::new(s.tug.into_inner().unwrap_or_else(PoisonError::into_inner)),
                    None,
                ),
                Err(shared) => Tug2::There(Helper {
                    shared,
                    thread: None,
                }),
            },
        }
    }

    /// The problem, to read.
    pub(crate) fn get(&self) -> TugRef<'_> {
        match self {
            Tug2::Here(tug, _) => TugRef::Here(tug),
            Tug2::There(h) => TugRef::Locked(lock(&h.shared.tug)),
        }
    }

    /// The problem, to change (not while a step is under way).
    pub(crate) fn get_mut(&mut self) -> TugMut<'_> {
        match self {
            Tug2::Here(tug, _) => TugMut::Here(tug),
            Tug2::There(h) => TugMut::Locked(lock(&h.shared.tug)),
        }
    }

    /// Starts a step (here it is taken at once).
    pub(crate) fn start(&mut self, data: &TugStepData<'_>) {
        match self {
            Tug2::Here(tug, result) => {
                let report = tug.step(data);
                *result = Some((report, poses(tug)));
            }
            Tug2::There(h) if h.thread.is_some() => {
                lock(&h.shared.job).set(data);
                h.shared.state.store(POSTED, Ordering::Release);
                if let Some(t) = &h.thread {
                    t.thread().unpark();
                }
            }
            Tug2::There(h) => {
                // No thread to take it: step here.
                let mut tug = lock(&h.shared.tug);
                let report = tug.step(data);
                *lock(&h.shared.result) = Some(Ok((report, poses(&tug))));
                h.shared.state.store(DONE, Ordering::Release);
            }
        }
    }

    /// The started step's report and tug 2's poses. Raises a panic of the
    /// helper's step here.
    pub(crate) fn finish(&mut self) -> (ScpReport, Poses) {
        match self {
            Tug2::Here(tug, result) => result
                .take()
                .unwrap_or_else(|| (ScpReport::never_run(), poses(tug))),
            Tug2::There(h) => {
                while h.shared.state.load(Ordering::Acquire) != DONE {
                    if h.thread.as_ref().is_none_or(JoinHandle::is_finished) {
                        break;
                    }
                    // As in the helper's wait: leave the core to tug 2's step.
                    std::thread::yield_now();
                }
                h.shared.state.store(IDLE, Ordering::Release);
                match lock(&h.shared.result).take() {
                    Some(Ok(done)) => done,
                    Some(Err(panic)) => resume_unwind(panic),
                    None => (ScpReport::never_run(), [[f64::NAN; 3]; HORIZON]),
                }
            }
        }
    }
}

impl Drop for Helper {
    fn drop(&mut self) {
        self.shared.state.store(EXIT, Ordering::Release);
        if let Some(t) = self.thread.take() {
            t.thread().unpark();
            // A helper that panicked has reported it already.
            let _ = t.join();
        }
    }
}

/// Tug 2's problem, borrowed to read.
pub enum TugRef<'a> {
    /// On this thread.
    Here(&'a TugMpc),
    /// Behind the helper's lock.
    Locked(MutexGuard<'a, TugMpc>),
}

impl Deref for TugRef<'_> {
    type Target = TugMpc;
    fn deref(&self) -> &TugMpc {
        match self {
            TugRef::Here(t) => t,
            TugRef::Locked(g) => g,
        }
    }
}

impl std::fmt::Debug for TugRef<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        (**self).fmt(f)
    }
}

/// Tug 2's problem, borrowed to change.
pub(crate) enum TugMut<'a> {
    Here(&'a mut TugMpc),
    Locked(MutexGuard<'a, TugMpc>),
}

impl Deref for TugMut<'_> {
    type Target = TugMpc;
    fn deref(&self) -> &TugMpc {
        match self {
            TugMut::Here(t) => t,
            TugMut::Locked(g) => g,
        }
    }
}

impl DerefMut for TugMut<'_> {
    fn deref_mut(&mut self) -> &mut TugMpc {
        match self {
            TugMut::Here(t) => t,
            TugMut::Locked(g) => g,
        }
    }
}
