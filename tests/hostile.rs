//! Hostile inputs (issue 16 item 6): scenes mutated from valid ones through what
//! `talus check` runs, byte flips of checkpoints, and a run killed with SIGKILL and
//! resumed. Each asserts no panic and no abort: a refusal that names the key path (or
//! says where the text breaks), or a whole result.
//!
//! CI runs 10⁴ mutated scenes and 10³ checkpoint flips (well under a minute in release).
//! A longer soak: `TALUS_SOAK=N cargo test --release --test hostile` runs N scenes and N/10
//! flips of each kind, from case 0 on, so a soak covers the CI cases and more. A failure
//! prints the case number and writes the mutated scene to the temporary folder.

mod common;

use common::mutate::{below, key_names, mutate, mutate_text, override_text, pick};
use serde_json::{Value, json};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use talus::base::rng::Rng;
use talus::scene::{self, SceneError};
use talus::sim::Simulation;

/// How many cases to run: `ci`, or `TALUS_SOAK` (scaled by `per_scene`) when it asks
/// for more.
fn cases(ci: usize, per_scene: f64) -> usize {
    let soak = std::env::var("TALUS_SOAK")
        .ok()
        .and_then(|s| s.parse::<f64>().ok());
    soak.map_or(ci, |n| ci.max((n * per_scene) as usize))
}

fn tmp(name: &str) -> PathBuf {
    common::tmp("hostile", name)
}

// ---------------------------------------------------------------------------------------
// Mutated scenes
// ---------------------------------------------------------------------------------------

/// The most particles a seed scene may create. A mutated count (4294967295, a lattice's
/// bottom row times ten) is then refused by the limit before anything is allocated,
/// instead of building a million particles in a test that must stay fast; the limit
/// itself is never mutated, since raising it is the user's consent to a large scene.
const MAX_PARTICLES: f64 = 4e4;

/// Every scene file of the repository (the built-in default is scenes/default_heap.json),
/// with `limits.max_particles` lowered to [`MAX_PARTICLES`], point-source counts cut to
/// it (heap_50k: a source creates nothing before the run, so its count only matters to
/// the limit), and lattice piles cut to 40 in the bottom row (820 particles): the full
/// piles of 5 000 and 10 000 polygons took four fifths of the fuzz's time and test
/// nothing the small ones do not.
fn seeds() -> Vec<(String, Value)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<PathBuf> = ["scenes", "benches/scenes"]
        .iter()
        .flat_map(|d| std::fs::read_dir(root.join(d)).unwrap().flatten())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    let mut out = Vec::new();
    for path in files {
        let mut v: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        v["limits"]["max_particles"] = json!(MAX_PARTICLES);
        for block in v["particles"].as_array_mut().unwrap() {
            if block["count"].as_f64().is_some_and(|c| c > MAX_PARTICLES) {
                block["count"] = json!(MAX_PARTICLES as u64);
            }
            if block["bottom_row"].as_u64().is_some_and(|l| l > 40) {
                block["bottom_row"] = json!(40);
            }
        }
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let scene = scene::parse(&v.to_string(), &[])
            .unwrap_or_else(|e| panic!("seed {name} is not valid: {e}"));
        Simulation::new(scene).unwrap_or_else(|e| panic!("seed {name} does not build: {e}"));
        out.push((name, v));
    }
    assert!(out.len() >= 10, "the seed scenes are found: {}", out.len());
    out
}

/// What `talus check` does (src/cli/mod.rs `build_simulation`): parse with overrides, the
/// warnings, the initial state. An accepted scene must also come back from the JSON a
/// run writes (scene.json, and the copy inside every checkpoint that a resume parses),
/// and take its first steps.
fn check(text: &str, overrides: &[String]) -> Result<usize, SceneError> {
    let scene = scene::parse(text, overrides)?;
    let _ = scene::warnings(&scene);
    let sim = Simulation::new(scene)?;
    let written = serde_json::to_string_pretty(&sim.scene).expect("a scene serialises");
    let back = scene::parse(&written, &[])
        .unwrap_or_else(|e| panic!("an accepted scene, written back, is refused: {e}"));
    assert_eq!(
        serde_json::to_string(&back).unwrap(),
        serde_json::to_string(&sim.scene).unwrap(),
        "an accepted scene changes on its way through JSON"
    );
    // The first steps run too: a divergence is an answer, a panic is not.
    let mut sim = sim;
    let _ = sim.advance(3);
    Ok(sim.particles.len())
}

