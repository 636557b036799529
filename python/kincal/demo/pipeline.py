"""`kincal demo`: the whole pipeline on the built-in examples, with one report page.

1. a measurement campaign on a simulated kr500 whose truth has geometric errors, joint compliance
   under the 300 kg head, and a hidden backlash on joint 2 (not in the starting model);
2. identification (geometry + compliance) with a held-out validation;
3. the diagnosis, which has to find the backlash;
4. the Samak paper's 1480 mm line compensated on the identification-only model and on the diagnosed
   model (the named effect included, DIR/diagnosis/model.json), in the tracker's frame, and both run
   on the truth (its backlash acting with the directions of the commanded motion), against the
   uncompensated program;
5. the standard figures of the cell (accuracy_demo.py): ISO 9283 of the three programs run on the truth,
   and the Samak paper's mean position and orientation errors of the line before and after;
6. the derivative analysis of both programs;
7. the Kiper paper's Table I, the error matrix on the simulated over-constrained 6-bar, and VDI/DGQ 3441
   figures of the corrected mechanism along x and y;
8. the same robot calibrated without a tracker: six spheres and a length bar, the touches planned
   (`kincal plan --kind sphere`), made on the truth and identified with the effects the data choose,
   its ball centre's accuracy beside the tracker model's.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional

import numpy as np

from .. import _core, compensate, fk, line_program, load_robot, run_program
from . import accuracy as accuracy_demo
from .. import diagnose as dg
from ..programs import feed as feedmod
from .. import fivebar as fb
from ..calibration import identify as ident
from ..calibration import probe_plan
from ..calibration.fitting import FitOptions
from .. import report
from ..io import strict_json
from ..io.csv_text import format_rows

if TYPE_CHECKING:
    from .._core import CompensationResult, Robot
    from ..typing_ import FloatArray

SEED = 7
#: the effect the starting model does not know: joint 2 lags 0.01 deg behind its command (a gear's play)
HIDDEN = [("backlash", 2, [math.radians(-0.01)])]


def _gcode(poses: FloatArray) -> str:
    g = ["; kincal demo: 1480 mm straight tool path, 297 poses, tool pointing down (tracker frame)", "G90"]
    g += [f"N{10 * (i + 1)} G1 X{p[0]:.4f} Y{p[1]:.4f} Z{p[2]:.4f} A{p[3]:.5f} B{p[4]:.5f} C{p[5]:.5f}"
          for i, p in enumerate(poses)]
    return "\n".join(g + ["M30"]) + "\n"


def _table1() -> Optional[Path]:
    """The Kiper paper's Table I (../shared/data/fivebar-table1.csv beside the repository): searched
    above the package (a source tree or a virtual environment inside it) and above the working folder."""
    for top in (Path(__file__).resolve(), Path.cwd().resolve()):
        for folder in top.parents:
            path = folder / "shared" / "data" / "fivebar-table1.csv"
            if path.exists():
                return path
    return None


def _line(out: Path, b_fit: Robot, identified: Robot, diagnosed: Robot, truth: Robot) -> tuple[Any, ...]:
    """The demo's line program (taught where the nominal robot with the measured tracker frame puts
    it), uncompensated and compensated on the identified and the diagnosed models, and what the true
    robot does with each: the poses, the uncompensated and compensated joints, the compensation's
    result and the (position, orientation) errors of the three programs on the truth."""
    w = _core.write_file_atomic
    base_line = line_program()
    # the line is taught in the tracker (user) frame: where the nominal robot would put it
    poses = fk(b_fit, compensate(b_fit, base_line, compensate=False)["q_deg"], frame="instrument")
    w(str(out / "line.csv"), format_rows(["x", "y", "z", "a", "b", "c"], poses))
    w(str(out / "line.gcode"), _gcode(poses))
    tracker = _core.ProgramOptions(instrument=True)  # the line is in the tracker's frame
    unc = _core.compensate_program(b_fit, str(out / "line.gcode"), str(out / "uncompensated.gcode"),
                                   _core.ProgramOptions(compensate=False, instrument=True))
    com = _core.compensate_program(identified, str(out / "line.gcode"), str(out / "compensated.gcode"), tracker)
    _core.compensate_program(identified, str(out / "line.csv"), str(out / "compensated.csv"), tracker)
    com_d = _core.compensate_program(diagnosed, str(out / "line.gcode"), str(out / "compensated_diagnosed.gcode"),
                                     tracker)
    q_unc, q_com, q_dia = np.asarray(unc["q_deg"]), np.asarray(com["q_deg"]), np.asarray(com_d["q_deg"])
    # what the true robot does with each program: geometry, compliance and the backlash of joint 2,
    # which acts with the direction each axis arrives from (the sign of its commanded motion)
    def on_truth(q: FloatArray) -> tuple[FloatArray, FloatArray]:
        att = run_program(truth, q, frame="instrument")
        return (np.linalg.norm(att[:, :3] - poses[:, :3], axis=1),
                accuracy_demo.angles_between_deg(poses[:, 3:], att[:, 3:]))
    return poses, q_unc, q_com, com, on_truth(q_unc), on_truth(q_com), on_truth(q_dia)


def _fivebar(out: Path) -> tuple[dict[str, dict[str, Any]], list[float], dict[Any, Any]]:
    """The demo's five-bar step: the Kiper paper's Table I fitted three ways (when ../shared has it),
    the simulated 6-bar's minimax fit and error matrix with their error maps, and the axes' VDI/DGQ
    3441 figures. Returns the Table I fits, the largest error of the nominal, fitted and corrected
    mechanism (mm) and the axes' reports."""
    w = _core.write_file_atomic
    hdir = out / "fivebar"
    hdir.mkdir(exist_ok=True)
    table_fits: dict[str, dict[str, Any]] = {}
    table = _table1()
    if table is not None:
        t1_pts = fb.read_table(str(table))
        for m, sc in (("polynomial", "desired"), ("lsq", "desired"), ("minimax", "measured")):
            f = table_fits[f"{m} ({sc} score)"] = fb.fit(t1_pts, m, sc)
            model = fb.FiveBar(f["a"], f["b"], f["c"], f["d"])  # each fit under both scores, for the table
            f["largest_mm"] = {sc_: fb.largest_error(model, t1_pts, sc_ == "desired") for sc_ in ("desired", "measured")}
    sixbar = _core.paper_sixbar(1)
    tab_xy = np.array([(212.132, 0), (212.132, 75), (262.132, 75), (262.132, 0), (262.132, -75), (212.132, -75),
                       (162.132, -75), (162.132, 0), (162.132, 75)])
    rng = np.random.default_rng(SEED)
    val = np.c_[rng.uniform(163, 261, 400), rng.uniform(-74, 74, 400)]
    meas9 = _core.sixbar_campaign(sixbar, fb.FiveBar(), None, tab_xy, 0.020, 1)
    fit = fb.fit(meas9, "minimax")
    w(str(hdir / "fit.json"), strict_json.dumps(fit, indent=1) + "\n")
    model = fb.model_of(fit)
    grid = _core.sixbar_campaign(sixbar, model, None, fb.grid_targets(), 0.001, 2)
    matrix = _core.ErrorMatrix.from_points(grid, "grid")
    w(str(hdir / "matrix.json"), matrix.to_json())
    v0 = _core.sixbar_campaign(sixbar, fb.FiveBar(), None, val, 0.001, 3)
    v1 = _core.sixbar_campaign(sixbar, model, None, val, 0.001, 4)
    v2 = _core.sixbar_campaign(sixbar, model, matrix, val, 0.001, 5)
    fb.error_map_figure([("nominal lengths", v0), ("after the fit", v1), ("after fit + matrix", v2)],
                        str(hdir / "error_maps.png"))
    hb = [float(fb.position_errors(v).max()) for v in (v0, v1, v2)]
    axes = accuracy_demo.fivebar_axes(sixbar, model, matrix, out, SEED)

    return table_fits, hb, axes


