"""A run folder as `talus run` writes it (docs/FORMATS.md): `summary.json`, `log.csv`,
`final.json` and `snapshots/`."""

import glob
import json
import os

import numpy as np

from .snapshot import SnapshotError, read_snapshot, _metadata


def read_log(path):
    """`log.csv` as a dict of numpy arrays, one per column (`step`, `time`, energies);
    the `#` lines at its head (which talus runs wrote it) are skipped."""
    path = os.fspath(path)
    if os.path.isdir(path):
        path = os.path.join(path, "log.csv")
    with open(path, encoding="utf-8") as f:
        line = f.readline()
        while line.startswith("#"):  # the runs that wrote it (talus's provenance)
            line = f.readline()
        header = line.strip().split(",")
        rows = np.loadtxt(f, delimiter=",", ndmin=2)
    if rows.size == 0:
        rows = np.zeros((0, len(header)))
    return {name: rows[:, k] for k, name in enumerate(header)}


class Snapshots:
    """The snapshots of a run in time order; each is read (`read_snapshot`) when
    indexed, so a long run's series does not have to fit in memory. `times` and
    `paths` are known without reading the data."""

    def __init__(self, paths, verify):
        metas = [(_metadata(p)[2], p) for p in paths]
        metas.sort(key=lambda m: (m[0]["time"], m[0]["step"]))
        self.times = np.array([m["time"] for m, _ in metas])
        self.paths = [p for _, p in metas]
        self._verify = verify

    def __len__(self):
        return len(self.paths)

    def __getitem__(self, k):
        if isinstance(k, slice):
            return [read_snapshot(p, self._verify) for p in self.paths[k]]
        return read_snapshot(self.paths[k], self._verify)

    def __iter__(self):
        return (read_snapshot(p, self._verify) for p in self.paths)


def read_run(path, verify=True):
    """A run folder: `summary` (dict, None while the run has not finished), `scene`
    (the resolved scene), `log` (`read_log`), `snapshots` (in time order, read lazily:
    `run["snapshots"][-1]`) and `final` (the final snapshot, or None)."""
    path = os.fspath(path)
    if not os.path.isdir(path):
        raise SnapshotError(f"{path}: not a run folder")

    def load(name):
        p = os.path.join(path, name)
        if not os.path.isfile(p):
            return None
        with open(p, encoding="utf-8") as f:
            return json.load(f)

    paths = sorted(glob.glob(os.path.join(path, "snapshots", "*.json")))
    final = os.path.join(path, "final.json")
    log = os.path.join(path, "log.csv")
    return {
        "summary": load("summary.json"),
        "scene": load("scene.json"),
        "log": read_log(log) if os.path.isfile(log) else None,
        "snapshots": Snapshots(paths, verify),
        "final": read_snapshot(final, verify) if os.path.isfile(final) else None,
    }


def walls_at(scene, t):
    """The scene's wall segments where they were at time t, as an array of shape
    (walls, 2, 2) (each wall's two ends, x and z): a wall with a `motion` moved by
    v t + A sin(2 pi t / T), as talus moves it (src/scene/schema.rs
    `WallMotion::displacement`). `scene` is a run's `scene.json` (`read_run(...)["scene"]`)."""
    out = []
    for w in scene.get("walls", []):
        m = w.get("motion") or {}
        v = np.asarray(m.get("velocity", [0.0, 0.0]), dtype=float)
        a = np.asarray(m.get("amplitude", [0.0, 0.0]), dtype=float)
        period = m.get("period")
        omega = 2.0 * np.pi / period if period is not None and np.any(a != 0.0) else 0.0
        d = v * t + a * np.sin(omega * t)
        out.append([np.asarray(w["from"], dtype=float) + d, np.asarray(w["to"], dtype=float) + d])
    return np.array(out, dtype=float).reshape(-1, 2, 2)
