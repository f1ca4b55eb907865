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
}

impl Progress {
    /// `start_step..total` is the range of steps this run will take.
    pub fn new(start_step: u64, total: u64, quiet: bool) -> Self {
        let bar = if !quiet && std::io::stderr().is_terminal() {
            let b =
                ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr_with_hz(4));
            b.set_style(
                ProgressStyle::with_template("{bar:30.cyan/blue} {percent:>3}% {msg} ETA {eta}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            b.set_position(start_step);
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
            b.set_position(step);
            b.set_message(msg);
        } else if step >= self.next_line {
            let eta = (self.total - step) as f64 / rate.max(1e-9);
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

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
