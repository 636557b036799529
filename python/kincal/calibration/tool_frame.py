"""The tool frame (TCP) placed from known target offsets after an identification, and what a model
records of where its TCP comes from (the model file's top-level "tcp": "measured" by 6-D rows,
"tool-targets", or "nominal" when reflectors alone could not place it)."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import numpy as np

from .. import _core
from .._core import Robot

if TYPE_CHECKING:
    from ..typing_ import FloatArray


def tool_from_targets(robot: Robot, targets: FloatArray, known: FloatArray) -> Robot:
    """Reflectors alone cannot tell where the TCP is: the tool frame is redundant with the target
    offsets and stays nominal in the fit. Given the targets' offsets in the tool frame as designed
    or measured on a CMM (``known``, one row per target, mm), the tool frame of an identified
    ``robot`` whose fit placed the targets at ``targets`` is moved so that they sit where they should:
    a rigid fit (Horn) for three or more targets, a translation for one or two. Returns the robot with
    the moved tool (with ``known`` as its targets, the predicted reflector points do not change)."""
    known = np.asarray(known, dtype=float).reshape(-1, 3)
    ident_t = np.asarray(targets, dtype=float)
    if len(known) != len(ident_t):
        raise ValueError(f"{len(known)} known target offsets for {len(ident_t)} identified targets")
    # identified t_k (tool frame M) = T known_k: then M' = M T puts known_k at the same points
    fit = _core.rigid_fit(known, ident_t)  # Horn; a translation for one or two targets, or collinear ones
    r, t = fit[:3, :3], fit[:3, 3]
    tool = robot.calibrated_spec.tool
    m_r = _core.abc_to_rotation(np.asarray(tool.abc_deg, dtype=float))
    m_t = np.asarray(tool.xyz_mm, dtype=float)
    new_r, new_t = m_r @ r, m_t + m_r @ t
    return robot.with_tool(new_t, _core.rotation_to_abc(new_r), "tool-targets")


#: the summary's line on the TCP, by the model's "tcp"
_TCP_LINES = {
    "measured": "TCP: measured (the frame the 6-D rows measure is the tool frame, identified with the rest)",
    "tool-targets": "TCP: placed by --tool-targets (the targets' known offsets in the tool frame)",
    "nominal": "TCP: nominal (reflectors, or a probe's ball, place only themselves, not the tool frame; "
               "--tool-targets or a 6-D row measures it)",
}


def tcp_summary_line(robot: Robot) -> list[str]:
    """The identification summary's line on where the TCP comes from (none when not recorded)."""
    line = _TCP_LINES.get(robot.tcp)
    return [line] if line else []


def warn_nominal_tcp(robot: Robot, source: str, program: str = "kincal") -> None:
    """One warning line on stderr for a model whose TCP is nominal (not measured); nothing otherwise
    (the TCP measured or placed, or a model that does not record it: older files, built-in robots,
    URDFs)."""
    w = robot.tcp_warning(str(source))
    if w:
        print(f"{program}: warning: {w}", file=sys.stderr)
