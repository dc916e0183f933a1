"""What the Python tests share: the repository's folders, the CLI they compare with, the keys
of `results.npz`, and a bit-for-bit comparison of arrays."""

import os
import subprocess
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples"
FRETDYN = os.environ.get("FRETDYN", str(ROOT / "target" / "release" / "fretdyn"))
KEYS = [
    "t", "q", "qdot", "contact_normal_force", "contact_tangential_force",
    "contact_slip_velocity", "contact_penetration", "contact_status", "contact_position",
]


def cli(args, cwd):
    """Runs the `fretdyn` command (the FRETDYN binary) with `args` in `cwd`."""
    return subprocess.run([FRETDYN, *args], cwd=cwd, capture_output=True, text=True)


def same_bits(a, b):
    """Whether two arrays have the same shape, type and bits."""
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()
