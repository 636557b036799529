"""kincal accuracy iso9283 and kincal accuracy axis: every figure checked against a separate, direct
implementation in this file (plain loops over the rows, written from the standards' formulas, see
kincal/accuracy.py's docstring for the sources), convergence to the theoretical values on simulated
runs of known repeatability, order independence, bad input and the report in a headless browser."""

from __future__ import annotations

import json
import math
import re
import shutil
import subprocess

import numpy as np
import pytest

import kincal
from kincal.standards import accuracy as acc

from conftest import run

RUNS_HEAD = "point,cycle,xc,yc,zc,ac,bc,cc,x,y,z,a,b,c,direction"

# hand-made runs: two points, two approach directions, four cycles each; P2's commanded a = 179.9 deg
# so its attained angles cross +-180
CMD = {"P1": (1000.0, 0.0, 500.0, 0.0, 0.0, 0.0), "P2": (1200.0, 300.0, 400.0, 179.9, 10.0, -20.0)}
HAND = [
    ("P1", 1, "A", (1000.10, 0.02, 500.00, 0.010, -0.020, 0.000)),
    ("P1", 2, "A", (1000.13, -0.01, 500.03, 0.020, -0.010, 0.005)),
    ("P1", 3, "A", (1000.08, 0.04, 499.98, 0.000, -0.030, -0.004)),
    ("P1", 4, "A", (1000.11, 0.00, 500.05, 0.015, -0.025, 0.002)),
    ("P1", 1, "B", (999.95, 0.07, 500.10, 0.030, 0.010, 0.010)),
    ("P1", 2, "B", (999.97, 0.09, 500.08, 0.025, 0.000, 0.012)),
    ("P1", 3, "B", (999.92, 0.06, 500.12, 0.035, 0.020, 0.008)),
    ("P1", 4, "B", (999.96, 0.10, 500.09, 0.028, 0.015, 0.011)),
    ("P2", 1, "A", (1200.30, 299.90, 400.20, 179.95, 10.010, -20.000)),
    ("P2", 2, "A", (1200.28, 299.95, 400.22, -179.98, 10.020, -20.010)),
    ("P2", 3, "A", (1200.33, 299.88, 400.18, 179.99, 10.000, -19.990)),
    ("P2", 4, "A", (1200.31, 299.93, 400.25, -179.96, 10.015, -20.005)),
    ("P2", 1, "B", (1200.10, 300.05, 400.05, 179.92, 9.990, -20.020)),
    ("P2", 2, "B", (1200.12, 300.02, 400.01, 179.93, 9.995, -20.030)),
    ("P2", 3, "B", (1200.08, 300.07, 400.08, 179.91, 9.985, -20.015)),
    ("P2", 4, "B", (1200.11, 300.04, 400.03, 179.94, 9.990, -20.025)),
]


def _runs_csv(rows) -> str:
    return RUNS_HEAD + "\n" + "".join(
        f"{p},{c},{','.join(repr(v) for v in CMD[p])},{','.join(repr(v) for v in att)},{d}\n" for p, c, d, att in rows)


def _mean(v):
    return sum(v) / len(v)


def _sd(v):
    m = _mean(v)
    return math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1))


def _angle_diff(a, b):
    """a - b in (-180, 180]."""
    d = a - b
    while d > 180.0:
        d -= 360.0
    while d <= -180.0:
        d += 360.0
    return d


def _direct_point(cmd, atts):
    """ISO 9283 7.2, written out: barycentre, AP, l_j, RP_l = mean l + 3 S_l, RP_a = 3 S_a."""
    bary = [_mean([a[k] for a in atts]) for k in range(3)]
    ap = [bary[k] - cmd[k] for k in range(3)]
    l = [math.sqrt(sum((a[k] - bary[k]) ** 2 for k in range(3))) for a in atts]
    out = {"AP_P_mm": math.sqrt(sum(x * x for x in ap)), "AP_x_mm": ap[0], "AP_y_mm": ap[1], "AP_z_mm": ap[2],
           "RP_l_mm": _mean(l) + 3 * _sd(l), "bary": bary}
    for k, n in enumerate("abc"):
        d = [_angle_diff(a[3 + k], cmd[3 + k]) for a in atts]  # attained - commanded, unwrapped near +-180
        out[f"AP_{n}_deg"] = _mean(d)
        out[f"RP_{n}_deg"] = 3 * _sd(d)
    return out


