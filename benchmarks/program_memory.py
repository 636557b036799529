"""Peak resident memory and time per pose of a program compensated file to file (issue 33, item 5):
`kincal-compensate` and `kincal compensate` on pose programs of 100,000, 1,000,000 and 10,000,000
poses, with a model that has every effect (joint compliance, transmission errors, backlash, thermal
expansion; backlash without --initial-direction: the program is read twice). The commands as a user
runs them (subprocesses of the installed ones, under /usr/bin/time -v: "Maximum resident set size" and
the wall time, process start included). The programs are written on the fly in --workdir (a smooth
joint path of the kr500 through `kincal fk`, 20,000 poses, then back and forth to the length asked:
10,000,000 poses are about 0.8 GB of CSV) and deleted after each size.

With --baseline DIR (a folder holding another build's `kincal` and `kincal-compensate`, e.g. a venv's
bin), each command is also timed there, alternating the two builds run by run (--repeat times), up to
--baseline-max poses. Per command and size: the largest peak resident memory, the shortest wall and CPU
(user + system) times of the runs, and the CPU time per pose (steadier than the wall time on a shared
machine). Prints one JSON object; BENCHMARKS.md ("Programs in bounded memory") has the table.

    .venv/bin/python benchmarks/program_memory.py --workdir /tmp/kincal-memory
    .venv/bin/python benchmarks/program_memory.py --baseline /tmp/old-venv/bin --sizes 100000,1000000 --repeat 3
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

from scale import smooth_joint_path  # the same path as the scale's programs (this folder)

BIN = Path(sys.executable).parent
SEGMENT = 20_000


def measured(argv: list[str]) -> tuple[float, float, float]:
    """(peak resident MB, wall seconds, CPU seconds: user + system) of one run of argv; a failure stops
    the script."""
    p = subprocess.run(["/usr/bin/time", "-v", *argv], capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed:\n{p.stderr[-2000:]}")

    def field(name: str) -> str:
        return re.search(re.escape(name) + r": (.*)", p.stderr).group(1).strip()

    *hm, sec = field("Elapsed (wall clock) time (h:mm:ss or m:ss)").split(":")
    wall = float(sec) + 60 * int(hm[-1]) + (3600 * int(hm[0]) if len(hm) == 2 else 0)
    cpu = float(field("User time (seconds)")) + float(field("System time (seconds)"))
    return int(field("Maximum resident set size (kbytes)")) / 1024, wall, cpu


def model(wd: Path, kincal: str) -> Path:
    """A kr500 model identified with every effect from a simulated campaign whose truth has them."""
    data, out = wd / "campaign.csv", wd / "model.json"
    subprocess.run([kincal, "simulate", "--robot", "kr500", "--poses", "300", "--out", str(data), "--seed", "1",
                    "--hide", "transmission_error:2:0.01,0.005,0.003,0.002", "--hide", "backlash:3:0.01",
                    "--hide", "thermal_expansion:0:1.2e-5", "--truth-out", str(wd / "truth.json")],
                   check=True, capture_output=True)
    subprocess.run([kincal, "identify", "--robot", "kr500", "--data", str(data), "--out", str(out), "--effects",
                    "joint_compliance,transmission_error,backlash,thermal_expansion"], check=True, capture_output=True)
    return out


def segment(wd: Path, kincal: str) -> list[str]:
    """The pose lines (CSV x,y,z,a,b,c, no header) of a smooth joint path of the kr500: each joint a sum
    of two slow sines inside 60% of its range (scale.py's smooth_joint_path), through `kincal fk`."""
    q = smooth_joint_path(SEGMENT, 1)
    joints, poses = wd / "segment.joints.csv", wd / "segment.csv"
    np.savetxt(joints, q, delimiter=",", header="q1,q2,q3,q4,q5,q6", comments="", fmt="%.6f")
    subprocess.run([kincal, "fk", "--robot", "kr500", "--joints", str(joints), "--out", str(poses)], check=True,
                   capture_output=True)
    lines = poses.read_text().splitlines()[1:]
    return [",".join(f"{float(v):.6f}" for v in line.split(",")) for line in lines]


def write_program(path: Path, seg: list[str], n: int) -> None:
    """n poses: the segment forward, backward, forward, ... (written a segment at a time). G-code for a
    path not ending in .csv (G1 X.. Y.. Z.. A.. B.. C.. lines)."""
    csv = path.suffix == ".csv"
    fwd = seg if csv else ["G1 X{} Y{} Z{} A{} B{} C{}".format(*line.split(",")) for line in seg]
    back = fwd[::-1]
    with open(path, "w") as f:
        if csv:
            f.write("x,y,z,a,b,c\n")
        done, k = 0, 0
        while done < n:
            part = (fwd if k % 2 == 0 else back)[: n - done]
            f.write("\n".join(part) + "\n")
            done += len(part)
            k += 1


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--workdir", default="/tmp/kincal-memory")
    ap.add_argument("--sizes", default="100000,1000000,10000000", help="program lengths (poses), comma separated")
    ap.add_argument("--formats", default="csv", help="csv, gcode or both (comma separated)")
    ap.add_argument("--baseline", help="a folder with another build's kincal and kincal-compensate, timed alternately")
    ap.add_argument("--baseline-max", type=int, default=1_000_000, help="the longest program run on the baseline")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each command and size (the figures: the fastest)")
    a = ap.parse_args()
    wd = Path(a.workdir)
    shutil.rmtree(wd, ignore_errors=True)
    wd.mkdir(parents=True)
    kincal = str(BIN / "kincal")
    mdl = model(wd, kincal)
    seg = segment(wd, kincal)
    builds = {"new": BIN} | ({"baseline": Path(a.baseline)} if a.baseline else {})
    out: dict[str, dict] = {}
    for fmt in a.formats.split(","):
        for n in [int(s) for s in a.sizes.split(",")]:
            prog = wd / f"p{n}.{fmt}"
            write_program(prog, seg, n)
            size_mb = prog.stat().st_size / 1e6
            runs: dict[str, list[tuple[float, float, float]]] = {}
            for _ in range(a.repeat):
                for build, bindir in builds.items():
                    if build != "new" and n > a.baseline_max:
                        continue
                    for cmd, argv in (("kincal-compensate", [str(bindir / "kincal-compensate")]),
                                      ("kincal compensate", [str(bindir / "kincal"), "compensate"])):
                        res = measured([*argv, "--model", str(mdl), "--program", str(prog), "--out",
                                        str(wd / f"out.{fmt}"), "--temperature", "25"])
                        runs.setdefault(f"{cmd} ({build})", []).append(res)
                        print(fmt, n, cmd, build, f"{res[0]:.1f} MB, {res[1]:.2f} s, CPU {res[2]:.2f} s",
                              file=sys.stderr, flush=True)
                        (wd / f"out.{fmt}").unlink()
            for key, rs in runs.items():
                out.setdefault(f"{fmt}: {key}", {})[str(n)] = {
                    "rss_mb": round(max(r[0] for r in rs), 1),
                    "seconds": round(min(r[1] for r in rs), 2),
                    "cpu_seconds": round(min(r[2] for r in rs), 2),
                    "us_per_pose": round(1e6 * min(r[2] for r in rs) / n, 2),
                    "program_mb": round(size_mb, 1)}
            prog.unlink()
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
