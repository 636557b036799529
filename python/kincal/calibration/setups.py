"""Campaigns measured from several instrument placements (the ``setup`` column): simulated ones
for tests and demos, the robot seen from a named placement, and the table of `kincal validate`.
The joint identification of every placement and the validation itself are in identify.py."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Iterable, Mapping, Optional, Sequence

import numpy as np

from .. import _core
from .._core import Robot
from .fitting import DEFAULT_LOSS_SCALE_MM, FitOptions, orientation_errors_deg, rms
from .simulation import simulate

if TYPE_CHECKING:
    from .._core import Loss, MeasurementSet
    from ..typing_ import BoolArray, FloatArray


def simulate_setups(truth: Robot, placements: Mapping[str, Sequence[float]], poses: int = 150, *, seed: int = 1,
                    **options: Any) -> MeasurementSet:
    """A campaign measured from several instrument placements: ``placements`` maps each setup's
    name to the robot base frame seen from the instrument there, (x, y, z mm, a, b, c deg). Each
    setup measures ``poses`` random configurations (its own seed, ``seed`` + its index) with the
    options of simulate(); the rows are concatenated in the order of ``placements``, pose ids
    running on, with the ``setup`` column (and time_s running on from setup to setup when the
    options ask for a duration). The truth's own placement is not used."""

    if len(placements) < 1:
        raise ValueError("simulate_setups: at least one placement")
    parts = []
    t0 = 0.0
    for k, (name, frame) in enumerate(placements.items()):
        f = [float(v) for v in frame]
        if len(f) != 6:
            raise ValueError(f"simulate_setups: placement {name}: x, y, z, a, b, c")
        d = simulate(truth.with_placements([(str(name), f[:3], f[3:])]), poses, seed=seed + k, **options)
        c = d.columns()
        c["pose"] = d.pose + k * poses
        c["setup"] = np.full(len(d), k, dtype=np.int64)
        if d.time_s is not None:  # one setup after the other
            c["time_s"] = d.time_s + t0
            t0 = float(d.time_s[-1]) + t0 + 60.0
        parts.append(c)
    # the parts' columns (the same in each): the arrays' rows concatenated, the rest the first part's
    out = {key: (np.concatenate([p[key] for p in parts]) if isinstance(parts[0][key], np.ndarray)
                 else parts[0][key]) for key in parts[0]}
    out["setup_names"] = [str(n) for n in placements]
    return _core.MeasurementSet(out, truth.dof)


def with_setups(truth: Robot, placements: Mapping[str, Sequence[float]]) -> Robot:
    """The truth seen from the placements of simulate_setups (by name): what its points are
    compared with (point_errors)."""
    return truth.with_placements([(str(n), [float(v) for v in f[:3]], [float(v) for v in f[3:]])
                                  for n, f in placements.items()])


def robot_for_setup(robot: Robot, name: str, source: str = "the model") -> Robot:
    """The robot seen from its placement ``name`` (fk and compensate --frame instrument use the
    model's first placement otherwise). ValueError naming the known setups when it has no such."""
    known = [n for n, _, _ in robot.placements]
    for n, xyz, abc in robot.placements:
        if n == name:
            return robot.with_placements([(n, [float(v) for v in xyz], [float(v) for v in abc])])
    have = ", ".join(known) if known != [""] else "none: it was identified from one placement"
    raise ValueError(f"{source}: no setup '{name}' (setups: {have})")


def validation_summary(v: dict[str, Any]) -> str:
    """The table of identify's summary for a validation (validate()'s result): RMS, mean (the Samak
    paper's figure) and largest position error before (the nominal model) and after (the calibrated
    one), the placements refitted on both; per setup when there are several, and the orientation
    when measured."""
    lines = [f"{'position error (mm)':<28}{'RMS before':>12}{'RMS after':>12}{'mean before':>12}"
             f"{'mean after':>12}{'max before':>12}{'max after':>12}"]

    def row(label: str, f: dict[str, Any], unit: str = "mm") -> None:
        lines.append(f"{label:<28}" + "".join(f"{f[f'{w}{s}_{unit}']:>12.4f}" for s in ("rms", "mean", "max")
                                              for w in ("before_", "")))

    row(f"new points ({v['points']})", v)
    for name, f in v.get("setups", {}).items():
        row(f"  setup {name} ({f['points']})", f)
    if "rms_deg" in v:
        row("orientation (deg)", v, "deg")
        for name, f in v.get("setups", {}).items():
            row(f"  setup {name}", f, "deg")
    lines.append("")
    lines.append(f"refitted: {v['refitted']}")
    loss = v.get("loss")
    if loss and loss["scale_mm"]:
        lines.append(f"robust loss: {loss['name']} bending at {loss['scale_mm']:.4f} mm (from {loss['scale_from']})")
    lines += [f"warning: {e['message']}" for e in v.get("extrapolated", [])]
    return "\n".join(lines)



