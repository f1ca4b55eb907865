"""A snapshot: `NAME.json` (metadata) beside `NAME.bin` (little-endian columns), as
docs/FORMATS.md "Snapshots" describes them."""

import json
import os

import numpy as np

FORMAT = "talus-snapshot"
VERSIONS = (1, 2)
DTYPES = {"f64": "<f8", "u32": "<u4", "u8": "u1"}
FNV_START = 0xCBF29CE484222325
FNV_PRIME = 0x100000001B3
MASK = (1 << 64) - 1


class SnapshotError(ValueError):
    """A snapshot that cannot be read: missing, not a talus snapshot, or damaged."""


def fnv1a64(h, data):
    """FNV-1a (64 bits) over `data`, continuing from `h` (src/base/files.rs `fnv1a64`)."""
    for b in data:
        h = ((h ^ b) * FNV_PRIME) & MASK
    return h


def _compact_without_checksum(text):
    """The metadata as talus hashed it: its JSON without whitespace outside strings and
    without the trailing `checksum` member (serde_json's compact form of the same
    values, numbers written as they stand in the file)."""
    out, in_string, escaped = [], False, False
    for ch in text:
        if in_string:
            out.append(ch)
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_string = False
        elif ch == '"':
            in_string = True
            out.append(ch)
        elif not ch.isspace():
            out.append(ch)
    compact = "".join(out)
    at = compact.rfind(',"checksum":')
    if at < 0:
        raise SnapshotError("metadata has no checksum")
    return compact[:at] + "}"


def _metadata(path):
    path = os.fspath(path)
    if path.endswith(".bin"):
        path = path[: -len(".bin")] + ".json"
    elif os.path.isdir(path):
        path = os.path.join(path, "final.json")
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise SnapshotError(f"{path}: {e.strerror}") from None
    try:
        meta = json.loads(text)
    except json.JSONDecodeError as e:
        raise SnapshotError(f"{path}: not JSON ({e})") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise SnapshotError(f"{path}: not a talus snapshot (format is not {FORMAT!r})")
    if meta.get("version") not in VERSIONS:
        raise SnapshotError(
            f"{path}: snapshot version {meta.get('version')}; this reader knows {VERSIONS}"
        )
    return path, text, meta


def read_columns(path, verify=True):
    """The metadata and every column of a snapshot, keyed `table.name` (`particles.x`,
    `contacts.fn`, `corners.x`), as numpy arrays. `verify` checks the checksum of
    version-2 snapshots (FNV-1a over the data, then the metadata), as talus does."""
    path, text, meta = _metadata(path)
    data = meta.get("data", "")
    if not data or os.path.basename(data) != data:
        raise SnapshotError(f"{path}: `data` must be a file name beside it, got {data!r}")
    bin_path = os.path.join(os.path.dirname(os.path.abspath(path)), data)
    try:
        with open(bin_path, "rb") as f:
            raw = f.read()
    except OSError as e:
        raise SnapshotError(f"{bin_path}: {e.strerror}") from None
    if verify and meta["version"] >= 2:
        want = meta.get("checksum", "")
        h = fnv1a64(fnv1a64(FNV_START, raw), _compact_without_checksum(text).encode())
        if want != f"fnv1a64:{h:016x}":
            raise SnapshotError(
                f"{path}: damaged: its checksum does not match its data and metadata"
            )
    columns = {}
    for c in meta["columns"]:
        dtype = DTYPES.get(c["dtype"])
        if dtype is None:
            raise SnapshotError(f"{path}: column {c['name']}: unknown dtype {c['dtype']!r}")
        size = np.dtype(dtype).itemsize * c["count"]
        if c["offset"] + size > len(raw):
            raise SnapshotError(f"{path}: column {c['name']} runs past the end of {data}")
        columns[f"{c['table']}.{c['name']}"] = np.frombuffer(
            raw, dtype=dtype, count=c["count"], offset=c["offset"]
        )
    return meta, columns


def read_snapshot(path, verify=True):
    """One snapshot as a dict of numpy arrays, from its `.json` (or `.bin`, or a run
    folder for its `final.json`), from any working directory:

    - `position` (N, 2), `velocity` (N, 2), `angle`, `angular_velocity`, `radius`,
      `mass`, `id`, `fixed` (bool), `material`, `corners` (0 for a disk), `sweep`:
      the particles in id order;
    - `vertices`: for each particle its polygon's corners in the world frame ((k, 2)
      arrays; empty for disks);
    - `contacts`: `i`, `j` (ids; `j >= wall_base` is wall `j - wall_base`), `normal`
      (M, 2) from j to i, `normal_force`, `tangential_force`, `force` (M, 2) on i,
      `point` (M, 2), `overlap`;
    - `time`, `step`, `scene`, `units`, `wall_base`, `provenance` (what wrote it: version,
      commit, command line, threads, backend; None in older snapshots), and `columns`
      (every column by its `table.name` key).
    """
    meta, col = read_columns(path, verify)

    def get(key):
        if key not in col:
            raise SnapshotError(f"{path}: no column {key}")
        return col[key]

    pair = lambda a, b: np.column_stack([get(a), get(b)])  # noqa: E731
    corners = get("particles.corners").astype(np.int64)
    angle = get("particles.theta")
    position = pair("particles.x", "particles.z")
    vertices, start = [], 0
    cx, cz = col.get("corners.x", np.zeros(0)), col.get("corners.z", np.zeros(0))
    for k, (p, a) in enumerate(zip(position, angle)):
        n = corners[k]
        body = np.column_stack([cx[start : start + n], cz[start : start + n]])
        c, s = np.cos(a), np.sin(a)
        vertices.append(p + body @ np.array([[c, s], [-s, c]]))
        start += n
    normal = pair("contacts.nx", "contacts.nz")
    fn, ft = get("contacts.fn"), get("contacts.ft")
    tangent = np.column_stack([-normal[:, 1], normal[:, 0]])
    return {
        "time": meta["time"],
        "step": meta["step"],
        "scene": meta["scene"],
        "units": meta["units"],
        "wall_base": meta["wall_base"],
        "provenance": meta.get("provenance"),
        "id": get("particles.id"),
        "position": position,
        "velocity": pair("particles.vx", "particles.vz"),
        "angle": angle,
        "angular_velocity": get("particles.omega"),
        "radius": get("particles.radius"),
        "mass": get("particles.mass"),
        "fixed": get("particles.fixed").astype(bool),
        "material": get("particles.material"),
        "corners": corners,
        "sweep": col.get("particles.sweep", np.zeros(len(angle))),
        "vertices": vertices,
        "contacts": {
            "i": get("contacts.i"),
            "j": get("contacts.j"),
            "normal": normal,
            "normal_force": fn,
            "tangential_force": ft,
            "force": fn[:, None] * normal + ft[:, None] * tangent,
            "point": pair("contacts.px", "contacts.pz"),
            "overlap": get("contacts.overlap"),
        },
        "columns": col,
    }
