//! What an analysis reads: a snapshot (particles, polygon corners, contacts) and, from
//! the run it belongs to, gravity and friction (`scene.json`) and the energy log
//! (`log.csv`).

use super::AnalyzeError;
use crate::base::geometry::tangent;
use crate::io::snapshot::{self, Snapshot};
use crate::shape::{P2, area, world};
use std::path::{Path, PathBuf};

/// One particle of the snapshot.
#[derive(Clone, Debug, Default)]
pub struct Grain {
    pub id: u32,
    pub x: f64,
    pub z: f64,
    pub theta: f64,
    /// Reach: the radius of a disk, the circumscribed radius of a polygon.
    pub radius: f64,
    pub mass: f64,
    pub fixed: bool,
    /// Velocity (x, z) and angular velocity.
    pub velocity: P2,
    pub omega: f64,
    /// Area of the actual shape (per unit thickness).
    pub area: f64,
    /// World corners (empty for a disk; a rod's outline, its core swept by its sweep
    /// radius, for pictures and bounds).
    pub corners: Vec<P2>,
}

impl Grain {
    /// Lowest and highest point of the grain's shape.
    pub fn bottom(&self) -> f64 {
        self.extreme(1, f64::min)
    }
    pub fn top(&self) -> f64 {
        self.extreme(1, f64::max)
    }
    /// Leftmost and rightmost point of the grain's shape.
    pub fn left(&self) -> f64 {
        self.extreme(0, f64::min)
    }
    pub fn right(&self) -> f64 {
        self.extreme(0, f64::max)
    }
    /// The smallest (`pick` = min) or largest (max) coordinate `axis` (0: x, 1: z) of the
    /// shape: of its corners, or the disk's centre ± radius.
    fn extreme(&self, axis: usize, pick: fn(f64, f64) -> f64) -> f64 {
        let centre = [self.x, self.z][axis];
        if self.corners.is_empty() {
            return pick(centre - self.radius, centre + self.radius);
        }
        (self.corners.iter().map(|c| c[axis]))
            .reduce(pick)
            .unwrap_or(centre)
    }
}

/// One contact: the force on `a` (and −force on `b` unless `b` is a wall) acting at
/// `point`.
#[derive(Clone, Debug)]
pub struct Touch {
    pub a: usize,
    /// Index of the other grain, or None for a wall.
    pub b: Option<usize>,
    pub force: P2,
    pub normal_force: f64,
    pub point: P2,
}

/// A loaded snapshot with the scene facts the measurements need.
#[derive(Clone, Debug)]
pub struct Input {
    pub source: PathBuf,
    pub scene: String,
    pub units: String,
    pub step: u64,
    pub time: f64,
    pub grains: Vec<Grain>,
    pub touches: Vec<Touch>,
    /// Gravity's magnitude.
    pub g: f64,
    /// Coulomb friction coefficient of the contact law (None if unknown).
    pub mu: Option<f64>,
    /// The run's energy log, if found: (header, rows).
    pub log: Option<(Vec<String>, Vec<Vec<f64>>)>,
    /// Unit names of length, force, time (for CSV headers).
    pub length_unit: String,
    pub force_unit: String,
    /// The domain's period in x (scene `domain.periodic_x`), 0 when not periodic.
    pub period_x: f64,
    /// The wall segments (scene `walls`) where they were at the snapshot's time: a
    /// moving wall (`walls[k].motion`) placed as the run placed it.
    pub walls: Vec<[P2; 2]>,
}

/// The snapshot a path names: a snapshot's .json, or a run folder (its final.json).
pub fn snapshot_path(path: &Path) -> Result<PathBuf, AnalyzeError> {
    if path.is_dir() {
        let p = path.join("final.json");
        if p.is_file() {
            return Ok(p);
        }
        return Err(AnalyzeError::Unfinished(path.to_path_buf()));
    }
    if path.is_file() {
        return Ok(path.to_path_buf());
    }
    Err(AnalyzeError::NoSuchPath(path.to_path_buf()))
}

