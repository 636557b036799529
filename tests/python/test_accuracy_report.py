"""The pages and figures of kincal accuracy iso9283 / axis, what is testable without pixels: the
attained-positions figure's layout (every attained point and RP_l circle inside its panel, the scale
set by the scatter, the commanded position drawn or pointed at), the titles naming the run, and one
precision rule for the tables, the figures' titles and the command's text."""

from __future__ import annotations

import html
import re

import numpy as np
import pytest

from kincal.standards import accuracy as acc
from kincal.standards import report as rep

from test_accuracy import _axis_csv, _axis_items

COMMANDED = {"P1": (1000.0, 0.0, 500.0), "P2": (1200.0, 300.0, 400.0), "P3": (900.0, -250.0, 700.0)}


def _runs(path, bias_mm: float, seed: int, directions: bool = False) -> str:
    """Simulated runs (the truth of these tests): 30 cycles per point, attained = commanded + b + e,
    b a fixed offset per point of size ``bias_mm`` (the robot's accuracy), e ~ N(0, 0.02^2 I3) mm (its
    repeatability; RP_l about 3.6 x 0.02 = 0.07 mm); with ``directions``, cycles alternate between
    directions +1 and -1, which sit 0.03 mm apart along x."""
    rng = np.random.default_rng(seed)
    lines = ["point,cycle,xc,yc,zc,x,y,z" + (",direction" if directions else "")]
    for name, cmd in COMMANDED.items():
        u = rng.normal(size=3)
        bias = bias_mm * u / np.linalg.norm(u)
        for c in range(1, 31):
            d = 1 if c % 2 else -1
            att = np.asarray(cmd) + bias + rng.normal(0.0, 0.02, 3) + ([0.015 * d, 0, 0] if directions else 0)
            lines.append(f"{name},{c},{','.join(repr(v) for v in cmd)},{','.join(repr(float(v)) for v in att)}" +
                         (f",{d}" if directions else ""))
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def _layout(path):
    runs = acc.read_runs(path)
    res = acc.iso9283(runs)
    return runs, res, rep.deviation_layout(runs, res)


def _inside(lay: dict) -> None:
    """Every attained point and every RP_l circle (radius around the origin, the barycentre) inside
    its panel of half-width lim; the scale is the one the figure states (um below 1 mm)."""
    lim = lay["lim_mm"]
    for q in lay["panels"]:
        assert np.abs(q["xy"]).max() <= lim
        assert q["RP_l_mm"] <= lim
    assert lay["unit"] == ("um" if lim < 1.0 else "mm")


@pytest.mark.parametrize("directions", [False, True])
def test_uncalibrated_robot_scatter_fills_the_panels(tmp_path, directions):
    """AP_P of 4 mm against a 0.02 mm scatter (an uncalibrated robot): the panels are scaled to the
    scatter (the largest distance of a point or RP_l circle from its barycentre is 1/PANEL_MARGIN of
    the half-width, which is under a tenth of the smallest AP_P), so every attained point and circle
    is inside and readable; no commanded position fits, and each panel has an arrow on its edge,
    outside every point and circle, pointing exactly toward the commanded position."""
    runs, res, lay = _layout(_runs(tmp_path / "runs.csv", 4.0, seed=11, directions=directions))
    _inside(lay)
    lim, reach = lay["lim_mm"], lay["reach_mm"]
    assert lim == pytest.approx(rep.PANEL_MARGIN * reach)
    assert lim < 0.1 * min(p["AP_P_mm"] for p in res["points"])
    assert lay["unit"] == "um" and len(lay["panels"]) == 6
    for q in lay["panels"]:
        assert not q["commanded_inside"]
        tail, head = q["arrow"]
        assert np.abs(head).max() <= lim and np.abs(head).max() >= 0.98 * lim  # on the panel's edge
        assert np.linalg.norm(tail) > reach  # clear of the points and the circle
        c = q["commanded"]
        assert np.dot(head - tail, c) / (np.linalg.norm(head - tail) * np.linalg.norm(c)) == pytest.approx(1.0)
        assert np.dot(tail, c) > 0
    page = rep.iso9283_html(runs, res, "t", lay, "runs.csv")
    assert "an arrow on the panel's edge points toward it" in page and "in um" in page


def test_compensated_robot_shows_the_commanded_position(tmp_path):
    """AP_P of 0.01 mm against the same scatter (a compensated robot: AP and RP comparable): every
    commanded position is drawn inside its panel (and the panel still holds every point and circle)."""
    runs, res, lay = _layout(_runs(tmp_path / "runs.csv", 0.01, seed=12))
    _inside(lay)
    for q in lay["panels"]:
        assert q["commanded_inside"] and "arrow" not in q
        assert np.abs(q["commanded"]).max() <= 0.95 * lay["lim_mm"]
    assert "it lies inside every panel" in rep.iso9283_html(runs, res, "t", lay, "runs.csv")


def test_commanded_position_a_few_scatters_away_is_taken_in(tmp_path):
    """AP_P of 0.12 mm (under COMMANDED_REACH times the scatter's extent): the panels grow to take
    every commanded position in rather than point at it."""
    runs, res, lay = _layout(_runs(tmp_path / "runs.csv", 0.12, seed=13))
    _inside(lay)
    far = max(np.abs(q["commanded"]).max() for q in lay["panels"])
    assert far > lay["reach_mm"]  # it would be off a panel scaled to the scatter alone
    assert all(q["commanded_inside"] for q in lay["panels"])


