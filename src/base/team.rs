//! A team of threads that stay awake between the stages of a step (issue 13): the
//! engine under `parallel`.
//!
//! A step of the CPU path is a few stages of a few hundred microseconds each with a little
//! serial work between them. Rayon's workers fall asleep in those gaps and must be woken
//! by the kernel for the next stage, and its work stealing hands a particle to a
//! different core from one stage to the next, so its data moves between caches. Both cost
//! a 2-thread run about a quarter of its speed (measured: 1.6× instead of 2× on
//! packing-10000). A team does what OpenMP's static schedule with an active wait policy
//! does, and what LAMMPS gets from one MPI rank per core: thread t always takes the t-th
//! contiguous share of every stage, and between stages it spins, then yields its core
//! between checks, and after a millisecond without work parks until the next job. A
//! team is never larger than the cores: with more threads, rayon runs the shares.
//!
//! One team per thread count lives for the rest of the process. A job that finds its
//! team busy (another caller, or a job started from inside a job) runs on rayon instead:
//! the shares are the same, only the threads that run them differ, so the results are too.

use std::cell::UnsafeCell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, OnceLock, TryLockError};
use std::time::{Duration, Instant};

/// How long a member spins for the next job before it parks.
const SPIN: Duration = Duration::from_millis(1);

/// A job: the share number t in 0..threads.
type Job<'a> = &'a (dyn Fn(usize) + Sync);

/// Runs job(t) for every t in 0..threads, share 0 on the calling thread, and returns when
/// all are done. A panic in any share is raised again here.
pub fn run(threads: usize, job: Job) {
    if threads <= 1 {
        job(0);
        return;
    }
    if threads > cores() {
        // More threads than cores: a member spinning for work would hold a core that a
        // thread with work needs (measured: 3 threads on 2 cores ran a rod pile 500×
        // slower). Rayon's workers sleep instead.
        rayon_run(threads, job);
        return;
    }
    let team = team_of(threads);
    match team.dispatch.try_lock() {
        Ok(_only_caller) => team.run(job),
        Err(TryLockError::WouldBlock) => rayon_run(threads, job),
        Err(TryLockError::Poisoned(e)) => {
            // A share panicked last time and its panic went to that caller; the team
            // itself is in order (every member finished its share).
            let _only_caller = e.into_inner();
            team.run(job)
        }
    }
}

/// The cores this process may run on.
fn cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// Spins before a waiting thread starts yielding its core to others (other processes,
/// or threads of a busy machine) between checks.
const PURE_SPINS: u32 = 1 << 10;

fn rayon_run(threads: usize, job: Job) {
    use rayon::prelude::*;
    (0..threads).into_par_iter().for_each(job);
}

/// The team of `threads` threads (the caller and threads − 1 members), made on first use.
fn team_of(threads: usize) -> Arc<Team> {
    static TEAMS: OnceLock<Mutex<Vec<Arc<Team>>>> = OnceLock::new();
    let mut teams = TEAMS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    if let Some(t) = teams.iter().find(|t| t.threads == threads) {
        return t.clone();
    }
    let team = spawn_team(threads);
    teams.push(team.clone());
    team
}

/// A new team: its members started, waiting for the first job.
fn spawn_team(threads: usize) -> Arc<Team> {
    let team = Arc::new(Team::new(threads));
    for t in 1..threads {
        let member = team.clone();
        std::thread::Builder::new()
            .name(format!("talus-team-{t}"))
            .spawn(move || member.serve(t))
            .expect("the operating system starts a thread");
    }
    team
}

struct Team {
    threads: usize,
    /// Held by the one caller whose job the team runs.
    dispatch: Mutex<()>,
    /// The current job: written by the caller before it bumps `generation`, read by
    /// members after they see the bump, and not touched again until every member has
    /// counted itself in `done`.
    job: UnsafeCell<Option<Job<'static>>>,
    /// Bumped once per job.
    generation: AtomicUsize,
    /// Members that have finished the current job.
    done: AtomicUsize,
    panicked: AtomicBool,
    /// Members parked on `wake` (they spun for `SPIN` without a job).
    parked: AtomicUsize,
    sleep: Mutex<()>,
    wake: Condvar,
}

// SAFETY: `job` is only written by the caller holding `dispatch` while no member reads it
// (before the generation bump, after every member is done), and only read by members
// between the bump and their `done` count (the protocol in `run` and `serve`).
unsafe impl Sync for Team {}

impl Team {
    fn new(threads: usize) -> Self {
        Team {
            threads,
            dispatch: Mutex::new(()),
            job: UnsafeCell::new(None),
            generation: AtomicUsize::new(0),
            done: AtomicUsize::new(0),
            panicked: AtomicBool::new(false),
            parked: AtomicUsize::new(0),
            sleep: Mutex::new(()),
            wake: Condvar::new(),
        }
    }

