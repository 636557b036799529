"""The standard accuracy figures of `kincal demo`, each computed by `kincal accuracy` (accuracy.py,
accuracy_report.py) from runs the demo simulates and writes as the files those commands read:

- ISO 9283 on the kr500: the test poses of `kincal accuracy plan-iso9283` (the largest cube, P1..P5,
  30 cycles P1 -> P5 -> P4 -> P3 -> P2 -> P1), taught in the tracker frame, as three joint programs
  (nominal IK, Newton on the identified model, Newton on the diagnosed one), each run on the
  simulated truth (its backlash acting with the directions of the commanded motion) with a stated
  repeatability scatter added;
- VDI/DGQ 3441 (and ISO 230-2) of the five-bar along x and along y: the corrected mechanism (fitted
  lengths + error matrix) and, for comparison, the nominal one, commanded to targets along a line
  from both directions on the simulated 6-bar with a stated joint clearance and instrument noise;
- the Samak paper's figures of the line: the mean position and orientation errors before and after.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional, Union

import numpy as np

from .. import _core, compensate, fk, run_program
from ..standards import report as accrep
from .. import fivebar as fb
from ..standards import iso9283_plan
from .. import report
from ..io.csv_text import format_rows

if TYPE_CHECKING:
    from ..typing_ import FloatArray

#: ISO 9283 runs: the truth is deterministic, its repeatability is simulated as an isotropic
#: Gaussian scatter of the attained position (mm, per axis) and of each attained angle (deg)
REPEATABILITY_MM = 0.02
REPEATABILITY_DEG = 0.001
CYCLES = 30
#: five-bar axis runs: runs per direction, instrument noise (mm), the pin clearance's reversal (mm):
#: the point stays this far behind, against the direction it arrives from, on top of the 6-bar's own
#: random clearance (SixBar.clearance, a disc of that radius)
AXIS_RUNS = 5
AXIS_NOISE_MM = 0.001
AXIS_REVERSAL_MM = 0.003
AXIS_TARGETS = 11

RUNS_HEAD = ["point", "cycle", "xc", "yc", "zc", "ac", "bc", "cc", "x", "y", "z", "a", "b", "c"]


def angles_between_deg(a: FloatArray, b: FloatArray) -> FloatArray:
    """Angle (deg) of the rotation between the orientations (KUKA ABC, deg) of the rows of a and b."""
    out = np.empty(len(a))
    for i, (u, v) in enumerate(zip(a, b)):
        r = _core.abc_to_rotation(np.asarray(u, dtype=float)).T @ _core.abc_to_rotation(np.asarray(v, dtype=float))
        out[i] = np.degrees(np.arccos(np.clip((np.trace(r) - 1.0) / 2.0, -1.0, 1.0)))
    return out


def iso9283_runs(robot: _core.Robot, nominal_fitted: _core.Robot, models: dict[str, tuple[str, _core.Robot]],
                 truth: _core.Robot, out: Path, seed: int) -> dict[str, Any]:
    """The ISO 9283 test on the truth: the test poses of ``robot`` (plan-iso9283, in its base frame)
    taught in the tracker frame where ``nominal_fitted`` (the nominal geometry with the measured
    tracker frame) puts them; per program (nominal IK, then Newton on each of ``models``: label ->
    Robot) its runs written to OUT/iso9283/<key>/runs.csv and its report (`kincal accuracy iso9283
    --distance P2,P4`) to that folder. Returns the plan and the reports."""
    plan = iso9283_plan.plan(robot, cycles=CYCLES, seed=0)
    rows = plan["rows"]
    base_poses = np.array([r[:6] for r in rows], dtype=float)
    names, cycles = [r[6] for r in rows], [int(r[7]) for r in rows]
    taught = fk(nominal_fitted, compensate(nominal_fitted, base_poses, compensate=False)["q_deg"], frame="instrument")
    programs: dict[str, tuple[str, FloatArray]] = {
        "uncompensated": ("uncompensated (nominal IK)",
                          compensate(nominal_fitted, taught, compensate=False, frame="instrument")["q_deg"])}
    for key, (label, model) in models.items():
        programs[key] = (label, compensate(model, taught, frame="instrument")["q_deg"])
    rng = np.random.default_rng(seed)
    measured = [i for i, c in enumerate(cycles) if c >= 1]  # cycle 0 is the start at P1
    reports: dict[str, dict[str, Any]] = {}
    for key, (label, q) in programs.items():
        att = run_program(truth, q, frame="instrument")
        att[:, :3] += rng.normal(0.0, REPEATABILITY_MM, (len(att), 3))
        att[:, 3:] += rng.normal(0.0, REPEATABILITY_DEG, (len(att), 3))
        folder = out / "iso9283" / key
        folder.mkdir(parents=True, exist_ok=True)
        table = [[names[i], cycles[i], *taught[i], *att[i]] for i in measured]
        _core.write_file_atomic(str(folder / "runs.csv"), format_rows(RUNS_HEAD, table))
        res = accrep.run_iso9283(str(folder / "runs.csv"), str(folder), distance="P2,P4",
                                 frame_label="the tracker's (the demo's simulated campaign)", label=f"kr500, {label}")
        reports[key] = {"label": label, "report": res}
    return {"plan": plan, "programs": reports}


def _axis_csv(path: Path, sixbar: _core.SixBar, model: _core.FiveBar, matrix: Optional[_core.ErrorMatrix],
              line: FloatArray, coord: int, seed: int) -> None:
    """AXIS.csv of `kincal accuracy axis` for one coordinate of the five-bar: the targets of ``line``
    (n x 2, in order of increasing ``coord``) visited up then down, AXIS_RUNS times."""
    rows: list[list[Union[str, int]]] = []
    for run in range(1, AXIS_RUNS + 1):
        for d in (1, -1):
            order = line if d == 1 else line[::-1]
            pts = _core.sixbar_campaign(sixbar, model, matrix, order, AXIS_NOISE_MM, seed + 2 * run + (d < 0))
            if len(pts["desired"]) != len(order):
                raise RuntimeError("five-bar axis runs: a target out of reach")
            meas = np.asarray(pts["measured"])[:, coord] - d * AXIS_REVERSAL_MM
            rows += [[f"{t:.3f}", d, run, f"{m:.6f}"] for t, m in zip(np.asarray(pts["desired"])[:, coord], meas)]
    _core.write_file_atomic(str(path), format_rows(["target", "direction", "run", "measured"], rows))


def fivebar_axes(sixbar: _core.SixBar, model: _core.FiveBar, matrix: Optional[_core.ErrorMatrix], out: Path,
                 seed: int) -> dict[tuple[str, str], dict[str, Any]]:
    """VDI/DGQ 3441 and ISO 230-2 of the five-bar along x (at y = 0) and along y (at the workspace's
    middle x), corrected (``model`` + ``matrix``) and nominal: OUT/fivebar/axis_<mech>_<x|y>/ with
    axis.csv and the report of `kincal accuracy axis`."""
    (x0, x1), (y0, y1) = fb.WORKSPACE
    xm = (x0 + x1) / 2.0
    lines = {"x": (np.c_[np.linspace(x0 + 1, x1 - 1, AXIS_TARGETS), np.zeros(AXIS_TARGETS)], 0),
             "y": (np.c_[np.full(AXIS_TARGETS, xm), np.linspace(y0 + 1, y1 - 1, AXIS_TARGETS)], 1)}
    res: dict[tuple[str, str], dict[str, Any]] = {}
    for mech, (m, mx) in (("corrected", (model, matrix)), ("nominal", (fb.FiveBar(), None))):
        for name, (line, coord) in lines.items():
            folder = out / "fivebar" / f"axis_{mech}_{name}"
            folder.mkdir(parents=True, exist_ok=True)
            _axis_csv(folder / "axis.csv", sixbar, m, mx, line, coord, seed + 100 * len(res))
            res[(mech, name)] = accrep.run_axis(str(folder / "axis.csv"), str(folder),
                                                label=f"five-bar, {mech} mechanism, along {name}")
    return res


# --- the report's sections ------------------------------------------------------------------------

def _f(v: Optional[float], digits: int = 3) -> str:
    return accrep._f(v, digits)


def iso9283_section(iso: dict[str, Any], sigma_note: str) -> str:
    plan = iso["plan"]
    c = plan["centre_mm"]
    # the precision rule of accuracy_report.py (the finest any program's repeatability asks for)
    dp = max(accrep.iso9283_decimals(p["report"])[0] for p in iso["programs"].values())
    da = max(accrep.iso9283_decimals(p["report"])[1] for p in iso["programs"].values())
    rows = []
    for key, p in iso["programs"].items():
        r = p["report"]
        pts = r["points"]
        ap = [x["AP_P_mm"] for x in pts]
        rp = [x["RP_l_mm"] for x in pts]
        ang = max(max(abs(x[f"AP_{n}_deg"]) for n in "abc") for x in pts)
        rows.append([p["label"], _f(min(ap), dp), _f(max(ap), dp), _f(max(rp), dp), _f(ang, da), _f(r["AD_mm"], dp),
                     _f(r["RD_mm"], dp)])
    detail = []
    for key, p in iso["programs"].items():
        detail.append([p["label"]] + [_f(x["AP_P_mm"], dp) for x in p["report"]["points"]])
    names = [x["point"] for x in next(iter(iso["programs"].values()))["report"]["points"]]
    links = ", ".join(f'<a href="iso9283/{k}/report.html">{report.esc(k)}</a>' for k in iso["programs"])
    return f"""<h3>ISO 9283 pose accuracy and repeatability of the kr500</h3>