/// The top-level keys of a scene: a refusal's key path starts with one of them (or
/// `scene` for the whole document).
const SCENE_KEYS: &[&str] = &[
    "scene",
    "name",
    "units",
    "seed",
    "dt",
    "stop",
    "integrator",
    "gravity",
    "domain",
    "materials",
    "contact",
    "walls",
    "particles",
    "output",
    "limits",
    "skin",
];

/// Whether a refusal says where: a key path of the scene (from a known key, or an
/// unknown one as the text spells it, or the override it came from) and a reason, or the
/// line and column where the JSON breaks.
fn explains(e: &SceneError, text: &str, overrides: &[String]) -> bool {
    match e {
        SceneError::Invalid { path, reason } => {
            let head = path.split(['.', '[']).next().unwrap_or("");
            let named = SCENE_KEYS.contains(&head)
                || [head, path.as_str()]
                    .iter()
                    .any(|k| !k.is_empty() && text.contains(&Value::from(*k).to_string()))
                || overrides
                    .iter()
                    .any(|o| !path.is_empty() && o.starts_with(path.as_str()));
            named && !reason.trim().is_empty()
        }
        SceneError::Syntax(m) => m.contains(" line ") && m.contains(" column "),
        SceneError::Io { .. } => false,
    }
}

/// A panic's message.
fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
    (p.downcast_ref::<String>().cloned())
        .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_default()
}

/// A mutated scene, its overrides and how it was made.
struct Case {
    number: usize,
    text: String,
    overrides: Vec<String>,
    did: Vec<String>,
}

impl Case {
    /// Case `number` of the fuzz, drawn from its own seed so that it replays alone.
    fn draw(number: usize, seeds: &[(String, Value)], keys: &[String]) -> Self {
        let mut rng = Rng::new(number as u64);
        let (_, seed) = pick(&mut rng, seeds);
        let mut v = seed.clone();
        let mut did = Vec::new();
        for _ in 0..1 + below(&mut rng, 3) {
            did.push(mutate(&mut v, seeds, keys, &mut rng));
        }
        let mut text = v.to_string();
        if below(&mut rng, 5) == 0 {
            did.push(mutate_text(&mut text, &mut rng));
        }
        let overrides = if below(&mut rng, 6) == 0 {
            let n = 1 + below(&mut rng, 2);
            (0..n).map(|_| override_text(seed, &mut rng)).collect()
        } else {
            Vec::new()
        };
        Self {
            number,
            text,
            overrides,
            did,
        }
    }

    /// What the case is: its mutations, overrides and (the start of) its text.
    fn describe(&self) -> String {
        let text = &self.text[..self.text.floor_char_boundary(600)];
        format!(
            "mutations: {:?}\n  overrides: {:?}\n  scene: {text}",
            self.did, self.overrides
        )
    }

    /// The case as a failure report; the whole scene goes to the temporary folder.
    fn report(&self, what: &str) -> String {
        let file = tmp("fuzz").join(format!("case_{}.json", self.number));
        std::fs::write(&file, &self.text).unwrap();
        let (n, path) = (self.number, file.display());
        format!("case {n} ({path}): {what}\n  {}", self.describe())
    }
}