def test_iso9283_formulas_on_hand_made_runs(tmp_path):
    """Hand-made runs (above): AP_P, AP_x/y/z, RP_l, AP_a/b/c, RP_a/b/c over all of a point's cycles,
    vAP_P (largest distance between the two directions' barycentres) and AD/RD between P1 and P2
    (cycle by cycle: D_j = |P1_j - P2_j|, AD = mean D - |P1c - P2c|, RD = 3 S_D) as computed directly
    here; the command's exit is 0 and the folder holds the JSON, the page and its figures."""
    (tmp_path / "runs.csv").write_text(_runs_csv(HAND))
    r = run("kincal", "accuracy", "iso9283", "--data", str(tmp_path / "runs.csv"), "--out", str(tmp_path / "rep"),
            "--distance", "P1,P2")
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "rep" / "iso9283.json").read_text())
    assert {f.name for f in (tmp_path / "rep").iterdir()} == {"iso9283.json", "report.html", "deviations.png",
                                                               "summary.png"}
    assert [p["point"] for p in doc["points"]] == ["P1", "P2"]
    for p in doc["points"]:
        rows = [x for x in HAND if x[0] == p["point"]]
        want = _direct_point(CMD[p["point"]], [x[3] for x in rows])
        assert p["n"] == 8
        for k in ("AP_P_mm", "AP_x_mm", "AP_y_mm", "AP_z_mm", "RP_l_mm", "AP_a_deg", "AP_b_deg", "AP_c_deg",
                  "RP_a_deg", "RP_b_deg", "RP_c_deg"):
            assert p[k] == pytest.approx(want[k], abs=1e-9), k
        bary = {d: _direct_point(CMD[p["point"]], [x[3] for x in rows if x[2] == d])["bary"] for d in "AB"}
        assert p["vAP_P_mm"] == pytest.approx(math.dist(bary["A"], bary["B"]), abs=1e-9)
    # P2's angle a: attained values on both sides of +-180 average near 179.96, not near 0
    assert abs(doc["points"][1]["AP_a_deg"]) < 0.1
    pairs = [(a[3], b[3]) for a in HAND if a[0] == "P1" for b in HAND if b[0] == "P2" and (b[1], b[2]) == (a[1], a[2])]
    d = [math.dist(a[:3], b[:3]) for a, b in pairs]
    assert len(d) == 8
    assert doc["AD_mm"] == pytest.approx(_mean(d) - math.dist(CMD["P1"][:3], CMD["P2"][:3]), abs=1e-9)
    assert doc["RD_mm"] == pytest.approx(3 * _sd(d), abs=1e-9)
    assert "RP_l" in r.stdout and "AD" in r.stdout


# hand-made axis runs (mm): three targets, both directions, three runs each
AXIS = {(0.0, 1): [0.004, 0.006, 0.005], (0.0, -1): [-0.002, -0.001, -0.004],
        (250.0, 1): [250.010, 250.013, 250.008], (250.0, -1): [250.001, 250.004, 249.999],
        (500.0, 1): [499.995, 499.998, 499.992], (500.0, -1): [499.985, 499.990, 499.987]}


def _axis_csv(items) -> str:
    return "target,direction,run,measured\n" + "".join(f"{t},{d},{k},{m}\n" for t, d, k, m in items)


def _axis_items():
    return [(t, d, k + 1, m) for (t, d), ms in AXIS.items() for k, m in enumerate(ms)]


