//! Snapshots: the particles and contacts at one step, as little-endian binary columns
//! (`NAME.bin`) described by JSON metadata (`NAME.json`). The format is documented in
//! docs/FORMATS.md. `capture` takes one from the state in memory, `write` writes it and
//! `read` loads it back. The `.bin` is renamed into place before the `.json`, so
//! metadata never points at missing data.

use crate::base::files::write_atomic;
use crate::cpu::contacts::WALL_BASE;
use crate::sim::Simulation;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub const FORMAT: &str = "talus-snapshot";
/// 2: the metadata carries a checksum of itself and the data (version 1 files, without
/// one, are still read).
pub const VERSION: u32 = 2;

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ColumnMeta {
    /// "particles" or "contacts".
    pub table: String,
    pub name: String,
    /// "f64", "u32" or "u8".
    pub dtype: String,
    pub unit: String,
    /// Byte offset in the .bin file, and the number of values.
    pub offset: u64,
    pub count: u64,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Meta {
    pub format: String,
    pub version: u32,
    pub scene: String,
    pub units: String,
    pub step: u64,
    pub time: f64,
    pub particles: u64,
    pub contacts: u64,
    /// Id used in the contact column `j` for wall w: wall_base + w.
    pub wall_base: u32,
    pub data: String,
    pub columns: Vec<ColumnMeta>,
    /// What wrote it (since issue 41; absent in older snapshots and in one captured in
    /// memory).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<crate::base::provenance::Provenance>,
    /// "fnv1a64:" and 16 hex digits: FNV-1a over the `.bin` and then this metadata
    /// without the checksum, as compact JSON (`digest`). A snapshot in memory has none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub checksum: Option<String>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Column {
    F64(Vec<f64>),
    U32(Vec<u32>),
    U8(Vec<u8>),
}

/// A snapshot read back from disk.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub meta: Meta,
    pub columns: BTreeMap<String, Column>,
}

impl Snapshot {
    pub fn f64(&self, key: &str) -> Option<&[f64]> {
        match self.columns.get(key) {
            Some(Column::F64(v)) => Some(v),
            _ => None,
        }
    }
    pub fn u32(&self, key: &str) -> Option<&[u32]> {
        match self.columns.get(key) {
            Some(Column::U32(v)) => Some(v),
            _ => None,
        }
    }
}

/// Columns in the order they are written, with their byte offsets in the `.bin`.
#[derive(Default)]
struct Builder {
    size: u64,
    meta: Vec<ColumnMeta>,
    columns: BTreeMap<String, Column>,
}

impl Builder {
    fn push(&mut self, table: &str, name: &str, unit: &str, col: Column) {
        let (dtype, count, width) = match &col {
            Column::F64(v) => ("f64", v.len(), 8),
            Column::U32(v) => ("u32", v.len(), 4),
            Column::U8(v) => ("u8", v.len(), 1),
        };
        self.meta.push(ColumnMeta {
            table: table.into(),
            name: name.into(),
            dtype: dtype.into(),
            unit: unit.into(),
            offset: self.size,
            count: count as u64,
        });
        self.size += (count * width) as u64;
        self.columns.insert(format!("{table}.{name}"), col);
    }
}

/// Writes `DIR/STEM.bin` and `DIR/STEM.json`; returns the JSON path.
pub fn write(sim: &Simulation, dir: &Path, stem: &str) -> std::io::Result<PathBuf> {
    capture(sim, stem).write(dir, stem)
}

/// `write`, the metadata saying what wrote it (a run's snapshots).
pub fn write_with(
    sim: &Simulation,
    dir: &Path,
    stem: &str,
    provenance: &crate::base::provenance::Provenance,
) -> std::io::Result<PathBuf> {
    let mut snap = capture(sim, stem);
    snap.meta.provenance = Some(provenance.clone());
    snap.write(dir, stem)
}