#: the probe's ball on the tool (mm, tool frame) in the demo's sphere campaign
PROBE = (0.0, 0.0, 150.0)


def _spheres(out: Path, robot: Robot, truth: Robot, tracker_model: Robot, diagnosed_model: Robot) -> dict[str, Any]:
    """The demo's probe step: six spheres with a length bar, 25 touches each planned, made on the
    truth (0.005 mm), identified with the effects the data choose; the ball centre's RMS over 200
    configurations drawn within 90% of each limit after the best rigid transform, against the tracker's models
    (identified and diagnosed) and the nominal one."""
    lim = np.asarray(robot.limits_deg)
    q = np.random.default_rng(SEED).uniform(0.9 * lim[:, 0], 0.9 * lim[:, 1], size=(200, robot.dof))
    plan = probe_plan.plan_probe(robot, "sphere", stations=6, touches=25, cone_deg=60, probe=PROBE, noise_mm=0.005,
                                 configurations=q, seed=SEED)
    touches = probe_plan.measure(truth, plan.data, PROBE, 0.005, seed=SEED)  # the truth's backlash acting
    _core.write_file_atomic(str(out / "spheres.csv"), ident.measurements_csv(  # the controller's numbers
        touches.with_columns(q_deg=_core.joints_to_controller(robot, touches.q_deg)), robot.dof))
    _core.write_file_atomic(str(out / "spheres-artifact.csv"), _core.format_artifact(touches, robot.dof))
    res = ident.identify(robot, touches, fit=FitOptions(target_start=[PROBE]))
    _core.write_file_atomic(str(out / "spheres_model.json"), res.model_json())
    ball = np.asarray(PROBE)
    t = probe_plan.ball_centres(truth, q, ball)
    return {"touches": int(len(touches.pose)), "stations": 6, "predicted_mm": plan.tcp_uncertainty_mm,
            "effects": res.effect_labels(), "nominal_mm": probe_plan.rigid_rms(probe_plan.ball_centres(robot, q, ball), t),
            "spheres_mm": probe_plan.rigid_rms(probe_plan.ball_centres(res.robot, q, np.asarray(res.targets)[0]), t),
            "tracker_mm": probe_plan.rigid_rms(probe_plan.ball_centres(tracker_model, q, ball), t),
            "tracker_diagnosed_mm": probe_plan.rigid_rms(probe_plan.ball_centres(diagnosed_model, q, ball), t),
            "held_out_rms_mm": res.validation["after_rms_mm"]}


