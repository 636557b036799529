"""MUKCa's own optimizer against kincal on MUKCa's public Gen3 lite data, one placement held out.

For each of the four placements P of tests/data/mukca (MUKCa's data/dinova_1: a ball on the tool seated
in two sockets 50 mm apart), both tools are trained on the other three placements and scored on P with
MUKCa's metric (calibrate_fk.utils.evaluate_model, outlier removal off):

- spread: per socket the mean distance of the predicted ball centres from their mean, the two sockets
  weighted by their row counts (MUKCa's "mean absolute error");
- distance error: | distance between the two sockets' mean centres - 50 mm |.

MUKCa runs in its own interpreter (its CasADi / yourdfpy / forwardkinematics environment, see README.md):
this file re-runs itself there with --mukca-fold. kincal runs through its CLI (`kincal identify ...
--artifact`) and its Python FK (`kincal.load_robot`, `kincal.fk`), in the interpreter that runs this file.

    .venv/bin/python benchmarks/mukca/compare.py --mukca-python /work/mukca-venv/bin/python \
        --mukca-src /work/mukca-src --workdir /tmp/mukca-bench
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
DATA = REPO / "tests" / "data" / "mukca"
PLACEMENTS = ("front", "left", "lower_left", "raised_back")
BASE, TIP = "kinova_base_link", "ball_link"
OFFSET_M = 0.05  # the sockets' distance, MUKCa's --offset-distance default

#: MUKCa's optimizer settings. "mukca": ParameterOptimizer.optimize()'s defaults (variance + distance
#: + regularisation), as its leave-placements-out script statistical_analysis_many_to_one.py and the
#: last ("MUKCa") scenario of comparison_with_sota.py run it; "run_optimizer": what its README's
#: scripts/run_optimizer.py passes (variance only).
MUKCA_SETTINGS = {
    "mukca": {"use_dynamic_means": True, "use_distortion_error": True, "use_regularization": True},
    "run_optimizer": {"use_dynamic_means": True, "use_distortion_error": False, "use_regularization": False},
}
#: kincal's identify options: its defaults, and the geometry alone
KINCAL_SETTINGS = {"default": [], "effects_none": ["--effects", "none"]}


# ------------------------------------------------------------------------------------------- metric
def mukca_metric(fks_0: np.ndarray, fks_1: np.ndarray, offset: float) -> dict:
    """MUKCa's evaluate_model figures from the ball centres of socket 0 and socket 1 (N x 3, any one
    length unit; ``offset`` in that unit), recomputed here line for line."""
    m0, m1 = fks_0.mean(axis=0), fks_1.mean(axis=0)
    a0 = float(np.mean(np.linalg.norm(fks_0 - m0, axis=1)))
    a1 = float(np.mean(np.linalg.norm(fks_1 - m1, axis=1)))
    n0, n1 = len(fks_0), len(fks_1)
    var0, var1 = float(np.sum(np.var(fks_0, axis=0))), float(np.sum(np.var(fks_1, axis=0)))
    u = (m0 - m1) / np.linalg.norm(m0 - m1)
    se = float(np.sqrt(np.var(fks_0 @ u, ddof=1) / n0 + np.var(fks_1 @ u, ddof=1) / n1))
    return {
        "distance_se": se,  # not MUKCa's: the standard error of that distance from the rows' scatter
        "spread": (n0 * a0 + n1 * a1) / (n0 + n1),  # MUKCa's "mean_absolute_error"
        "spread_socket0": a0,
        "spread_socket1": a1,
        "distance_error": float(abs(np.linalg.norm(m0 - m1) - offset)),
        "distance": float(np.linalg.norm(m0 - m1)),
        "std_dev_fk": float(np.sqrt((var0 * n0 + var1 * n1) / (n0 + n1))),  # MUKCa's "std_dev_fk"
        "rows": [n0, n1],
    }


def load_placement(data: Path, p: str) -> tuple[np.ndarray, np.ndarray]:
    """Joint readings (rad) of socket 0 and socket 1, read as MUKCa's read_each reads them."""
    h0, h1 = (np.atleast_2d(np.loadtxt(data / p / f"hole_{k}.csv", delimiter=",")) for k in (0, 1))
    return h0, h1


