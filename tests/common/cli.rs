//! Starting the `talus` binary from a test: one builder for every command line, so each
//! test file says only which arguments it passes and what it expects back.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The talus binary that tests start: `TALUS_BIN` when set (`scripts/gpu-check` runs
/// test binaries staged without cargo's target folder, beside a staged talus), else the
/// one cargo built with the tests.
pub fn talus_bin() -> PathBuf {
    std::env::var_os("TALUS_BIN").map_or_else(|| env!("CARGO_BIN_EXE_talus").into(), Into::into)
}

/// `talus ARGS`, not yet started (to add an environment or spawn it).
pub fn command<S: AsRef<OsStr>>(args: impl IntoIterator<Item = S>) -> Command {
    let mut c = Command::new(talus_bin());
    c.args(args);
    c
}

/// Runs `talus ARGS` to its end: (exit code, stdout, stderr); −1 for a run ended by a
/// signal.
pub fn talus<S: AsRef<OsStr>>(args: impl IntoIterator<Item = S>) -> (i32, String, String) {
    let out = command(args).output().expect("the talus binary starts");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// Runs `talus ARGS` and fails the test, with its stderr, unless it succeeds; its stdout.
pub fn talus_ok<S: AsRef<OsStr>>(args: impl IntoIterator<Item = S>) -> String {
    let (code, out, err) = talus(args);
    assert_eq!(code, 0, "talus failed: {err}");
    out
}

/// A fresh folder for one test's files: `talus-GROUP-PID-NAME` in the temporary folder.
pub fn tmp(group: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("talus-{group}-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The built-in default scene with one edit applied to its JSON, written to
/// `DIR/scene.json`.
pub fn default_scene_file(dir: &Path, edit: impl Fn(&mut serde_json::Value)) -> PathBuf {
    let mut v: serde_json::Value = serde_json::from_str(talus::scene::DEFAULT_SCENE).unwrap();
    edit(&mut v);
    let p = dir.join("scene.json");
    std::fs::write(&p, v.to_string()).unwrap();
    p
}