def test_axis_formulas_on_hand_made_runs(tmp_path):
    """Hand-made runs of one axis (above): ISO 230-2 (B_i, B, R_i, R, E, M, A, per target means and
    s) and VDI/DGQ 3441 (U, Ps, Pa, P, their means, P per metre over the 0.5 m travel) as computed
    directly here from the deviations measured - target."""
    (tmp_path / "axis.csv").write_text(_axis_csv(_axis_items()))
    r = run("kincal", "accuracy", "axis", "--data", str(tmp_path / "axis.csv"), "--out", str(tmp_path / "ax"))
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "ax" / "axis.json").read_text())
    assert {f.name for f in (tmp_path / "ax").iterdir()} == {"axis.json", "report.html", "axis.png"}
    targets = [0.0, 250.0, 500.0]
    dev = {k: [m - k[0] for m in v] for k, v in AXIS.items()}
    mu = [_mean(dev[(t, 1)]) for t in targets]
    md = [_mean(dev[(t, -1)]) for t in targets]
    su = [_sd(dev[(t, 1)]) for t in targets]
    sd = [_sd(dev[(t, -1)]) for t in targets]
    b = [u - d for u, d in zip(mu, md)]
    r_i = [max(2 * su[i] + 2 * sd[i] + abs(b[i]), 4 * su[i], 4 * sd[i]) for i in range(3)]
    mid = [(u + d) / 2 for u, d in zip(mu, md)]
    iso = doc["iso230_2"]
    assert iso["B"] == pytest.approx(max(abs(x) for x in b), abs=1e-12)
    assert iso["R"] == pytest.approx(max(r_i), abs=1e-12)
    assert iso["E"] == pytest.approx(max(mu + md) - min(mu + md), abs=1e-12)
    assert iso["M"] == pytest.approx(max(mid) - min(mid), abs=1e-12)
    assert iso["A"] == pytest.approx(max([m + 2 * s for m, s in zip(mu + md, su + sd)]) -
                                     min([m - 2 * s for m, s in zip(mu + md, su + sd)]), abs=1e-12)
    for i, p in enumerate(iso["targets"]):
        assert p["target"] == targets[i]
        for k, v in (("mean_up", mu[i]), ("mean_down", md[i]), ("s_up", su[i]), ("s_down", sd[i]), ("B_i", b[i]),
                     ("R_i", r_i[i])):
            assert p[k] == pytest.approx(v, abs=1e-12), k
    u = [abs(x) for x in b]
    ps = [6 * (su[i] + sd[i]) / 2 for i in range(3)]
    vdi = doc["vdi3441"]
    assert vdi["U"] == pytest.approx(max(u), abs=1e-12) and vdi["U_mean"] == pytest.approx(_mean(u), abs=1e-12)
    assert vdi["Ps"] == pytest.approx(max(ps), abs=1e-12) and vdi["Ps_mean"] == pytest.approx(_mean(ps), abs=1e-12)
    assert vdi["Pa"] == pytest.approx(max(mid) - min(mid), abs=1e-12)
    p_unc = max(mid[i] + (u[i] + ps[i]) / 2 for i in range(3)) - min(mid[i] - (u[i] + ps[i]) / 2 for i in range(3))
    assert vdi["P"] == pytest.approx(p_unc, abs=1e-12)
    assert vdi["P_per_m"] == pytest.approx(p_unc / 0.5, abs=1e-12)
    # in degrees: the same numbers, no per-metre figure
    r = run("kincal", "accuracy", "axis", "--data", str(tmp_path / "axis.csv"), "--out", str(tmp_path / "deg"),
            "--unit", "deg")
    assert r.returncode == 0, r.stderr
    deg = json.loads((tmp_path / "deg" / "axis.json").read_text())
    assert deg["unit"] == "deg" and "P_per_m" not in deg["vdi3441"] and deg["vdi3441"]["P"] == vdi["P"]


