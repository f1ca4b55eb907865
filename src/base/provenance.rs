//! What produced an output (issue 41 item 3): talus's version and the commit it was
//! built from, the command line, the CPU path's threads and the backend. Every run's
//! `summary.json`, snapshot and `log.csv` carries it, as LAMMPS heads its logs.

use serde::{Deserialize, Serialize};

pub const VERSION: &str = env!("CARGO_PKG_VERSION");
/// The commit of the build (build.rs: `git rev-parse --short=12 HEAD`), "unknown"
/// when built outside a git checkout.
pub const COMMIT: &str = env!("TALUS_COMMIT");

/// `talus --version`: "0.1.0 (commit 0123456789ab)".
pub const VERSION_LINE: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("TALUS_COMMIT"),
    ")"
);

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Provenance {
    pub version: String,
    pub commit: String,
    /// The process's arguments, the program first.
    pub command_line: Vec<String>,
    /// Threads of the CPU path where the output was written.
    pub threads: usize,
    pub backend: String,
}

impl Provenance {
    /// This process, on `backend`, with the threads of the pool it runs in.
    pub fn here(backend: &str) -> Self {
        Provenance {
            version: VERSION.into(),
            commit: COMMIT.into(),
            command_line: std::env::args().collect(),
            threads: rayon::current_num_threads(),
            backend: backend.into(),
        }
    }

    /// One line for a log's head: "talus 0.1.0 (commit …), backend cpu, 2 threads:
    /// talus run scene.json".
    pub fn line(&self) -> String {
        let quoted: Vec<String> = (self.command_line.iter())
            .map(|a| {
                if a.is_empty() || a.contains(|c: char| c.is_whitespace() || "'\"\\$`".contains(c))
                {
                    format!("'{}'", a.replace('\'', r"'\''"))
                } else {
                    a.clone()
                }
            })
            .collect();
        format!(
            "talus {} (commit {}), backend {}, {} thread{}: {}",
            self.version,
            self.commit,
            self.backend,
            self.threads,
            if self.threads == 1 { "" } else { "s" },
            quoted.join(" ")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_line_quotes_what_a_shell_would_split() {
        let p = Provenance {
            version: "0.1.0".into(),
            commit: "abc".into(),
            command_line: [
                "talus",
                "run",
                "--set",
                "contact.mu=0.3",
                "my scene.json",
                "it's",
            ]
            .map(String::from)
            .to_vec(),
            threads: 1,
            backend: "cpu".into(),
        };
        assert_eq!(
            p.line(),
            r"talus 0.1.0 (commit abc), backend cpu, 1 thread: talus run --set contact.mu=0.3 'my scene.json' 'it'\''s'"
        );
    }
}
