"""Simulated measurement campaigns (`kincal simulate`): a true robot drawn with realistic errors,
its measurements by a simulated laser tracker, and the effects hidden in it (`--hide`)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Literal, Optional, Sequence, Union

import numpy as np

from .. import _core
from .._core import Robot

if TYPE_CHECKING:
    from .._core import MeasurementSet

#: reflector offsets (mm, tool frame) used by `kincal simulate --targets N`
DEFAULT_TARGETS = np.array([[0.0, 0.0, 0.0], [120.0, 0.0, 30.0], [0.0, 150.0, -20.0], [-100.0, -80.0, 40.0]])
#: where the simulated laser tracker sees the robot base: x, y, z (mm), a, b, c (deg)
DEFAULT_INSTRUMENT = (3500.0, -1500.0, -400.0, 35.0, 1.5, -0.8)
#: harmonic orders of transmission_error unless --harmonics says otherwise
DEFAULT_HARMONICS = (1, 2)

#: an effect hidden in a simulated truth: (Effect, values), or (name, joint from 1 or 0, values), values in core units
HiddenEffect = Union[tuple[_core.Effect, Sequence[float]], tuple[str, int, Sequence[float]]]


def default_truth(robot: Robot, seed: int = 1, sigma_mm: float = 1.0, sigma_deg: float = 0.05,
                  compliance: float = 0.003) -> Robot:
    """A simulated true robot: realistic geometric errors and joint compliance, seen by an
    instrument at DEFAULT_INSTRUMENT. The same seed with ``compliance=0`` is this robot without its
    compliance (the compliances are drawn, and dropped, in either case)."""
    return robot.with_calibrated(seed, sigma_mm, sigma_deg, compliance, DEFAULT_INSTRUMENT)


def simulate(truth: Robot, poses: int = 150, *, seed: int = 1, noise_mm: float = 0.02, targets: int = 1,
             outlier_fraction: float = 0.0, outlier_mm: float = 5.0, effects: Sequence[HiddenEffect] = (),
             t_ref: float = 20.0, orientation_noise_deg: Optional[float] = None,
             duration_h: Optional[float] = None) -> MeasurementSet:
    """Measure ``poses`` random configurations (inside the joint limits) of the truth's calibrated
    model with ``targets`` reflectors, Gaussian noise per coordinate and optional gross outliers.
    ``effects`` hides more effects in the truth: (Effect, values) or (name, joint from 1 or 0, values),
    the values in the registry's core units (``Effect.units``: radians for transmission_error's sine
    and cosine amplitudes and backlash's offset per direction sign, 1/degC for thermal_expansion about
    t_ref). Every row gets dir1..dirN and
    temperature_c (drifting from 18 to 30 C over the campaign). With ``orientation_noise_deg`` the
    first target's rows are 6-D (a probe measuring the tool frame moved by that target's offset:
    columns a, b, c), the other targets' stay reflector rows. With ``duration_h`` the
    rows get time_s, the campaign running from 0 to that many hours in pose order; a hidden drift
    (mm/h and rad/h) without it gets a 3 h campaign, the drift centred on its mean time."""
    if poses < 1:
        raise ValueError(f"the number of poses must be positive, not {poses}")
    if not 1 <= targets <= len(DEFAULT_TARGETS):
        raise ValueError(f"--targets must be 1..{len(DEFAULT_TARGETS)}, not {targets}")
    if noise_mm < 0 or not math.isfinite(noise_mm):
        raise ValueError(f"the noise must be a finite non-negative number, not {noise_mm}")
    if not 0.0 <= outlier_fraction <= 1.0:
        raise ValueError(f"the outlier fraction must be in 0..1, not {outlier_fraction}")
    if duration_h is not None and not (duration_h > 0 and math.isfinite(duration_h)):
        raise ValueError(f"the campaign's duration must be a positive number of hours, not {duration_h}")
    o = _core.SimulationOptions()
    o.poses, o.seed, o.noise_mm = poses, seed, noise_mm
    o.outlier_fraction, o.outlier_mm = outlier_fraction, outlier_mm
    o.targets = DEFAULT_TARGETS[:targets]
    o.effects = [_effect_value(e) for e in effects]
    o.t_ref = t_ref
    o.orientation_noise_deg = -1.0 if orientation_noise_deg is None else float(orientation_noise_deg)
    o.duration_s = 0.0 if duration_h is None else 3600.0 * float(duration_h)
    return _core.simulate(truth, o)


def simulate_probe(truth: Robot, kind: Literal["sphere", "plane", "distance"], *, stations: int = 3, touches: int = 25, cone_deg: float = 35.0,
                   probe: Sequence[float] = (0.0, 0.0, 150.0), radius_mm: float = 3.0, length_mm: float = 150.0,
                   block_mm: float = 400.0, noise_mm: float = 0.005, seed: int = 1,
                   artifact: bool = True) -> MeasurementSet:
    """A probe campaign (no tracker) on the truth's calibrated model: ``kind`` 'sphere' (the ball in
    ``stations`` fixed nests placed in reach), 'plane' (the faces of one block of ``block_mm``: top,
    the face towards the robot, the sideways ones, the surface plate it stands on) or 'distance' (a ballbar of
    ``length_mm`` at ``stations`` pivots); ``touches`` rows per station, the probe's axis within
    ``cone_deg`` of its station's mean direction, the ball centre at ``probe`` in the tool frame,
    ``noise_mm`` along each constraint. With ``artifact`` the data carry the known distances (from
    the first station) or the block's angles and edge under 'artifact'."""
    if stations < 1 or touches < 1:
        raise ValueError(f"--stations and --touches must be positive, not {stations} and {touches}")
    if noise_mm < 0 or not math.isfinite(noise_mm):
        raise ValueError(f"the noise must be a finite non-negative number, not {noise_mm}")
    o = _core.ProbeSimulationOptions()
    o.kind = kind
    o.stations, o.touches, o.cone_deg = int(stations), int(touches), float(cone_deg)
    o.probe = np.asarray(probe, dtype=float)
    o.radius_mm, o.length_mm, o.block_mm, o.noise_mm = float(radius_mm), float(length_mm), float(block_mm), float(noise_mm)
    o.seed, o.artifact = int(seed), bool(artifact)
    return _core.simulate_probe(truth, o)


