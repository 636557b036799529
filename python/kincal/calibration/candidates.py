"""The candidate effects of a serial robot's model: every library effect (the core's registry) that
applies to the robot and the data's columns, joint compliance as one candidate in the form its
gravity torques take (JointCompliance), their expansion into the core's effects, and the check that
the data carry the columns the effects read. The effect choice (effect_choice.py) and the diagnosis
search these candidates."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal, Optional, Sequence, Union

import numpy as np

from .. import _core
from .._core import Robot
from .fitting import gravity_fitted

if TYPE_CHECKING:
    from .._core import Gravity, MeasurementSet

#: joint_map candidates: orders 1..MAX_MAP_ORDER, the cross-validation chooses
MAX_MAP_ORDER = 8


class JointCompliance:
    """The library's joint_compliance on every gravity-loaded joint (as ``--effects joint_compliance``):
    one candidate, its gravity torques from the model's link masses (``gravity`` "masses") or from
    mass moments fitted with it ("fit": a model without link masses, or --gravity fit)."""
    name = "joint_compliance"
    joint = 0
    order = 0
    harmonics: tuple[int, ...] = ()

    def __init__(self, gravity: Literal["masses", "fit"] = "masses") -> None:
        if gravity not in ("masses", "fit"):
            raise ValueError(f"joint compliance's gravity is 'masses' or 'fit', not '{gravity}'")
        self.gravity = gravity

    @property
    def kind(self) -> _core.EffectKind:
        return _core.effect_kind(self.name)

    @property
    def label(self) -> str:
        return "joint_compliance" if self.gravity == "masses" else "joint_compliance (fitted mass moments)"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, JointCompliance) and other.gravity == self.gravity

    def __hash__(self) -> int:
        return hash(self.label)

    def __repr__(self) -> str:
        return self.label


#: a candidate of the serial robot's search, and an effect of its model: an effect of the core's
#: registry, or joint compliance on every gravity-loaded joint as one
Candidate = Union[_core.Effect, JointCompliance]


def applicable_joints(robot: Robot, kind: _core.EffectKind) -> list[int]:
    """Joints (from 1) where a joint-wise effect applies: the gravity-loaded ones (from the
    identification layout) for an effect that needs gravity, every joint otherwise."""
    if kind.gravity_loaded_only:
        return list(_core.PointModel(robot, 1).layout.loaded)
    return list(range(1, robot.dof + 1))


def loaded_joints(robot: Robot, q_deg: Any, loaded: Sequence[int]) -> list[int]:
    """Of the gravity-loaded joints ``loaded`` (from 1), those whose compliance the core identifies on
    these poses with the model's masses: the largest gravity torque over the poses at least the
    core's min_torque_share of the largest joint's (identifiability's fix_unloaded_compliances)."""
    q = np.atleast_2d(np.asarray(q_deg, dtype=float))
    if not len(q):
        return []
    tmax = np.max(np.abs([_core.gravity_torque(robot, row, False)[0] for row in q]), axis=0)
    top = float(np.max(tmax))
    share = _core.IdentifyOptions().min_torque_share
    return [j for j in loaded if top > 0 and tmax[j - 1] >= share * top]


def candidates(robot: Robot, data: MeasurementSet, start: Sequence[Candidate] = (),
               gravity: str = "auto") -> tuple[list[Candidate], list[str]]:
    """Every candidate effect (a _core.Effect per joint where it applies, from the registry; joint
    compliance as one JointCompliance in the form ``gravity`` gives) the data can support, and notes
    on those skipped. Effects of ``start`` (the model the search starts from) are no candidates."""
    out: list[Candidate] = []
    notes: list[str] = []
    have = {(e.name, e.joint) for e in start}
    for kind in _core.effect_kinds():
        if kind.domain != "serial":
            continue
        col = kind.needs  # the measurement set's attribute of the column the kind reads ('' when none)
        have_col = bool(col) and getattr(data, col) is not None
        if col == "dir" and not have_col:
            notes.append(f"{kind.name} skipped: the data have no dir1..dir{robot.dof} columns")
            continue
        if col == "temperature_c" and (not have_col or np.ptp(np.asarray(data.temperature_c)) <= 0.5):
            notes.append(f"{kind.name} skipped: no temperature_c column, or it does not vary")
            continue
        if col == "time_s" and (not have_col or np.ptp(np.asarray(data.time_s)) <= 0):
            notes.append(f"{kind.name} skipped: no time_s column, or it does not vary")
            continue
        if col and not have_col:
            notes.append(f"{kind.name} skipped: the data have no {col} column")
            continue
        joints = applicable_joints(robot, kind) if kind.concerns == "joint" else [0]
        if kind.gravity_loaded_only:  # one candidate: every gravity-loaded joint
            if joints and not any(e.name == kind.name for e in start):
                fitted = gravity_fitted(robot, gravity)
                out.append(JointCompliance("fit" if fitted else "masses"))
                if fitted:
                    why = "--gravity fit" if gravity == "fit" else "the model has no link masses"
                    notes.append(f"{kind.name} on joints {', '.join(map(str, joints))}: the gravity torques' mass "
                                 f"moments fitted with it ({why})")
            continue
        if kind.ordered:  # the highest order: the engine chooses among its variants
            out += [_core.Effect(kind.name, j, order=MAX_MAP_ORDER) for j in joints if (kind.name, j) not in have]
        else:
            out += [_core.Effect(kind.name, j) for j in joints if (kind.name, j) not in have]
    return out, notes


def expand(effects: Sequence[Candidate], robot: Robot) -> tuple[list[_core.Effect], Optional[Gravity]]:
    """The core's effects of a model (JointCompliance as joint_compliance on every gravity-loaded
    joint) and the gravity mode it needs (None: the options' own)."""
    out: list[_core.Effect] = []
    gravity: Optional[Gravity] = None
    for e in effects:
        if isinstance(e, JointCompliance):
            gravity = e.gravity
            out += [_core.Effect("joint_compliance", j)
                    for j in applicable_joints(robot, _core.effect_kind("joint_compliance"))]
        else:
            out.append(e)
    return out, gravity


def check_data(effects: Sequence[Candidate], data: MeasurementSet, robot: Robot) -> None:
    """The data columns the effects read (the registry's ``needs``) are present: a clear error names
    the file and the column otherwise."""
    # the core's check (JointCompliance reads no column of its own)
    _core.check_effect_columns(robot, data, [e for e in effects if isinstance(e, _core.Effect)])