def _summary(res: ident.Identification, diag: dict[str, Any], diagnosed: ident.Identification, iso: dict[str, Any],
             axes: dict[Any, Any], spheres: dict[str, Any], com: CompensationResult, fres: dict[str, dict[str, Any]],
             hb: list[float], table_fits: dict[str, dict[str, Any]], poses: int,
             errors: tuple[FloatArray, FloatArray, FloatArray],
             angles: tuple[FloatArray, FloatArray, FloatArray]) -> dict[str, Any]:
    """summary.json's figures (the seconds and the files added by run())."""
    err_unc, err_com, err_dia = errors
    ori_unc, ori_com, ori_dia = angles
    return {
        "robot": "kr500 (simulated truth: seed 7; hidden backlash of -0.01 deg on joint 2)",
        "poses": int(poses),
        "identification": {"held_out_rms_before_mm": res.validation["before_rms_mm"],
                           "held_out_rms_after_mm": res.validation["after_rms_mm"]},
        "diagnosis": [{"effect": s["effect"], "joint": s["joint"], "rms_before_mm": s["rms_before_mm"],
                       "rms_after_mm": s["rms_after_mm"]} for s in diag["steps"]],
        "position_error_uncompensated_mm": {"mean": float(err_unc.mean()), "max": float(err_unc.max())},
        "position_error_compensated_mm": {"mean": float(err_com.mean()), "max": float(err_com.max())},
        "position_error_compensated_diagnosed_mm": {"mean": float(err_dia.mean()), "max": float(err_dia.max())},
        "orientation_error_uncompensated_deg": {"mean": float(ori_unc.mean()), "max": float(ori_unc.max())},
        "orientation_error_compensated_deg": {"mean": float(ori_com.mean()), "max": float(ori_com.max())},
        "orientation_error_compensated_diagnosed_deg": {"mean": float(ori_dia.mean()), "max": float(ori_dia.max())},
        "iso9283": {"cube_edge_mm": iso["plan"]["edge_mm"], "cycles": accuracy_demo.CYCLES,
                    "repeatability_sigma_mm": accuracy_demo.REPEATABILITY_MM,
                    "programs": {k: {"AP_P_mm": {p["point"]: p["AP_P_mm"] for p in v["report"]["points"]},
                                     "RP_l_mm": {p["point"]: p["RP_l_mm"] for p in v["report"]["points"]},
                                     "AD_mm": v["report"]["AD_mm"], "RD_mm": v["report"]["RD_mm"]}
                                 for k, v in iso["programs"].items()}},
        "fivebar_vdi3441_um": {f"{m} {a}": {k: r["vdi3441"][k] * 1000
                                            for k in ("P", "P_per_m", "Pa", "Ps", "U", "Ps_mean", "U_mean")}
                               for (m, a), r in axes.items()},
        "diagnosed_model_effects": diagnosed.effect_labels(),
        "without_tracker": spheres,
        "newton_iterations": {"max": int(np.max(com["iterations"]))},
        "feed_violations": {k: len(v["violations"]) for k, v in fres.items()},
        "time_optimal_s": {k: v["time_optimal"]["time_s"] for k, v in fres.items()},
        "fivebar_max_error_mm": {"nominal": hb[0], "fit": hb[1], "fit_and_matrix": hb[2]},
        "table1": {k: {"points": v["points"], "a": v["a"], "b": v["b"], "c": v["c"], "d": v["d"],
                       "max_error_mm": v["max_error_mm"]} for k, v in table_fits.items()},
    }


