//! How a failed command ends: the one place where each library error gets its exit code.
//! 2: bad input (arguments, scenes, checkpoints, snapshots, an output folder another run
//! holds); 1: a run or an output that failed (divergence, I/O, no GPU); 130: a run
//! stopped by SIGINT or SIGTERM.

use std::fmt::Display;
use talus::analyze::AnalyzeError;
use talus::bench::BenchError;
use talus::gpu::GpuError;
use talus::io::checkpoint::CheckpointError;
use talus::render::RenderError;
use talus::reproduce::ReproductionError;
use talus::run::RunError;
use talus::scene::SceneError;
use talus::sweep::SweepError;

pub const INPUT: u8 = 2;
pub const FAILED: u8 = 1;
pub const INTERRUPTED: u8 = 130;

/// A failed command: its exit code and the message printed once by `main`.
#[derive(Debug)]
pub struct Failure {
    pub code: u8,
    pub message: String,
}

impl Failure {
    /// Bad input (exit code 2): for the arguments the CLI checks itself.
    pub fn input(message: impl Display) -> Self {
        Self::new(INPUT, message)
    }

    /// A failure of the command (exit code 1).
    pub fn failed(message: impl Display) -> Self {
        Self::new(FAILED, message)
    }

    /// A command stopped by a signal (exit code 130).
    pub fn interrupted(message: impl Display) -> Self {
        Self::new(INTERRUPTED, message)
    }

    fn new(code: u8, message: impl Display) -> Self {
        Failure {
            code,
            message: printable(&message.to_string()),
        }
    }

    /// The same failure, saying what failed first.
    pub fn within(self, what: impl Display) -> Self {
        Failure {
            message: format!("{}: {}", printable(&what.to_string()), self.message),
            ..self
        }
    }
}

/// The message with control characters other than newlines and tabs escaped, so that a
/// key or file name echoed from hostile input cannot drive the terminal (issue 16: a key
/// holding `\u{1b}[31m` coloured the error red).
fn printable(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    for c in message.chars() {
        if c.is_control() && c != '\n' && c != '\t' {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    out
}

impl From<SceneError> for Failure {
    fn from(e: SceneError) -> Self {
        Self::new(INPUT, e)
    }
}

impl From<CheckpointError> for Failure {
    fn from(e: CheckpointError) -> Self {
        Self::new(INPUT, e)
    }
}

impl From<ReproductionError> for Failure {
    fn from(e: ReproductionError) -> Self {
        Self::new(INPUT, e)
    }
}

/// Reading a snapshot is input; writing the tables is not.
impl From<AnalyzeError> for Failure {
    fn from(e: AnalyzeError) -> Self {
        let code = match e {
            AnalyzeError::Write { .. } => FAILED,
            _ => INPUT,
        };
        Self::new(code, e)
    }
}

impl From<RenderError> for Failure {
    fn from(e: RenderError) -> Self {
        Self::new(FAILED, e)
    }
}

impl From<GpuError> for Failure {
    fn from(e: GpuError) -> Self {
        Self::new(FAILED, e)
    }
}

impl From<BenchError> for Failure {
    fn from(e: BenchError) -> Self {
        Self::new(FAILED, e)
    }
}

/// A sweep's arguments, plan and folder are input; writing its files is not.
impl From<SweepError> for Failure {
    fn from(e: SweepError) -> Self {
        let code = match e {
            SweepError::Io { .. } => FAILED,
            _ => INPUT,
        };
        Self::new(code, e)
    }
}

/// A run fails (1) unless its folder holds another run (2) or it was interrupted (130).
impl From<RunError> for Failure {
    fn from(e: RunError) -> Self {
        let code = match e {
            RunError::FolderInUse { .. } => INPUT,
            RunError::Interrupted { .. } => INTERRUPTED,
            _ => FAILED,
        };
        Self::new(code, e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_in_a_message_are_escaped() {
        let f = Failure::input("unknown field `a\u{7}\u{1b}[31mb`\n\tsee docs");
        assert_eq!(f.message, "unknown field `a\\u{7}\\u{1b}[31mb`\n\tsee docs");
        let f = Failure::failed("x").within("in \u{9b}file");
        assert_eq!(f.message, "in \\u{9b}file: x");
    }
}