#[test]
fn mutated_scenes_are_refused_by_key_or_built_whole() {
    let seeds = seeds();
    let keys = key_names(&seeds);
    let n = cases(10_000, 1.0);
    let mut accepted = 0;
    // Failures by kind (panic, unclear refusal, slow), refusals by top-level key, and
    // every key path a refusal named (list indices left out).
    let mut failures = std::collections::BTreeMap::<&str, Vec<String>>::new();
    let mut refusals = std::collections::BTreeMap::<&str, usize>::new();
    let mut named = std::collections::BTreeSet::<String>::new();
    let mut slowest = (Duration::ZERO, 0);
    let current = tmp("fuzz").join("current_case.txt");
    let start = Instant::now();
    for number in 0..n {
        let case = Case::draw(number, &seeds, &keys);
        // An abort cannot be caught: the case in progress stays on disk to replay.
        std::fs::write(&current, format!("case {number}\n{}", case.describe())).unwrap();
        let t = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| check(&case.text, &case.overrides)));
        let took = t.elapsed();
        slowest = slowest.max((took, number));
        match outcome {
            Ok(Ok(_)) => accepted += 1,
            Ok(Err(e)) => {
                if !explains(&e, &case.text, &case.overrides) {
                    let report = case.report(&format!("unclear refusal: {e}"));
                    failures.entry("unclear refusal").or_default().push(report);
                }
                let head = match &e {
                    SceneError::Invalid { path, .. } => {
                        let bare = path
                            .split('[')
                            .map(|p| p.split_once(']').map_or(p, |x| x.1));
                        named.insert(bare.collect());
                        let head = path.split(['.', '[']).next().unwrap_or("");
                        SCENE_KEYS
                            .iter()
                            .find(|k| **k == head)
                            .map_or("(other)", |k| k)
                    }
                    SceneError::Syntax(_) => "(syntax)",
                    SceneError::Io { .. } => "(io)",
                };
                *refusals.entry(head).or_default() += 1;
            }
            Err(panic) => {
                let report = case.report(&format!("panic: {}", panic_message(panic)));
                failures.entry("panic").or_default().push(report);
            }
        }
        // A case takes milliseconds; seconds mean a scene that should have been refused
        // (or a hang on its way).
        if took > Duration::from_secs(5) {
            let report = case.report(&format!("took {took:?}"));
            failures.entry("slow").or_default().push(report);
        }
    }
    eprintln!(
        "{n} mutated scenes in {:.1} s: {accepted} accepted; refusals by key {refusals:?}, \
         naming {} key paths; slowest: case {} ({:?})",
        start.elapsed().as_secs_f64(),
        named.len(),
        slowest.1,
        slowest.0
    );
    for (kind, reports) in &failures {
        eprintln!(
            "{} {kind}:\n{}",
            reports.len(),
            reports[..reports.len().min(10)].join("\n")
        );
    }
    let counts: Vec<(&str, usize)> = failures.iter().map(|(k, r)| (*k, r.len())).collect();
    assert!(
        failures.is_empty(),
        "of {n} mutated scenes, failures {counts:?} (above)"
    );
    // The fuzz must reach both sides and deep into the scene, not stop at the parser.
    assert!(accepted >= n / 50, "too few accepted: {accepted} of {n}");
    assert!(
        named.len() >= 100,
        "refusals name too few key paths: {named:?}"
    );
    std::fs::remove_dir_all(tmp("fuzz")).ok();
}

/// What the fuzz found, pinned (issue 16): a layered block's polygon of 4294967295
/// corners aborted `talus check` on a 68 GB allocation (7·10⁶ hung), since the particle
/// estimate built the polygons before the corners were checked; a scene that is a list
/// was refused as "[0]: invalid type: map, expected a string"; `--set =1` was refused
/// as ": empty key in override path".
#[test]
fn what_the_fuzz_found_stays_fixed() {
    let layered = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/r7_layered_medium.json"),
    )
    .unwrap();
    for corners in ["4294967295", "7000000"] {
        let t = Instant::now();
        let e = scene::parse(
            &layered,
            &[format!("particles[0].polygon.corners={corners}")],
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("particles[0].polygon.corners: must be in [3, 16]"),
            "{e}"
        );
        assert!(t.elapsed() < Duration::from_secs(1), "refused at once");
    }
    let e = scene::parse(r#"[{"dt": 1}, 2]"#, &[])
        .unwrap_err()
        .to_string();
    assert_eq!(e, "scene: expected an object with named keys, got an array");
    let e = scene::parse(scene::DEFAULT_SCENE, &["=1".into()])
        .unwrap_err()
        .to_string();
    assert_eq!(e, "=1: an override needs a key path before `=`");
    // Ends that are finite but a width that is not: refused rather than run.
    for ends in ["[-1e308,1e308]", "[-1.7e308,1.7e308]"] {
        let e = scene::parse(scene::DEFAULT_SCENE, &[format!("domain.x={ends}")])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("domain.x: must be [min, max]"), "{e}");
    }
}

// ---------------------------------------------------------------------------------------
// Checkpoint byte flips
// ---------------------------------------------------------------------------------------

