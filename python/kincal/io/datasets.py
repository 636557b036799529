"""Readers for public measurement data sets (converted to kincal's measurement sets)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .._core import MeasurementSet, abc_to_rotation, rotation_to_abc

if TYPE_CHECKING:
    from ..typing_ import FloatArray

UR_JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
             "wrist_3_joint"]


def read_ipa(path: str | Path, orientation: bool = False) -> MeasurementSet:
    """A series of the UR10 laser-tracker data of Landgraf et al. (CASE 2021; ../shared/data/
    ipa-robot-accuracy): ';' separated, ',' decimal mark, joints in rad, the T-Mac probe's position
    in the tracker frame in mm. Returns a measurement set (one target: the probe) with the
    temperature (deg C) of every row as ``temperature_c``; with ``orientation`` also the probe's measured
    orientation (intrinsic XYZ Euler angles in the file) as KUKA ABC angles ``abc``: 6-D poses."""
    path = Path(path)
    try:
        lines = path.read_text().splitlines()
    except OSError as e:
        raise ValueError(f"{path}: {e.strerror}") from None
    if not lines:
        raise ValueError(f"{path}: empty file")
    header = [h.strip() for h in lines[0].split(";")]
    need = UR_JOINTS + ["measurement_x", "measurement_y", "measurement_z", "measurement_temperature",
                        "measurement_rx", "measurement_ry", "measurement_rz"]
    for name in need:
        if name not in header:
            raise ValueError(f"{path}:1: missing column '{name}'")
    col = [header.index(n) for n in need]
    rows = []
    for i, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        f = line.split(";")
        try:
            rows.append([float(f[c].replace(",", ".")) for c in col])
        except (ValueError, IndexError):
            raise ValueError(f"{path}:{i}: a field is missing or not a number") from None
    a = np.asarray(rows, dtype=float)
    if not np.all(np.isfinite(a)):
        bad = int(np.argwhere(~np.isfinite(a))[0, 0])
        raise ValueError(f"{path}: row {bad + 2}: not a finite number")
    n = len(a)
    out: dict[str, object] = {
        "pose": np.arange(n, dtype=np.int32),
        "q_deg": np.degrees(a[:, :6]),
        "xyz": a[:, 6:9].copy(),
        "target": np.zeros(n, dtype=np.int32),
        "payload_kg": np.full(n, np.nan),
        "line": np.arange(2, n + 2, dtype=np.int32),
        "source": str(path),
        "temperature_c": a[:, 9].copy(),
    }
    if orientation:
        out["abc"] = np.array([_abc_of_xyz_intrinsic(*np.radians(r)) for r in a[:, 10:13]])
    return MeasurementSet(out, 6)


def _abc_of_xyz_intrinsic(rx: float, ry: float, rz: float) -> FloatArray:
    """KUKA ABC (deg) of the rotation Rx(rx) Ry(ry) Rz(rz) (intrinsic XYZ Euler angles, rad)."""
    # intrinsic X, Y, Z is the product Rx Ry Rz; each factor is a KUKA rotation with one angle set
    r = (abc_to_rotation(np.array([0.0, 0.0, np.degrees(rx)]))
         @ abc_to_rotation(np.array([0.0, np.degrees(ry), 0.0]))
         @ abc_to_rotation(np.array([np.degrees(rz), 0.0, 0.0])))
    return rotation_to_abc(r)
