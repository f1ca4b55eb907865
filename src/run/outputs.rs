//! A run's outputs as a schedule: the energy log, snapshots, their VTK files and
//! checkpoints, each with the steps it writes at, written from the state in memory; and
//! the settling check, on its own schedule.

use super::{Engine, RunError, io};
use crate::base::files::write_atomic;
use crate::base::progress::Progress;
use crate::base::provenance::Provenance;
use crate::scene::Scene;
use crate::sim::Simulation;
use crate::{analyze, io::checkpoint, io::snapshot, render};
use std::path::{Path, PathBuf};

/// How many checkpoint files are kept (older ones are deleted).
const KEEP_CHECKPOINTS: usize = 3;

/// Every so many steps, or never.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Schedule(Option<u64>);

impl Schedule {
    pub const NEVER: Schedule = Schedule(None);

    pub fn steps(k: u64) -> Self {
        Schedule(Some(k.max(1)))
    }

    /// Every `interval` of simulated time, rounded to whole steps of `dt` (at least
    /// one); never for an interval of 0.
    pub fn every(interval: f64, dt: f64) -> Self {
        Schedule((interval > 0.0).then(|| ((interval / dt).round() as u64).max(1)))
    }

    pub fn due(self, step: u64) -> bool {
        self.0.is_some_and(|k| step.is_multiple_of(k))
    }

    /// The first step after `step` at which it is due (u64::MAX if never).
    pub fn next_after(self, step: u64) -> u64 {
        self.0.map_or(u64::MAX, |k| (step / k + 1) * k)
    }
}

/// One output of a run.
pub trait Output {
    /// Whether it writes at `step`.
    fn due(&self, step: u64) -> bool;
    /// The first step after `step` at which it writes.
    fn next_after(&self, step: u64) -> u64;
    /// Writes it for the engine's current step.
    fn write(&mut self, engine: &mut Engine) -> Result<(), RunError>;
}

/// Every output of a run.
pub struct Outputs {
    log: Log,
    snapshots: Snapshots,
    vtk: Vtk,
    checkpoints: Checkpoints,
}

impl Outputs {
    /// The outputs of `scene` into run folder `out`, for a run starting at `start_step`.
    pub fn new(scene: &Scene, out: &Path, start_step: u64, provenance: &Provenance) -> Self {
        let (o, dt) = (&scene.output, scene.dt);
        let snapshots = Schedule::every(o.snapshot_every, dt);
        let checkpoints = Schedule::every(o.checkpoint_every.unwrap_or(0.1 * scene.stop.time), dt);
        let log = if o.log_every > 0.0 {
            o.log_every
        } else {
            scene.stop.time / 200.0
        };
        let snap_dir = out.join("snapshots");
        Outputs {
            log: Log::new(
                out.join("log.csv"),
                Schedule::every(log, dt),
                checkpoints,
                start_step,
                provenance,
            ),
            snapshots: Snapshots {
                every: snapshots,
                dir: snap_dir.clone(),
                provenance: provenance.clone(),
            },
            vtk: Vtk {
                every: if o.vtk || o.dump {
                    snapshots
                } else {
                    Schedule::NEVER
                },
                vtk: o.vtk,
                dump: o.dump,
                dir: snap_dir,
                scene: serde_json::to_value(scene).expect("a scene always serialises"),
                entries: Vec::new(),
            },
            checkpoints: Checkpoints::new(checkpoints, out.join("checkpoints"), start_step),
        }
    }

    /// In the order they are written at a step: the log row first, so that the log a
    /// checkpoint saves holds the checkpoint's own step.
    fn all(&mut self) -> [&mut dyn Output; 4] {
        [
            &mut self.log,
            &mut self.snapshots,
            &mut self.vtk,
            &mut self.checkpoints,
        ]
    }

    /// This run's newest checkpoint.
    pub fn last_checkpoint(&self) -> Option<&Path> {
        self.checkpoints.last()
    }

    /// The first step after `step` at which any of them writes.
    pub fn next_after(&mut self, step: u64) -> u64 {
        (self.all().iter().map(|o| o.next_after(step)))
            .min()
            .unwrap_or(u64::MAX)
    }