/// The snapshot of the state in memory, as `read` would give it back once written
/// under `stem`.
pub fn capture(sim: &Simulation, stem: &str) -> Snapshot {
    let p = &sim.particles;
    let dt = sim.dt();
    let ids: Vec<usize> = (0..p.len()).filter(|&i| p.active[i]).collect();
    let f = |g: &dyn Fn(usize) -> f64| Column::F64(ids.iter().map(|&i| g(i)).collect());
    let (len, time, mass) = match sim.scene.units {
        crate::scene::Units::Si => ("m", "s", "kg"),
        crate::scene::Units::Reduced => ("sigma", "sqrt(sigma/g)", "m"),
    };
    let vel = format!("{len}/{time}");
    let force = if sim.scene.units == crate::scene::Units::Si {
        "N".to_string()
    } else {
        "m g".to_string()
    };
    let mut b = Builder::default();
    b.push(
        "particles",
        "id",
        "",
        Column::U32(ids.iter().map(|&i| i as u32).collect()),
    );
    b.push("particles", "x", len, f(&|i| p.q[0][i][0]));
    b.push("particles", "z", len, f(&|i| p.q[0][i][1]));
    b.push("particles", "theta", "rad", f(&|i| p.q[0][i][2]));
    b.push("particles", "vx", &vel, f(&|i| p.q[1][i][0] / dt));
    b.push("particles", "vz", &vel, f(&|i| p.q[1][i][1] / dt));
    b.push(
        "particles",
        "omega",
        &format!("rad/{time}"),
        f(&|i| p.q[1][i][2] / dt),
    );
    b.push("particles", "radius", len, f(&|i| p.radius[i]));
    b.push("particles", "mass", mass, f(&|i| p.mass[i]));
    b.push(
        "particles",
        "fixed",
        "",
        Column::U8(ids.iter().map(|&i| p.fixed[i] as u8).collect()),
    );
    b.push(
        "particles",
        "material",
        "",
        Column::U32(ids.iter().map(|&i| p.material[i]).collect()),
    );
    // Polygons: the corner count per particle (0 for disks), then every corner in the
    // body frame (rotate by theta and add (x, z) for the world frame), particle by
    // particle.
    b.push(
        "particles",
        "corners",
        "",
        Column::U32(ids.iter().map(|&i| p.shape[i].len() as u32).collect()),
    );
    let body = |k: usize| {
        Column::F64(
            ids.iter()
                .flat_map(|&i| p.shape[i].iter().map(move |v| v[k]))
                .collect(),
        )
    };
    b.push("corners", "x", len, body(0));
    b.push("corners", "z", len, body(1));
    // Spheropolygons (rods): the sweep radius about the core the corners give (0 for
    // disks and polygons).
    b.push(
        "particles",
        "sweep",
        len,
        Column::F64(ids.iter().map(|&i| p.sweep[i]).collect()),
    );
    // Copies of the scene (`replicas`): each particle's copy, only when there are copies.
    if sim.scene.replicas > 1 {
        b.push(
            "particles",
            "copy",
            "",
            Column::U32(ids.iter().map(|&i| p.copy[i]).collect()),
        );
    }
    let c = &sim.contacts;
    let pairs = &sim.pairs;
    let cf = |g: &dyn Fn(usize) -> f64| Column::F64((0..c.len()).map(g).collect());
    b.push(
        "contacts",
        "i",
        "",
        Column::U32(pairs.iter().map(|q| q.i).collect()),
    );
    b.push(
        "contacts",
        "j",
        "",
        Column::U32(pairs.iter().map(|q| q.j).collect()),
    );
    b.push("contacts", "nx", "", cf(&|k| c[k].n[0]));
    b.push("contacts", "nz", "", cf(&|k| c[k].n[1]));
    b.push("contacts", "fn", &force, cf(&|k| c[k].f_n));
    b.push("contacts", "ft", &force, cf(&|k| c[k].f_t));
    b.push("contacts", "px", len, cf(&|k| c[k].point[0]));
    b.push("contacts", "pz", len, cf(&|k| c[k].point[1]));
    b.push("contacts", "overlap", len, cf(&|k| c[k].overlap));
    let meta = Meta {
        format: FORMAT.into(),
        version: VERSION,
        scene: sim.scene.name.clone(),
        units: format!("{:?}", sim.scene.units).to_lowercase(),
        step: sim.step,
        time: sim.time(),
        particles: ids.len() as u64,
        contacts: c.len() as u64,
        wall_base: WALL_BASE,
        data: format!("{stem}.bin"),
        columns: b.meta,
        provenance: None,
        checksum: None,
    };
    Snapshot {
        meta,
        columns: b.columns,
    }
}

