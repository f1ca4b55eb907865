"""Read talus's output into numpy arrays: snapshots (`read_snapshot`) and whole run
folders (`read_run`). The formats are described in docs/FORMATS.md of the repository;
numpy is the only dependency."""

from .snapshot import SnapshotError, read_snapshot
from .run import read_log, read_run, walls_at

__all__ = ["read_snapshot", "read_run", "read_log", "walls_at", "SnapshotError"]
__version__ = "0.1.0"
