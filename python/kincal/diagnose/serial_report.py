"""The report of a serial robot's diagnosis: figures (the gap shrinking step by step, residual maps
before and after, residuals against each named effect's variable) and report.html."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any, Optional, Union

import numpy as np

from .. import _core
from .. import report
from .._core import Robot
from . import residual_vars
from ..stats.stepwise import noise_phrase
from .serial import Spec, step_effect

if TYPE_CHECKING:
    from .._core import MeasurementSet
    from ..calibration.effect_choice import Candidate
    from ..typing_ import BoolArray, FloatArray


def _label(step: dict[str, Any]) -> str:
    e = step_effect(step)
    return e.label + (f", order {e.order}" if e.kind.ordered else "")


def _variable(robot: Robot, data: MeasurementSet, effect: str, joint: Optional[int]) -> tuple[FloatArray, str]:
    """The natural variable of an effect for plots: (values per point, axis label)."""
    j = joint or 1
    kind = _core.effect_kind(effect)
    if kind.harmonic:
        return data.q_deg[:, j - 1], f"q{joint} (deg)"
    if kind.needs == "dir":
        return np.asarray(data.dir)[:, j - 1] + np.random.default_rng(0).uniform(-0.15, 0.15, len(data)), \
            f"dir{joint} (sign of the last motion, jittered)"
    if kind.needs == "temperature_c":
        return np.asarray(data.temperature_c, dtype=np.float64), "temperature (C)"
    if kind.needs == "time_s":
        return np.asarray(data.time_s) / 3600.0, "time of the measurement (h)"
    if joint is None:  # compliance of every loaded joint: the shoulder's gravity torque, when the masses are known
        tau = residual_vars.gravity_torques(robot, data.q_deg)[:, 1] / 1000.0
        return (tau, "gravity torque on joint 2 (kN m)") if np.ptp(tau) > 0 else (data.q_deg[:, 1], "q2 (deg)")
    tau = residual_vars.gravity_torques(robot, data.q_deg)[:, j - 1] / 1000.0
    return tau, f"gravity torque on joint {joint} (kN m)"


#: a row whose point the joint moves less than this share of the median row's (|J_j|) implies no
#: readable angle error of that joint: a residual of microns reads as degrees there
LEVER = 0.25


def _joint_error(res: _core.IdentifyResult, data: MeasurementSet, joint: int) -> tuple[FloatArray, BoolArray]:
    """The angle error of ``joint`` (deg) each row's residual implies: the least-squares joint-angle
    change that would close it (-J_j . r / J_j . J_j, J_j the joint's column at the fit); and which
    rows the joint moves enough (|J_j| at least LEVER times the median row's) to read it."""
    r, C = residual_vars.carriers(res, data)
    n = len(data.pose)
    Jj = C[:, 6 + joint - 1].reshape(n, -1)
    rr = r.reshape(n, -1)
    lever = np.sqrt(np.sum(Jj * Jj, axis=1))
    err = -np.degrees(np.sum(Jj * rr, axis=1) / np.maximum(lever ** 2, 1e-300))
    return err, lever >= LEVER * np.median(lever)


def _effect_curve(res: _core.IdentifyResult, data: MeasurementSet, effect: Candidate,
                  var: FloatArray) -> Optional[tuple[FloatArray, FloatArray]]:
    """The identified effect as a joint-angle change (deg) along its variable, sorted, less its mean
    over the points (a constant change is the joint's offset, which the geometry carries, so the
    residuals never show it), or None (thermal_expansion)."""
    if effect.kind.gravity_loaded_only:
        c = [float(x) for p, x in zip(res.layout.parameters, res.x) if p.kind == "compliance" and p.joint == effect.joint]
        xs = np.sort(var)
        return (xs, c[0] * (xs - np.mean(var))) if c else None  # deg/kNm * kN m
    vals = next((v for e, v in res.robot.effects if e == effect), None)
    if vals is None or effect.kind.acts_on != "joint_angle":
        return None
    if effect.kind.reads_dir:  # drawn at the two directions only (var: the jittered signs)
        return np.array([-1.0, 1.0]), np.degrees(vals[0]) * (np.array([-1.0, 1.0]) - np.mean(np.sign(var)))

    def dq(deg: FloatArray) -> FloatArray:
        t = np.radians(deg)
        change: FloatArray = np.degrees(sum(vals[2 * i] * np.sin(k * t) + vals[2 * i + 1] * np.cos(k * t)
                                            for i, k in enumerate(effect.harmonics)))
        return change

    xs = np.linspace(float(np.min(var)), float(np.max(var)), 400)
    return xs, dq(xs) - float(np.mean(dq(np.asarray(var, dtype=float))))


def _step_figure(plt: ModuleType, robot: Robot, data: MeasurementSet, k: int, st: dict[str, Any],
                 before_fit: _core.IdentifyResult, after_fit: _core.IdentifyResult, path: Path) -> None:
    """The residual against the variable that carries a step's effect, before and after it was
    added: as the joint's implied angle error for a joint-angle effect (with the identified effect's
    curve), as the point error otherwise."""
    effect = step_effect(st)
    var, lab = _variable(robot, data, st["effect"], st["joint"])
    fig, ax = plt.subplots(figsize=(7.5, 3.4), constrained_layout=True)
    notes = []
    if effect.joint > 0:
        (b, seen), (a, _) = _joint_error(before_fit, data, effect.joint), _joint_error(after_fit, data, effect.joint)
        if not seen.all():
            notes.append(f"{int(np.sum(~seen))} points the joint barely moves left out")
        var, b, a = var[seen], b[seen], a[seen]
        lim = float(np.percentile(np.abs(b), 99.5)) * 1.3 or 1.0
        clipped = int(np.sum((np.abs(b) > lim) | (np.abs(a) > lim)))
        if clipped:
            notes.append(f"{clipped} beyond +-{lim * 1000:.0f} mdeg drawn on the frame")
        ax.scatter(var, np.clip(b, -lim, lim) * 1000, s=6, alpha=0.5, label="before")
        ax.scatter(var, np.clip(a, -lim, lim) * 1000, s=6, alpha=0.5, label="after")
        curve = _effect_curve(after_fit, data, effect, var)
        if curve is not None and effect.kind.reads_dir:  # one level per direction
            ax.hlines(curve[1] * 1000, curve[0] - 0.15, curve[0] + 0.15, color="k", lw=2.5, label="identified effect")
        elif curve is not None:
            ax.plot(curve[0], curve[1] * 1000, color="k", lw=1.5, label="identified effect")
        ax.set_ylabel(f"joint {effect.joint} angle error (mdeg)")
    else:
        ax.scatter(var, _point_errors(before_fit, data) * 1000, s=6, alpha=0.6, label="before")
        ax.scatter(var, _point_errors(after_fit, data) * 1000, s=6, alpha=0.6, label="after")
        ax.set_ylabel("point error (um)")
    ax.set_xlabel(lab)
    ax.set_title(f"step {k + 1}: {_label(st)}" + (f"\n({'; '.join(notes)})" if notes else ""), fontsize=10)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)  # beside the data, never on it
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _compact(model: str) -> str:
    """A model's label with the joints of each effect gathered: "geometry + joint_compliance(2, 3)"
    for "geometry + joint_compliance(joint 2) + joint_compliance(joint 3)"."""
    joints: dict[str, list[str]] = {}
    for part in model.split(" + "):
        name, _, rest = part.partition("(")
        joints.setdefault(name, []).extend([rest.rstrip(")").replace("joint ", "")] if rest else [])
    return " + ".join(f"{n}({', '.join(j)})" if j else n for n, j in joints.items())


def _p(p: float) -> str:
    """A p-value for the table (one that underflows to 0 is below what a double holds, not 0)."""
    return f"{p:.2g}" if p > 0 else "< 1e-300"


def _share(share: float) -> str:
    """A held-out share for the table: below zero the variable explains nothing (its fit only adds noise)."""
    return f"{share:.1%}" if share > 0 else f"none ({share:.1%})"


def _point_errors(res: _core.IdentifyResult, data: MeasurementSet) -> FloatArray:
    return _core.point_errors(res.robot, res.targets, data)


def _variables_figure(plt: ModuleType, scores: list[dict[str, Any]], path: Path) -> None:
    """The held-out share of the residual each candidate variable explains, one bar each, signed (a
    share below zero: fitting the variable only adds noise, the bar goes left of zero)."""
    fig, ax = plt.subplots(figsize=(8, 1.0 + 0.28 * len(scores)), constrained_layout=True)
    y = np.arange(len(scores))[::-1]
    vals = [100 * s["share"] for s in scores]
    carries = 100 * residual_vars.CARRIES
    ax.barh(y, vals, color=["tab:red" if v >= carries else ("tab:gray" if v > 0 else "silver") for v in vals])
    for yy, v in zip(y, vals):  # the value beside the bar's end, outside it
        ax.text(v, yy, f" {v:.1f}%" if v > 0 else f"{v:.1f}% ", va="center", ha="left" if v > 0 else "right",
                fontsize=8)
    ax.set_yticks(y, [s["variable"] for s in scores], fontsize=8)
    lo, hi = min(0.0, min(vals)), max(10.0, max(vals))
    ax.set_xlim(lo - 0.25 * (hi - lo) if lo < 0 else 0.0, hi * 1.25)
    ax.axvline(0.0, color="k", lw=0.8)
    ax.axvline(carries, color="k", ls=":", lw=0.8)
    ax.text(carries, len(scores) - 0.5, f" {carries:.0f}%: carries the rest", fontsize=8, va="bottom")
    ax.set_ylim(-0.7, len(scores) + 0.1)
    ax.set_xlabel("share of the final residual's variance a smooth function of the variable explains, held out (%)")
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _residual_figure(plt: ModuleType, data: MeasurementSet, e0: FloatArray, e1: FloatArray, path: Path) -> None:
    """The rows' errors with the starting model (e0) and the final one (e1): a map of the measured
    points in the instrument frame; for a campaign with probe rows each row's error along its
    constraint against the configurations, one colour per station (tracker points as one more)."""
    station = np.asarray(data.station) if data.station is not None else np.full(len(data), -1)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    if np.any(station >= 0):
        names = list(data.station_names or [])
        groups = [(k, names[k]) for k in range(len(names))] + ([(-1, "tracker points")] if np.any(station < 0) else [])
        row = np.arange(len(station))
        for ax, e, lab in ((axes[0], e0, "starting model"), (axes[1], e1, "final model")):
            for k, name in groups:
                m = station == k
                ax.scatter(row[m], np.maximum(e[m], 1e-6) * 1000, s=8, label=name)
            ax.set_yscale("log")
            ax.set_title(f"{lab}: RMS {np.sqrt(np.mean(e ** 2)) * 1000:.1f} um (fitted rows)", fontsize=10)
            ax.set_xlabel("configuration (row of the campaign)")
        axes[0].set_ylabel("error along the constraint (um, log scale)")
        axes[1].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False, title="station")
    else:
        norm = report.error_norm(np.concatenate([e0, e1]) * 1000)
        for ax, e, lab in ((axes[0], e0, "starting model"), (axes[1], e1, "final model")):
            sc = ax.scatter(data.xyz[:, 0], data.xyz[:, 1], c=e * 1000, s=8, cmap="viridis", norm=norm)
            ax.set_title(f"{lab}: RMS {np.sqrt(np.mean(e ** 2)) * 1000:.1f} um (fitted points)", fontsize=10)
            ax.set_xlabel("x (mm, instrument)")
            ax.set_aspect("equal")
        axes[0].set_ylabel("y (mm, instrument)")
        fig.colorbar(sc, ax=list(axes), label="point error (um, log scale)")
    fig.savefig(path, dpi=100)
    plt.close(fig)