def setup_frames(placements: Iterable[tuple[str, Iterable[float], Iterable[float]]]) -> list[dict[str, Any]]:
    """Placements as (name, xyz, abc) (an IdentifyResult's or a Robot's) in files: {"name",
    "base_in_instrument": {"xyz_mm", "abc_deg"}} per setup, in the data's order."""
    return [{"name": n, "base_in_instrument": {"xyz_mm": [float(v) for v in xyz], "abc_deg": [float(v) for v in abc]}}
            for n, xyz, abc in placements]


def drift_report(fit: _core.IdentifyResult) -> Optional[dict[str, Any]]:
    """The instrument's drift an identification found (a property of the measurement: removed from
    the fit, never compensated), in the model file's units with standard deviations, or None."""
    found = [i for i, e in enumerate(fit.layout.effect_list) if e.kind.of_instrument]
    if not found:
        return None
    e, off = fit.layout.effect_list[found[0]], fit.layout.effect_offset[found[0]]
    vals, sd = np.asarray(fit.x)[off:off + e.size], np.asarray(fit.stddev)[off:off + e.size]
    return {"t_mean_s": fit.t_mean_s,
            "note": "the instrument's placement moving with time_s about t_mean_s (a base point x is seen at "
                    "Exp(tau w) R x + t + tau v, tau in hours, v and w in the instrument's axes): removed from the "
                    "fit, never applied by fk or compensate",
            "parameters": [{"name": n, "value": float(v * sc), "stddev": None if math.isnan(d) else float(d * sc),
                            "unit": u}
                           for n, v, d, sc, u in zip(e.parameter_names, vals, sd, e.file_scale, e.file_units)]}


def validation_figures(after: FloatArray, before: FloatArray, o_after: Optional[FloatArray],
                       o_before: Optional[FloatArray], data: MeasurementSet) -> dict[str, Any]:
    """The figures of `kincal validate` from the position errors (mm) after (the calibrated model)
    and before (the nominal one) and, with measured orientations, the orientation errors (deg):
    ``points``, ``rms_mm``, ``mean_mm``, ``max_mm``, ``before_rms_mm`` (``before_mean_mm``,
    ``before_max_mm``; ``rms_deg``, ``mean_deg``, ``max_deg``, ``before_rms_deg``,
    ``before_mean_deg``, ``before_max_deg``), the same per setup under ``setups`` when the data have several, and
    ``rows``, ``after_rms_mm``, ``after_max_mm`` (the names of earlier versions)."""
    ea, eb = np.asarray(after), np.asarray(before)
    # the orientation errors are those of the 6-D rows (reflector rows among them have NaN a, b, c)
    six_d = (~np.isnan(np.asarray(data.abc, dtype=float)[:, 0]) if data.abc is not None
             else np.ones(len(ea), dtype=bool))

    def figures(mask: BoolArray) -> dict[str, Any]:
        out: dict[str, Any] = {"points": int(mask.sum()), "rms_mm": rms(ea[mask]), "mean_mm": float(np.mean(ea[mask])),
               "max_mm": float(np.max(ea[mask])), "before_rms_mm": rms(eb[mask]),
               "before_mean_mm": float(np.mean(eb[mask])), "before_max_mm": float(np.max(eb[mask]))}
        if o_after is not None and o_before is not None and np.any(mask[six_d]):
            oa, ob = np.asarray(o_after)[mask[six_d]], np.asarray(o_before)[mask[six_d]]
            out.update(rms_deg=rms(oa), mean_deg=float(np.mean(oa)), max_deg=float(np.max(oa)),
                       before_rms_deg=rms(ob), before_mean_deg=float(np.mean(ob)), before_max_deg=float(np.max(ob)))
        return out

    v = figures(np.ones(len(ea), dtype=bool))
    v.update(rows=v["points"], after_rms_mm=v["rms_mm"], after_max_mm=v["max_mm"])
    if data.setup is not None and data.setup_names is not None and len(data.setup_names) > 1:
        codes = np.asarray(data.setup)
        v["setups"] = {name: figures(codes == k) for k, name in enumerate(data.setup_names) if np.any(codes == k)}
    return v


def _refit_placements(robot: Robot, data: MeasurementSet, loss: Loss = "huber",
                      loss_scale_mm: Optional[float] = DEFAULT_LOSS_SCALE_MM,
                      target_start: Optional[Sequence[Sequence[float]]] = None) -> tuple[
        FloatArray, FloatArray, Optional[FloatArray], Optional[FloatArray], _core.IdentifyResult]:
    """validate()'s errors: every row's position error after refitting only the placements and
    targets, on the calibrated model (after) and the nominal one (before); orientation errors (or
    None); and the calibrated refit. The robust loss bends as in every fit (FitOptions): at
    ``loss_scale_mm``, or (None, 0) where the residuals' robust spread puts it."""

    def frames_only(calibrated: bool) -> _core.IdentifyResult:
        # the calibrated geometry may load a joint the nominal one does not: each its own names
        layout = _core.PointModel(robot, int(np.max(data.target)) + 1, [], 20.0, calibrated, []).layout
        held = [p.name for p in layout.parameters if p.kind not in ("base", "target")]
        opts = _core.IdentifyOptions(compliance=False, loss=loss, loss_scale_mm=loss_scale_mm or 0.0, fix=held,
                                     covariance=False)
        if target_start is not None:
            opts.target_start = [np.asarray(t, dtype=float) for t in target_start]
        return _core.identify(robot, data, opts, None, calibrated)

    cal, nom = frames_only(True), frames_only(False)
    ea = np.asarray(_core.point_errors(cal.robot, cal.targets, data, cal.stations))
    eb = np.asarray(_core.point_errors(nom.robot, nom.targets, data, nom.stations))
    oa = ob = None
    if data.abc is not None:
        oa, ob = orientation_errors_deg(cal.robot, data), orientation_errors_deg(nom.robot, data)
    return ea, eb, oa, ob, cal