# ------------------------------------------------------------------------------- MUKCa (its venv)
def symbolic_origin_shim() -> str:
    """MUKCa pins forwardkinematics to a git branch (maxspahn/forwardKinematics ft-symbolic-fk,
    662b776, 'version 1.2.4') whose FK takes ``symbolic_parameters``: CasADi symbols that replace the
    x, y, z, roll, pitch, yaw of the named joints' URDF origins. PyPI has only 1.2.3, without them.
    When the installed forwardkinematics lacks them, this gives its URDF FK that argument (our own
    code: URDF origin = translation, then Rz(yaw) Ry(pitch) Rx(roll); revolute joints rotate about
    their axis by q, prismatic ones slide along it), for fixed joints too (MUKCa's ball_joint).
    Returns what it did."""
    import inspect

    import casadi as ca
    from forwardkinematics.urdfFks import urdfFk
    from forwardkinematics.urdfFks.casadiConversion import urdfparser

    if "symbolic_parameters" in inspect.signature(urdfFk.URDFForwardKinematics.casadi).parameters:
        return "none: the installed forwardkinematics takes symbolic_parameters"

    def origin(v):
        x, y, z, r, p, w = v
        rx = ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, ca.cos(r), -ca.sin(r)), ca.horzcat(0, ca.sin(r), ca.cos(r)))
        ry = ca.vertcat(ca.horzcat(ca.cos(p), 0, ca.sin(p)), ca.horzcat(0, 1, 0), ca.horzcat(-ca.sin(p), 0, ca.cos(p)))
        rz = ca.vertcat(ca.horzcat(ca.cos(w), -ca.sin(w), 0), ca.horzcat(ca.sin(w), ca.cos(w), 0), ca.horzcat(0, 0, 1))
        return ca.vertcat(ca.horzcat(ca.mtimes([rz, ry, rx]), ca.vertcat(x, y, z)), ca.horzcat(0, 0, 0, 1))

    def about_axis(axis, qi):  # Rodrigues, axis as the URDF gives it
        k = ca.DM(axis)
        kx = ca.vertcat(ca.horzcat(0, -k[2], k[1]), ca.horzcat(k[2], 0, -k[0]), ca.horzcat(-k[1], k[0], 0))
        rot = ca.cos(qi) * ca.DM.eye(3) + ca.sin(qi) * kx + (1 - ca.cos(qi)) * ca.mtimes(k, k.T)
        return ca.vertcat(ca.horzcat(rot, ca.DM.zeros(3, 1)), ca.horzcat(0, 0, 0, 1))

    def along_axis(axis, qi):
        return ca.vertcat(ca.horzcat(ca.DM.eye(3), ca.DM(axis) * qi), ca.horzcat(0, 0, 0, 1))

    def get_forward_kinematics(self, root, tip, q, link_transformation=None, symbolic_parameters=None):
        link_transformation = np.eye(4) if link_transformation is None else link_transformation
        sym = symbolic_parameters or {}
        t = ca.SX.eye(4)
        for joint in self.get_joint_info(self._absolute_root_link, tip):
            o = joint.origin
            v = list(o.xyz) + list(o.rpy) if o is not None else [0.0] * 6
            for i, key in enumerate(("x", "y", "z", "roll", "pitch", "yaw")):
                if key in sym.get(joint.name, {}):
                    v[i] = sym[joint.name][key]
            t = ca.mtimes(t, origin(v))
            axis = joint.axis if joint.axis is not None else [1.0, 0.0, 0.0]
            if joint.type in ("revolute", "continuous"):
                t = ca.mtimes(t, about_axis(axis, q[self._joint_map[joint.name]]))
            elif joint.type == "prismatic":
                t = ca.mtimes(t, along_axis(axis, q[self._joint_map[joint.name]]))
        return {"T_fk": ca.mtimes(t, link_transformation)}

    def casadi(self, q, child_link, parent_link=None, link_transformation=None, position_only=False,
               symbolic_parameters=None):
        link_transformation = np.eye(4) if link_transformation is None else link_transformation
        if self._base_type != "holonomic":
            raise NotImplementedError("symbolic_origin_shim: fixed-base arms only")
        if child_link not in self.robot.link_names():
            raise urdfFk.LinkNotInURDFError(f"{child_link} is not in the urdf")
        fk = self.robot.get_forward_kinematics(parent_link or self._root_link, child_link, q,
                                               link_transformation, symbolic_parameters)["T_fk"]
        fk = ca.mtimes(self._mount_transformation, fk)
        return fk[0:3, 3] if position_only else fk

    urdfparser.URDFparser.get_forward_kinematics = get_forward_kinematics
    urdfFk.URDFForwardKinematics.casadi = casadi
    return "symbolic_origin_shim: forwardkinematics' URDF FK given symbolic_parameters (PyPI 1.2.3 lacks them)"