def test_repeatability_converges_to_theory(tmp_path):
    """Simulated runs, 1,000 cycles per point (seed 3): attained = commanded + bias + e, e ~ N(0, s^2 I3)
    with s = 0.05 mm, angles with N(0, 0.01^2) deg. l_j = |P_j - barycentre| is then s (1 - 1/n)^(1/2)
    times a chi variable with 3 degrees of freedom: mean sqrt(8/pi) = 1.5958, variance 3 - 8/pi =
    0.4535, so RP_l -> s (sqrt(8/pi) + 3 sqrt(3 - 8/pi)) = 3.6161 s = 0.1808 mm; RP_a -> 3 x 0.01 deg.
    One axis, 1,000 runs per direction at 5 targets (seed 4): deviation = systematic(target) +- b/2 +
    e, e ~ N(0, s^2), s = 0.002 mm, b = 0.006 mm: s_j -> s, so Ps_j = 6 s_j -> 6 s = 0.012 mm (Ps, the
    largest of 5, and Ps_mean); U -> b; ISO 230-2 R_i -> 2 s + 2 s + b = 0.014 mm. Each within 10%."""
    rng = np.random.default_rng(3)
    s, n = 0.05, 1000
    lines = [RUNS_HEAD]
    for name, cmd in CMD.items():
        bias = rng.normal(0, 0.2, 3)
        for j in range(n):
            att = np.r_[np.asarray(cmd[:3]) + bias + rng.normal(0, s, 3), np.asarray(cmd[3:]) + rng.normal(0, 0.01, 3)]
            lines.append(f"{name},{j},{','.join(repr(v) for v in cmd)},{','.join(repr(float(v)) for v in att)},A")
    (tmp_path / "runs.csv").write_text("\n".join(lines) + "\n")
    res = acc.iso9283(acc.read_runs(str(tmp_path / "runs.csv")))
    theory = s * (math.sqrt(8 / math.pi) + 3 * math.sqrt(3 - 8 / math.pi))
    assert theory == pytest.approx(0.1808, abs=1e-4)
    for p in res["points"]:
        assert p["n"] == n
        assert p["RP_l_mm"] == pytest.approx(theory, rel=0.10)
        for k in "abc":
            assert p[f"RP_{k}_deg"] == pytest.approx(0.03, rel=0.10)
    rng = np.random.default_rng(4)
    s, b = 0.002, 0.006
    items = []
    for t in (0.0, 200.0, 400.0, 600.0, 800.0):
        for d in (1, -1):
            for k in range(n):
                items.append((t, d, k, t + 0.01 * math.sin(t / 250) + d * b / 2 + rng.normal(0, s)))
    (tmp_path / "axis.csv").write_text(_axis_csv(items))
    res = acc.axis_statistics(acc.read_axis(str(tmp_path / "axis.csv")))
    vdi = res["vdi3441"]
    assert vdi["Ps"] == pytest.approx(6 * s, rel=0.10)
    assert vdi["Ps_mean"] == pytest.approx(6 * s, rel=0.10)
    assert vdi["U"] == pytest.approx(b, rel=0.10)
    assert res["iso230_2"]["R"] == pytest.approx(4 * s + b, rel=0.10)


def test_rows_in_any_order_give_the_same_report(tmp_path):
    """The hand-made runs and axis file, rows shuffled (seed 5): every file of both folders is the
    same to the byte (JSON, page and figures)."""
    rng = np.random.default_rng(5)
    shuffled = [HAND[i] for i in rng.permutation(len(HAND))]
    items = _axis_items()
    items_shuffled = [items[i] for i in rng.permutation(len(items))]
    for sub, runs, axis in (("a", HAND, items), ("b", shuffled, items_shuffled)):
        (tmp_path / sub).mkdir()
        (tmp_path / sub / "runs.csv").write_text(_runs_csv(runs))
        (tmp_path / sub / "axis.csv").write_text(_axis_csv(axis))
        r = run("kincal", "accuracy", "iso9283", "--data", str(tmp_path / sub / "runs.csv"), "--out",
                str(tmp_path / sub / "iso"), "--distance", "P2,P1")
        assert r.returncode == 0, r.stderr
        r = run("kincal", "accuracy", "axis", "--data", str(tmp_path / sub / "axis.csv"), "--out",
                str(tmp_path / sub / "axis"))
        assert r.returncode == 0, r.stderr
    assert (tmp_path / "a" / "runs.csv").read_text() != (tmp_path / "b" / "runs.csv").read_text()
    for folder in ("iso", "axis"):
        names = sorted(f.name for f in (tmp_path / "a" / folder).iterdir())
        assert names == sorted(f.name for f in (tmp_path / "b" / folder).iterdir())
        for name in names:
            assert (tmp_path / "a" / folder / name).read_bytes() == (tmp_path / "b" / folder / name).read_bytes(), name


