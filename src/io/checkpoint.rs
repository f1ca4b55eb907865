//! Checkpoints: the complete dynamic state (all six Gear values, the spring table, the
//! random generator, source progress, step count) plus the scene, bit for bit, so that a
//! resumed run is bitwise identical to an uninterrupted one (SPEC 3).

use crate::base::files::{Decoder, Encoder, write_atomic};
use crate::base::rng::Rng;
use crate::cpu::springs::SpringTable;
use crate::create::source::SourceState;
use crate::gpu::DeviceState;
use crate::scene::Scene;
use crate::sim::Simulation;
use crate::state::{GEAR_VALUES, Particles};
use std::path::Path;

const MAGIC: &[u8; 8] = b"TALUSCK3";
/// Checkpoints before the checksum (stop 28): read as they are.
const UNCHECKED_MAGIC: &[u8; 8] = b"TALUSCK2";
/// Checkpoints of talus before polygons (no shapes): named in the error.
const OLD_MAGIC: &[u8; 8] = b"TALUSCK1";
/// Version of the raw device arrays a GPU checkpoint carries (fixed-point positions and,
/// since 4, fixed-point q1).
const DEVICE_LAYOUT: u8 = 4;

#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    #[error("cannot read checkpoint {0}: {1}")]
    Io(String, std::io::Error),
    #[error("{0} is not a talus checkpoint (bad magic)")]
    Magic(String),
    #[error(
        "{0} was written by an older talus (format TALUSCK1, before polygons); rerun the scene"
    )]
    OldFormat(String),
    #[error("checkpoint {0} is damaged: its checksum does not match its contents")]
    Checksum(String),
    #[error("checkpoint {0} is damaged: {1}")]
    Corrupt(String, crate::base::files::DecodeError),
    #[error("checkpoint {0} holds an invalid scene: {1}")]
    Scene(String, crate::scene::SceneError),
    /// A new stage's scene (`--from`) that cannot continue the state.
    #[error("--from {0}: {1}")]
    Stage(String, crate::scene::SceneError),
}