/// Checkpoints of the three kinds of state, after a short run each: disks with
/// tangential springs and a pouring source (the default heap), a polygon pile, rods (the
/// spheropolygon section at the end). Made once for the tests that share them.
fn checkpoints() -> Vec<(&'static str, Vec<u8>)> {
    static MADE: std::sync::OnceLock<Vec<(&'static str, Vec<u8>)>> = std::sync::OnceLock::new();
    MADE.get_or_init(make_checkpoints).clone()
}

fn make_checkpoints() -> Vec<(&'static str, Vec<u8>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let heap = scene::parse(
        scene::DEFAULT_SCENE,
        &[
            "particles[1].count=120".into(),
            "particles[1].rate=40".into(),
        ],
    )
    .unwrap();
    let file = |name: &str| {
        let text = std::fs::read_to_string(root.join("scenes").join(name)).unwrap();
        scene::parse(&text, &[]).unwrap()
    };
    [
        ("disks", heap, 2500),
        ("polygons", file("r8_polygon_pile_reduced.json"), 200),
        ("rods", file("rods_box.json"), 8000),
    ]
    .into_iter()
    .map(|(name, scene, steps)| {
        let mut sim = Simulation::new(scene).unwrap();
        sim.advance(steps).unwrap();
        let springs = sim.spring_table();
        assert!(!springs.is_empty(), "{name}: the state has springs");
        if name == "rods" {
            assert!(
                !springs.sub.is_empty(),
                "rods: the state has sub-contact springs"
            );
        }
        (name, talus::io::checkpoint::encode(&sim, None))
    })
    .collect()
}

/// Reads checkpoint bytes through a file, as `talus run --resume` does, and runs the
/// state it holds for `steps` steps; a panic is returned as its message.
fn read_checkpoint(file: &Path, bytes: &[u8], steps: u64) -> Result<Result<(), String>, String> {
    std::fs::write(file, bytes).unwrap();
    let resume = || {
        let mut sim = talus::io::checkpoint::read(file, &[])
            .map_err(|e| e.to_string())?
            .sim;
        // A divergence is an answer too; only a panic is not.
        let _ = sim.advance(steps);
        Ok(())
    };
    catch_unwind(resume).map_err(panic_message)
}

/// The refusal of a damaged file says so; one whose magic bytes (the first 8) are
/// gone is not recognised as a checkpoint (or looks like an older format).
fn says_damaged(message: &str, magic_intact: bool) -> bool {
    if magic_intact {
        return message.contains("is damaged");
    }
    ["is damaged", "not a talus checkpoint", "older talus"]
        .iter()
        .any(|m| message.contains(m))
}

#[test]
fn every_byte_flip_of_a_checkpoint_is_refused() {
    // Issue 16: of 30 random one-byte flips none was noticed and 9 resumed into another
    // result; the checksum (TALUSCK3) now refuses them all.
    let file = tmp("flips").join("flipped.bin");
    let states = checkpoints();
    for (name, bytes) in &states {
        assert_eq!(
            read_checkpoint(&file, bytes, 0),
            Ok(Ok(())),
            "{name} loads intact"
        );
    }
    let n = cases(1000, 0.1);
    let mut rng = Rng::new(16);
    let mut failures = Vec::new();
    for case in 0..n {
        let (name, bytes) = &states[case % states.len()];
        let mut b = bytes.clone();
        let at = below(&mut rng, b.len());
        b[at] ^= 1 + below(&mut rng, 255) as u8;
        match read_checkpoint(&file, &b, 0) {
            Ok(Err(e)) if says_damaged(&e, at >= 8) => {}
            other => failures.push(format!("{name}, byte {at} of {}: {other:?}", b.len())),
        }
    }
    // Cut anywhere (a disk full, a copy interrupted), or with bytes added; and not a
    // checkpoint at all.
    for (name, bytes) in &states {
        let len = bytes.len();
        let mut cuts: Vec<Vec<u8>> = [
            0,
            1,
            7,
            8,
            9,
            15,
            16,
            17,
            len / 3,
            len / 2,
            len - 9,
            len - 8,
            len - 1,
        ]
        .iter()
        .map(|&k| bytes[..k].to_vec())
        .collect();
        cuts.push([bytes.as_slice(), &[0]].concat());
        cuts.push([bytes.as_slice(), bytes.as_slice()].concat());
        cuts.push(b"not a checkpoint at all".to_vec());
        for b in cuts {
            match read_checkpoint(&file, &b, 0) {
                Ok(Err(e)) if says_damaged(&e, b.starts_with(&bytes[..8])) => {}
                other => failures.push(format!("{name} cut to {} bytes: {other:?}", b.len())),
            }
        }
    }
    eprintln!("{n} byte flips of {} checkpoints", states.len());
    assert!(
        failures.is_empty(),
        "{} damaged checkpoints not refused:\n{}",
        failures.len(),
        failures.join("\n")
    );
    std::fs::remove_dir_all(file.parent().unwrap()).ok();
}