def run(out: Path, say: Callable[[int, int, str], None]) -> dict[str, Any]:
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    n_steps = 9
    w = _core.write_file_atomic
    robot = load_robot("kr500")

    say(1, n_steps, "simulated kr500 campaign: 200 poses x 3 reflectors, 0.02 mm noise; the truth has "
                    "geometric errors, joint compliance and a hidden backlash on joint 2")
    truth = ident.default_truth(robot, seed=SEED)
    truth = truth.with_effects([(_core.Effect(n, j), v) for n, j, v in HIDDEN], 20.0)
    data = ident.simulate(truth, 200, seed=SEED, targets=3)
    w(str(out / "truth.json"), truth.to_json())
    w(str(out / "measurements.csv"), ident.measurements_csv(data, robot.dof))

    say(2, n_steps, "identification: 30 geometric + 5 compliance parameters, tracker frame and reflectors (Ceres)")
    # the head's reflector nest was measured on a CMM: the targets' offsets in the tool frame are known,
    # which places the TCP (reflectors alone cannot)
    res = ident.tool_from_targets(ident.identify(robot, data, effects="joint_compliance"), ident.DEFAULT_TARGETS[:3])
    w(str(out / "model.json"), res.model_json())
    w(str(out / "identify.txt"), res.summary() + "\n")

    say(3, n_steps, "diagnosis: which effect is the model missing?")
    ddir = out / "diagnosis"
    ddir.mkdir(exist_ok=True)
    diag = dg.diagnose(robot, data)
    dg.write_report(robot, data, diag, ddir, title="kincal demo: diagnosis")
    w(str(ddir / "diagnosis.json"), strict_json.dumps(dg.contract_json(diag), indent=1) + "\n")
    diagnosed = dg.final_identification(robot, data, diag, ident.DEFAULT_TARGETS[:3])
    w(str(ddir / "model.json"), diagnosed.model_json())

    say(4, n_steps, "the paper's line: nominal IK (uncompensated) and Newton compensation on the identified model")
    b_fit = res.fit["nominal_fitted"]  # nominal geometry with the measured tracker frame
    poses, q_unc, q_com, com, (err_unc, ori_unc), (err_com, ori_com), (err_dia, ori_dia) = _line(
        out, b_fit, res.robot, diagnosed.robot, truth)

    say(5, n_steps, "ISO 9283 on the true robot: the largest cube's test poses, 30 cycles, three programs")
    iso = accuracy_demo.iso9283_runs(robot, b_fit, {
        "identified": ("compensated on the identified model", res.robot),
        "diagnosed": ("compensated on the diagnosed model", diagnosed.robot)}, truth, out, SEED)

    say(6, n_steps, "derivative analysis of both programs (2900 points of s, built-in limits)")
    limits = feedmod.robot_limits(robot)
    fres = {"program": feedmod.analyse(q_com, *limits), "compare": feedmod.analyse(q_unc, *limits)}
    fres["program"]["label"], fres["compare"]["label"] = "compensated", "uncompensated"
    fdir = out / "feed"
    fdir.mkdir(exist_ok=True)
    for axis in range(1, 7):
        feedmod.figure(fres, *limits, feedmod.DEFAULT_FEED, axis, str(fdir / f"axis{axis}.png"))
    w(str(fdir / "feed.json"), strict_json.dumps({"feed_rad_s": feedmod.DEFAULT_FEED,
                                           "programs": {k: feedmod.json_ready(v) for k, v in fres.items()}}) + "\n")

    say(7, n_steps, "five-bar: the Kiper paper's Table I, fit and error matrix on the simulated 6-bar, VDI/DGQ 3441")
    table_fits, hb, axes = _fivebar(out)

    say(8, n_steps, "without a tracker: six spheres and a length bar, 25 planned touches each, the effects chosen by "
                    "the data")
    spheres = _spheres(out, robot, truth, res.robot, diagnosed.robot)

    say(9, n_steps, "report")
    summary = _summary(res, diag, diagnosed, iso, axes, spheres, com, fres, hb, table_fits, len(poses),
                       (err_unc, err_com, err_dia), (ori_unc, ori_com, ori_dia))
    summary["seconds"] = time.perf_counter() - t0
    sections = {"iso": accuracy_demo.iso9283_section(iso, (
        f"the truth being deterministic, its repeatability is simulated as a Gaussian scatter of "
        f"{accuracy_demo.REPEATABILITY_MM * 1000:.0f} um per axis on each attained position and "
        f"{accuracy_demo.REPEATABILITY_DEG:g} deg on each attained angle.")),
        "axis": accuracy_demo.axis_section(axes)}
    _report(out, res, diag, summary, err_unc, err_com, err_dia, fres, table_fits, sections)
    summary["files"] = sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file()) + ["summary.json"]
    w(str(out / "summary.json"), strict_json.dumps(summary, indent=2) + "\n")
    return summary