pub fn encode(sim: &Simulation, device: Option<&DeviceState>) -> Vec<u8> {
    let mut e = Encoder::default();
    e.bytes.extend_from_slice(MAGIC);
    e.str(&serde_json::to_string(&sim.scene).expect("a scene always serialises"));
    e.u64(sim.step);
    e.u64(sim.lost);
    e.u64(sim.rng.state);
    e.u64(sim.sources.len() as u64);
    for s in &sim.sources {
        e.u32(s.inserted);
        // A drawn candidate: 1, its five values; 2 (a rod's, which falls with a kick
        // of velocity), the five and the kick. Without a kick the bytes are those of
        // checkpoints before the kick was kept.
        match s.pending {
            Some(c) => {
                let kicked = c.kick != [0.0; 2];
                e.u8(if kicked { 2 } else { 1 });
                for v in [c.x, c.axes[0], c.axes[1], c.start, c.theta] {
                    e.f64(v);
                }
                if kicked {
                    e.f64(c.kick[0]);
                    e.f64(c.kick[1]);
                }
            }
            None => e.u8(0),
        }
        e.u64(s.rng.state);
    }
    let p = &sim.particles;
    e.u64(p.len() as u64);
    for k in 0..GEAR_VALUES {
        p.q[k].iter().flatten().for_each(|&v| e.f64(v));
    }
    for col in [&p.radius, &p.mass, &p.inertia] {
        col.iter().for_each(|&v| e.f64(v));
    }
    p.fixed.iter().for_each(|&v| e.u8(v as u8));
    p.active.iter().for_each(|&v| e.u8(v as u8));
    p.material.iter().for_each(|&v| e.u32(v));
    // Polygon corners (body frame): a count per particle (0 for disks), then the corners.
    for corners in &p.shape {
        e.u32(corners.len() as u32);
        corners.iter().flatten().for_each(|&v| e.f64(v));
    }
    let springs = sim.spring_table();
    e.u64(springs.capacity() as u64);
    springs.keys.iter().for_each(|&k| e.u64(k));
    springs.values.iter().for_each(|&v| e.f64(v));
    // From a GPU run: the exact device state, for a bitwise GPU resume. The flag is the
    // device layout's version (1: f32 offsets before fixed point, 2: f32 orientations,
    // 3: f32 q1; none is read any more: such a checkpoint resumes from its f64 state).
    match device {
        Some(ds) => {
            e.u8(DEVICE_LAYOUT);
            for raw in [
                bytemuck::cast_slice::<_, u8>(&ds.states),
                bytemuck::cast_slice(&ds.props),
                bytemuck::cast_slice(&ds.springs),
            ] {
                e.u64(raw.len() as u64);
                e.bytes.extend_from_slice(raw);
            }
        }
        None => e.u8(0),
    }
    // Spheropolygons (rods) or rolling springs, only when the state has some, so that
    // other checkpoints stay as they were: a tag, each particle's sweep, and each pair's
    // `SubSprings` (pair key, count, then the count's keys and values).
    let subs = !springs.sub.is_empty() || device.is_some_and(|d| !d.sub.is_empty());
    if subs || p.sweep.iter().any(|&s| s > 0.0) {
        e.u8(SWEPT);
        p.sweep.iter().for_each(|&v| e.f64(v));
        e.u64(springs.sub.len() as u64);
        for (&key, s) in &springs.sub {
            e.u64(key);
            e.u8(s.count as u8);
            for k in 0..s.count {
                e.u32(s.key[k]);
                e.f64(s.xi[k]);
            }
        }
        // From a GPU run: the device's sub-contact springs beside `springs` above.
        if let Some(ds) = device {
            let raw = bytemuck::cast_slice::<_, u8>(&ds.sub);
            e.u64(raw.len() as u64);
            e.bytes.extend_from_slice(raw);
        }
    }
    // Copies of the scene (`replicas`), only when there are some: a tag and each
    // particle's copy.
    if p.copy.iter().any(|&c| c != 0) {
        e.u8(REPLICAS);
        p.copy.iter().for_each(|&c| e.u32(c));
    }
    // A checksum of everything before it (issue 16: of 30 random one-byte flips none was
    // noticed and 9 resumed into another result).
    let sum = checksum(&e.bytes);
    e.bytes.extend_from_slice(&sum.to_le_bytes());
    e.bytes
}

fn checksum(bytes: &[u8]) -> u64 {
    crate::base::files::fnv1a64(crate::base::files::FNV_START, bytes)
}

/// The tags of the optional sections at a checkpoint's end, in this order: the
/// spheropolygons' (and any pair's `SubSprings`: rolling springs too), then the
/// copies'.
const SWEPT: u8 = 1;
const REPLICAS: u8 = 2;

pub fn write(sim: &Simulation, device: Option<&DeviceState>, path: &Path) -> std::io::Result<()> {
    write_atomic(path, &encode(sim, device))
}

/// What a checkpoint holds: the f64 state, and from a GPU run the exact device state (a
/// GPU run resumes from it bitwise; the CPU path continues from the f64 state).
pub struct Checkpoint {
    pub sim: Simulation,
    pub device: Option<DeviceState>,
}

impl Checkpoint {
    /// A start from a scene: no device state.
    pub fn fresh(sim: Simulation) -> Self {
        Self { sim, device: None }
    }
}

