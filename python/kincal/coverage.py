"""Which joint angles a model was fitted on, and where new data ask it to extrapolate.

An effect periodic in a joint's angle (transmission_error, joint_map) is known only over the angles
its fit saw: beyond them its series goes on, but nothing measured it. The fitted range of each joint
is the shortest arc of the circle holding every fitted angle (angles taken modulo 360 deg, since the
effects are periodic), written ``[lo, hi]`` with ``lo`` in [-180, 180) and ``hi - lo`` its length; a
joint whose fitted angles leave no gap wider than ``FULL_TURN_GAP_DEG`` covers the whole turn."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Optional, Sequence, Union

import numpy as np

#: fitted angles with no gap wider than this between neighbours (deg) cover the whole turn
FULL_TURN_GAP_DEG = 10.0
#: an angle this close to a fitted range (deg) is inside it
MARGIN_DEG = 1.0
#: the effects that are periodic functions of their joint's angle
PERIODIC = ("transmission_error", "joint_map")


def joint_ranges(q_deg: np.ndarray) -> list:
    """Per joint, the fitted range ``[lo, hi]`` (deg) of the rows' angles: the circle less its widest
    gap; ``[-180, 180]`` when no gap is wider than FULL_TURN_GAP_DEG."""
    out = []
    for col in np.atleast_2d(np.asarray(q_deg, dtype=float)).T:
        a = np.sort(np.unique(np.round(np.mod(col + 180.0, 360.0) - 180.0, 9)))
        gaps = np.diff(np.r_[a, a[0] + 360.0])  # gap i: from a[i] to the next angle, going up
        i = int(np.argmax(gaps))
        if gaps[i] <= FULL_TURN_GAP_DEG:
            out.append([-180.0, 180.0])
            continue
        lo = float(a[(i + 1) % len(a)])
        out.append([lo, lo + 360.0 - float(gaps[i])])
    return out


def fitted_ranges(model: Union[str, Path]) -> Optional[list]:
    """A model JSON's ``identification.joint_ranges_deg`` (None for a built-in robot, a URDF or a model
    written before they were recorded)."""
    if not str(model).lower().endswith(".json"):
        return None
    return json.loads(Path(model).read_text()).get("identification", {}).get("joint_ranges_deg")


def outside(q_deg: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Rows whose angle (deg, any turn) lies outside the range [lo, hi] by more than MARGIN_DEG."""
    if hi - lo >= 360.0 - 2 * MARGIN_DEG:
        return np.zeros(len(q_deg), dtype=bool)
    past = np.mod(np.asarray(q_deg, dtype=float) - (lo - MARGIN_DEG), 360.0)  # 0 at the range's start
    return past > hi - lo + 2 * MARGIN_DEG


def extrapolated(robot, ranges: Optional[Sequence], q_deg: np.ndarray) -> list:
    """For each joint whose periodic effects the model carries and whose fitted range the rows leave:
    ``{"joint", "effects", "fitted_deg", "share_outside", "rows_outside"}`` (joints counted from 1).
    Empty without ranges (a model written before they were recorded, or a built-in robot)."""
    if not ranges:
        return []
    q = np.atleast_2d(np.asarray(q_deg, dtype=float))
    per_joint: dict = {}
    for effect, _ in robot.effects:
        if effect.name in PERIODIC:
            per_joint.setdefault(effect.joint, []).append(effect.label)
    out = []
    for joint, labels in sorted(per_joint.items()):
        lo, hi = ranges[joint - 1]
        mask = outside(q[:, joint - 1], lo, hi)
        if mask.any():
            out.append({"joint": joint, "effects": labels, "fitted_deg": [lo, hi],
                        "share_outside": float(mask.mean()), "rows_outside": int(mask.sum())})
    return out


def _share(s: float) -> str:
    return f"{s:.0%}" if s >= 0.005 else f"{s:.1%}"


def summary_lines(found: list) -> list:
    """The warnings of extrapolated(), one line per joint."""
    return [f"warning: {_share(e['share_outside'])} of these rows ({e['rows_outside']}) put joint {e['joint']} outside the "
            f"{e['fitted_deg'][0]:.0f}..{e['fitted_deg'][1]:.0f} deg its {', '.join(e['effects'])} was fitted on "
            f"(angles modulo 360 deg): there the effect is extrapolated, not measured" for e in found]