    /// Writes those due at the engine's step.
    pub fn write_due(&mut self, engine: &mut Engine) -> Result<(), RunError> {
        let step = engine.step();
        for o in self.all() {
            if o.due(step) {
                o.write(engine)?;
            }
        }
        Ok(())
    }

    /// At the start of a run (not of a resumed one): the snapshot of the initial state.
    pub fn write_start(&mut self, engine: &mut Engine) -> Result<(), RunError> {
        for o in [&mut self.snapshots as &mut dyn Output, &mut self.vtk] {
            if o.due(engine.step()) {
                o.write(engine)?;
            }
        }
        Ok(())
    }

    /// At the end: the log, then the last step's checkpoint (unless written already).
    /// The log goes first, as at every checkpoint, so that a kill between the two never
    /// leaves the newest checkpoint ahead of the log a resume from it continues.
    pub fn write_end(&mut self, engine: &mut Engine) -> Result<(), RunError> {
        self.log.save()?;
        let last = format!("ckpt_{:010}.bin", engine.step());
        let c = &mut self.checkpoints;
        if c.every != Schedule::NEVER && c.last().is_none_or(|p| !p.ends_with(&last)) {
            c.write(engine)?;
        }
        Ok(())
    }
}

/// `log.csv`: a row of energies every `rows` steps, kept in memory and saved with every
/// checkpoint (`saves`) and at the end, so that a resume from a checkpoint finds the
/// log up to it. Its head is a `#` line per run that wrote it (`Provenance::line`: a
/// resumed run adds its own), then the column names.
pub struct Log {
    rows: Schedule,
    saves: Schedule,
    path: PathBuf,
    text: String,
}

const LOG_HEADER: &str =
    "step,time,particles,contacts,kinetic_translational,kinetic_rotational,elastic,potential\n";

impl Log {
    /// A resumed run (`start_step` > 0) continues the log of the run it resumes: its
    /// rows up to the start.
    fn new(
        path: PathBuf,
        rows: Schedule,
        saves: Schedule,
        start_step: u64,
        provenance: &Provenance,
    ) -> Self {
        let old = if start_step > 0 {
            std::fs::read_to_string(&path).unwrap_or_default()
        } else {
            String::new()
        };
        // The runs that wrote the log before this one, then this one.
        let mut text: String = (old.lines())
            .take_while(|l| l.starts_with('#'))
            .map(|l| format!("{l}\n"))
            .collect();
        text.push_str(&format!("# {}\n", provenance.line()));
        text.push_str(LOG_HEADER);
        let mut old_rows = old.lines().skip_while(|l| l.starts_with('#'));
        if start_step > 0 && old_rows.next() == Some(LOG_HEADER.trim_end()) {
            for line in old_rows {
                match line.split(',').next().and_then(|s| s.parse::<u64>().ok()) {
                    Some(step) if step <= start_step => {
                        text.push_str(line);
                        text.push('\n');
                    }
                    _ => break,
                }
            }
        }
        Log {
            rows,
            saves,
            path,
            text,
        }
    }

    fn row(&mut self, step: u64, sim: &Simulation) {
        let e = sim.energies();
        self.text.push_str(&format!(
            "{step},{:.9e},{},{},{:.9e},{:.9e},{:.9e},{:.9e}\n",
            sim.time(),
            sim.particles.active_count(),
            sim.pairs.len(),
            e.kinetic_translational,
            e.kinetic_rotational,
            e.elastic,
            e.potential
        ));
    }

    fn save(&self) -> Result<(), RunError> {
        write_atomic(&self.path, self.text.as_bytes()).map_err(io(&self.path))
    }
}

impl Output for Log {
    fn due(&self, step: u64) -> bool {
        self.rows.due(step) || self.saves.due(step)
    }
    fn next_after(&self, step: u64) -> u64 {
        self.rows.next_after(step).min(self.saves.next_after(step))
    }
    fn write(&mut self, engine: &mut Engine) -> Result<(), RunError> {
        let step = engine.step();
        if self.rows.due(step) {
            self.row(step, engine.sim()?);
        }
        if self.saves.due(step) {
            self.save()?;
        }
        Ok(())
    }
}

/// `snapshots/snap_SSSSSSSSSS.{bin,json}` (docs/FORMATS.md).
pub struct Snapshots {
    every: Schedule,
    dir: PathBuf,
    provenance: Provenance,
}