def write_report(robot: Robot, data: MeasurementSet, diag: dict[str, Any], out_dir: Union[str, Path],
                 title: str = "kincal diagnose", model_file: Optional[str] = None) -> list[str]:
    """Figures and report.html of a diagnosis in out_dir; returns the files written. ``model_file``:
    the name of the final model's JSON written beside it (said in the report)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    files: list[str] = []
    # 1. the gap shrinking step by step
    hist = diag["history"]
    # one horizontal bar per step, labelled by the effect that step added (the model is cumulative):
    # long labels never overlap
    fig, ax = plt.subplots(figsize=(8, 1.2 + 0.45 * len(hist)), constrained_layout=True)
    labels = [_compact(h["model"]) if k == 0 else "+ " + h["model"].split(" + ")[-1] for k, h in enumerate(hist)]
    y = np.arange(len(hist))[::-1]
    vals = [h["cv_rms_mm"] * 1000 for h in hist]
    ax.barh(y, vals, color="tab:blue")
    for yy, v in zip(y, vals):
        ax.text(v, yy, f" {v:.1f}", va="center", fontsize=8)
    ax.axvline(diag["noise_rms_mm"] * 1000, color="k", ls="--",
               label="the instrument's noise" if diag["noise_known"] else "the final fit's scatter\n(noise not known:\nit only bounds it)")
    ax.set_yticks(y, labels, fontsize=8)
    ax.set_xlabel("cross-validated RMS (um), each step adds one effect to the model above it")
    ax.set_xlim(0, max(vals) * 1.15)
    ax.legend(loc="lower left", bbox_to_anchor=(1.01, 0.0), fontsize=8, frameon=False)  # beside the bars, never on them
    fig.savefig(out / "gap.png", dpi=100)
    plt.close(fig)
    files.append("gap.png")
    # 2. residuals before (geometry only) and after (final model): where the points are, or per station
    start: Spec = diag["_start"]
    e0 = start.errors(start.fit(data), data)
    e1 = diag["_spec"].errors(diag["_final_fit"], data)
    _residual_figure(plt, data, e0, e1, out / "residual_map.png")
    files.append("residual_map.png")
    # 3. residuals against each named effect's variable, before and after it was added
    spec = start
    before = spec.fit(data)
    for k, st in enumerate(diag["steps"]):
        eff = step_effect(st)
        spec = spec.with_(eff, diag["_spec"].penalties_of(eff))
        after = spec.fit(data)
        name = f"step{k + 1}.png"
        _step_figure(plt, robot, data, k, st, before, after, out / name)
        files.append(name)
        before = after
    # 4. what remains against every candidate variable
    scores = diag.get("residual_variables", [])
    if scores and max(sc_["share"] for sc_ in scores) > 0:  # no chart of bars that all say "nothing"
        _variables_figure(plt, scores, out / "residual_variables.png")
        files.append("residual_variables.png")
    rows = [[k + 1, _label(s), f"{s['evidence']['F']:.3g}", _p(s['evidence']['p_value']),
             f"{s['evidence']['cv_gain_linear']:.1%}", f"{s['rms_before_mm'] * 1000:.1f}",
             f"{s['rms_after_mm'] * 1000:.1f}"] for k, s in enumerate(diag["steps"])]
    notes = "".join(f"<li>{report.esc(n)}</li>" for n in diag["notes"])
    fm = diag.get("final_model", {})
    model_note = "" if not model_file else (
        f"<p><b>Model:</b> {report.esc(model_file)} was written: the final model "
        f"({report.esc(' + '.join(['geometry'] + [e['label'] for e in fm.get('effects', [])]))}), identified on all "
        f"the data, ready for <code>kincal compensate --model {report.esc(model_file)}</code>.</p>")
    steps_img = "".join(report.figure(f, f) for f in files if f.startswith("step"))
    body = f"""<h1>{report.esc(title)}</h1>
