//! The output folder holds one run (issue 16). A run refuses a folder that holds another
//! run's outputs, unless told to clear them first (`--force`) or unless it resumes that
//! run from one of the folder's own checkpoints: then only the outputs past the
//! checkpoint go, and the log up to it carries on.

use super::RunError;
use crate::base::files::{is_temporary, remove_stale_temporaries};
use std::path::Path;

/// What a run writes into its folder. Not `scene.json`: it is written over, and may be
/// the user's own scene file.
const OUTPUTS: [&str; 9] = [
    "snapshots",
    "checkpoints",
    "log.csv",
    "summary.json",
    "final.json",
    "final.bin",
    "analysis",
    "pictures",
    "copies",
];

/// What `claim` found and removed.
#[derive(Debug)]
pub enum Claimed {
    /// Nothing of another run.
    Empty,
    /// Another run's outputs, removed (`--force`).
    Cleared(Vec<&'static str>),
    /// The run this one resumes: this many snapshot and checkpoint files past its start
    /// went (they are written again).
    Resumed(usize),
}

/// Makes `out` ready for a run that starts at `step` (from the checkpoint
/// `resumed_from`, if any), as the module doc says; `force` clears another run's
/// outputs instead of refusing them. Sweeps the temporaries a killed run left.
pub fn claim(
    out: &Path,
    step: u64,
    resumed_from: Option<&Path>,
    force: bool,
) -> Result<Claimed, RunError> {
    refuse_another_run(out, resumed_from, force)?;
    std::fs::create_dir_all(out).map_err(super::io(out))?;
    let claimed = if resumed_from.is_some_and(|c| is_own_checkpoint(out, c)) {
        // A summary marks a finished run; the one left here must not vouch for this run
        // until it has finished too.
        remove(&out.join("summary.json"))?;
        Claimed::Resumed(remove_later_outputs(out, step)?)
    } else {
        let found = outputs_in(out);
        if found.is_empty() {
            Claimed::Empty
        } else {
            for name in &found {
                remove(&out.join(name))?;
            }
            Claimed::Cleared(found)
        }
    };
    remove_temporaries(out);
    Ok(claimed)
}

/// The refusal of `claim`, without touching anything: a folder holding another run's
/// outputs, unless `force` or the run resumes from one of the folder's own checkpoints.
pub fn refuse_another_run(
    out: &Path,
    resumed_from: Option<&Path>,
    force: bool,
) -> Result<(), RunError> {
    if force || resumed_from.is_some_and(|c| is_own_checkpoint(out, c)) {
        return Ok(());
    }
    let found = outputs_in(out);
    if found.is_empty() {
        return Ok(());
    }
    Err(RunError::FolderInUse {
        path: out.display().to_string(),
        found: found.join(", "),
    })
}

/// Removes the temporaries in a run folder (an interrupted or failed run's, or a killed
/// one's); returns how many.
pub fn remove_temporaries(out: &Path) -> usize {
    ["", "snapshots", "checkpoints"]
        .iter()
        .map(|sub| remove_stale_temporaries(&out.join(sub)))
        .sum()
}

/// Whether checkpoint `ckpt` is one of `out`'s own (in its `checkpoints/`).
fn is_own_checkpoint(out: &Path, ckpt: &Path) -> bool {
    let dir = ckpt
        .canonicalize()
        .ok()
        .and_then(|c| c.parent().map(Path::to_path_buf));
    dir.is_some() && dir == out.join("checkpoints").canonicalize().ok()
}

/// The outputs of a run present in `out` (a folder of them only if it holds more than
/// temporaries).
fn outputs_in(out: &Path) -> Vec<&'static str> {
    OUTPUTS
        .into_iter()
        .filter(|name| {
            let p = out.join(name);
            match std::fs::read_dir(&p) {
                Ok(mut entries) => entries
                    .any(|e| e.is_ok_and(|e| !is_temporary(&e.file_name().to_string_lossy()))),
                Err(_) => p.symlink_metadata().is_ok(),
            }
        })
        .collect()
}

/// Removes a file or a folder with everything in it (a link, not what it points to).
fn remove(path: &Path) -> Result<(), RunError> {
    let removed = match path.symlink_metadata() {
        Err(_) => return Ok(()),
        Ok(m) if m.is_dir() => std::fs::remove_dir_all(path),
        Ok(_) => std::fs::remove_file(path),
    };
    removed.map_err(|source| RunError::Remove {
        path: path.display().to_string(),
        source,
    })
}

/// Removes the snapshots (with their VTK files) and checkpoints in a run folder whose
/// step is past `step`; returns how many files went.
fn remove_later_outputs(out: &Path, step: u64) -> Result<usize, RunError> {
    let mut removed = 0;
    for (sub, prefix) in [("snapshots", "snap_"), ("checkpoints", "ckpt_")] {
        let Ok(entries) = std::fs::read_dir(out.join(sub)) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            // snap_0000001000.json, .bin, _grains.vtp, _contacts.vtp, _walls.vtp;
            // ckpt_0000001000.bin
            let later = (name.strip_prefix(prefix))
                .and_then(|rest| rest.get(..10))
                .and_then(|digits| digits.parse::<u64>().ok())
                .is_some_and(|s| s > step);
            if later {
                remove(&e.path())?;
                removed += 1;
            }
        }
    }
    Ok(removed)
}