/// Loads a checkpoint; `overrides` may change `stop.*`, `output.*` (so a run can be
/// extended) and `skin` (which changes only the speed), since anything else would break
/// the continuation.
pub fn read(path: &Path, overrides: &[String]) -> Result<Checkpoint, CheckpointError> {
    let name = path.display().to_string();
    for o in overrides {
        let key = o.split('=').next().unwrap_or("").trim();
        if !(key.starts_with("stop.") || key.starts_with("output.") || key == "skin") {
            return Err(CheckpointError::Scene(
                name,
                crate::scene::SceneError::invalid(
                    key,
                    "only stop.*, output.* and skin can be changed when resuming",
                ),
            ));
        }
    }
    decode(path, |text| {
        crate::scene::parse(text, overrides).map_err(|e| CheckpointError::Scene(name.clone(), e))
    })
}

/// The state of a checkpoint under a new scene: the next stage of a multi-stage run
/// (`talus run SCENE --from CHECKPOINT`), which may change gravity, the contact law and
/// its parameters, the walls, the domain, the stop rule and the outputs, and goes on
/// from the checkpoint's step and time. What was created cannot change under it: the
/// scene's `particles` (its point sources continue where they were), its materials
/// (the particles' masses were made from their densities), `replicas`, and `dt` (Gear's
/// state is scaled by it). A GPU run starts on the device from the f64 state.
pub fn read_as_stage(path: &Path, scene: Scene) -> Result<Checkpoint, CheckpointError> {
    let name = path.display().to_string();
    let mut start = decode(path, |text| {
        let old =
            crate::scene::parse(text, &[]).map_err(|e| CheckpointError::Scene(name.clone(), e))?;
        stage_fits(&old, &scene).map_err(|e| CheckpointError::Stage(name.clone(), e))?;
        Ok(scene)
    })?;
    if start.sim.time() >= start.sim.scene.stop.time {
        return Err(CheckpointError::Stage(
            name,
            crate::scene::SceneError::invalid(
                "stop.time",
                format!(
                    "the state is at t = {}, at or past the stage's stop.time {}: a stage \
                     goes on from the state's time",
                    start.sim.time(),
                    start.sim.scene.stop.time
                ),
            ),
        ));
    }
    start.device = None;
    Ok(start)
}

/// Whether `new` can take over the state that `old` made (`read_as_stage`).
fn stage_fits(old: &Scene, new: &Scene) -> Result<(), crate::scene::SceneError> {
    use crate::scene::SceneError;
    if json(&old.particles) != json(&new.particles) {
        return Err(SceneError::invalid(
            "particles",
            "differs from the scene that made the state: a stage goes on with the particles \
             (and point sources) it has; change gravity, contact, rolling, walls, stop or output",
        ));
    }
    let names = |s: &Scene| s.materials.keys().cloned().collect::<Vec<_>>().join(", ");
    if names(old) != names(new) {
        return Err(SceneError::invalid(
            "materials",
            format!(
                "the state's particles are of {}; the scene has {}",
                names(old),
                names(new)
            ),
        ));
    }
    for (k, m) in &old.materials {
        if json(m) != json(&new.materials[k]) {
            return Err(SceneError::invalid(
                format!("materials.{k}"),
                "differs from the state's (its particles' masses were made from it)",
            ));
        }
    }
    if old.replicas != new.replicas {
        return Err(SceneError::invalid(
            "replicas",
            format!(
                "the state has {} copies, the scene {}",
                old.replicas, new.replicas
            ),
        ));
    }
    if old.dt != new.dt {
        return Err(SceneError::invalid(
            "dt",
            format!(
                "the state was integrated at dt = {} (Gear's state is scaled by it), the \
                 scene has {}",
                old.dt, new.dt
            ),
        ));
    }
    Ok(())
}

/// A part of a scene as the scene file says it, for comparing two.
fn json<T: serde::Serialize>(v: &T) -> serde_json::Value {
    serde_json::to_value(v).unwrap_or_default()
}

