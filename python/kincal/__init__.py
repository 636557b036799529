"""kincal: calibration, compensation and derivative analysis of industrial robots.

The hot paths run in the C++ core (``kincal._core``); this package is the typed front over it, in
packages that follow the pipeline: ``calibration`` (identify, priors, setups, the effect choice,
plan), ``diagnose``, ``programs`` (pose and joint files, feed), ``standards`` (ISO 9283, ISO 230-2,
VDI/DGQ 3441), ``fivebar``, ``report``, ``io`` (JSON, CSV, URDF, public data sets), ``stats`` and
``cli`` (the `kincal` command). The modules of the earlier flat layout (``kincal.identify``,
``kincal.feed``, ...) are still reachable by their old names, with a DeprecationWarning.

    >>> import kincal
    >>> robot = kincal.load_robot("kr500")
    >>> poses = kincal.fk(robot, [[0, -90, 90, 0, 90, 0]])      # x,y,z,a,b,c (mm, deg)
    >>> q = kincal.compensate(robot, poses)["q_deg"]
"""

from __future__ import annotations

import importlib
import warnings
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Optional, Sequence, Union

import numpy as np

from . import _core
from ._core import MeasurementSet, Robot
from .io.urdf import urdf_model_json

if TYPE_CHECKING:
    from ._core import CompensationResult, IkSolution, Residual
    from .typing_ import FloatArray

#: the modules of the flat layout of 0.1 and where they are now; reachable by the old name, with a
#: DeprecationWarning, for one release
MOVED = {
    "identify": "calibration.identify", "priors": "calibration.priors", "setups": "calibration.setups",
    "plan": "calibration.plan", "fitting": "calibration.fitting", "gravity": "calibration.gravity",
    "effect_choice": "calibration.effect_choice", "choice_report": "calibration.choice_report",
    "tool_frame": "calibration.tool_frame", "simulation": "calibration.simulation",
    "grouping": "stats.grouping", "stepwise": "stats.stepwise", "robust_scores": "stats.robust_scores",
    "feed": "programs.feed", "kinematics_files": "programs.kinematics_files",
    "accuracy": "standards.accuracy", "iso9283_plan": "standards.iso9283_plan", "accuracy_report": "standards.report",
    "datasets": "io.datasets", "csv_text": "io.csv_text", "urdf": "io.urdf", "strict_json": "io.strict_json",
    "accuracy_demo": "demo.accuracy",
}


def __getattr__(name: str) -> ModuleType:
    """The old flat modules by their old names (MOVED), with a DeprecationWarning."""
    if name in MOVED:
        warnings.warn(f"kincal.{name} is now kincal.{MOVED[name]}; the old name goes in the next release",
                      DeprecationWarning, stacklevel=2)
        return importlib.import_module(f".{MOVED[name]}", __name__)
    raise AttributeError(f"module 'kincal' has no attribute '{name}'")


__all__ = ["Robot", "MeasurementSet", "load_robot", "fk", "ik", "compensate", "run_program", "jacobian", "line_program", "__version__"]
__version__ = "0.1.0"

ArrayLike = Union[np.ndarray, Sequence[Sequence[float]]]
#: one value, or one per pose (temperatures; initial directions: one per joint)
Floats = Union[None, float, Sequence[float], np.ndarray]


def load_robot(name_or_path: Union[str, Path], base: Optional[str] = None, tip: Optional[str] = None,
               joint_convention: Optional[str] = None) -> Robot:
    """A robot by built-in name (``kr500``), URDF file (chain ``base`` to ``tip``) or model JSON;
    ``joint_convention`` (``fanuc``) says how the controller numbers the joints (a URDF's or built-in
    robot's; a model JSON carries its own)."""
    s = str(name_or_path)
    robot = Robot.from_json(urdf_model_json(s, base, tip), s) if s.lower().endswith(".urdf") else Robot.load(s)
    return robot.with_joint_convention(s, joint_convention or "")


def fk(robot: Robot, q_deg: ArrayLike, calibrated: bool = True, frame: str = "base",
       dir: Optional[ArrayLike] = None, temperature_c: Floats = None) -> FloatArray:
    """Tool poses (N x 6: x,y,z mm, a,b,c deg) for joint angles in degrees (N x dof), every effect
    of the model acting: ``dir`` (N x dof signs +-1, the direction of each joint's last motion into
    the pose) when it has backlash, ``temperature_c`` (one value or N) when it has thermal expansion."""
    if frame not in ("base", "instrument"):
        raise ValueError(f"frame must be 'base' or 'instrument', not '{frame}'")
    q = np.atleast_2d(np.asarray(q_deg, dtype=float))
    d = None if dir is None else np.atleast_2d(np.asarray(dir, dtype=float))
    t = None if temperature_c is None else np.broadcast_to(np.asarray(temperature_c, dtype=float), (len(q),)).copy()
    return _core.fk(robot, q, calibrated, frame == "instrument", d, t)