impl Snapshot {
    /// The `.bin`: the columns back to back at their offsets, little-endian.
    fn encode(&self) -> Vec<u8> {
        let mut bytes = Vec::new();
        for c in &self.meta.columns {
            match self.columns.get(&format!("{}.{}", c.table, c.name)) {
                Some(Column::F64(v)) => v
                    .iter()
                    .for_each(|x| bytes.extend_from_slice(&x.to_le_bytes())),
                Some(Column::U32(v)) => v
                    .iter()
                    .for_each(|x| bytes.extend_from_slice(&x.to_le_bytes())),
                Some(Column::U8(v)) => bytes.extend_from_slice(v),
                None => {}
            }
        }
        bytes
    }

    /// Writes `DIR/STEM.bin`, then `DIR/STEM.json` with the checksum of both; returns
    /// the JSON path.
    pub fn write(&self, dir: &Path, stem: &str) -> std::io::Result<PathBuf> {
        let bin = self.encode();
        write_atomic(&dir.join(format!("{stem}.bin")), &bin)?;
        let json_path = dir.join(format!("{stem}.json"));
        let meta = Meta {
            checksum: Some(digest(&self.meta, &bin)),
            ..self.meta.clone()
        };
        let text = serde_json::to_string_pretty(&meta).map_err(std::io::Error::other)?;
        write_atomic(&json_path, text.as_bytes())?;
        Ok(json_path)
    }
}

/// The checksum of a snapshot: FNV-1a over its data and then its metadata without the
/// checksum (compact JSON), so that a changed byte in either file is noticed; whitespace
/// in the `.json` does not count (it changes no value).
fn digest(meta: &Meta, bin: &[u8]) -> String {
    use crate::base::files::{FNV_START, fnv1a64};
    let bare = Meta {
        checksum: None,
        ..meta.clone()
    };
    let text = serde_json::to_vec(&bare).unwrap_or_default();
    format!("fnv1a64:{:016x}", fnv1a64(fnv1a64(FNV_START, bin), &text))
}

/// Why a snapshot cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum SnapshotError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {source}", path.display())]
    Json {
        path: PathBuf,
        source: serde_json::Error,
    },
    #[error("{}: not a talus snapshot", .0.display())]
    NotASnapshot(PathBuf),
    #[error("column {column}: unknown dtype {dtype}")]
    UnknownDtype { column: String, dtype: String },
    #[error("column {column} runs past the end of {}", data.display())]
    PastTheEnd { column: String, data: PathBuf },
    #[error("{}: {damage}", path.display())]
    Damaged { path: PathBuf, damage: Damage },
    #[error(
        "snapshot {} is damaged: its checksum does not match its data and metadata",
        .0.display()
    )]
    Checksum(PathBuf),
    #[error("{}: version {found} of the snapshot format is newer than this talus reads ({VERSION})", path.display())]
    Newer { path: PathBuf, found: u32 },
}

/// What `check` finds wrong in a snapshot that was read whole.
#[derive(Debug, thiserror::Error)]
pub enum Damage {
    #[error("column {column} holds {len} values, not {want}")]
    Length {
        column: String,
        len: usize,
        want: u64,
    },
    #[error("column {column}: value {index} is {value}")]
    NotFinite {
        column: String,
        index: usize,
        value: f64,
    },
    #[error("{column}: particle {id} is not in the snapshot")]
    UnknownParticle { column: String, id: u32 },
}

/// Reads a snapshot's metadata (its `.json`).
pub fn read_meta(json_path: &Path) -> Result<Meta, SnapshotError> {
    let path = || json_path.to_path_buf();
    let text = std::fs::read_to_string(json_path).map_err(|source| SnapshotError::Io {
        path: path(),
        source,
    })?;
    serde_json::from_str(&text).map_err(|source| SnapshotError::Json {
        path: path(),
        source,
    })
}

