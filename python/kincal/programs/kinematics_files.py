"""`kincal fk` and `kincal ik` on the contract's files: a joint program in, tool poses out (every
effect of the model acting, with the context columns its effects read), and a pose program in,
nominal closed-form joint angles out."""

from __future__ import annotations

import json
import sys
from typing import TYPE_CHECKING, Optional, Sequence, Union

import numpy as np

from .. import _core, fk, ik
from ..io.csv_text import format_rows, header, text_columns

if TYPE_CHECKING:
    from ..typing_ import FloatArray


def effect_columns(path: str, robot: _core.Robot, n: int, temperature: Optional[float]) -> dict[str, FloatArray]:
    """What the model's effects read from a joint file of ``n`` rows: ``dir`` from dir1..dirN
    (backlash) and ``temperature_c`` (thermal expansion, unless ``temperature`` is given); a missing
    column is an error naming it."""
    out: dict[str, FloatArray] = {}
    if robot.needs_temperature and temperature is not None:
        out["temperature_c"] = np.full(n, float(temperature))
    if not (robot.needs_dir or (robot.needs_temperature and temperature is None)):
        return out
    head = header(path) if path.lower().endswith(".csv") else []
    if robot.needs_dir:
        names = [f"dir{j + 1}" for j in range(robot.dof)]
        missing = [c for c in names if c not in head]
        if missing:
            raise ValueError(f"{path}:1: missing column '{missing[0]}': the model has backlash, which needs each "
                             f"joint's direction of motion into the pose (dir1..dir{robot.dof}, +1 or -1)")
        d = _core.read_csv_columns(path, names)
        bad = np.argwhere((d != 1.0) & (d != -1.0))
        if len(bad):
            raise ValueError(f"{path}: row {bad[0][0] + 1}: column '{names[bad[0][1]]}': "
                             f"{d[bad[0][0], bad[0][1]]:g} is not +1 or -1")
        out["dir"] = d
    if robot.needs_temperature and temperature is None:
        if "temperature_c" not in head:
            raise ValueError(f"{path}:1: missing column 'temperature_c': the model has thermal expansion "
                             "(or give --temperature C)")
        out["temperature_c"] = _core.read_csv_columns(path, ["temperature_c"])[:, 0]
    return out


def carried_targets(robot_arg: str) -> Optional[FloatArray]:
    """Target offsets (tool frame, mm) an identified model JSON carries, or None."""
    if str(robot_arg).lower().endswith(".json"):
        with open(robot_arg) as f:
            d = json.load(f)
        t = d.get("identification", {}).get("targets_mm")
        if t:
            return np.asarray(t, dtype=float)
    return None


def identified_targets(robot_arg: str) -> FloatArray:
    """Target offsets (tool frame, mm) an identified model JSON carries; only the tool point otherwise."""
    t = carried_targets(robot_arg)
    return np.zeros((1, 3)) if t is None else t


def fk_file(robot: _core.Robot, robot_arg: str, joints: str, out: str, frame: str = "base",
            temperature: Optional[float] = None) -> None:
    """`kincal fk`: the poses of the joint program ``joints`` written to ``out`` (x,y,z,a,b,c per row,
    after the pose and target columns when the input has them: then the rows are the targets'
    points, from the offsets the model ``robot_arg`` identified)."""
    if frame == "instrument" and not robot.identified:
        raise ValueError(f"{robot_arg}: --frame instrument needs an identified model (kincal identify)")
    q, _ = _core.read_joint_program(joints, robot.dof)
    q = _core.joints_from_controller(robot, np.asarray(q, dtype=float).reshape(-1, robot.dof))  # controller's numbers
    ctx = effect_columns(joints, robot, len(q), temperature)
    poses = fk(robot, q, frame=frame, dir=ctx.get("dir"), temperature_c=ctx.get("temperature_c"))
    extra = text_columns(joints, ["pose", "target"]) if joints.lower().endswith(".csv") else {}
    if "target" in extra:
        targets = identified_targets(robot_arg)
        for i, t in enumerate(extra["target"]):
            try:
                k = int(t)
            except ValueError:
                raise ValueError(f"{joints}:{i + 2}: column 'target': '{t}' is not an integer") from None
            if not 0 <= k < len(targets):
                raise ValueError(f"{joints}:{i + 2}: target {t} but the model knows {len(targets)} target(s)")
            if targets[k].any():
                poses[i, :3] = poses[i, :3] + _core.abc_to_rotation(poses[i, 3:]) @ targets[k]
    elif frame == "instrument" and identified_targets(robot_arg).any():
        # a user with one reflector expects the reflector: say what the rows are
        print(f"kincal fk: {joints} has no target column: the rows are the tool frame's poses, not the "
              f"identified targets' points (add a target column to predict those)", file=sys.stderr)
    head = list(extra) + ["x", "y", "z", "a", "b", "c"]
    rows = [[extra[k][i] for k in extra] + list(p) for i, p in enumerate(poses)]
    _core.write_file_atomic(out, format_rows(head, rows))


def _controller(robot: _core.Robot, q: Union[Sequence[float], FloatArray]) -> list[float]:
    """One configuration as the controller numbers its joints (the robot's joint convention)."""
    return list(_core.joints_to_controller(robot, np.asarray(q, dtype=float).reshape(1, -1))[0])


def ik_file(robot: _core.Robot, robot_arg: str, poses_path: str, out: str, every: bool = False) -> None:
    """`kincal ik`: nominal closed-form IK of the pose program ``poses_path`` written to ``out``, each
    pose's solution nearest the previous one (the first nearest the robot's home); ``every``: all
    solutions, each row with ``row``, ``solution`` and ``within_limits``."""
    if not robot.closed_form_ik:
        raise ValueError(f"{robot_arg}: no closed-form IK for this robot ({robot.ik_reason})")
    poses, lines = _core.read_pose_program(poses_path)
    ref = list(robot.home_deg) or [0.0] * robot.dof
    rows: list[list[float]] = []  # integers (row, solution, within_limits) and angles
    for i, (pose, line) in enumerate(zip(poses, lines)):
        sols = ik(robot, pose, ref)
        if not sols:
            raise ValueError(f"{poses_path}:{line}: pose out of reach of the robot (no IK solution)")
        if every:
            rows += [[i, k, int(s["within_limits"])] + _controller(robot, s["q_deg"]) for k, s in enumerate(sols)]
        best = _core.ik_nearest(robot, np.asarray(pose, dtype=float), np.asarray(ref, dtype=float))
        if best is None:
            raise ValueError(f"{poses_path}:{line}: no IK solution within the joint limits")
        ref = list(sols[best]["q_deg"])
        if not every:
            rows.append(_controller(robot, ref))
    qn = [f"q{j + 1}" for j in range(robot.dof)]
    head = ["row", "solution", "within_limits"] + qn if every else qn
    _core.write_file_atomic(out, format_rows(head, rows))
