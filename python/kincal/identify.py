"""Measurement campaigns and parameter identification (the Samak paper's calibration step 3).

A measurement set is a dict of numpy arrays (``pose``, ``q_deg``, ``xyz``, ``target``,
``payload_kg``, ``line``, ``source``), the rows of the contract's measurement CSV.
The heavy work (residuals, analytic Jacobian, Ceres) runs in the C++ core.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Callable, Optional, Sequence

import numpy as np

from . import _core
from ._core import Robot

#: reflector offsets (mm, tool frame) used by `kincal simulate --targets N`
DEFAULT_TARGETS = np.array([[0.0, 0.0, 0.0], [120.0, 0.0, 30.0], [0.0, 150.0, -20.0], [-100.0, -80.0, 40.0]])
#: where the simulated laser tracker sees the robot base: x, y, z (mm), a, b, c (deg)
DEFAULT_INSTRUMENT = (3500.0, -1500.0, -400.0, 35.0, 1.5, -0.8)
#: the effects identify knows (contract names)
IDENTIFY_EFFECTS = ("joint_compliance",)
KNOWN_EFFECTS = ("joint_compliance", "transmission_error", "backlash", "thermal_expansion", "link_deflection")


def default_truth(robot: Robot, seed: int = 1, sigma_mm: float = 1.0, sigma_deg: float = 0.05,
                  compliance: float = 0.003) -> Robot:
    """A simulated true robot: realistic geometric errors and joint compliance, seen by an
    instrument at DEFAULT_INSTRUMENT."""
    return robot.with_calibrated(seed, sigma_mm, sigma_deg, compliance, DEFAULT_INSTRUMENT)


def simulate(truth: Robot, poses: int = 150, *, seed: int = 1, noise_mm: float = 0.02, targets: int = 1,
             outlier_fraction: float = 0.0, outlier_mm: float = 5.0, effects: Sequence = (),
             t_ref: float = 20.0, orientation_noise_deg: Optional[float] = None) -> dict:
    """Measure ``poses`` random configurations (inside the joint limits) of the truth's calibrated
    model with ``targets`` reflectors, Gaussian noise per coordinate and optional gross outliers.
    ``effects`` hides more effects in the truth: (name, joint from 1 or 0, values) with the values in
    radians (transmission_error: sin q, cos q, sin 2q, cos 2q amplitudes; backlash: offset per
    direction sign) or per degree C (thermal_expansion, about t_ref). Every row gets dir1..dirN and
    temperature_c (drifting from 18 to 30 C over the campaign). With ``orientation_noise_deg`` the
    tool frame's orientation is measured too (a 6-D probe): columns a, b, c."""
    if poses < 1:
        raise ValueError(f"the number of poses must be positive, not {poses}")
    if not 1 <= targets <= len(DEFAULT_TARGETS):
        raise ValueError(f"--targets must be 1..{len(DEFAULT_TARGETS)}, not {targets}")
    if noise_mm < 0 or not math.isfinite(noise_mm):
        raise ValueError(f"the noise must be a finite non-negative number, not {noise_mm}")
    if not 0.0 <= outlier_fraction <= 1.0:
        raise ValueError(f"the outlier fraction must be in 0..1, not {outlier_fraction}")
    return _core.simulate(truth, poses, seed, noise_mm, outlier_fraction, outlier_mm, DEFAULT_TARGETS[:targets], 0.9,
                          [(str(n), int(j), [float(v) for v in vals]) for n, j, vals in effects], t_ref,
                          -1.0 if orientation_noise_deg is None else float(orientation_noise_deg))