fn snapshot_stem(step: u64) -> String {
    format!("snap_{step:010}")
}

impl Output for Snapshots {
    fn due(&self, step: u64) -> bool {
        self.every.due(step)
    }
    fn next_after(&self, step: u64) -> u64 {
        self.every.next_after(step)
    }
    fn write(&mut self, engine: &mut Engine) -> Result<(), RunError> {
        let stem = snapshot_stem(engine.step());
        snapshot::write_with(engine.sim()?, &self.dir, &stem, &self.provenance)
            .map_err(io(&self.dir))?;
        Ok(())
    }
}

/// With `output.vtk`, beside each snapshot: its grains and contacts as VTK PolyData
/// (`snap_SSSSSSSSSS_grains.vtp`, `_contacts.vtp`), and `snapshots.pvd` listing every
/// one this run wrote, for ParaView; with `output.dump`, its grains as a LAMMPS-style
/// dump (`snap_SSSSSSSSSS_grains.dump`) for OVITO. Both from one analysis of the state.
pub struct Vtk {
    every: Schedule,
    vtk: bool,
    dump: bool,
    dir: PathBuf,
    /// The scene as `scene.json` holds it: gravity and friction for the analysis.
    scene: serde_json::Value,
    /// (time, its files: grains, contacts and walls if any) of each one written.
    entries: Vec<(f64, Vec<String>)>,
}

impl Output for Vtk {
    fn due(&self, step: u64) -> bool {
        self.every.due(step)
    }
    fn next_after(&self, step: u64) -> u64 {
        self.every.next_after(step)
    }
    fn write(&mut self, engine: &mut Engine) -> Result<(), RunError> {
        let stem = snapshot_stem(engine.step());
        let sim = engine.sim()?;
        // The snapshot's analysis, from the state in memory: what `talus analyze` finds
        // in the snapshot file.
        let snap = snapshot::capture(sim, &stem);
        let source = self.dir.join(format!("{stem}.json"));
        let input = analyze::input::of_snapshot(&snap, source, Some(&self.scene), None)?;
        if input.grains.is_empty() {
            return Ok(()); // nothing to draw yet (a pour before its first grain)
        }
        let time = input.time;
        let a = analyze::analyze(input, &analyze::Options::default())?;
        let prefix = format!("{stem}_");
        if self.dump {
            render::dump::write_named(&a, &self.dir, &prefix)?;
        }
        if !self.vtk {
            return Ok(());
        }
        let files = render::vtk::write_named(&a, &self.dir, &prefix)?;
        let names = files
            .iter()
            .filter_map(|f| f.file_name().map(|n| n.to_string_lossy().into_owned()))
            .collect();
        self.entries.push((time, names));
        let pvd = self.dir.join("snapshots.pvd");
        let text = render::vtk::collection(&self.entries);
        write_atomic(&pvd, text.as_bytes()).map_err(io(&pvd))
    }
}

/// `checkpoints/ckpt_SSSSSSSSSS.bin`, the newest `KEEP_CHECKPOINTS` of this run kept.
pub struct Checkpoints {
    every: Schedule,
    dir: PathBuf,
    written: Vec<PathBuf>,
}

impl Checkpoints {
    /// A resumed run (`start_step` > 0) counts the folder's checkpoints up to its start
    /// (those past it were removed by `folder::claim`) among the ones it keeps, so that a
    /// run resumed again and again still keeps only the newest `KEEP_CHECKPOINTS`.
    fn new(every: Schedule, dir: PathBuf, start_step: u64) -> Self {
        let mut written = Vec::new();
        if start_step > 0
            && let Ok(entries) = std::fs::read_dir(&dir)
        {
            written = (entries.flatten().map(|e| e.path()))
                .filter(|p| checkpoint_step(p).is_some_and(|s| s <= start_step))
                .collect();
            written.sort();
        }
        Checkpoints {
            every,
            dir,
            written,
        }
    }

    fn last(&self) -> Option<&Path> {
        self.written.last().map(PathBuf::as_path)
    }
}