def mukca_fold(args: argparse.Namespace) -> int:
    """Runs inside MUKCa's interpreter: trains MUKCa's ParameterOptimizer on --train, evaluates the
    nominal and the calibrated URDF on --test with MUKCa's evaluate_model, writes JSON."""
    import types

    # parameter_optimizer opens a Tk root window at import (for its interactive file picker, unused
    # here); a headless machine has no display, so stand a do-nothing tkinter in for it
    tk = types.ModuleType("tkinter")
    fd = types.ModuleType("tkinter.filedialog")
    setattr(tk, "Tk", lambda *a, **k: types.SimpleNamespace(withdraw=lambda: None))  # noqa: B010
    setattr(tk, "filedialog", fd)  # noqa: B010
    sys.modules.setdefault("tkinter", tk)
    sys.modules.setdefault("tkinter.filedialog", fd)

    import casadi as ca
    import yaml
    import yourdfpy

    shim = symbolic_origin_shim()
    print(shim)
    import calibrate_fk.utils as mu
    from calibrate_fk.parameter_optimizer import ParameterOptimizer

    # no outlier removal, for both tools (at MUKCa's HEAD remove_outliers already leaves the data as
    # they are: its filtering line is commented out; made explicit here and checked on the row counts)
    mu.remove_outliers = lambda model, data, verbose=False: data

    solvers = []
    nlpsol = ca.nlpsol

    def recording_nlpsol(*a, **k):  # only records the solver, for its iteration count and status
        s = nlpsol(*a, **k)
        solvers.append(s)
        return s

    ca.nlpsol = recording_nlpsol

    src, out = Path(args.mukca_src), Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    urdf = str(Path(args.urdf).resolve())
    train = [str(Path(args.data) / p) for p in args.train]
    test = [str(Path(args.data) / args.test)]

    def evaluate(model, folders):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            stats = mu.evaluate_model(model, folders, verbose=True, offset_distance=OFFSET_M)
        printed = buf.getvalue()
        sys.stdout.write(printed)
        res = {}
        for block in printed.split("Tool position: ")[1:]:
            name = block.splitlines()[0].strip()
            res[name] = {
                "printed_mean_absolute_error": float(re.search(r"Mean absolute error: (\S+)", block).group(1)),
                "printed_distance_error": float(re.search(r"Distance error: (\S+)", block).group(1)),
                "fks_1": stats[name]["fks_1"],
                "fks_2": stats[name]["fks_2"],
                "mean_absolute_error": stats[name]["mean_absolute_error"],
                "distance_error": stats[name]["distance_error"],
            }
        return res

    joints = yaml.safe_load((src / "config_optimizer" / "gen3lite.yaml").read_text())["joints"]
    t0 = time.perf_counter()
    opt = ParameterOptimizer(str(out))
    opt.set_offset_distance(OFFSET_M)
    opt.set_regulizer_weight(args.regularizer)
    opt.load_model(urdf)
    opt.read_data(train)
    opt.create_symbolic_fk(args.root_link, TIP)
    opt.select_parameters(variance_noise=0.0, selected_parameters=joints)
    nominal = {j: dict(v) for j, v in opt.best_params.items()}
    train_rows = {k: [np.asarray(s).tolist() for s in v] for k, v in opt.data.items()}
    nominal_model = yourdfpy.URDF.load(urdf)
    t1 = time.perf_counter()
    opt.optimize(saving_steps=False, **MUKCA_SETTINGS[args.settings])
    t2 = time.perf_counter()
    stats = solvers[-1].stats()
    result = {
        "settings": args.settings,
        "forwardkinematics": shim,
        "flags": MUKCA_SETTINGS[args.settings],
        "regularizer": args.regularizer,
        "root_link": args.root_link,
        "train": args.train,
        "test": args.test,
        "selected_joints": joints,
        "nominal_params": nominal,
        "fitted_params": opt.best_params,
        "urdf": str(out / Path(urdf).name),
        "seconds_setup": t1 - t0,
        "seconds_optimize": t2 - t1,  # symbolic objective built + IPOPT
        "ipopt_iterations": int(stats.get("iter_count", -1)),
        "ipopt_status": str(stats.get("return_status")),
        "train_rows": train_rows,
        "test_rows": {k: [np.asarray(s).tolist() for s in v] for k, v in mu.read_data(test).items()},
    }
    print("== MUKCa evaluate_model, nominal URDF, held-out placement")
    result["nominal_test"] = evaluate(nominal_model, test)
    print("== MUKCa evaluate_model, calibrated URDF, held-out placement")
    result["calibrated_test"] = evaluate(opt._model, test)
    print("== MUKCa evaluate_model, calibrated URDF, training placements")
    result["calibrated_train"] = evaluate(opt._model, train)
    # the FK MUKCa optimised (CasADi, symbolic origins) against the URDF it wrote (yourdfpy)
    fk = ca.Function("fk", [opt._q, opt.list_parameters()], [opt._fk_casadi_expr])
    x = opt.list_best_parameters()
    ev = result["calibrated_test"][args.test]
    sym = [np.array([np.asarray(fk(q, x)).ravel() for q in rows]) for rows in mu.read_data(test)[args.test]]
    result["symbolic_vs_urdf_m"] = max(float(np.max(np.abs(sym[0] - np.asarray(ev["fks_1"])))),
                                       float(np.max(np.abs(sym[1] - np.asarray(ev["fks_2"])))))
    (out / "mukca_result.json").write_text(json.dumps(result))
    return 0


