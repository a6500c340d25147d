//! Work the model hands off (a lesson step's preparation, the frames stepped while the window
//! paints), behind two small interfaces so that the same model runs with threads in the desktop
//! app and without any in a test or a web page:
//!
//! - [`Background`]: where a one-off job runs — on a thread of its own, or at once, in place;
//!   its result is a [`Pending`] looked at without blocking.
//! - [`Stepper`]: where the frames of the running sessions are stepped — [`ThreadStepper`] on a
//!   thread while the window paints (the paint is the longer part of a frame with a software
//!   renderer; docs/APP.md), [`InlineStepper`] at once.

use super::session::Session;

/// Where one-off jobs run.
#[cfg_attr(not(test), allow(dead_code))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Background {
    /// On a thread of their own (the desktop app).
    #[default]
    Threads,
    /// At once, in place (a test of the model alone; a page without threads).
    Inline,
}

impl Background {
    /// Threads where the platform has them (the desktop), in place otherwise (a page).
    pub fn of_platform() -> Background {
        if super::platform::HAS_THREADS { Background::Threads } else { Background::Inline }
    }

    /// Runs `job` as this policy says; its result is pending until it is ready.
    pub fn run<T: Send + 'static>(self, job: impl FnOnce() -> T + Send + 'static) -> Pending<T> {
        match self {
            Background::Threads => Pending::Thread(std::thread::spawn(job)),
            Background::Inline => Pending::Ready(Some(job())),
        }
    }
}

/// A job's result, once ready.
pub enum Pending<T> {
    Thread(std::thread::JoinHandle<T>),
    Ready(Option<T>),
}

impl<T> Pending<T> {
    /// Whether the result can be taken without waiting.
    pub fn is_ready(&self) -> bool {
        match self {
            Pending::Thread(h) => h.is_finished(),
            Pending::Ready(r) => r.is_some(),
        }
    }

    /// The result, waiting for it if need be; None if the job panicked (or was taken).
    pub fn take(self) -> Option<T> {
        match self {
            Pending::Thread(h) => h.join().ok(),
            Pending::Ready(r) => r,
        }
    }
}

/// Where the sessions' frames are stepped: `start` takes the sessions and the frames to step,
/// `finish` gives them back (waiting if need be) with the frames stepped.
#[cfg_attr(not(test), allow(dead_code))]
pub trait Stepper: Send {
    fn start(&mut self, sessions: Vec<Session>, frames: usize, one_at_a_time: bool);
    /// The sessions handed to `start`, stepped, and how many frames were asked; None when
    /// nothing is under way.
    fn finish(&mut self) -> Option<(Vec<Session>, usize)>;
    /// Whether sessions are out being stepped.
    fn busy(&self) -> bool;
}

/// Steps on a thread of its own while the window paints.
#[derive(Default)]
pub struct ThreadStepper {
    under_way: Option<(std::thread::JoinHandle<Vec<Session>>, usize)>,
}

impl Stepper for ThreadStepper {
    fn start(&mut self, sessions: Vec<Session>, frames: usize, one_at_a_time: bool) {
        let handle = std::thread::spawn(move || {
            let mut sessions = sessions;
            step_frames(&mut sessions, frames, one_at_a_time);
            sessions
        });
        self.under_way = Some((handle, frames));
    }

    fn finish(&mut self) -> Option<(Vec<Session>, usize)> {
        let (handle, frames) = self.under_way.take()?;
        match handle.join() {
            Ok(sessions) => Some((sessions, frames)),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    }

    fn busy(&self) -> bool {
        self.under_way.is_some()
    }
}

/// Steps at once, in place: no thread.
#[cfg_attr(not(test), allow(dead_code))]
#[derive(Default)]
pub struct InlineStepper {
    done: Option<(Vec<Session>, usize)>,
}

impl Stepper for InlineStepper {
    fn start(&mut self, mut sessions: Vec<Session>, frames: usize, one_at_a_time: bool) {
        step_frames(&mut sessions, frames, one_at_a_time);
        self.done = Some((sessions, frames));
    }

    fn finish(&mut self) -> Option<(Vec<Session>, usize)> {
        self.done.take()
    }

    fn busy(&self) -> bool {
        self.done.is_some()
    }
}

/// The platform's stepper: on a thread while the window paints where there are threads (the
/// desktop), at once in a page.
pub fn platform_stepper() -> Box<dyn Stepper> {
    if super::platform::HAS_THREADS { Box::new(ThreadStepper::default()) } else { Box::new(InlineStepper::default()) }
}

/// Whether a *Settle* is under way in any of `sessions`.
pub fn any_settling(sessions: &[Session]) -> bool {
    sessions.iter().any(|s| s.settler.is_some())
}

/// `frames` frames of every session; a settle that ends on the way stops there, at rest (issue
/// #35: the frames left ran on undamped).
pub fn step_frames(sessions: &mut [Session], frames: usize, one_at_a_time: bool) {
    let was_settling = any_settling(sessions);
    for _ in 0..frames {
        if was_settling && !any_settling(sessions) {
            break;
        }
        step_sessions(sessions, one_at_a_time);
    }
}

/// One frame of every session: in parallel in compare mode, unless `one_at_a_time` (a lesson
/// timing frames: each configuration then has the cores to itself, as in `hox lesson`). While a
/// *Settle* is under way, a configuration that has settled waits at rest for the other (issue
/// #35: it ran on undamped and read other numbers than `hox lesson`).
pub fn step_sessions(sessions: &mut [Session], one_at_a_time: bool) {
    use rayon::prelude::*;
    let settling = any_settling(sessions);
    let step = |s: &mut Session| {
        if !settling || s.settler.is_some() {
            s.step(1);
        }
    };
    if one_at_a_time || sessions.len() == 1 {
        sessions.iter_mut().for_each(step);
    } else {
        sessions.par_iter_mut().for_each(step);
    }
}