/// Reads a snapshot from its `.json` path.
pub fn read(json_path: &Path) -> Result<Snapshot, SnapshotError> {
    let meta = read_meta(json_path)?;
    if meta.format != FORMAT {
        return Err(SnapshotError::NotASnapshot(json_path.to_path_buf()));
    }
    if meta.version > VERSION {
        return Err(SnapshotError::Newer {
            path: json_path.to_path_buf(),
            found: meta.version,
        });
    }
    // The data lies beside the metadata: a plain file name, never a path to elsewhere.
    if Path::new(&meta.data).file_name() != Some(std::ffi::OsStr::new(&meta.data)) {
        return Err(SnapshotError::NotASnapshot(json_path.to_path_buf()));
    }
    let bin = json_path.with_file_name(&meta.data);
    let bytes = std::fs::read(&bin).map_err(|source| SnapshotError::Io {
        path: bin.clone(),
        source,
    })?;
    // From version 2 on a snapshot must carry its checksum; one without it was edited.
    if meta.version >= 2 && meta.checksum.as_deref() != Some(digest(&meta, &bytes).as_str()) {
        return Err(SnapshotError::Checksum(json_path.to_path_buf()));
    }
    let mut columns = BTreeMap::new();
    for c in &meta.columns {
        let size = match c.dtype.as_str() {
            "f64" => 8,
            "u32" => 4,
            "u8" => 1,
            other => {
                return Err(SnapshotError::UnknownDtype {
                    column: c.name.clone(),
                    dtype: other.into(),
                });
            }
        };
        let start = c.offset as usize;
        let end = (c.count as usize)
            .checked_mul(size)
            .and_then(|n| n.checked_add(start))
            .unwrap_or(usize::MAX);
        let raw = bytes
            .get(start..end)
            .ok_or_else(|| SnapshotError::PastTheEnd {
                column: format!("{}.{}", c.table, c.name),
                data: bin.clone(),
            })?;
        let col = match size {
            8 => Column::F64(
                raw.chunks_exact(8)
                    .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
                    .collect(),
            ),
            4 => Column::U32(
                raw.chunks_exact(4)
                    .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
                    .collect(),
            ),
            _ => Column::U8(raw.to_vec()),
        };
        columns.insert(format!("{}.{}", c.table, c.name), col);
    }
    let snap = Snapshot { meta, columns };
    check(&snap).map_err(|damage| SnapshotError::Damaged {
        path: json_path.to_path_buf(),
        damage,
    })?;
    Ok(snap)
}

/// What a reader relies on (issue 16: a damaged or edited snapshot is refused, not
/// indexed out of bounds or drawn with NaN): each table's columns as long as its count,
/// the corners as many as the particles' corner counts add up to, every number finite,
/// and each contact between particles of the snapshot (or a wall).
fn check(s: &Snapshot) -> Result<(), Damage> {
    let m = &s.meta;
    let len = |c: &Column| match c {
        Column::F64(v) => v.len(),
        Column::U32(v) => v.len(),
        Column::U8(v) => v.len(),
    };
    let corners: u64 = (s.u32("particles.corners").unwrap_or(&[]).iter())
        .map(|&c| c as u64)
        .sum();
    for (key, c) in &s.columns {
        let table = key.split('.').next().unwrap_or("");
        let want = match table {
            "particles" => m.particles,
            "contacts" => m.contacts,
            "corners" => corners,
            _ => continue,
        };
        if len(c) as u64 != want {
            return Err(Damage::Length {
                column: key.clone(),
                len: len(c),
                want,
            });
        }
        if let Column::F64(v) = c
            && let Some(k) = v.iter().position(|x| !x.is_finite())
        {
            return Err(Damage::NotFinite {
                column: key.clone(),
                index: k,
                value: v[k],
            });
        }
    }
    let ids: std::collections::HashSet<u32> = (s.u32("particles.id").unwrap_or(&[]).iter())
        .copied()
        .collect();
    for key in ["contacts.i", "contacts.j"] {
        for &id in s.u32(key).unwrap_or(&[]) {
            if !ids.contains(&id) && id < m.wall_base {
                return Err(Damage::UnknownParticle {
                    column: key.into(),
                    id,
                });
            }
        }
    }
    Ok(())
}