    /// The caller's side (it holds `dispatch`).
    fn run(&self, job: Job) {
        // SAFETY: the job is borrowed for the duration of this call only: members stop
        // reading it before they count themselves done, and this call waits for that.
        let job_static: Job<'static> = unsafe { std::mem::transmute(job) };
        unsafe { *self.job.get() = Some(job_static) };
        self.done.store(0, Ordering::Relaxed);
        self.generation.fetch_add(1, Ordering::SeqCst);
        if self.parked.load(Ordering::SeqCst) > 0 {
            let _guard = self.sleep.lock().unwrap_or_else(|e| e.into_inner());
            self.wake.notify_all();
        }
        let mine = catch_unwind(AssertUnwindSafe(|| job(0)));
        let members = self.threads - 1;
        let mut spins = 0u32;
        while self.done.load(Ordering::Acquire) < members {
            spins = spins.saturating_add(1);
            if spins < PURE_SPINS {
                std::hint::spin_loop();
            } else {
                // A member was descheduled: let it run.
                std::thread::yield_now();
            }
        }
        unsafe { *self.job.get() = None };
        if let Err(p) = mine {
            std::panic::resume_unwind(p);
        }
        if self.panicked.swap(false, Ordering::Relaxed) {
            panic!("a thread of the CPU path panicked (its message is above)");
        }
    }

    /// A member's loop: wait for a job, run share t, count itself done.
    fn serve(&self, t: usize) {
        // Members start before the first job (generation 0).
        let mut seen = 0;
        loop {
            seen = self.next_job(seen);
            // SAFETY: the caller set the job before the bump that `next_job` saw and
            // keeps it until this member counts itself done.
            let job = unsafe { (*self.job.get()).expect("a job is set while one runs") };
            if catch_unwind(AssertUnwindSafe(|| job(t))).is_err() {
                self.panicked.store(true, Ordering::Relaxed);
            }
            self.done.fetch_add(1, Ordering::Release);
        }
    }

    /// Spins, then parks, until the generation moves past `seen`; returns the new one.
    fn next_job(&self, seen: usize) -> usize {
        let start = Instant::now();
        let mut spins = 0u32;
        loop {
            let g = self.generation.load(Ordering::Acquire);
            if g != seen {
                return g;
            }
            spins = spins.saturating_add(1);
            if spins < PURE_SPINS {
                std::hint::spin_loop();
                continue;
            }
            if start.elapsed() < SPIN {
                // Still awake for the next job, but a thread with work (ours, or another
                // program's) may take the core meanwhile.
                std::thread::yield_now();
                continue;
            }
            let mut guard = self.sleep.lock().unwrap_or_else(|e| e.into_inner());
            self.parked.fetch_add(1, Ordering::SeqCst);
            // SeqCst on both sides: either the caller sees this member parked and
            // notifies under the lock, or this member sees the new generation here.
            while self.generation.load(Ordering::SeqCst) == seen {
                guard = self.wake.wait(guard).unwrap_or_else(|e| e.into_inner());
            }
            self.parked.fetch_sub(1, Ordering::SeqCst);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_share_runs_once_per_job_and_jobs_follow_each_other() {
        for threads in [1, 2, 3, 5] {
            let counts: Vec<AtomicUsize> = (0..threads).map(|_| AtomicUsize::new(0)).collect();
            for _ in 0..1000 {
                run(threads, &|t| {
                    counts[t].fetch_add(1, Ordering::Relaxed);
                });
            }
            assert!(counts.iter().all(|c| c.load(Ordering::Relaxed) == 1000));
            // A team itself, whatever the cores (its members yield to each other).
            let team = spawn_team(threads);
            for _ in 0..1000 {
                team.run(&|t| {
                    counts[t].fetch_add(1, Ordering::Relaxed);
                });
            }
            assert!(counts.iter().all(|c| c.load(Ordering::Relaxed) == 2000));
        }
    }

    #[test]
    fn a_job_started_inside_a_job_runs_elsewhere() {
        let inner = AtomicUsize::new(0);
        run(2, &|_| {
            run(2, &|_| {
                inner.fetch_add(1, Ordering::Relaxed);
            })
        });
        assert_eq!(inner.load(Ordering::Relaxed), 4);
    }

    #[test]
    fn a_panic_in_a_member_reaches_the_caller_and_the_team_goes_on() {
        let team = spawn_team(3);
        let r = catch_unwind(AssertUnwindSafe(|| {
            team.run(&|t| {
                if t == 2 {
                    panic!("share 2 fails");
                }
            })
        }));
        assert!(r.is_err());
        let ran = AtomicUsize::new(0);
        team.run(&|_| {
            ran.fetch_add(1, Ordering::Relaxed);
        });
        assert_eq!(ran.load(Ordering::Relaxed), 3);
    }

    #[test]
    fn members_park_when_idle_and_wake_for_the_next_job() {
        // A team of its own (the shared ones serve the other tests meanwhile).
        let team = spawn_team(3);
        team.run(&|_| {});
        let start = Instant::now();
        while team.parked.load(Ordering::SeqCst) < 2 {
            assert!(start.elapsed() < SPIN * 5000, "idle members park");
            std::thread::sleep(SPIN);
        }
        let ran = AtomicUsize::new(0);
        team.run(&|_| {
            ran.fetch_add(1, Ordering::Relaxed);
        });
        assert_eq!(ran.load(Ordering::Relaxed), 3);
    }
}