def _line_figure(plt: Any, path: Path, err_unc: FloatArray, err_com: FloatArray, err_dia: FloatArray) -> None:
    """The line's errors on the true robot along it: uncompensated, compensated on the identified
    and on the diagnosed model."""
    fig, ax = plt.subplots(figsize=(10, 3.4), constrained_layout=True)
    s_mm = np.arange(len(err_unc)) * 5.0
    ax.plot(s_mm, err_unc, label="uncompensated (nominal IK)")
    ax.plot(s_mm, err_com, label="compensated on the identified model (geometry + compliance)")
    ax.plot(s_mm, err_dia, label="compensated on the diagnosed model (+ the named effects)")
    ax.set_xlabel("position along the line (mm)")
    ax.set_ylabel("error on the true robot (mm)")
    ax.set_yscale("log")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))  # beside the curves, never on them
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _tables(res: ident.Identification, diag: dict[str, Any], summary: dict[str, Any], fres: dict[str, dict[str, Any]],
            table_fits: dict[str, dict[str, Any]]) -> dict[str, str]:
    """The report's tables and figure rows, as HTML."""
    v = res.validation
    ident_rows = [["fitted poses", f"{res.fit['nominal_rms_mm']:.3f}", f"{res.fit['rms_mm']:.3f}",
                   f"{res.fit['nominal_max_mm']:.3f}", f"{res.fit['max_mm']:.3f}"],
                  [f"held-out poses ({v['scheme']}, {v['configurations']} configurations)",
                   f"{v['before_rms_mm']:.3f}", f"{v['after_rms_mm']:.3f}",
                   f"{v['before_max_mm']:.3f}", f"{v['after_max_mm']:.3f}"]]
    diag_rows = [[k + 1, s["effect"], s["joint"] or "", f"{s['evidence']['F']:.3g}",
                  f"{s['rms_before_mm'] * 1000:.1f}", f"{s['rms_after_mm'] * 1000:.1f}"]
                 for k, s in enumerate(diag["steps"])]
    feed_rows = [[r["label"], f"{r['s_total_rad']:.4f}", len(r["violations"]), f"{r['time_optimal']['time_s']:.3f}",
                  f"{r['time_optimal']['constant_feed_time_s']:.3f}"] for r in fres.values()]
    t1_rows = [[k, " ".join(map(str, v["points"])) if isinstance(v["points"], list) else v["points"],
                f"{v['a']:.3f}", f"{v['b']:.3f}", f"{v['c']:.3f}", f"{v['d']:.3f}",
                *(f"{v['largest_mm'][d] * 1000:.1f}" for d in ("desired", "measured"))] for k, v in table_fits.items()]
    t1_html = ("<p>Table I of the Kiper paper, ranked as the paper does for the polynomial and least-squares methods:</p>"
               + report.table(["method", "points", "a", "b", "c", "d", "largest error to the desired points (um)",
                               "to the measured points (um)"], t1_rows, numeric=True, labelled=True)
               if t1_rows else "<p>Table I of the Kiper paper (shared/data/fivebar-table1.csv) was not found above "
               "the package or the working folder: its fits are left out.</p>")
    feed_imgs = "".join(report.figure(f"feed/axis{a}.png", f"axis {a}") for a in (1, 2, 3))
    wt = summary["without_tracker"]
    spheres_table = report.table(["model", "ball centre RMS (mm)"], [
        ["nominal", f"{wt['nominal_mm']:.4f}"],
        ["the tracker's identified (section 2, its TCP from the reflectors' offsets)", f"{wt['tracker_mm']:.4f}"],
        ["the tracker's diagnosed (section 3, the backlash included)", f"{wt['tracker_diagnosed_mm']:.4f}"],
        [f"the spheres' (the plan promised {wt['predicted_mm']:.4f})", f"{wt['spheres_mm']:.4f}"]],
        numeric=True, labelled=True)
    return {"ident": report.table(["", "RMS before", "RMS after", "max before", "max after"], ident_rows),
            "diag": report.table(["step", "effect", "joint", "F", "CV RMS before (um)", "after (um)"], diag_rows),
            "feed": report.table(["program", "s total (rad)", "violations", "time-optimal traversal (s)",
                                  "at constant feed (s)"], feed_rows),
            "t1": t1_html, "feed_imgs": feed_imgs, "spheres": spheres_table}


