//! Progress reporting, the only place the library writes to the terminal (stderr).
//!
//! On a terminal: a live bar with step, simulated time, particles, steps/s and ETA.
//! Elsewhere (CI, pipes): a plain line about every 10 % of the run.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::Instant;

pub struct Progress {
    bar: Option<ProgressBar>,
    quiet: bool,
    start: Instant,
    start_step: u64,
    total: u64,
    next_line: u64,
    work: Work,
}

/// The work a run is expected to take up to each step: particle-steps of the moving
/// particles, sampled (`Work::at` interpolates). A pour's steps get dearer as its heap
/// grows, so an ETA from steps alone is too early (issue 20: 82 s left at 10 % of a
/// 726 s run); one from this work is not, as long as a particle-step costs about the same
/// throughout.
#[derive(Clone, Debug, PartialEq)]
pub struct Work {
    /// (step, expected particle-steps from the run's start to it), increasing.
    pub samples: Vec<(u64, f64)>,
}

impl Work {
    /// Work proportional to the steps (a constant particle count).
    pub fn steps(start: u64, total: u64) -> Self {
        Work {
            samples: vec![(start, 0.0), (total, (total - start) as f64)],
        }
    }

    /// The work from the run's start to `step`.
    pub fn at(&self, step: u64) -> f64 {
        let s = &self.samples;
        let k = s.partition_point(|p| p.0 <= step);
        if k == 0 {
            return 0.0;
        }
        if k == s.len() {
            return s[k - 1].1;
        }
        let (a, b) = (s[k - 1], s[k]);
        a.1 + (b.1 - a.1) * (step - a.0) as f64 / (b.0 - a.0).max(1) as f64
    }

    pub fn total(&self) -> f64 {
        self.samples.last().map_or(0.0, |p| p.1)
    }

    /// Seconds left at `step`, `elapsed` seconds after the start, from the rate of the
    /// work done so far.
    pub fn eta(&self, step: u64, elapsed: f64) -> f64 {
        let done = self.at(step);
        (self.total() - done) * elapsed / done.max(1e-300)
    }
}

impl Progress {
    /// `start_step..total` is the range of steps this run will take; `work` what they
    /// are expected to cost (the bar and the ETA follow it).
    pub fn new(start_step: u64, total: u64, quiet: bool, work: Work) -> Self {
        let bar = if !quiet && std::io::stderr().is_terminal() {
            let b = ProgressBar::with_draw_target(
                Some(work.total().ceil() as u64),
                ProgressDrawTarget::stderr_with_hz(4),
            );
            b.set_style(
                ProgressStyle::with_template("{bar:30.cyan/blue} {percent:>3}% {msg} ETA {eta}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            Some(b)
        } else {
            None
        };
        Self {
            bar,
            quiet,
            start: Instant::now(),
            start_step,
            total,
            next_line: start_step,
            work,
        }
    }

    /// Steps per second of wall time since this run started.
    pub fn rate(&self, step: u64) -> f64 {
        (step - self.start_step) as f64 / self.start.elapsed().as_secs_f64().max(1e-9)
    }

    pub fn update(&mut self, step: u64, time: f64, particles: usize) {
        if self.quiet {
            return;
        }
        let rate = self.rate(step);
        let msg = format!("step {step} t={time:.4} particles={particles} {rate:.0} steps/s");
        if let Some(b) = &self.bar {
            b.set_position(self.work.at(step) as u64);
            b.set_message(msg);
        } else if step >= self.next_line {
            let eta = self.work.eta(step, self.start.elapsed().as_secs_f64());
            eprintln!(
                "  {:>3.0}% {msg} ETA {eta:.0}s",
                100.0 * step as f64 / self.total as f64
            );
            self.next_line = step + (self.total / 10).max(1);
        }
    }

    pub fn note(&self, text: &str) {
        if self.quiet {
            return;
        }
        match &self.bar {
            Some(b) => b.println(text),
            None => eprintln!("{text}"),
        }
    }

    /// A warning: printed even when quiet (`-q` silences progress, not problems).
    pub fn warn(&self, text: &str) {
        match &self.bar {
            Some(b) => b.println(text),
            None => eprintln!("{text}"),
        }
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