def select_observable(robot: Robot, candidates: dict, poses: int, compliance: bool = True) -> dict:
    """Choose ``poses`` of the candidate campaign's poses that maximise observability: greedy
    D-optimal design on the nominal model's identification Jacobian (unit-scaled columns of the
    parameters a generic campaign identifies), each step adding the pose that most increases
    log det of the information matrix. Returns the chosen rows."""
    n_targets = int(np.max(candidates["target"])) + 1
    res = _core.identify(robot, candidates, compliance, "none", 0.1, 0, [], None, False, False)
    free = ~np.asarray(res["fixed"])
    pm = _core.PointModel(robot, n_targets)
    _, J = pm.residuals(list(res["x"]), candidates, True)
    J = np.asarray(J)[:, free]
    J = J / np.maximum(np.linalg.norm(J, axis=0), 1e-300)
    ids = np.unique(candidates["pose"])
    if poses >= len(ids):
        return candidates
    rows_of = {int(i): np.repeat(np.flatnonzero(candidates["pose"] == i) * 3, 3) + np.tile([0, 1, 2],
               int(np.sum(candidates["pose"] == i))) for i in ids}
    p = J.shape[1]
    info = 1e-6 * np.eye(p)
    chosen: list[int] = []
    left = [int(i) for i in ids]
    for _ in range(poses):
        inv = np.linalg.inv(info)
        best, gain = left[0], -np.inf
        for i in left:
            Ji = J[rows_of[i]]
            # log det(I + Ji inv Ji^T): the information this pose adds
            g = np.linalg.slogdet(np.eye(len(Ji)) + Ji @ inv @ Ji.T)[1]
            if g > gain:
                best, gain = i, g
        chosen.append(best)
        left.remove(best)
        info += J[rows_of[best]].T @ J[rows_of[best]]
    return subset(candidates, np.isin(candidates["pose"], chosen))


def read_measurements(path: str, robot: Robot) -> dict:
    """The measurement CSV of the contract (errors name file:line and cause)."""
    return _core.read_measurements(str(path), robot.dof)


def measurements_csv(data: dict, dof: int) -> str:
    return _core.format_measurements(data, dof)


def subset(data: dict, mask: np.ndarray) -> dict:
    out = {k: (v[mask] if isinstance(v, np.ndarray) else v) for k, v in data.items()}
    return out


