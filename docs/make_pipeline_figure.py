"""Draws docs/pipeline.png, the README's picture of what kincal does (run: python docs/make_pipeline_figure.py)."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch  # noqa: E402

W, H = 0.21, 0.30
BOXES = [
    ("model", 0.02, 0.58, "robot model\nkr500 / ur10 / URDF\nPOE: 30 geometric\n+ 5 compliance"),
    ("meas", 0.02, 0.08, "laser tracker\nmeasurements\n(points or 6-D poses)\nkincal simulate"),
    ("ident", 0.27, 0.58, "identify (Ceres)\nidentifiability,\nrobust loss,\nvalidation"),
    ("diag", 0.27, 0.08, "diagnose\nname the missing effect,\nadd it, refit"),
    ("comp", 0.52, 0.58, "compensate\nPaden-Kahan IK +\nNewton on the\ncalibrated model"),
    ("ctrl", 0.52, 0.08, "kincal-compensate\ncontroller PC,\n--stream (C++)"),
    ("feed", 0.77, 0.58, "feed\nderivatives in s vs\nvelocity, acceleration,\njerk limits"),
    ("five", 0.77, 0.08, "hidden robot\nfive-bar fit, error\nmatrix, 2 kHz\ncorrector"),
]
# arrows between box edges: (from, side, to, side); sides r, l, t, b
ARROWS = [("model", "r", "ident", "l"), ("meas", "r", "ident", "l"), ("ident", "b", "diag", "t"),
          ("ident", "r", "comp", "l"), ("comp", "b", "ctrl", "t"), ("comp", "r", "feed", "l")]


def main() -> None:
    fig, ax = plt.subplots(figsize=(11, 4.2))
    ax.set_axis_off()
    pos = {}
    for key, x, y, text in BOXES:
        colour = "#e8f0fb" if key != "five" else "#fbf0e8"
        ax.add_patch(FancyBboxPatch((x, y), W, H, boxstyle="round,pad=0.01", fc=colour, ec="#36c", lw=1.2))
        ax.text(x + W / 2, y + H / 2, text, ha="center", va="center", fontsize=9)
        pos[key] = (x, y)

    def edge(key, side):
        x, y = pos[key]
        return {"r": (x + W + 0.01, y + H / 2), "l": (x - 0.01, y + H / 2), "t": (x + W / 2, y + H + 0.01),
                "b": (x + W / 2, y - 0.01)}[side]

    for a, sa, b, sb in ARROWS:
        ax.add_patch(FancyArrowPatch(edge(a, sa), edge(b, sb), arrowstyle="-|>", mutation_scale=14, color="#333"))
    ax.set_xlim(0, 1.0)
    ax.set_ylim(0, 0.92)
    ax.set_title("kincal: model, measure, identify, diagnose, compensate, check, and the hidden robot", fontsize=11)
    fig.savefig(Path(__file__).with_name("pipeline.png"), dpi=110, bbox_inches="tight")


if __name__ == "__main__":
    main()