def _report(out: Path, res: ident.Identification, diag: dict[str, Any], summary: dict[str, Any], err_unc: FloatArray,
            err_com: FloatArray, err_dia: FloatArray, fres: dict[str, dict[str, Any]],
            table_fits: dict[str, dict[str, Any]], sections: dict[str, str]) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    _line_figure(plt, out / "line_errors.png", err_unc, err_com, err_dia)

    tables = _tables(res, diag, summary, fres, table_fits)
    hb = summary["fivebar_max_error_mm"]
    wt = summary["without_tracker"]
    body = f"""<h1>kincal demo</h1>
<p>The whole pipeline on built-in examples, in {summary['seconds']:.0f} s. Every number here comes from this
run; the inputs and outputs are in this folder (listed at the end).</p>

<h2>1. A measurement campaign</h2>
<p>A simulated KUKA KR 500-class robot (<code>kr500</code>, 300 kg tape-laying head) whose true geometry differs
from the nominal one by about 1 mm and 0.05 deg per axis, whose joints bend under gravity (about 0.003 deg per
kN m), and which has a backlash of 0.01 deg on joint 2 that the starting model does not know. A laser tracker
measures 3 reflectors at 200 random configurations with 0.02 mm noise (<code>measurements.csv</code>,
truth in <code>truth.json</code>).</p>

<h2>2. Identification</h2>
<p>Geometry (30 parameters) and joint compliance (5), the tracker frame and the reflector offsets, by Ceres
with an analytic Jacobian (<code>model.json</code>, full summary in <code>identify.txt</code>). Position
error in mm, nominal model (with the measured tracker frame) against the identified one:</p>
{tables["ident"]}
<p>Condition number {res.fit['condition_number']:.3g}; {sum(res.fit['fixed'])} parameters are held because the
data cannot determine them (redundant with others), named in <code>identify.txt</code>.</p>

<h2>3. Diagnosis: what is the model missing?</h2>
{tables["diag"]}
<p>{report.esc(diag['verdict'])} (cross-validated RMS {diag['final_rms_mm'] * 1000:.1f} um). The hidden effect was
backlash on joint 2. Full report: <a href="diagnosis/report.html">diagnosis/report.html</a>.</p>
{report.figure("diagnosis/gap.png", "gap")}

<h2>4. Compensation of the paper's line: the named effect reaches the robot</h2>
<p>The Samak paper's use case: 297 poses 5 mm apart on a 1480 mm line, tool orientation constant, taught in the
tracker frame (<code>line.gcode</code>). The uncompensated program is the nominal closed-form IK; the compensated
ones are Newton on a model (at most {summary['newton_iterations']['max']} iterations per pose): the identified
model (geometry and compliance, <code>model.json</code>) and the diagnosed one, which carries the effects the
diagnosis named ({report.esc(", ".join(summary['diagnosed_model_effects']) or "none")},
<code>diagnosis/model.json</code>). Each program runs on the true robot, whose joint 2 lags by its backlash
in the direction the commanded motion arrives from. Errors on the true robot, as the Samak paper states its
result (the mean position and orientation errors over the line's poses; the orientation error is the angle of
the rotation between the commanded and the attained tool orientation):</p>
{report.table(["program", "mean position error (mm)", "max (mm)", "mean orientation error (deg)", "max (deg)"],
              [[label, f"{summary[f'position_error_{k}_mm']['mean']:.4f}", f"{summary[f'position_error_{k}_mm']['max']:.4f}",
                f"{summary[f'orientation_error_{k}_deg']['mean']:.4f}", f"{summary[f'orientation_error_{k}_deg']['max']:.4f}"]
               for label, k in (("uncompensated (nominal IK)", "uncompensated"),
                                ("compensated on the identified model", "compensated"),
                                ("compensated on the diagnosed model", "compensated_diagnosed"))],
              numeric=True, labelled=True)}
<p>The paper's own figures, on its real robot: 2.04 &rarr; 0.58 mm and 0.147 &rarr; 0.095 deg.</p>
{report.figure("line_errors.png", "line errors")}

<h2>5. Accepting the cell: the standard figures</h2>
{sections['iso']}

<h2>6. Derivative analysis</h2>
<p>Both programs against the kr500's velocity, acceleration and jerk limits at a rate of s of
{feedmod.DEFAULT_FEED} rad/s (<code>feed/feed.json</code>, one figure per axis in <code>feed/</code>):</p>
{tables["feed"]}
{tables["feed_imgs"]}

<h2>7. The five-bar hidden robot</h2>
{tables["t1"]}
<p>On the simulated over-constrained 6-bar: nominal lengths miss by up to {hb['nominal'] * 1000:.0f} um, the fitted
hidden robot by {hb['fit'] * 1000:.0f} um, fit plus the 5 mm error matrix by {hb['fit_and_matrix'] * 1000:.1f} um
(400 points off the grid, 1 um instrument; target 30 um).</p>
{report.figure("fivebar/error_maps.png", "five-bar error maps")}
{sections['axis']}

<h2>8. Without a tracker: six spheres and a length bar</h2>
<p>The same robot calibrated from a touch probe: a 150 mm ball on the tool seated in six spheres placed in
reach, their distances from the first known (a length bar), {wt['touches']} touches
whose orientations <code>kincal plan --kind sphere</code> chose (D-optimal within a 60 deg cone), made on the
true robot with 0.005 mm of noise (<code>spheres.csv</code>, <code>spheres-artifact.csv</code>) and identified
with the effects the data choose ({report.esc(", ".join(wt["effects"]) or "geometry alone")})
into <code>spheres_model.json</code>. The ball centre over 200 random configurations, RMS after the best
rigid transform (the spheres do not see the base frame), in mm:</p>
{tables["spheres"]}

<h2>Files</h2>
<p>{", ".join(f'<a href="{report.esc(f)}">{report.esc(f)}</a>' for f in
             sorted({str(p.relative_to(out)) for p in out.rglob("*") if p.is_file()} | {"summary.json"}
                    - {"report.html"}))}</p>
"""
    report.write(out / "report.html", "kincal demo", body)


def summary_text(summary: dict[str, Any]) -> str:
    """One line on what run() found (its summary)."""
    return (f"identification: held-out RMS {summary['identification']['held_out_rms_before_mm']:.3f} -> "
            f"{summary['identification']['held_out_rms_after_mm']:.3f} mm; diagnosis named "
            + ", ".join(f"{d['effect']}" + (f" (joint {d['joint']})" if d["joint"] else "") for d in summary["diagnosis"])
            + f"; the line on the true robot: uncompensated {summary['position_error_uncompensated_mm']['mean']:.3f} mm, "
            f"compensated on the identified model {summary['position_error_compensated_mm']['mean']:.3f} mm, on the "
            f"diagnosed model {summary['position_error_compensated_diagnosed_mm']['mean']:.4f} mm (mean); feed "
            f"violations {summary['feed_violations']}; five-bar "
            f"{summary['fivebar_max_error_mm']['fit_and_matrix'] * 1000:.1f} um after fit + matrix; without a tracker "
            f"(six spheres) the ball centre {summary['without_tracker']['spheres_mm']:.4f} mm against the tracker's "
            f"diagnosed model's {summary['without_tracker']['tracker_diagnosed_mm']:.4f} mm ({summary['seconds']:.0f} s)")