/// The snapshots of a run folder at times ≥ `from` (not the final one), in time order.
pub fn snapshots_from(run: &Path, from: f64) -> Result<Vec<PathBuf>, AnalyzeError> {
    let dir = run.join("snapshots");
    let mut found = Vec::new();
    let entries = std::fs::read_dir(&dir).map_err(|source| AnalyzeError::Read {
        path: dir.clone(),
        source,
    })?;
    for e in entries.flatten() {
        let p = e.path();
        if p.extension().is_some_and(|x| x == "json") {
            let meta = snapshot::read_meta(&p)?;
            if meta.time >= from {
                found.push((meta.time, p));
            }
        }
    }
    found.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(found.into_iter().map(|(_, p)| p).collect())
}

/// The run folder of a snapshot: its own folder, or the parent of `snapshots/`.
fn run_folder(snapshot: &Path) -> Option<PathBuf> {
    let dir = snapshot.parent()?;
    for d in [Some(dir), dir.parent()].into_iter().flatten() {
        if d.join("scene.json").is_file() {
            return Some(d.to_path_buf());
        }
    }
    None
}

fn read_log(path: &Path) -> Option<(Vec<String>, Vec<Vec<f64>>)> {
    let text = std::fs::read_to_string(path).ok()?;
    // The `#` lines at its head say which runs wrote it (issue 41).
    let mut lines = text.lines().skip_while(|l| l.starts_with('#'));
    let header: Vec<String> = lines.next()?.split(',').map(str::to_string).collect();
    let rows = lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.split(',')
                .map(|v| v.trim().parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    Some((header, rows))
}

fn column<'a, T>(
    s: &'a Snapshot,
    name: &str,
    get: fn(&'a Snapshot, &str) -> Option<&'a [T]>,
) -> Result<&'a [T], AnalyzeError> {
    get(s, name).ok_or_else(|| AnalyzeError::MissingColumn(name.into()))
}

/// Loads a snapshot (or a run folder's final snapshot) with its run's scene and energy
/// log; `g` overrides gravity.
pub fn load(path: &Path, g: Option<f64>) -> Result<Input, AnalyzeError> {
    let json = snapshot_path(path)?;
    let s = snapshot::read(&json)?;
    let run = run_folder(&json);
    let scene: Option<serde_json::Value> = run
        .as_ref()
        .and_then(|d| std::fs::read_to_string(d.join("scene.json")).ok())
        .and_then(|t| serde_json::from_str(&t).ok());
    let mut input = of_snapshot(&s, json, scene.as_ref(), g)?;
    input.log = run.as_ref().and_then(|d| read_log(&d.join("log.csv")));
    Ok(input)
}