def _effect_value(e: HiddenEffect) -> tuple[_core.Effect, list[float]]:
    """(Effect, values) from (Effect, values) or (name, joint from 1 or 0, values)."""
    if len(e) == 2 and isinstance(e[0], _core.Effect):
        return e[0], [float(v) for v in e[1]]
    name, joint, vals = e
    vals = [float(v) for v in vals]
    if _core.effect_kind(str(name)).ordered:  # its order from the number of values: a sine and a cosine per order
        return _core.Effect(str(name), int(joint), order=max(1, len(vals) // 2)), vals
    return _core.Effect(str(name), int(joint)), vals


def parse_hidden_effect(text: str, dof: int,
                        harmonics: Sequence[int] = DEFAULT_HARMONICS) -> tuple[_core.Effect, list[float]]:
    """NAME:JOINT:V1,V2.. of `kincal simulate --hide`: (Effect, values in core units). The values are
    in the model file's units (degrees for angles, 1/C for thermal_expansion: joint 0); their number
    comes from the registry (transmission_error: a sine and a cosine amplitude per harmonic order;
    joint_map: its order is half their number)."""
    parts = text.split(":")
    if len(parts) != 3:
        raise ValueError(f"--hide {text}: expected NAME:JOINT:VALUES")
    name, joint, vals = parts[0], parts[1], parts[2]
    kinds = [k for k in _core.effect_kinds() if k.domain == "serial" and not k.gravity_loaded_only]
    kind = next((k for k in kinds if k.name == name), None)
    if kind is None:
        raise ValueError(f"--hide {text}: unknown effect '{name}' ({', '.join(k.name for k in kinds)})")
    try:
        j = int(joint)
        v = [float(x) for x in vals.split(",")]
    except ValueError:
        raise ValueError(f"--hide {text}: joint and values must be numbers") from None
    if kind.concerns == "joint" and not 1 <= j <= dof:
        raise ValueError(f"--hide {text}: joint {j} is not one of 1..{dof}")
    if kind.ordered:
        if len(v) < 2 or len(v) % 2 or len(v) > 128:
            raise ValueError(f"--hide {text}: {name} takes a sine and a cosine amplitude (deg) per order "
                             "1..K: an even number of values, 2 to 128")
        e = _core.Effect(name, j, order=len(v) // 2)
    else:
        e = _core.Effect(name, j if kind.concerns == "joint" else 0, list(harmonics))
    if len(v) != e.size or not all(math.isfinite(x) for x in v):
        raise ValueError(f"--hide {text}: {e.label} takes {e.size} finite value(s) "
                         f"({', '.join(f'{n} ({u})' for n, u in zip(e.parameter_names, e.file_units))})")
    return e, [x / sc for x, sc in zip(v, e.file_scale)]