/// A checkpoint from before the checksum (TALUSCK2) is read as it is, so damaged bytes
/// reach the decoder: it must refuse them or build a state that runs, never panic or
/// abort (the flips above stop at the checksum and never test this).
#[test]
fn the_decoder_survives_damage_the_checksum_would_catch() {
    let file = tmp("unchecked").join("flipped.bin");
    let states: Vec<(&str, Vec<u8>)> = checkpoints()
        .into_iter()
        .map(|(name, b)| {
            let mut b = b[..b.len() - 8].to_vec();
            b[..8].copy_from_slice(b"TALUSCK2");
            (name, b)
        })
        .collect();
    for (name, bytes) in &states {
        assert_eq!(
            read_checkpoint(&file, bytes, 0),
            Ok(Ok(())),
            "{name} loads without a checksum"
        );
    }
    let n = cases(1000, 0.1);
    let mut rng = Rng::new(17);
    let (mut refused, mut failures) = (0, Vec::new());
    for case in 0..n {
        let (name, bytes) = &states[case % states.len()];
        let mut b = bytes.clone();
        // One byte, or a run of bytes (a length field made huge, a block of zeros).
        let at = below(&mut rng, b.len());
        let end = (at + if below(&mut rng, 4) == 0 { 8 } else { 1 }).min(b.len());
        let fill = below(&mut rng, 3);
        for x in &mut b[at..end] {
            *x = match fill {
                0 => *x ^ (1 + below(&mut rng, 255) as u8),
                1 => 0xff,
                _ => 0,
            };
        }
        match read_checkpoint(&file, &b, 3) {
            Ok(Ok(())) => {}
            Ok(Err(e)) if says_damaged(&e, false) || e.contains("invalid scene") => refused += 1,
            other => failures.push(format!(
                "{name}, bytes {at}..{end} of {}: {other:?}",
                b.len()
            )),
        }
    }
    eprintln!("{n} damaged unchecked checkpoints: {refused} refused, the rest loaded");
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
    std::fs::remove_dir_all(file.parent().unwrap()).ok();
}

/// Pinned (issue 16, found by the decoder fuzz above): a TALUSCK2 checkpoint whose
/// spring-table size was damaged to 2⁶⁰ panicked with "capacity overflow" (the table was
/// reserved before it was read); a checkpoint cut to 8–15 bytes, its magic whole, was
/// called "not a talus checkpoint (bad magic)".
#[test]
fn damaged_lengths_in_a_checkpoint_are_refused() {
    let file = tmp("lengths").join("damaged.bin");
    let (_, bytes) = checkpoints().swap_remove(0);
    let body = &bytes[..bytes.len() - 8];
    // The disks' state ends with the table's size, its keys and values (8 bytes each per
    // slot) and the device flag: find the size by where it must stand.
    let size_at = (0..32)
        .map(|k| 1usize << k)
        .find_map(|cap| {
            let at = body.len().checked_sub(1 + 16 * cap + 8)?;
            (body[at..at + 8] == (cap as u64).to_le_bytes()).then_some(at)
        })
        .expect("the spring table's size");
    let mut b = body.to_vec();
    b[..8].copy_from_slice(b"TALUSCK2");
    b[size_at..size_at + 8].copy_from_slice(&(1u64 << 60).to_le_bytes());
    match read_checkpoint(&file, &b, 0) {
        Ok(Err(e)) => assert!(e.contains("is damaged"), "{e}"),
        other => panic!("a size of 2^60 is refused: {other:?}"),
    }
    for len in 8..16 {
        match read_checkpoint(&file, &bytes[..len], 0) {
            Ok(Err(e)) => assert!(e.contains("is damaged"), "{len} bytes: {e}"),
            other => panic!("{len} bytes: {other:?}"),
        }
    }
    std::fs::remove_dir_all(file.parent().unwrap()).ok();
}

// ---------------------------------------------------------------------------------------
// A run killed and resumed
// ---------------------------------------------------------------------------------------

/// `talus run` on the CPU path with one thread (results are bitwise the same for any
/// count; one leaves the other tests their cores).
fn talus_run(args: &[&str]) -> std::process::Command {
    let mut c = common::command(["--threads", "1", "run", "-q", "--backend", "cpu"]);
    c.args(args);
    c
}