def run_program(robot: Robot, q_deg: ArrayLike, *, initial_direction: Floats = None,
                temperature_c: Floats = None, frame: str = "base") -> FloatArray:
    """The tool poses a robot reaches when it runs a joint program (N x 6 joint angles in degrees,
    in order): each joint's direction into each pose is the sign of its commanded change, held while
    it stands still (the first pose's from ``initial_direction``, default the direction of the first
    motion), as backlash sees it; ``temperature_c`` for thermal expansion."""
    q = np.atleast_2d(np.asarray(q_deg, dtype=float))
    init = [] if initial_direction is None else [float(v) for v in np.atleast_1d(initial_direction)]
    d = _core.motion_directions(q, init) if robot.needs_dir else None
    return fk(robot, q, frame=frame, dir=d, temperature_c=temperature_c)


def jacobian(robot: Robot, q_deg: Sequence[float], calibrated: bool = True) -> FloatArray:
    """6 x dof geometric Jacobian at the tool point (linear mm/rad, angular rad/rad), base frame."""
    return _core.jacobian(robot, np.asarray(q_deg, dtype=float), calibrated)


def ik(robot: Robot, pose: Sequence[float], ref_deg: Optional[Sequence[float]] = None) -> list[IkSolution]:
    """Every closed-form solution of the nominal model for one pose x,y,z,a,b,c (up to 8).

    Each is a dict with ``q_deg``, ``within_limits``, ``wrist_singular``, ``shoulder_singular``;
    an empty list means the pose is out of reach."""
    return _core.ik_all(robot, np.asarray(pose, dtype=float), None if ref_deg is None else list(ref_deg))


def compensate(robot: Robot, poses: ArrayLike, *, compensate: bool = True, finite_difference: bool = False,
               delta: float = 1e-8, epsilon: float = 1e-15, max_iterations: int = 20,
               corrected_start: bool = True, frame: str = "base", residual: Residual = "rotation_vector",
               temperature_c: Floats = None,
               initial_direction: Floats = None, keep_branch: bool = False) -> CompensationResult:
    """Machine coordinates for desired tool poses (N x 6, in program order) on the robot's calibrated
    model, every effect it carries acting: backlash with the directions of the program's own
    commanded motion (the first pose's from ``initial_direction``, default the direction of the
    first motion), thermal expansion at ``temperature_c`` (one value or one per pose). Newton's
    orientation residual is the rotation vector (``residual="abc"``: the paper's eq. 6).

    Returns ``q_deg`` (N x 6), ``iterations`` and ``residual`` (|F| of eq. 9) per pose, ``dir``
    (each joint's direction into each pose, zeros without backlash) and ``warnings`` (branch changes)."""
    p = np.atleast_2d(np.asarray(poses, dtype=float))
    temps = None
    if temperature_c is not None:
        temps = np.broadcast_to(np.asarray(temperature_c, dtype=float), (len(p),)).copy()
    init = [] if initial_direction is None else [float(v) for v in np.atleast_1d(initial_direction)]
    options = _core.ProgramOptions(compensate=compensate, instrument=frame == "instrument",
                                   finite_difference=finite_difference, delta=delta, epsilon=epsilon,
                                   max_iterations=max_iterations, corrected_start=corrected_start, residual=residual,
                                   initial_direction=init, keep_branch=keep_branch)
    return _core.compensate_poses(robot, p, options, temps)


def line_program(start: Sequence[float] = (2000.0, -740.0, 500.0), direction: Sequence[float] = (0.0, 1.0, 0.0),
                 count: int = 297, step_mm: float = 5.0, abc: Sequence[float] = (180.0, 0.0, 180.0)) -> FloatArray:
    """The Samak paper's use case: a straight tool path of ``count`` poses ``step_mm`` apart at
    constant orientation (297 x 5 mm, about 1500 mm, tool pointing down)."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    xyz = np.asarray(start, dtype=float)[None, :] + np.arange(count)[:, None] * step_mm * d[None, :]
    return np.hstack([xyz, np.tile(np.asarray(abc, dtype=float), (count, 1))])