<p>The test poses of <code>kincal accuracy plan-iso9283 --robot kr500</code>: the largest cube in the workspace
(edge {plan['edge_mm']:.0f} mm, centre {c[0]:.0f}, {c[1]:.0f}, {c[2]:.0f} mm, tool at a,b,c =
{', '.join(f'{v:g}' for v in plan['abc_deg'])} deg), P1 at its centre, P2..P5 on a diagonal plane, {CYCLES} cycles
P1 &rarr; P5 &rarr; P4 &rarr; P3 &rarr; P2 &rarr; P1, taught in the tracker frame as the line is. Each program runs on
the simulated truth (backlash acting with the commanded motion); {sigma_note} The attained poses are written as
<code>iso9283/*/runs.csv</code> and reported by <code>kincal accuracy iso9283 --data runs.csv --distance P2,P4</code>
(full reports: {links}). In mm and deg, frame: the tracker's:</p>
{report.table(["program", "AP_P min", "AP_P max", "RP_l max", "largest |AP_a,b,c| (deg)", "AD P2-P4", "RD P2-P4"],
              rows, numeric=True, labelled=True)}
{report.table(["AP_P (mm)"] + names, detail, numeric=True, labelled=True)}
<p>The identified model carries no backlash: it misses the poses where joint 2 arrives moving upwards (P2 and
P5 in this cycle) and hits the others, as along the line, where its error jumps when joint 2 reverses. The
diagnosed model, which carries the backlash, brings every AP_P below the repeatability.</p>"""


def axis_section(axes: dict[tuple[str, str], dict[str, Any]]) -> str:
    rows = []
    for (mech, name), r in axes.items():
        v, i = r["vdi3441"], r["iso230_2"]
        d, dm = accrep.axis_decimals(r)  # the precision rule of accuracy_report.py, here in um
        um = [accrep.rounded(x, d, 1000.0) for x in (v["P"], v["Pa"], v["Ps"], v["U"], i["A"], i["R"])]
        per_m = accrep.rounded(v["P_per_m"], dm + 3, 1000.0) if "P_per_m" in v else ""
        rows.append([f"{mech}, along {name}", f"{v['travel']:.0f}", um[0], per_m, *um[1:]])
    links = ", ".join(f'<a href="fivebar/axis_{m}_{n}/report.html">{m} {n}</a>' for m, n in axes)
    return f"""<h3>VDI/DGQ 3441 and ISO 230-2 of the five-bar along x and y</h3>
<p>{AXIS_TARGETS} targets along x (y = 0) and along y (x at the workspace's middle), each visited upwards then
downwards, {AXIS_RUNS} runs per direction, on the simulated 6-bar: its own pin clearance (a random offset in a
disc of {_core.paper_sixbar(1).clearance * 1000:.0f} um radius) plus a reversal of {AXIS_REVERSAL_MM * 1000:.0f} um
(the point stays behind, against the direction it arrives from), instrument noise {AXIS_NOISE_MM * 1000:.0f} um.
Written as <code>fivebar/axis_*/axis.csv</code> and reported by <code>kincal accuracy axis</code> (full reports:
{links}). The Kiper paper states its result as these figures (precision +-37 um/m, repeatability +-26 um/m). In um
(per metre of travel where said):</p>
{report.table(["mechanism, axis", "travel (mm)", "P", "P per m", "Pa", "Ps", "U", "ISO A", "ISO R"], rows,
              numeric=True, labelled=True)}
<p>Per metre, P of the corrected mechanism is several times the paper's figure: over 0.1-0.15 m of travel the
scatter and reversal stated above (about 20 um whatever the travel) are divided by a short length.</p>"""