impl Output for Checkpoints {
    fn due(&self, step: u64) -> bool {
        self.every.due(step)
    }
    fn next_after(&self, step: u64) -> u64 {
        self.every.next_after(step)
    }
    fn write(&mut self, engine: &mut Engine) -> Result<(), RunError> {
        let (sim, device) = engine.checkpoint_state()?;
        let path = self.dir.join(format!("ckpt_{:010}.bin", sim.step));
        checkpoint::write(sim, device, &path).map_err(io(&path))?;
        self.written.push(path);
        while self.written.len() > KEEP_CHECKPOINTS {
            let old = self.written.remove(0);
            let _ = std::fs::remove_file(old);
        }
        Ok(())
    }
}

/// The step of `ckpt_SSSSSSSSSS.bin`.
fn checkpoint_step(path: &Path) -> Option<u64> {
    let name = path.file_name()?.to_str()?;
    let digits = name.strip_prefix("ckpt_")?.strip_suffix(".bin")?;
    (digits.len() == 10).then(|| digits.parse().ok())?
}

/// The settling rules of `stop`, checked every `stop.check_every` (else every step). A
/// scene with copies (`replicas`) has the rules once per copy, each copy judged on its
/// own (`Simulation::replica`); a copy that has settled stays settled, and the run ends
/// when every copy has.
pub struct Settling {
    pub every: Schedule,
    rules: Vec<Rule>,
}

/// One copy's settling rules and what they have seen.
struct Rule {
    kinetic_drop: Option<f64>,
    kinetic_fraction: Option<f64>,
    not_before: f64,
    /// The mean kinetic energy per particle when the relaxation began (`kinetic_drop`).
    relaxing_from: Option<f64>,
    settled: bool,
}

impl Settling {
    pub fn new(scene: &Scene) -> Self {
        let every = Schedule::every(scene.stop.check_every, scene.dt);
        let rule = || Rule {
            kinetic_drop: scene.stop.kinetic_drop,
            kinetic_fraction: scene.stop.kinetic_fraction,
            not_before: scene.stop.not_before,
            relaxing_from: None,
            settled: false,
        };
        Settling {
            every: if every == Schedule::NEVER {
                Schedule::steps(1)
            } else {
                every
            },
            rules: (0..scene.replicas).map(|_| rule()).collect(),
        }
    }

    /// Which copies have settled (one entry without copies).
    pub fn copies_settled(&self) -> Vec<bool> {
        self.rules.iter().map(|r| r.settled).collect()
    }

    /// Whether the run has settled at `time` (every copy of it); says so through
    /// `progress`.
    pub fn settled(
        &mut self,
        engine: &mut Engine,
        time: f64,
        progress: &Progress,
    ) -> Result<bool, RunError> {
        let sim = engine.sim()?;
        if let [rule] = &mut self.rules[..] {
            return Ok(rule.check(sim, time, progress, ""));
        }
        for (c, rule) in self.rules.iter_mut().enumerate() {
            if !rule.settled {
                let copy = sim.replica(c as u32).map_err(RunError::Copy)?;
                rule.settled = rule.check(&copy, time, progress, &format!("copy {c}: "));
            }
        }
        Ok(self.rules.iter().all(|r| r.settled))
    }
}

impl Rule {
    /// Whether `sim` has settled at `time`; says so through `progress`, after `who`.
    fn check(&mut self, sim: &Simulation, time: f64, progress: &Progress, who: &str) -> bool {
        if time < self.not_before {
            return false;
        }
        if let Some(drop) = self.kinetic_drop
            && sim.feeding_done()
        {
            // Paper 004's rule: the mean kinetic energy against its value when the
            // relaxation began (the first check after the sources are done).
            let n = sim.particles.active_count().max(1) as f64;
            let mean = sim.energies().kinetic() / n;
            let start = *self.relaxing_from.get_or_insert(mean);
            if mean < drop * start {
                progress.note(&format!(
                    "{who}relaxed at t = {:.4}: mean kinetic energy {mean:.3e}, {:.1e} of its {start:.3e} when the sources were done",
                    sim.time(),
                    mean / start
                ));
                return true;
            }
        }
        if let Some(frac) = self.kinetic_fraction
            && sim.feeding_done()
        {
            let e = sim.energies();
            if e.elastic > 0.0 && e.kinetic() < frac * e.elastic {
                progress.note(&format!(
                    "{who}settled at t = {:.4}: kinetic/elastic = {:.3e}",
                    sim.time(),
                    e.kinetic() / e.elastic
                ));
                return true;
            }
        }
        false
    }
}