/// The step in a name like `ckpt_0000001000.bin` or `snap_0000001000.json`.
fn step_of(path: &Path) -> Option<u64> {
    let name = path.file_name()?.to_string_lossy().into_owned();
    let digits = name.split('_').nth(1)?.get(..10)?;
    digits.parse().ok()
}

/// The checkpoints of a run folder, oldest first.
fn checkpoints_in(dir: &Path) -> Vec<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir.join("checkpoints"))
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    found.retain(|p| p.extension().is_some_and(|x| x == "bin") && step_of(p).is_some());
    found.sort();
    found
}

/// Every output of a run folder, whenever the run was killed, is whole: snapshots and
/// checkpoints load, the log's rows are complete and in step order, the scene parses. A
/// temporary (`.NAME.tmp`) is the only thing a kill may leave half-written, and a
/// snapshot's `.bin` may lack its `.json` only for the snapshot being written (the
/// `.bin` goes first). Returns how many files were checked, and how many temporaries
/// there were.
fn assert_whole(dir: &Path) -> (usize, usize) {
    let (mut checked, mut temporaries) = (0, 0);
    let mut files: Vec<PathBuf> = Vec::new();
    for sub in ["", "snapshots", "checkpoints"] {
        if let Ok(d) = std::fs::read_dir(dir.join(sub)) {
            files.extend(d.flatten().map(|e| e.path()).filter(|p| p.is_file()));
        }
    }
    let newest_snapshot = (files.iter())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .filter_map(|p| step_of(p))
        .max();
    for p in &files {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let ext = p
            .extension()
            .map_or(String::new(), |x| x.to_string_lossy().into_owned());
        let shown = p.display();
        if name.starts_with('.') && name.ends_with(".tmp") {
            temporaries += 1;
            continue;
        }
        match (name.as_str(), ext.as_str()) {
            ("scene.json", _) => {
                let text = std::fs::read_to_string(p).unwrap();
                scene::parse(&text, &[]).unwrap_or_else(|e| panic!("{shown}: {e}"));
            }
            ("summary.json", _) => {
                let text = std::fs::read_to_string(p).unwrap();
                serde_json::from_str::<Value>(&text).unwrap_or_else(|e| panic!("{shown}: {e}"));
            }
            ("log.csv", _) => {
                let text = std::fs::read_to_string(p).unwrap();
                // The `#` lines at its head say which runs wrote it (provenance).
                let head = text.lines().take_while(|l| l.starts_with('#')).count();
                assert!(head >= 1, "{shown}: no provenance line");
                let mut last = None;
                for (k, line) in text.lines().enumerate().skip(head + 1) {
                    let fields: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
                    assert_eq!(fields.len(), 8, "{shown} line {k}: {line}");
                    assert!(last < Some(fields[0]), "{shown} line {k}: steps in order");
                    last = Some(fields[0]);
                }
                let header = text.lines().nth(head).unwrap_or("");
                assert!(header.starts_with("step,time,"), "{shown}: the header");
                assert!(text.ends_with('\n'), "{shown}: whole lines");
            }
            (_, "json") => {
                talus::io::snapshot::read(p).unwrap_or_else(|e| panic!("{e}"));
            }
            (_, "bin") if name.starts_with("ckpt_") => {
                talus::io::checkpoint::read(p, &[]).unwrap_or_else(|e| panic!("{e}"));
            }
            (_, "bin") => {
                let json_written = p.with_extension("json").is_file();
                let being_written = step_of(p) > newest_snapshot;
                assert!(json_written || being_written, "{shown} has no metadata");
            }
            _ => panic!("{shown}: an output nobody expects"),
        }
        checked += 1;
    }
    (checked, temporaries)
}

/// The step of the log's last row (None without a log).
fn last_logged(dir: &Path) -> Option<u64> {
    let text = std::fs::read_to_string(dir.join("log.csv")).ok()?;
    text.lines().skip(1).last()?.split(',').next()?.parse().ok()
}

/// The scene of the kill test, written into `dir`: the default heap, small and writing
/// often (a checkpoint every 0.4 of simulated time, 200 steps; a snapshot every 0.2; a
/// log row every 0.1), long enough (15 000 steps, about a second) to be killed midway.
fn small_scene(dir: &Path) -> PathBuf {
    let mut v: Value = serde_json::from_str(scene::DEFAULT_SCENE).unwrap();
    v["particles"][1]["count"] = json!(200);
    v["particles"][1]["rate"] = json!(40);
    v["stop"] = json!({ "time": 30.0 });
    v["output"] = json!({ "snapshot_every": 0.2, "checkpoint_every": 0.4, "log_every": 0.1 });
    let file = dir.join("scene.json");
    std::fs::write(&file, v.to_string()).unwrap();
    file
}