def test_attained_points_in_the_instrument_frame(tmp_path, kr500):
    """--model M --frame instrument: the hand-made attained poses moved into an instrument frame (the
    model's placement: 1500, -200, 300 mm, ABC 30, 2, -1 deg; p_instrument = R p_base + t) give the
    report of the base-frame runs (to 1e-9 mm and deg)."""
    model = kr500.with_calibrated(1, 1.0, 0.05, 0.003, [1500.0, -200.0, 300.0, 30.0, 2.0, -1.0])
    (tmp_path / "m.json").write_text(model.to_json())
    R = kincal._core.abc_to_rotation(np.array([30.0, 2.0, -1.0]))
    t = np.array([1500.0, -200.0, 300.0])
    moved = [(p, c, d, tuple(float(v) for v in np.r_[R @ np.asarray(a[:3]) + t, kincal._core.rotation_to_abc(
        R @ kincal._core.abc_to_rotation(np.asarray(a[3:])))])) for p, c, d, a in HAND]
    (tmp_path / "base.csv").write_text(_runs_csv(HAND))
    (tmp_path / "instr.csv").write_text(_runs_csv(moved))
    a = acc.iso9283(acc.read_runs(str(tmp_path / "base.csv")))
    b = acc.iso9283(acc.to_base(acc.read_runs(str(tmp_path / "instr.csv")), str(tmp_path / "m.json")))
    for p, q in zip(a["points"], b["points"]):
        for k in ("AP_P_mm", "AP_x_mm", "RP_l_mm", "AP_a_deg", "AP_b_deg", "AP_c_deg", "RP_a_deg", "vAP_P_mm"):
            assert q[k] == pytest.approx(p[k], abs=1e-9), k
    r = run("kincal", "accuracy", "iso9283", "--data", str(tmp_path / "instr.csv"), "--out", str(tmp_path / "rep"),
            "--model", str(tmp_path / "m.json"), "--frame", "instrument")
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "rep" / "iso9283.json").read_text())
    assert doc["points"][0]["AP_P_mm"] == pytest.approx(a["points"][0]["AP_P_mm"], abs=1e-9)
    # a nominal model has no instrument placement
    r = run("kincal", "accuracy", "iso9283", "--data", str(tmp_path / "instr.csv"), "--out", str(tmp_path / "no"),
            "--model", "kr500", "--frame", "instrument")
    assert r.returncode != 0 and "kr500: --frame instrument needs an identified model" in r.stderr
    assert not (tmp_path / "no").exists()


def _bad_runs(rows_text: str) -> str:
    return RUNS_HEAD + "\n" + rows_text