/// Decodes a checkpoint, its scene made from the scene text it holds by `scene`.
fn decode(
    path: &Path,
    scene: impl FnOnce(&str) -> Result<Scene, CheckpointError>,
) -> Result<Checkpoint, CheckpointError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| CheckpointError::Io(name.clone(), e))?;
    if bytes.len() >= 8 && &bytes[..8] == OLD_MAGIC {
        return Err(CheckpointError::OldFormat(name));
    }
    let body = if bytes.starts_with(MAGIC) {
        // Too short to hold the checksum: cut off, not foreign.
        if bytes.len() < 16 {
            return Err(CheckpointError::Checksum(name));
        }
        let (body, sum) = bytes.split_at(bytes.len() - 8);
        if checksum(body).to_le_bytes() != sum {
            return Err(CheckpointError::Checksum(name));
        }
        body
    } else if bytes.len() >= 8 && &bytes[..8] == UNCHECKED_MAGIC {
        &bytes[..]
    } else {
        return Err(CheckpointError::Magic(name));
    };
    let corrupt = |e| CheckpointError::Corrupt(name.clone(), e);
    let mut d = Decoder::new(&body[8..]);
    let scene_text = d.str().map_err(corrupt)?;
    let scene = scene(&scene_text)?;
    let step = d.u64().map_err(corrupt)?;
    let lost = d.u64().map_err(corrupt)?;
    let rng = Rng {
        state: d.u64().map_err(corrupt)?,
    };
    let n_sources = d.u64().map_err(corrupt)? as usize;
    let mut sources = Vec::new();
    for _ in 0..n_sources {
        let inserted = d.u32().map_err(corrupt)?;
        let flag = d.u8().map_err(corrupt)?;
        let pending = if flag == 1 || flag == 2 {
            let mut v = [0.0; 7];
            for x in &mut v[..if flag == 2 { 7 } else { 5 }] {
                *x = d.f64().map_err(corrupt)?;
            }
            Some(crate::create::source::Drawn {
                x: v[0],
                axes: [v[1], v[2]],
                start: v[3],
                theta: v[4],
                kick: [v[5], v[6]],
            })
        } else {
            None
        };
        let rng = Rng {
            state: d.u64().map_err(corrupt)?,
        };
        sources.push(SourceState {
            inserted,
            pending,
            rng,
        });
    }
    let n = d.u64().map_err(corrupt)? as usize;
    let mut p = Particles::default();
    for k in 0..GEAR_VALUES {
        for _ in 0..n {
            p.q[k].push([
                d.f64().map_err(corrupt)?,
                d.f64().map_err(corrupt)?,
                d.f64().map_err(corrupt)?,
            ]);
        }
    }
    for col in [&mut p.radius, &mut p.mass, &mut p.inertia] {
        for _ in 0..n {
            col.push(d.f64().map_err(corrupt)?);
        }
    }
    for _ in 0..n {
        p.fixed.push(d.u8().map_err(corrupt)? == 1);
    }
    for _ in 0..n {
        p.active.push(d.u8().map_err(corrupt)? == 1);
    }
    for _ in 0..n {
        p.material.push(d.u32().map_err(corrupt)?);
    }
    // A material the scene does not have would index past the law's pair table.
    if p.material
        .iter()
        .any(|&m| m as usize >= scene.materials.len())
    {
        return Err(corrupt(crate::base::files::DecodeError(bytes.len())));
    }
    for _ in 0..n {
        let count = d.u32().map_err(corrupt)? as usize;
        if count > crate::shape::MAX_CORNERS as usize {
            return Err(corrupt(crate::base::files::DecodeError(bytes.len())));
        }
        let mut corners = Vec::with_capacity(count);
        for _ in 0..count {
            corners.push([d.f64().map_err(corrupt)?, d.f64().map_err(corrupt)?]);
        }
        p.shape.push(corners);
    }
    // Disks and polygons of one copy; the sections at the end set sweeps and copies.
    p.sweep = vec![0.0; n];
    p.copy = vec![0; n];
    let cap = d.u64().map_err(corrupt)? as usize;
    // Grown as read, not reserved: a damaged count must end in an error at the data's
    // end, not in "capacity overflow" or an abort (issue 16; tests/hostile.rs).
    let mut springs = SpringTable {
        keys: Vec::new(),
        values: Vec::new(),
        sub: Default::default(),
    };
    for _ in 0..cap {
        springs.keys.push(d.u64().map_err(corrupt)?);
    }
    for _ in 0..cap {
        springs.values.push(d.f64().map_err(corrupt)?);
    }
    let flag = d.u8().map_err(corrupt)?;
    let mut device_state = if flag != 0 {
        let mut raw = || -> Result<&[u8], crate::base::files::DecodeError> {
            let n = d.u64()? as usize;
            d.take(n)
        };
        let states = raw().map_err(corrupt)?;
        let props = raw().map_err(corrupt)?;
        let springs = raw().map_err(corrupt)?;
        let sizes_ok = states.len() % size_of::<crate::gpu::layout::State>() == 0
            && props.len() % size_of::<crate::gpu::layout::Props>() == 0
            && springs.len() % size_of::<crate::gpu::layout::Entry>() == 0;
        if flag != DEVICE_LAYOUT {
            // An older device layout is skipped: the f64 state above is complete, only
            // the GPU resume is then not bitwise.
            None
        } else if !sizes_ok {
            return Err(corrupt(crate::base::files::DecodeError(bytes.len())));
        } else {
            Some(DeviceState {
                states: bytemuck::pod_collect_to_vec(states),
                props: bytemuck::pod_collect_to_vec(props),
                springs: bytemuck::pod_collect_to_vec(springs),
                sub: Vec::new(),
            })
        }
    } else {
        None
    };
    let damaged = || corrupt(crate::base::files::DecodeError(bytes.len()));
    let mut tag = if d.is_done() {
        None
    } else {
        Some(d.u8().map_err(corrupt)?)
    };
    if tag == Some(SWEPT) {
        // The spheropolygon section (`encode`).
        p.sweep = (0..n)
            .map(|_| d.f64())
            .collect::<Result<_, _>>()
            .map_err(corrupt)?;
        let entries = d.u64().map_err(corrupt)?;
        for _ in 0..entries {
            let key = d.u64().map_err(corrupt)?;
            let count = d.u8().map_err(corrupt)? as usize;
            if count > crate::cpu::springs::MAX_SUB {
                return Err(damaged());
            }
            let mut s = crate::cpu::springs::SubSprings {
                count,
                ..Default::default()
            };
            for k in 0..count {
                s.key[k] = d.u32().map_err(corrupt)?;
                s.xi[k] = d.f64().map_err(corrupt)?;
            }
            springs.sub.insert(key, s);
        }
        if let Some(ds) = device_state.as_mut() {
            let n = d.u64().map_err(corrupt)? as usize;
            let raw = d.take(n).map_err(corrupt)?;
            let size = size_of::<crate::gpu::layout::SubSprings>();
            if raw.len() % size != 0 || (!raw.is_empty() && raw.len() / size != ds.springs.len()) {
                return Err(damaged());
            }
            ds.sub = bytemuck::pod_collect_to_vec(raw);
        }
        tag = if d.is_done() {
            None
        } else {
            Some(d.u8().map_err(corrupt)?)
        };
    }
    if tag == Some(REPLICAS) {
        p.copy = (0..n)
            .map(|_| d.u32())
            .collect::<Result<_, _>>()
            .map_err(corrupt)?;
        if p.copy.iter().any(|&c| c >= scene.replicas) {
            return Err(damaged());
        }
        tag = None;
    }
    if tag.is_some() || !d.is_done() || !cap.is_power_of_two() {
        return Err(corrupt(crate::base::files::DecodeError(bytes.len())));
    }
    let sim = Simulation::from_parts(scene, p, springs, sources, rng, step, lost)
        .map_err(|e| CheckpointError::Scene(name, e))?;
    Ok(Checkpoint {
        sim,
        device: device_state,
    })
}