#[test]
fn a_killed_run_leaves_whole_files_and_resumes_bitwise() {
    let dir = tmp("kill");
    let scene_file = small_scene(&dir);
    let scene_arg = scene_file.to_str().unwrap();

    let whole = dir.join("whole");
    let status = talus_run(&[scene_arg, "--out", whole.to_str().unwrap()])
        .status()
        .unwrap();
    assert!(status.success());

    // The same run killed (SIGKILL) three times, each time a little after a checkpoint
    // appeared, and resumed from its newest checkpoint into the same folder.
    let killed = dir.join("killed");
    let out = killed.to_str().unwrap();
    let mut rng = Rng::new(3);
    let mut resume: Option<PathBuf> = None;
    let mut kills = 0;
    let mut log_behind = false;
    for round in 0..4 {
        let mut cmd = match &resume {
            None => talus_run(&[scene_arg, "--out", out]),
            Some(ckpt) => talus_run(&["--resume", ckpt.to_str().unwrap(), "--out", out]),
        };
        let mut child = cmd.spawn().unwrap();
        if round < 3 {
            // After 1, 4 and 7 more checkpoints (every 200 steps), so that the kills
            // spread over the run.
            let from = checkpoints_in(&killed).last().and_then(|p| step_of(p));
            let until = from.unwrap_or(0) + 200 * (1 + 3 * round);
            let t = Instant::now();
            while checkpoints_in(&killed).last().and_then(|p| step_of(p)) < Some(until)
                && child.try_wait().unwrap().is_none()
                && t.elapsed() < Duration::from_secs(60)
            {
                std::thread::sleep(Duration::from_millis(2));
            }
            std::thread::sleep(Duration::from_millis(below(&mut rng, 40) as u64));
            if child.try_wait().unwrap().is_none() {
                child.kill().unwrap();
                kills += 1;
            }
        }
        let status = child.wait().unwrap();
        let (checked, temporaries) = assert_whole(&killed);
        assert!(checked > 3, "round {round}: files to check: {checked}");
        if round == 3 {
            assert!(status.success(), "the last resume finishes");
            assert_eq!(temporaries, 0, "a finished run leaves no temporaries");
        }
        resume = checkpoints_in(&killed).last().cloned();
        assert!(
            resume.is_some(),
            "round {round}: a checkpoint to resume from"
        );
        log_behind |= last_logged(&killed) < resume.as_deref().and_then(step_of);
        let step = resume.as_deref().and_then(step_of);
        eprintln!(
            "kill test, round {round}: {checked} files whole, {temporaries} temporaries; resumes from step {step:?}"
        );
    }
    assert!(
        kills >= 2,
        "the runs were killed midway ({kills} of 3); make the scene longer"
    );

    // Bitwise the same end: the final snapshot, the last checkpoint, the energy log. The
    // log is saved before every checkpoint, so no kill leaves it behind the newest one.
    assert!(
        !log_behind,
        "a kill left log.csv behind its newest checkpoint"
    );
    let files = ["final.bin", "final.json", "log.csv"];
    for f in files {
        let (a, b) = (
            common::output_without_provenance(&whole.join(f)),
            common::output_without_provenance(&killed.join(f)),
        );
        assert!(
            a == b,
            "{f} differs between the whole run and the killed one"
        );
    }
    let (a, b) = (checkpoints_in(&whole), checkpoints_in(&killed));
    // Resumed three times, the folder still keeps only the newest three checkpoints.
    assert_eq!(a.len(), 3, "checkpoints kept by the whole run: {a:?}");
    assert_eq!(b.len(), 3, "checkpoints kept by the resumed runs: {b:?}");
    assert_eq!(
        a.last().and_then(|p| step_of(p)),
        b.last().and_then(|p| step_of(p))
    );
    assert!(
        std::fs::read(a.last().unwrap()).unwrap() == std::fs::read(b.last().unwrap()).unwrap(),
        "the last checkpoints differ"
    );
    std::fs::remove_dir_all(&dir).ok();
}