@pytest.mark.parametrize("name,files,args,message", [
    ("missing column", {"r.csv": _runs_csv(HAND).replace("zc,", "zq,", 1)},
     ["iso9283", "--data", "{d}/r.csv"], r"r\.csv:1: missing column 'zc'"),
    ("missing orientation column", {"r.csv": _runs_csv(HAND).replace(",cc,", ",cq,", 1)},
     ["iso9283", "--data", "{d}/r.csv"], r"r\.csv:1: missing column 'cc'"),
    ("one cycle only", {"r.csv": _runs_csv(HAND[:8] + HAND[8:9])},
     ["iso9283", "--data", "{d}/r.csv"], r"r\.csv:10: point P2 has one cycle only"),
    ("one cycle in a direction", {"r.csv": _runs_csv(HAND[:5])},
     ["iso9283", "--data", "{d}/r.csv"], r"r\.csv:6: point P1 direction B has one cycle only"),
    ("unknown point", {"r.csv": _runs_csv(HAND)},
     ["iso9283", "--data", "{d}/r.csv", "--distance", "P1,P9"], r"--distance P1,P9: no point 'P9' in .*r\.csv"),
    ("not a number", {"r.csv": _runs_csv(HAND).replace("1000.13", "1000.1x")},
     ["iso9283", "--data", "{d}/r.csv"], r"r\.csv:3: column 'x': '1000\.1x' is not a number"),
    ("measured twice", {"r.csv": _runs_csv(HAND + HAND[2:3])},
     ["iso9283", "--data", "{d}/r.csv"], r"r\.csv:18: point P1 direction A cycle 3 is measured twice \(line 4 too\)"),
    ("two commanded poses", {"r.csv": _runs_csv(HAND).replace("P1,4,1000.0", "P1,4,1000.5", 1)},
     ["iso9283", "--data", "{d}/r.csv"], r"r\.csv:5: point P1: the commanded pose differs"),
    ("missing file", {}, ["iso9283", "--data", "{d}/none.csv"], r"none\.csv"),
    ("axis missing column", {"a.csv": "target,direction,measured\n0,1,0.001\n"},
     ["axis", "--data", "{d}/a.csv"], r"a\.csv:1: missing column 'run'"),
    ("axis one run only", {"a.csv": _axis_csv(_axis_items()[:-2])},
     ["axis", "--data", "{d}/a.csv"], r"a\.csv:17: target 500 direction -1 has one run only"),
    ("axis one direction", {"a.csv": _axis_csv(_axis_items()[:-3])},
     ["axis", "--data", "{d}/a.csv"], r"a\.csv: target 500 has no run in direction -1"),
    ("axis bad direction", {"a.csv": _axis_csv(_axis_items()).replace("250.0,1,2,", "250.0,2,2,")},
     ["axis", "--data", "{d}/a.csv"], r"a\.csv:9: column 'direction': '2' is not \+1 or -1"),
])
def test_bad_input(tmp_path, name, files, args, message):
    """Each bad input: exit status 1, one message naming the file and line (or the option), and no
    output folder."""
    for f, text in files.items():
        (tmp_path / f).write_text(text)
    out = tmp_path / "out"
    r = run("kincal", "accuracy", *[a.format(d=tmp_path) for a in args], "--out", str(out))
    assert r.returncode == 1, r.stdout
    assert re.search(message, r.stderr), r.stderr
    assert r.stderr.startswith("kincal accuracy: error: ") and len(r.stderr.strip().splitlines()) == 1
    assert not out.exists()


def test_reports_open_in_a_headless_browser(tmp_path):
    """Both report pages open in Debian's chromium with every figure loaded (none empty or missing)."""
    (tmp_path / "runs.csv").write_text(_runs_csv(HAND))
    (tmp_path / "axis.csv").write_text(_axis_csv(_axis_items()))
    assert run("kincal", "accuracy", "iso9283", "--data", str(tmp_path / "runs.csv"), "--out",
               str(tmp_path / "iso")).returncode == 0
    assert run("kincal", "accuracy", "axis", "--data", str(tmp_path / "axis.csv"), "--out",
               str(tmp_path / "axis")).returncode == 0
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if browser is None:
        pytest.skip("chromium is not installed (scripts/setup.sh installs it)")
    for folder, figures in (("iso", 2), ("axis", 1)):
        dom = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--virtual-time-budget=10000",
                              "--dump-dom", (tmp_path / folder / "report.html").as_uri()],
                             capture_output=True, text=True, timeout=120)
        m = re.search(r'data-images-loaded="(\d+)/(\d+)"', dom.stdout)
        assert m, dom.stderr[-2000:]
        assert m.group(1) == m.group(2) == str(figures)
