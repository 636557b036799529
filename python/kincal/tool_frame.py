"""The tool frame (TCP) placed from known target offsets after an identification."""

from __future__ import annotations

import dataclasses
import json

import numpy as np

from . import _core
from . import strict_json
from ._core import Robot
from .identify import Identification


def tool_from_targets(result: Identification, known: np.ndarray) -> Identification:
    """Reflectors alone cannot tell where the TCP is: the tool frame is redundant with the target
    offsets and stays nominal in the fit. Given the targets' offsets in the tool frame as designed
    or measured on a CMM (``known``, one row per target, mm), the tool frame is moved so that the
    identified targets sit where they should: a rigid fit (Horn) for three or more targets, a
    translation for one or two. Returns the identification with the moved tool and the known
    offsets as its targets (the predicted reflector points do not change)."""
    known = np.asarray(known, dtype=float).reshape(-1, 3)
    ident_t = np.asarray(result.targets, dtype=float)
    if len(known) != len(ident_t):
        raise ValueError(f"{len(known)} known target offsets for {len(ident_t)} identified targets")
    # identified t_k (tool frame M) = T known_k: then M' = M T puts known_k at the same points
    if len(known) >= 3 and np.linalg.matrix_rank(known - known.mean(axis=0), tol=1e-6) >= 2:
        ca, cb = known.mean(axis=0), ident_t.mean(axis=0)
        h = (known - ca).T @ (ident_t - cb)
        u, _, vt = np.linalg.svd(h)
        d = np.diag([1.0, 1.0, np.sign(np.linalg.det(vt.T @ u.T))])
        r = vt.T @ d @ u.T
        t = cb - r @ ca
    else:
        r, t = np.eye(3), (ident_t - known).mean(axis=0)
    doc = json.loads(result.robot.to_json())
    tool = doc["calibrated"]["tool"]
    m_r = _core.abc_to_rotation(np.asarray(tool["abc_deg"], dtype=float))
    m_t = np.asarray(tool["xyz_mm"], dtype=float)
    new_r, new_t = m_r @ r, m_t + m_r @ t
    tool["xyz_mm"] = new_t.tolist()
    tool["abc_deg"] = _abc_of(new_r)
    robot = Robot.from_json(strict_json.dumps(doc), "<identified>")
    return dataclasses.replace(result, robot=robot, targets=known.copy())


def _abc_of(r: np.ndarray) -> list:
    """KUKA ABC (deg) of a rotation matrix, R = Rz(a) Ry(b) Rx(c) (the core's, exact at the pole)."""
    return [float(v) for v in _core.rotation_to_abc(np.asarray(r, dtype=float))]