# -------------------------------------------------------------------------------- kincal (this venv)
def write_campaign(d: Path, name: str, data: dict, placements) -> tuple[Path, Path]:
    """The rows as a kincal probe campaign: one sphere station per placement and socket (angles in
    deg), the sockets' 50 mm as the artifact (as tests/python/test_probe.py's _mukca_campaign)."""
    lines, art, pose = ["pose,q1,q2,q3,q4,q5,q6,kind,station"], ["a,b,distance_mm,angle_deg"], 0
    for p in placements:
        for k in (0, 1):
            for q in data[p][k]:
                lines.append(f"{pose}," + ",".join(repr(float(v)) for v in np.degrees(q)) + f",sphere,{p}/hole_{k}")
                pose += 1
        art.append(f"{p}/hole_0,{p}/hole_1,{OFFSET_M * 1000:g},")
    csv, acsv = d / f"{name}.csv", d / f"{name}-artifact.csv"
    csv.write_text("\n".join(lines) + "\n")
    acsv.write_text("\n".join(art) + "\n")
    return csv, acsv


def kincal_ball_mm(robot, q_rad: np.ndarray, target_mm=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Ball centres (mm, base frame) of a kincal model at joint readings in rad: the tool frame's pose
    (kincal.fk, every effect of the model acting) carrying the ball's offset in the tool frame (the
    identified model's identification.targets_mm[0]; zero for the URDF, whose tip is ball_link)."""
    import kincal
    from kincal import _core

    p = kincal.fk(robot, np.degrees(q_rad))
    rot = np.array([_core.abc_to_rotation(abc) for abc in p[:, 3:]])
    return p[:, :3] + rot @ np.asarray(target_mm, dtype=float)


def kincal_score(robot, hole0: np.ndarray, hole1: np.ndarray, target_mm=(0.0, 0.0, 0.0)) -> dict:
    return mukca_metric(kincal_ball_mm(robot, hole0, target_mm), kincal_ball_mm(robot, hole1, target_mm),
                        OFFSET_M * 1000)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mukca-python", default="/work/mukca-venv/bin/python",
                    help="the interpreter of MUKCa's environment (README.md)")
    ap.add_argument("--mukca-src", default="/work/mukca-src", help="MUKCa's source tree (its config_optimizer/)")
    ap.add_argument("--kincal", default=str(Path(sys.executable).with_name("kincal")), help="kincal's CLI")
    ap.add_argument("--data", default=str(DATA), help="folder of placements/hole_{0,1}.csv")
    ap.add_argument("--urdf", default=str(DATA / "gen3lite.urdf"))
    ap.add_argument("--workdir", default=None, help="where the models and logs go (default: a new temp dir)")
    ap.add_argument("--placements", nargs="+", default=list(PLACEMENTS))
    ap.add_argument("--regularizer", type=float, default=1e-4, help="MUKCa's --regularizer default")
    ap.add_argument("--root-link", default="base_link",
                    help="MUKCa's --root-link default; gen3lite.urdf has no such link, so its FK runs from "
                         "the URDF's root (world, joined to kinova_base_link by an identity joint)")
    ap.add_argument("--settings", default="mukca", help=argparse.SUPPRESS)
    ap.add_argument("--train", nargs="+", help=argparse.SUPPRESS)
    ap.add_argument("--test", help=argparse.SUPPRESS)
    ap.add_argument("--out", help=argparse.SUPPRESS)
    ap.add_argument("--mukca-fold", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.mukca_fold:
        return mukca_fold(args)

    import kincal

    data_dir, urdf = Path(args.data).resolve(), Path(args.urdf).resolve()
    work = Path(args.workdir or tempfile.mkdtemp(prefix="mukca-bench-")).resolve()
    work.mkdir(parents=True, exist_ok=True)
    data = {p: load_placement(data_dir, p) for p in PLACEMENTS}
    nominal = kincal.load_robot(str(urdf), BASE, TIP)
    results: dict[str, dict[str, Any]] = {}
    checks: list[tuple[str, str, str, float]] = []
    for held in args.placements:
        train = [p for p in PLACEMENTS if p != held]
        fold = work / held
        fold.mkdir(exist_ok=True)
        r: dict[str, Any] = {"train": train, "rows_test": [len(data[held][0]), len(data[held][1])],
                             "nominal": kincal_score(nominal, *data[held]), "mukca": {}, "kincal": {}}
        results[held] = r
        # ---- MUKCa, in its own interpreter
        for name in MUKCA_SETTINGS:
            out = fold / f"mukca_{name}"
            cmd = [args.mukca_python, str(Path(__file__).resolve()), "--mukca-fold", "--settings", name,
                   "--mukca-src", args.mukca_src, "--data", str(data_dir), "--urdf", str(urdf),
                   "--train", *train, "--test", held, "--out", str(out),
                   "--regularizer", repr(args.regularizer), "--root-link", args.root_link]
            t = time.perf_counter()
            proc = subprocess.run(cmd, capture_output=True, text=True, cwd=str(fold), check=False)
            wall = time.perf_counter() - t
            (fold / f"mukca_{name}.log").write_text(proc.stdout + proc.stderr)
            if proc.returncode != 0:
                sys.stderr.write(proc.stdout[-3000:] + proc.stderr[-3000:])
                raise SystemExit(f"MUKCa ({name}) failed on held-out {held}; log in {fold}")
            m = json.loads((out / "mukca_result.json").read_text())
            # the same rows as kincal's: every joint reading, in the same order, nothing dropped
            for p in train:
                assert all(np.array_equal(np.asarray(m["train_rows"][p][k]), data[p][k]) for k in (0, 1)), p
            assert all(np.array_equal(np.asarray(m["test_rows"][held][k]), data[held][k]) for k in (0, 1))
            printed = m["calibrated_test"][held]
            calibrated = kincal.load_robot(m["urdf"], BASE, TIP)
            own = {"spread": printed["printed_mean_absolute_error"] * 1000,
                   "distance_error": printed["printed_distance_error"] * 1000}
            # the reimplemented metric: on MUKCa's own FK points, and on kincal's FK of MUKCa's URDF
            on_points = mukca_metric(np.asarray(printed["fks_1"]), np.asarray(printed["fks_2"]), OFFSET_M)
            via_kincal = kincal_score(calibrated, *data[held])
            nom_printed = m["nominal_test"][held]
            for label, mine, theirs in (
                    ("MUKCa points, calibrated", (on_points["spread"] * 1000, on_points["distance_error"] * 1000),
                     (own["spread"], own["distance_error"])),
                    ("kincal FK of MUKCa URDF", (via_kincal["spread"], via_kincal["distance_error"]),
                     (own["spread"], own["distance_error"])),
                    ("kincal FK of nominal URDF", (r["nominal"]["spread"], r["nominal"]["distance_error"]),
                     (nom_printed["printed_mean_absolute_error"] * 1000, nom_printed["printed_distance_error"] * 1000))):
                checks.append((held, name, label, max(abs(a - b) for a, b in zip(mine, theirs))))
            checks.append((held, name, "MUKCa CasADi FK vs its URDF", m["symbolic_vs_urdf_m"] * 1000))
            r["mukca"][name] = {
                **via_kincal, "printed": own, "seconds_optimize": m["seconds_optimize"],
                "seconds_setup": m["seconds_setup"], "seconds_process": wall,
                "ipopt_iterations": m["ipopt_iterations"], "ipopt_status": m["ipopt_status"],
                "urdf": m["urdf"], "flags": m["flags"],
                "train_spread_mm": {k: v["printed_mean_absolute_error"] * 1000 for k, v in m["calibrated_train"].items()},
                "params_changed": {j: {k: m["fitted_params"][j][k] - m["nominal_params"][j][k] for k in v}
                                   for j, v in m["nominal_params"].items()},
            }
        # ---- kincal, trained on the same three placements
        fit_csv, fit_art = write_campaign(fold, "fit", data, train)
        for name, extra in KINCAL_SETTINGS.items():
            model = fold / f"kincal_{name}.json"
            cmd = [args.kincal, "identify", "--robot", str(urdf), "--base", BASE, "--tip", TIP,
                   "--data", str(fit_csv), "--artifact", str(fit_art), "--out", str(model), *extra]
            t = time.perf_counter()
            proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
            wall = time.perf_counter() - t
            (fold / f"kincal_{name}.log").write_text(proc.stdout + proc.stderr)
            if proc.returncode != 0:
                sys.stderr.write(proc.stdout[-3000:] + proc.stderr[-3000:])
                raise SystemExit(f"kincal identify ({name}) failed on held-out {held}; log in {fold}")
            robot = kincal.load_robot(str(model))
            doc = json.loads(model.read_text())
            ball = doc["identification"]["targets_mm"][0]  # the ball centre in the tool frame
            head = proc.stdout.splitlines()[0] if proc.stdout else ""
            # the ball centres as reconstructed here, against kincal's own fitted sockets: their RMS
            # distance must be the fit RMS that identify reports
            st = {q["name"]: q["value"] for q in doc["identification"]["parameters"] if q["name"].startswith("station[")}
            res = np.vstack([kincal_ball_mm(robot, data[p][k], ball)
                             - np.array([st[f"station[{p}/hole_{k}].{a}"] for a in "xyz"])
                             for p in train for k in (0, 1)])
            checks.append((held, f"kincal {name}", "ball centres vs its fit RMS",
                           abs(float(np.sqrt(np.mean(np.sum(res ** 2, axis=1)))) - doc["identification"]["fit"]["rms_mm"])))
            r["kincal"][name] = {**kincal_score(robot, *data[held], ball), "seconds_process": wall,
                                 "summary": head, "options": extra, "model": str(model), "ball_in_tool_mm": ball,
                                 "fit_rms_mm": doc["identification"]["fit"]["rms_mm"],
                                 "train_spread_mm": {p: kincal_score(robot, *data[p], ball)["spread"] for p in train}}
        print(f"{held}: nominal {r['nominal']['spread']:.3f} mm / {r['nominal']['distance_error']:.3f} mm, "
              f"MUKCa {r['mukca']['mukca']['spread']:.3f} / {r['mukca']['mukca']['distance_error']:.3f}, "
              f"kincal {r['kincal']['default']['spread']:.3f} / {r['kincal']['default']['distance_error']:.3f}",
              flush=True)

    core = Path(kincal._core.__file__)
    build = {"kincal_core": str(core), "sha256": __import__("hashlib").sha256(core.read_bytes()).hexdigest()[:16],
             "mtime_utc": time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime(core.stat().st_mtime))}
    (work / "results.json").write_text(json.dumps({"results": results, "metric_checks": checks, "kincal_build": build},
                                                  indent=1))
    print(f"kincal build: {build['kincal_core']} sha256 {build['sha256']}..., installed {build['mtime_utc']} UTC")
    print_report(results, checks, work)
    return 0