def extrapolated(robot: Robot, q_deg: FloatArray) -> list[dict[str, Any]]:
    """Where rows of joint angles take the robot's periodic effects outside the angles they were
    fitted on (_core.extrapolated), as the records of validate()'s ``extrapolated``."""
    n = len(q_deg)
    return [{"joint": e.joint, "effects": e.effects, "fitted_deg": list(e.fitted_deg), "rows_outside": e.rows,
             "share_outside": e.rows / n, "message": e.message(n, "rows")}
            for e in _core.extrapolated(robot, np.asarray(q_deg, dtype=float))]


def inside_and_outside(robot: Robot, data: MeasurementSet, loss: Loss = "huber",
                       loss_scale_mm: Optional[float] = DEFAULT_LOSS_SCALE_MM) -> dict[str, dict[str, Any]]:
    """validate()'s RMS (after, before) split between the rows that take none of the robot's periodic
    effects outside their fitted ranges and the rows that take one: ``{"inside": {"rows",
    "rms_mm", "before_rms_mm"}, "outside": {...}}`` (the placements refitted on every row)."""
    ea, eb, _, _, _ = _refit_placements(robot, data, loss, loss_scale_mm)
    q = np.asarray(data.q_deg, dtype=float)
    out = np.zeros(len(q), dtype=bool)
    for e in _core.extrapolated(robot, q):
        out |= np.asarray(_core.outside_range(q[:, e.joint - 1], e.fitted_deg))

    def part(m: BoolArray) -> dict[str, Any]:
        return {"rows": int(m.sum()), "rms_mm": rms(ea[m]), "before_rms_mm": rms(eb[m])}

    return {"inside": part(~out), "outside": part(out)}


def validate(robot: Robot, data: MeasurementSet, loss: Loss = "huber",
             loss_scale_mm: Optional[float] = DEFAULT_LOSS_SCALE_MM,
             target_start: Optional[Sequence[Sequence[float]]] = None) -> dict[str, Any]:
    """Accuracy of an identified robot on another measurement campaign, where the instrument stands
    elsewhere (each setup of the data its own placement) and the reflectors or probe may sit
    differently: only the placements and the target offsets are refitted, on the calibrated
    geometry (every effect it carries acting, its drift left out: that was the other campaign's)
    and, for the "before", on the nominal one. Returns the contract's figures (``points``,
    ``rms_mm``, ``mean_mm``, ``max_mm``, ``before_rms_mm``; with measured orientations ``rms_deg``,
    ``mean_deg``), ``before_mean_mm``, ``before_max_mm``, per setup the same under ``setups`` and
    the refitted ``placements``; ``rows``, ``after_rms_mm``, ``after_max_mm`` repeat them under the
    names of earlier versions. ``extrapolated``: the joints whose periodic effects these rows ask for
    outside the angles the model was fitted on (``robot.fitted_ranges_deg``), each ``{"joint",
    "effects", "fitted_deg", "rows_outside", "share_outside", "message"}``. ``loss``: the robust loss of
    the calibrated model's refit (``name``, ``scale_mm``: where it bent, ``noise_mm``: the residuals'
    robust spread when it was estimated, ``scale_from``; None for ``loss`` "none"): as in identify and
    diagnose, where the residuals' robust spread puts it unless ``loss_scale_mm`` is given; the nominal
    model's refit (the "before") bends by the same rule on its own residuals."""
    FitOptions(loss=loss, loss_scale_mm=loss_scale_mm)  # the fits' own checks of the loss and its scale
    ea, eb, oa, ob, cal = _refit_placements(robot, data, loss, loss_scale_mm, target_start)
    v = validation_figures(ea, eb, oa, ob, data)
    v.update(source=str(data.source), targets_mm=np.asarray(cal.targets).tolist(),
             refitted="the instrument placement of every setup and the target offsets"
                      + (", the probe stations" if data.station_names else "")
                      + "; the model's geometry and effects held (its drift left out)",
             placements=setup_frames(cal.setups),
             extrapolated=extrapolated(robot, data.q_deg),
             loss={"name": loss, "scale_mm": cal.loss_scale_mm or None, "noise_mm": cal.noise_mm or None,
                   "scale_from": None if loss == "none" else
                   "--loss-scale" if loss_scale_mm else "the residuals' robust spread"})
    return v