/// The input of snapshot `s` of a run of `scene` (as its `scene.json` holds it), read
/// from `source`, without an energy log: what `load` gives, also for a snapshot still
/// in memory (`snapshot::capture`). `g` overrides gravity.
pub fn of_snapshot(
    s: &Snapshot,
    source: PathBuf,
    scene: Option<&serde_json::Value>,
    g: Option<f64>,
) -> Result<Input, AnalyzeError> {
    let f = |name| column(s, name, Snapshot::f64);
    let (xs, zs, th) = (f("particles.x")?, f("particles.z")?, f("particles.theta")?);
    let (rs, ms) = (f("particles.radius")?, f("particles.mass")?);
    let (vx, vz, om) = (
        f("particles.vx")?,
        f("particles.vz")?,
        f("particles.omega")?,
    );
    let ids = column(s, "particles.id", Snapshot::u32)?;
    let counts = column(s, "particles.corners", Snapshot::u32)?;
    let (cx, cz) = (
        s.f64("corners.x").unwrap_or(&[]),
        s.f64("corners.z").unwrap_or(&[]),
    );
    // Spheropolygons (rods) since stop 27; older snapshots have none.
    let sweeps = s.f64("particles.sweep").unwrap_or(&[]);
    let fixed: Vec<bool> = match s.columns.get("particles.fixed") {
        Some(snapshot::Column::U8(v)) => v.iter().map(|&b| b != 0).collect(),
        _ => vec![false; ids.len()],
    };
    let mut grains = Vec::with_capacity(ids.len());
    let mut next = 0usize;
    let mut body = Vec::new();
    let mut index = std::collections::HashMap::new();
    for k in 0..ids.len() {
        let n = counts[k] as usize;
        body.clear();
        for m in next..next + n {
            body.push([cx[m], cz[m]]);
        }
        next += n;
        let mut corners = Vec::new();
        let sweep = sweeps.get(k).copied().unwrap_or(0.0);
        let a = if sweep > 0.0 {
            // A rod: its exact area, and its outline as the corners to draw and bound.
            let s = crate::shape::spheropolygon::Spheropolygon {
                core: body.clone(),
                radius: sweep,
            };
            world(&s.outline(8), [xs[k], zs[k]], th[k], &mut corners);
            s.area()
        } else if n >= 3 {
            world(&body, [xs[k], zs[k]], th[k], &mut corners);
            area(&body)
        } else {
            std::f64::consts::PI * rs[k] * rs[k]
        };
        index.insert(ids[k], k);
        grains.push(Grain {
            id: ids[k],
            x: xs[k],
            z: zs[k],
            theta: th[k],
            radius: rs[k],
            mass: ms[k],
            fixed: fixed[k],
            velocity: [vx[k], vz[k]],
            omega: om[k],
            area: a,
            corners,
        });
    }
    let ci = column(s, "contacts.i", Snapshot::u32)?;
    let cj = column(s, "contacts.j", Snapshot::u32)?;
    let (nx, nz) = (f("contacts.nx")?, f("contacts.nz")?);
    let (fnm, ftm) = (f("contacts.fn")?, f("contacts.ft")?);
    let (px, pz) = (f("contacts.px")?, f("contacts.pz")?);
    let mut touches = Vec::with_capacity(ci.len());
    for k in 0..ci.len() {
        // Contacts of particles no longer in the table (removed) are skipped.
        let Some(&a) = index.get(&ci[k]) else {
            continue;
        };
        let b = if cj[k] >= s.meta.wall_base {
            None
        } else {
            match index.get(&cj[k]) {
                Some(&b) => Some(b),
                None => continue,
            }
        };
        let n = [nx[k], nz[k]];
        let t = tangent(n);
        touches.push(Touch {
            a,
            b,
            force: [fnm[k] * n[0] + ftm[k] * t[0], fnm[k] * n[1] + ftm[k] * t[1]],
            normal_force: fnm[k],
            point: [px[k], pz[k]],
        });
    }
    let scene_g = scene.and_then(|v| {
        let g = v.pointer("/gravity/g")?.as_array()?;
        let (a, b) = (g.first()?.as_f64()?, g.get(1)?.as_f64()?);
        Some(a.hypot(b))
    });
    let units = s.meta.units.clone();
    let default_g = if units == "si" { 9.81 } else { 1.0 };
    let mu = scene.and_then(|v| v.pointer("/contact/mu").and_then(|m| m.as_f64()));
    let period_x = scene
        .and_then(|v| serde_json::from_value::<crate::scene::Domain>(v.get("domain")?.clone()).ok())
        .map_or(0.0, |d| d.period_x());
    let walls = scene
        .and_then(|v| {
            serde_json::from_value::<Vec<crate::scene::Wall>>(v.get("walls")?.clone()).ok()
        })
        .unwrap_or_default()
        .iter()
        .map(|w| {
            let d = w.motion.map_or([0.0; 2], |m| m.displacement(s.meta.time));
            [
                [w.from[0] + d[0], w.from[1] + d[1]],
                [w.to[0] + d[0], w.to[1] + d[1]],
            ]
        })
        .collect();
    let (length_unit, force_unit) = if units == "si" {
        ("m", "N")
    } else {
        ("sigma", "m g")
    };
    Ok(Input {
        source,
        scene: s.meta.scene.clone(),
        units,
        step: s.meta.step,
        time: s.meta.time,
        grains,
        touches,
        g: g.or(scene_g).unwrap_or(default_g),
        mu,
        log: None,
        length_unit: length_unit.into(),
        force_unit: force_unit.into(),
        period_x,
        walls,
    })
}
