//! A sweep as a Slurm job array: `DIR/sweep.sbatch` runs one task per run, each task
//! `talus sweep run-one DIR --index $SLURM_ARRAY_TASK_ID`. Slurm is the scheduler nearly
//! every university and lab cluster runs; talus hands it the array rather than
//! distributing work itself. A task skips a run already measured and resumes a stopped
//! one from its checkpoints, so the same array can be submitted again after a failure.

use super::Plan;
use std::fmt::Write as _;
use std::path::Path;

#[derive(Clone, Debug, Default)]
pub struct SlurmOptions {
    pub partition: Option<String>,
    /// Wall-time limit per task, as sbatch takes it (`HH:MM:SS`, `D-HH:MM`, minutes).
    pub time: Option<String>,
    /// CPU cores per task (the CPU path's threads); default 1.
    pub cpus: Option<usize>,
    /// At most this many tasks at once (`--array=0-N%J`).
    pub throttle: Option<usize>,
}

/// A value safe inside a `#SBATCH` line or a single-quoted shell word: no quotes,
/// whitespace or control characters.
fn plain(what: &str, value: &str) -> Result<(), String> {
    let bad = value.is_empty()
        || value
            .chars()
            .any(|c| c.is_whitespace() || c.is_control() || "'\"\\`$;&|<>".contains(c));
    if bad {
        Err(format!(
            "{what} {value:?}: must be one word without quotes or shell characters"
        ))
    } else {
        Ok(())
    }
}

/// The batch script. `dir` and `talus` must be absolute: the tasks run wherever Slurm
/// starts them.
pub fn sbatch(plan: &Plan, dir: &Path, talus: &Path, o: &SlurmOptions) -> Result<String, String> {
    let (dir, talus) = (dir.display().to_string(), talus.display().to_string());
    for (what, path) in [("the sweep folder", &dir), ("the talus binary", &talus)] {
        plain(what, path)?;
        if !path.starts_with('/') {
            return Err(format!("{what} {path}: must be an absolute path"));
        }
    }
    if let Some(p) = &o.partition {
        plain("--partition", p)?;
    }
    if let Some(t) = &o.time {
        plain("--time", t)?;
    }
    let cpus = o.cpus.unwrap_or(1).max(1);
    let last = plan.runs.len().saturating_sub(1);
    let throttle = o
        .throttle
        .map_or(String::new(), |j| format!("%{}", j.max(1)));
    let name: String = (plan.scene.chars())
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let mut s = String::new();
    let _ = writeln!(s, "#!/bin/bash");
    let _ = writeln!(
        s,
        "# talus sweep of `{}`: {} runs, one array task each (written by `talus sweep --slurm`).",
        plan.scene,
        plan.runs.len()
    );
    let _ = writeln!(
        s,
        "# Submit with `sbatch {dir}/sweep.sbatch` (again after a failure: finished runs are"
    );
    let _ = writeln!(s, "# skipped); afterwards `talus sweep collect {dir}`.");
    let _ = writeln!(s, "#SBATCH --job-name=talus-{name}");
    let _ = writeln!(s, "#SBATCH --array=0-{last}{throttle}");
    let _ = writeln!(s, "#SBATCH --ntasks=1");
    let _ = writeln!(s, "#SBATCH --cpus-per-task={cpus}");
    let _ = writeln!(s, "#SBATCH --output={dir}/slurm/%A_%a.out");
    if let Some(p) = &o.partition {
        let _ = writeln!(s, "#SBATCH --partition={p}");
    }
    if let Some(t) = &o.time {
        let _ = writeln!(s, "#SBATCH --time={t}");
    }
    let _ = writeln!(s, "set -eu");
    let _ = writeln!(
        s,
        "exec '{talus}' --threads \"${{SLURM_CPUS_PER_TASK:-{cpus}}}\" sweep run-one '{dir}' --index \"$SLURM_ARRAY_TASK_ID\""
    );
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene;
    use crate::sweep::{Measuring, parse_axis, plan};

    #[test]
    fn the_batch_script_is_an_array_of_run_one_tasks() {
        let base = scene::parse(scene::DEFAULT_SCENE, &[]).unwrap();
        let grid = [parse_axis("contact.mu=0.3,0.5").unwrap()];
        let p = plan(&base, &[1, 2, 3], &grid, "cpu", Measuring::default()).unwrap();
        let o = SlurmOptions {
            partition: Some("short".into()),
            time: Some("01:00:00".into()),
            cpus: Some(4),
            throttle: Some(2),
        };
        let s = sbatch(&p, Path::new("/data/sw"), Path::new("/opt/talus"), &o).unwrap();
        for line in [
            "#SBATCH --array=0-5%2",
            "#SBATCH --cpus-per-task=4",
            "#SBATCH --partition=short",
            "#SBATCH --time=01:00:00",
            "#SBATCH --output=/data/sw/slurm/%A_%a.out",
            "exec '/opt/talus' --threads \"${SLURM_CPUS_PER_TASK:-4}\" sweep run-one '/data/sw' --index \"$SLURM_ARRAY_TASK_ID\"",
        ] {
            assert!(s.lines().any(|l| l == line), "{line} missing from\n{s}");
        }
        let e = sbatch(&p, Path::new("sw"), Path::new("/opt/talus"), &o).unwrap_err();
        assert!(e.contains("absolute"), "{e}");
        let bad = SlurmOptions {
            partition: Some("a b".into()),
            ..o
        };
        let e = sbatch(&p, Path::new("/data/sw"), Path::new("/opt/talus"), &bad).unwrap_err();
        assert!(e.starts_with("--partition"), "{e}");
    }
}