def _h1(folder) -> str:
    return html.unescape(re.search(r"<h1>(.*?)</h1>", (folder / "report.html").read_text()).group(1))


def test_titles_name_the_run(tmp_path):
    """Sibling reports of files of one name are told apart: without a label the title names the
    output folder (and the data file), with one it names the label; the page's <title> too."""
    data = _runs(tmp_path / "runs.csv", 1.0, seed=14)
    for key in ("uncompensated", "identified"):
        rep.run_iso9283(data, str(tmp_path / key))
        assert _h1(tmp_path / key) == f"ISO 9283 pose accuracy and repeatability: {key} (runs.csv)"
    rep.run_iso9283(data, str(tmp_path / "lab"), label="kr500, compensated on the diagnosed model")
    page = (tmp_path / "lab" / "report.html").read_text()
    assert _h1(tmp_path / "lab").endswith(": kr500, compensated on the diagnosed model")
    assert "<title>ISO 9283 pose accuracy and repeatability: kr500, compensated on the diagnosed model</title>" in page
    (tmp_path / "axis.csv").write_text(_axis_csv(_axis_items()))
    rep.run_axis(str(tmp_path / "axis.csv"), str(tmp_path / "axis_nominal_y"))
    assert _h1(tmp_path / "axis_nominal_y") == "Positioning accuracy of one axis: axis_nominal_y (axis.csv)"
    rep.run_axis(str(tmp_path / "axis.csv"), str(tmp_path / "ax2"), label="five-bar, corrected mechanism, along x")
    assert _h1(tmp_path / "ax2") == "Positioning accuracy of one axis: five-bar, corrected mechanism, along x"


def test_precision_rule():
    """A value is printed to the largest power of ten not above a tenth of the repeatability figure
    (which then shows two significant digits); a change of unit keeps that step."""
    spreads = (0.1024, 0.059, 0.01, 0.0079, 3.0, 30.0, 0.0, float("nan"))
    assert [rep.decimals(v) for v in spreads] == [2, 3, 3, 4, 1, 0, 4, 4]
    assert rep.rounded(0.1072, 2, 1000.0) == "110"  # 0.11 mm in um
    assert rep.rounded(0.05901, 3, 1000.0) == "59"
    assert rep.rounded(4.22979, 3) == "4.230"
    assert rep._f(-0.0001, 3) == "0.000" and rep._f(-0.0006, 3) == "-0.001"  # no signed zero


def test_iso_tables_and_text_agree(tmp_path):
    """The simulated uncalibrated runs (smallest RP_l about 0.07 mm: 3 decimals): the page's position
    table and the command's summary give AP_P and RP_l with the same digits, which are those of the
    rule (never the 4 decimals, 0.1 um, of a 20 um scatter)."""
    data = _runs(tmp_path / "runs.csv", 4.0, seed=15)
    res = rep.run_iso9283(data, str(tmp_path / "r"))
    dp = rep.iso9283_decimals(res)[0]
    assert dp == rep.decimals(min(p["RP_l_mm"] for p in res["points"])) == 3
    page = (tmp_path / "r" / "report.html").read_text()
    text = rep.iso9283_summary(res, str(tmp_path / "r"))
    for p in res["points"]:
        for k in ("AP_P_mm", "RP_l_mm"):
            s = f"{p[k]:.3f}"
            assert f"<td>{s}</td>" in page and f" {s}" in text, (k, s)
        assert f"<td>{p['AP_P_mm']:.4f}</td>" not in page


def test_axis_figures_and_text_agree(tmp_path):
    """The hand-made axis runs (test_accuracy.py): the figures' titles, the page and the command's
    summary state the same values, each with its unit, to the digits of the rule (the mean Ps_j;
    per metre of travel for P and Ps per metre)."""
    (tmp_path / "axis.csv").write_text(_axis_csv(_axis_items()))
    res = rep.run_axis(str(tmp_path / "axis.csv"), str(tmp_path / "ax"))
    d, dm = rep.axis_decimals(res)
    vdi = res["vdi3441"]
    assert d == rep.decimals(vdi["Ps_mean"])
    assert dm == rep.decimals(vdi["Ps_mean"] * 1000 / (vdi["travel"] / 1000))
    text = rep.axis_figures_text(res)
    for k in ("P", "Pa", "Ps", "U"):
        assert f"{k} {vdi[k]:.{d}f} mm" in text["vdi"]
    for k in ("A", "E", "M", "R", "B"):
        assert f"{k} {res['iso230_2'][k]:.{d}f} mm" in text["iso"]
    per_m = f"P {vdi['P_per_m'] * 1000:.{dm}f} um/m, Ps {vdi['Ps_per_m'] * 1000:.{dm}f} um/m"
    assert text["per_m"] == per_m and f"({vdi['P_per_m'] * 1000:.{dm}f} um/m)" in text["vdi"]
    page = (tmp_path / "ax" / "report.html").read_text()
    assert per_m in page and f"<td>{vdi['P']:.{d}f}</td>" in page
    summary = rep.axis_summary(res, str(tmp_path / "ax"))
    assert text["iso"] in summary and text["vdi"] in summary