<p>{len(data)} measured points. Each step scores every candidate effect of the library against the
residual of the current model (projected off what the model can already absorb), adds the best significant one,
refits everything and checks that the cross-validated RMS falls ({diag['folds']} folds of whole configurations:
the repeats of one of the {diag['validation']['configurations']} configurations never sit on both sides).</p>
{report.table(["step", "effect", "F", "p", "linear CV gain", "CV RMS before (um)", "after (um)"], rows, numeric=True,
              text=[1])
 if rows else "<p>No effect was named: no candidate of the library passed the test.</p>"}
<p><b>Result:</b> cross-validated RMS {diag['final_rms_mm'] * 1000:.1f} um; {report.esc(noise_phrase(diag))}:
{report.esc(diag['verdict'])}.</p>
<ul>{notes}</ul>
<h2>The gap, step by step</h2>{report.figure("gap.png", "gap")}
<h2>Where the model and the measurements disagree</h2>{report.figure("residual_map.png", "residual map")}
<h2>Residuals against each named effect</h2>
<p>Each step's residual against the variable of its effect, before and after the step (fitted on every point):
for an effect on a joint angle, the angle error of that joint each point's residual implies, with the identified
effect's curve less its mean over the points (a constant is the joint's offset, which the geometry carries).</p>{steps_img}
<h2>What remains, against every candidate variable</h2>
<p>The final model's residual fitted, held out on the same folds, as a smooth function of each variable acting on
the instrument's placement and on every joint angle: {report.esc(diag.get("residual_summary", ""))}.</p>
{report.table(["variable", "what", "share held out", "RMS explained (um)"],
              [[s["variable"], s["label"], _share(s["share"]), f"{s['rms_explained_mm'] * 1000:.1f}"]
               for s in scores], numeric=False)}
{report.figure("residual_variables.png", "residual variables") if "residual_variables.png" in files else ""}
{model_note}
<p>Files: diagnosis.json (the contract's summary), {", ".join(([model_file] if model_file else []) + files)}.</p>"""
    report.write(out / "report.html", title, body)
    return files + ["report.html"]
