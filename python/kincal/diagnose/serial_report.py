"""The report of a serial robot's diagnosis: figures (the gap shrinking step by step, residual maps
before and after, residuals against each named effect's variable) and report.html."""

from __future__ import annotations

from pathlib import Path
from typing import Optional, Union

import numpy as np

from .. import _core
from .. import report
from .._core import Robot
from .serial import Spec


def _label(effect: str, joint: Optional[int]) -> str:
    return _core.Effect(effect, joint or 0).label


def _variable(robot: Robot, data: dict, effect: str, joint: Optional[int]):
    """The natural variable of an effect for plots: (values per point, axis label)."""
    j = joint or 1
    if effect == "transmission_error":
        return data["q_deg"][:, j - 1], f"q{joint} (deg)"
    if effect == "backlash":
        return data["dir"][:, j - 1] + np.random.default_rng(0).uniform(-0.15, 0.15, len(data["pose"])), \
            f"dir{joint} (sign of the last motion, jittered)"
    if effect == "thermal_expansion":
        return data["temperature_c"], "temperature (C)"
    if effect == "drift":
        return np.asarray(data["time_s"]) / 3600.0, "time of the measurement (h)"
    tau = np.array([_core.gravity_torque(robot, q)[0][j - 1] for q in data["q_deg"]]) / 1000.0
    return tau, f"gravity torque on joint {joint} (N m)"


def write_report(robot: Robot, data: dict, diag: dict, out_dir: Union[str, Path], title: str = "kincal diagnose",
                 model_file: Optional[str] = None) -> list:
    """Figures and report.html of a diagnosis in out_dir; returns the files written. ``model_file``:
    the name of the final model's JSON written beside it (said in the report)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    files = []
    # 1. the gap shrinking step by step
    hist = diag["history"]
    # one horizontal bar per step, labelled by the effect that step added (the model is cumulative):
    # long labels never overlap
    fig, ax = plt.subplots(figsize=(8, 1.2 + 0.45 * len(hist)), constrained_layout=True)
    labels = [h["model"].split(" + ")[-1] if k else "geometry" for k, h in enumerate(hist)]
    labels = [lab if k == 0 else "+ " + lab for k, lab in enumerate(labels)]
    y = np.arange(len(hist))[::-1]
    vals = [h["cv_rms_mm"] * 1000 for h in hist]
    ax.barh(y, vals, color="tab:blue")
    for yy, v in zip(y, vals):
        ax.text(v, yy, f" {v:.1f}", va="center", fontsize=8)
    ax.axvline(diag["noise_rms_mm"] * 1000, color="k", ls="--", label="noise estimate")
    ax.set_yticks(y, labels, fontsize=8)
    ax.set_xlabel("cross-validated RMS (um), each step adds one effect to the model above it")
    ax.set_xlim(0, max(vals) * 1.15)
    ax.legend(loc="lower right", fontsize=8)
    fig.savefig(out / "gap.png", dpi=100)
    plt.close(fig)
    files.append("gap.png")
    # 2. residual maps before (geometry only) and after (final model), in the instrument frame
    start: Spec = diag["_start"]
    e0 = start.errors(start.fit(robot, data), data)
    e1 = diag["_spec"].errors(diag["_final_fit"], data)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    vmax = float(np.max(e0)) * 1000
    for ax, e, lab in ((axes[0], e0, "starting model"), (axes[1], e1, "final model")):
        sc = ax.scatter(data["xyz"][:, 0], data["xyz"][:, 1], c=e * 1000, s=8, cmap="viridis", vmin=0, vmax=vmax)
        ax.set_title(f"{lab}: RMS {np.sqrt(np.mean(e ** 2)) * 1000:.1f} um (fitted points)", fontsize=10)
        ax.set_xlabel("x (mm, instrument)")
        ax.set_aspect("equal")
    axes[0].set_ylabel("y (mm, instrument)")
    fig.colorbar(sc, ax=list(axes), label="point error (um)")
    fig.savefig(out / "residual_map.png", dpi=100)
    plt.close(fig)
    files.append("residual_map.png")
    # 3. residuals against each named effect's variable, before and after it was added
    spec = start
    for k, st in enumerate(diag["steps"]):
        before = spec.errors(spec.fit(robot, data), data)
        spec = spec.with_(_core.Effect(st["effect"], st["joint"] or 0))
        after = spec.errors(spec.fit(robot, data), data)
        var, lab = _variable(robot, data, st["effect"], st["joint"])
        fig, ax = plt.subplots(figsize=(6.5, 3.4), constrained_layout=True)
        ax.scatter(var, before * 1000, s=6, alpha=0.6, label="before")
        ax.scatter(var, after * 1000, s=6, alpha=0.6, label="after")
        ax.set_xlabel(lab)
        ax.set_ylabel("point error (um)")
        ax.set_title(f"step {k + 1}: {_label(st['effect'], st['joint'])}", fontsize=10)
        ax.legend()
        name = f"step{k + 1}.png"
        fig.savefig(out / name, dpi=100)
        plt.close(fig)
        files.append(name)
    rows = [[k + 1, _label(s["effect"], s["joint"]), f"{s['evidence']['F']:.3g}", f"{s['evidence']['p_value']:.2g}",
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
<p>{len(data['pose'])} measured points. Each step scores every candidate effect of the library against the
residual of the current model (projected off what the model can already absorb), adds the best significant one,
refits everything and checks that the cross-validated RMS falls ({diag['folds']} folds of whole configurations:
the repeats of one of the {diag['validation']['configurations']} configurations never sit on both sides).</p>
{report.table(["step", "effect", "F", "p", "linear CV gain", "CV RMS before (um)", "after (um)"], rows, numeric=True)}
<p><b>Result:</b> cross-validated RMS {diag['final_rms_mm'] * 1000:.1f} um against a noise estimate of
{diag['noise_rms_mm'] * 1000:.1f} um: {report.esc(diag['verdict'])}.</p>
<ul>{notes}</ul>
<h2>The gap, step by step</h2>{report.figure("gap.png", "gap")}
<h2>Where the model and the measurements disagree</h2>{report.figure("residual_map.png", "residual map")}
<h2>Residuals against each named effect</h2>{steps_img}
{model_note}
<p>Files: diagnosis.json (the contract's summary), {", ".join(([model_file] if model_file else []) + files)}.</p>"""
    report.write(out / "report.html", title, body)
    return files + ["report.html"]