def split_poses(data: dict, holdout: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Boolean row masks (fit, held out): a random share ``holdout`` of the pose ids is held out."""
    ids = np.unique(data["pose"])
    rng = np.random.default_rng(seed)
    n_out = int(round(holdout * len(ids)))
    out_ids = rng.choice(ids, size=n_out, replace=False) if n_out else np.array([], dtype=ids.dtype)
    held = np.isin(data["pose"], out_ids)
    return ~held, held


def folds(data: dict, k: int, seed: int = 0) -> list[np.ndarray]:
    """k boolean masks of held-out rows, poses dealt at random into k folds."""
    ids = np.unique(data["pose"])
    rng = np.random.default_rng(seed)
    perm = rng.permutation(ids)
    return [np.isin(data["pose"], perm[i::k]) for i in range(k)]


def _rms(e: np.ndarray) -> float:
    return float(np.sqrt(np.mean(e ** 2))) if len(e) else float("nan")


@dataclass
class Identification:
    """What `kincal identify` found: the calibrated robot, targets, parameters and validation."""
    robot: Robot
    targets: np.ndarray
    fit: dict
    effects: list
    validation: dict = field(default_factory=dict)

    def parameters(self) -> list:
        f = self.fit
        return [{"name": n, "unit": u, "value": float(v), "stddev": (None if math.isnan(s) else float(s)),
                 "fixed": bool(fx), "reason": r}
                for n, u, v, s, fx, r in zip(f["names"], f["units"], f["x"], f["stddev"], f["fixed"],
                                             f["fixed_reason"])]

    def model_json(self) -> str:
        d = json.loads(self.robot.to_json())
        f = self.fit
        d["identification"] = {
            "effects": self.effects,
            "targets_mm": self.targets.tolist(),
            "parameters": self.parameters(),
            "condition_number": f["condition_number"],
            "observability_index": f["observability_index"],
            "correlations": [{"a": a, "b": b, "r": r} for a, b, r in f["correlations"]],
            "iterations": f["iterations"],
            "fit": {"rows": int(self.validation.get("fit_rows", 0)), "rms_mm": f["rms_mm"], "max_mm": f["max_mm"],
                    "nominal_rms_mm": f["nominal_rms_mm"], "nominal_max_mm": f["nominal_max_mm"]},
            "validation": self.validation,
        }
        return json.dumps(d, indent=1, sort_keys=True) + "\n"

    def summary(self) -> str:
        f, v = self.fit, self.validation
        lines = [f"identified {sum(not x for x in f['fixed'])} of {len(f['names'])} parameters "
                 f"({', '.join(['geometry'] + self.effects)}) in {f['iterations']} iterations"]
        lines.append("")
        lines.append(f"{'position error (mm)':<28}{'RMS before':>12}{'RMS after':>12}{'max before':>12}{'max after':>12}")
        lines.append(f"{'fitted poses':<28}{f['nominal_rms_mm']:>12.4f}{f['rms_mm']:>12.4f}"
                     f"{f['nominal_max_mm']:>12.4f}{f['max_mm']:>12.4f}")
        if v.get("held_rows"):
            lines.append(f"{'held-out poses (' + v['scheme'] + ')':<28}{v['before_rms_mm']:>12.4f}{v['after_rms_mm']:>12.4f}"
                         f"{v['before_max_mm']:>12.4f}{v['after_max_mm']:>12.4f}")
        if "after_rms_deg" in v:
            lines.append(f"{'orientation (deg), held out':<28}{v['before_rms_deg']:>12.4f}{v['after_rms_deg']:>12.4f}"
                         f"{v['before_max_deg']:>12.4f}{v['after_max_deg']:>12.4f}")
        lines.append("")
        lines.append(f"condition number {f['condition_number']:.4g}, observability index {f['observability_index']:.4g}")
        fixed = [(n, r) for n, fx, r in zip(f["names"], f["fixed"], f["fixed_reason"]) if fx]
        if fixed:
            lines.append("held at their start value:")
            for n, r in fixed:
                lines.append(f"  {n:<22} {r}")
        if f["correlations"]:
            lines.append("strong correlations:")
            for a, b, r in f["correlations"][:20]:
                lines.append(f"  {a:<22} {b:<22} {r:+.3f}")
        lines.append("parameters (value +- standard deviation):")
        for p in self.parameters():
            if not p["fixed"]:
                sd = "" if p["stddev"] is None else f" +- {p['stddev']:.3g}"
                lines.append(f"  {p['name']:<22} {p['value']:+.6g}{sd} {p['unit']}")
        return "\n".join(lines)


def _fit(robot: Robot, data: dict, effects: Sequence[str], loss: str, loss_scale_mm: float,
         progress: Optional[Callable[[int, float], None]] = None, orientation_weight: float = 100.0) -> dict:
    return _core.identify(robot, data, "joint_compliance" in effects, loss, loss_scale_mm, 100, [], progress,
                          False, True, [], [], orientation_weight)


def orientation_errors_deg(robot: Robot, data: dict) -> np.ndarray:
    """Angle (deg) between the measured and the predicted tool orientation of every 6-D row."""
    pred = _core.fk(robot, np.asarray(data["q_deg"], dtype=float), True, True)
    out = np.empty(len(pred))
    for i, (p, m) in enumerate(zip(pred[:, 3:], data["abc"])):
        r = _core.abc_to_rotation(m).T @ _core.abc_to_rotation(p)
        out[i] = math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(r) - 1) / 2))))
    return out


def check_effects(effects: Sequence[str]) -> list:
    out = []
    for e in effects:
        if e not in KNOWN_EFFECTS:
            raise ValueError(f"unknown effect '{e}' (known: {', '.join(KNOWN_EFFECTS)})")
        if e not in IDENTIFY_EFFECTS:
            raise ValueError(f"effect '{e}' is not available in identify (available: {', '.join(IDENTIFY_EFFECTS)})")
        out.append(e)
    return out


def identify(robot: Robot, data: dict, *, effects: Sequence[str] = ("joint_compliance",), loss: str = "huber",
             loss_scale_mm: float = 0.1, holdout: float = 0.25, k_folds: int = 0, seed: int = 0,
             progress: Optional[Callable[[int, float], None]] = None,
             orientation_weight: float = 100.0) -> Identification:
    """Identify the robot's parameters from measurements.

    Validation: ``k_folds`` > 1 fits k times, each time predicting the fold it did not see;
    otherwise a share ``holdout`` of the poses is held out. The returned model is fitted on all rows
    (k-fold) or on the fitted rows (split)."""
    effects = check_effects(effects)
    if loss not in ("none", "huber", "cauchy"):
        raise ValueError(f"unknown loss '{loss}' (none, huber, cauchy)")
    if k_folds == 1 or k_folds < 0:
        raise ValueError("--folds must be 0 (a split) or at least 2")
    if not 0.0 <= holdout < 1.0:
        raise ValueError(f"--holdout must be in [0, 1), not {holdout}")
    val: dict = {}
    if k_folds > 1:
        e_before, e_after = [], []
        for held in folds(data, k_folds, seed):
            r = _fit(robot, subset(data, ~held), effects, loss, loss_scale_mm, None, orientation_weight)
            e_after.append(_core.point_errors(r["robot"], r["targets"], subset(data, held)))
            e_before.append(_core.point_errors(r["nominal_fitted"], r["nominal_targets"], subset(data, held)))
        fit_mask = np.ones(len(data["pose"]), dtype=bool)
        eb, ea = np.concatenate(e_before), np.concatenate(e_after)
        val = {"scheme": f"{k_folds}-fold", "held_rows": int(len(ea))}
    else:
        fit_mask, held = split_poses(data, holdout, seed)
        val = {"scheme": f"{holdout:.0%} held out", "held_rows": int(held.sum())}
    r = _fit(robot, subset(data, fit_mask), effects, loss, loss_scale_mm, progress, orientation_weight)
    if k_folds <= 1 and val["held_rows"]:
        held_data = subset(data, ~fit_mask)
        ea = _core.point_errors(r["robot"], r["targets"], held_data)
        eb = _core.point_errors(r["nominal_fitted"], r["nominal_targets"], held_data)
    if val["held_rows"]:
        val.update(before_rms_mm=_rms(eb), after_rms_mm=_rms(ea), before_max_mm=float(np.max(eb)),
                   after_max_mm=float(np.max(ea)))
        if "abc" in data and k_folds <= 1:
            held_data = subset(data, ~fit_mask)
            ob = orientation_errors_deg(r["nominal_fitted"], held_data)
            oa = orientation_errors_deg(r["robot"], held_data)
            val.update(before_rms_deg=_rms(ob), after_rms_deg=_rms(oa), before_max_deg=float(np.max(ob)),
                       after_max_deg=float(np.max(oa)))
    val["fit_rows"] = int(fit_mask.sum())
    return Identification(robot=r["robot"], targets=np.asarray(r["targets"]), fit=r, effects=list(effects),
                          validation=val)


def validate(robot: Robot, data: dict, loss: str = "huber", loss_scale_mm: float = 0.1) -> dict:
    """Accuracy of an identified robot on another measurement series, where the instrument may stand
    elsewhere and the probe may sit differently: only the base frame and the targets are refitted
    (on the calibrated geometry, and on the nominal one for the "before")."""
    names = list(_core.PointModel(robot, int(np.max(data["target"])) + 1).names)
    frames_only = [n for n in names if not (n.startswith("base.") or n.startswith("target"))]
    cal = _core.identify(robot, data, False, loss, loss_scale_mm, 100, frames_only, None, True, False)
    nom = _core.identify(robot, data, False, loss, loss_scale_mm, 100, frames_only, None, False, False)
    ea = _core.point_errors(cal["robot"], cal["targets"], data)
    eb = _core.point_errors(nom["robot"], nom["targets"], data)
    return {"rows": int(len(ea)), "before_rms_mm": _rms(eb), "after_rms_mm": _rms(ea),
            "before_max_mm": float(np.max(eb)), "after_max_mm": float(np.max(ea))}


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
    robot = Robot.from_json(json.dumps(doc), "<identified>")
    fit = dict(result.fit)
    fit["robot"] = robot
    return Identification(robot=robot, targets=known.copy(), fit=fit, effects=result.effects,
                          validation=result.validation)


def _abc_of(r: np.ndarray) -> list:
    """KUKA ABC (deg) of a rotation matrix, R = Rz(a) Ry(b) Rx(c)."""
    b = math.degrees(math.atan2(-r[2, 0], math.hypot(r[0, 0], r[1, 0])))
    a = math.degrees(math.atan2(r[1, 0], r[0, 0]))
    c = math.degrees(math.atan2(r[2, 1], r[2, 2]))
    return [a, b, c]