def print_report(results: dict, checks: list, work: Path) -> None:
    def f(x):
        return f"{x:.3f}"

    def table(mk: str, kc: str) -> None:
        print(f"\nMUKCa settings '{mk}' {MUKCA_SETTINGS[mk]}; kincal identify options "
              f"{KINCAL_SETTINGS[kc] or '(defaults)'}. Held-out placement, MUKCa's metric, mm.")
        print("| held out | nominal spread | nominal dist err | MUKCa spread | MUKCa dist err "
              "| kincal spread | kincal dist err | kincal/MUKCa spread | kincal/MUKCa dist err |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
        for p, r in results.items():
            n, m, k = r["nominal"], r["mukca"][mk], r["kincal"][kc]
            print(f"| {p} | {f(n['spread'])} | {f(n['distance_error'])} | {f(m['spread'])} | "
                  f"{f(m['distance_error'])} | {f(k['spread'])} | {f(k['distance_error'])} | "
                  f"{k['spread'] / m['spread']:.2f} | {k['distance_error'] / m['distance_error']:.2f} |")

    for kc in KINCAL_SETTINGS:
        table("mukca", kc)
    print(f"\nMUKCa with scripts/run_optimizer.py's settings {MUKCA_SETTINGS['run_optimizer']} "
          "(held-out spread / distance error, mm):")
    for p, r in results.items():
        m = r["mukca"]["run_optimizer"]
        print(f"  {p}: {f(m['spread'])} / {f(m['distance_error'])} (distance between the socket means "
              f"{f(m['distance'])} mm)")
    print("\nper-socket spreads (socket 0 / socket 1, mm):")
    for p, r in results.items():
        parts = [f"nominal {f(r['nominal']['spread_socket0'])}/{f(r['nominal']['spread_socket1'])}"]
        parts += [f"MUKCa[{k}] {f(v['spread_socket0'])}/{f(v['spread_socket1'])}" for k, v in r["mukca"].items()]
        parts += [f"kincal[{k}] {f(v['spread_socket0'])}/{f(v['spread_socket1'])}" for k, v in r["kincal"].items()]
        print(f"  {p}: " + ", ".join(parts))
    print("\nstandard error of the held-out distance between the socket means, from the scatter of the rows "
          "along it (mm): a distance error below about twice it is not told apart from zero")
    for p, r in results.items():
        print(f"  {p}: nominal {f(r['nominal']['distance_se'])}, MUKCa {f(r['mukca']['mukca']['distance_se'])}, "
              + ", ".join(f"kincal[{k}] {f(v['distance_se'])}" for k, v in r["kincal"].items()))
    print("\ntraining time (s): MUKCa optimize (objective built + IPOPT) / whole process; kincal identify process")
    for p, r in results.items():
        parts = [f"MUKCa[{k}] {v['seconds_optimize']:.1f}/{v['seconds_process']:.1f} "
                 f"({v['ipopt_iterations']} it, {v['ipopt_status']})" for k, v in r["mukca"].items()]
        parts += [f"kincal[{k}] {v['seconds_process']:.1f}" for k, v in r["kincal"].items()]
        print(f"  {p}: " + ", ".join(parts))
    worst = max(c[3] for c in checks)
    print(f"\nchecks, largest |reimplemented - the tool's own figure| over {len(checks)} comparisons: {worst:.2e} mm")
    for c in checks:
        print(f"  {c[0]:12s} {c[1]:14s} {c[2]:28s} {c[3]:.2e} mm")
    print(f"\nmodels, logs and results.json in {work}")


if __name__ == "__main__":
    sys.exit(main())
