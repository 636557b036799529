"""What `kincal plan --kind` promises and what its campaigns reach (BENCHMARKS.md, "Planning a probe
campaign").

Truth: kincal simulate's default truth (the kr500 with 1 mm / 0.05 deg geometric errors and joint
compliance of about 0.003 deg/kNm), one per seed. For each design and seed: the plan (stations placed
with the seed, `--candidates` touches per station, the predicted TCP uncertainty over 200 random
configurations drawn within 90% of each limit), its touches made on the truth (probe_plan.measure: the ball
where the plan puts it, the truth's own angles, the probe's noise along each constraint), the fit
(`kincal identify --effects joint_compliance --probe 0,0,150` with the artifact), and the accuracy:
the ball centre's RMS over the same 200 configurations against the noise-free truth after the best
rigid transform (the base frame is free in these data). The same for the same number of touches
drawn at random from the candidates (`kincal simulate --kind`'s campaign, no plan).

    .venv/bin/python benchmarks/probe_plan.py [--seeds 5] [--kinds sphere,plane,distance]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import kincal
from kincal.calibration import identify as ident
from kincal.calibration import probe_plan as pp
from kincal.calibration import simulation as sim
from kincal.calibration.fitting import FitOptions

PROBE = np.array([0.0, 0.0, 150.0])
#: kind -> (stations, touches per station, cone deg, noise mm along the constraint, block edge mm)
DESIGNS = {"sphere": (6, 25, 60.0, 0.005, 400.0), "plane": (5, 40, 60.0, 0.005, 500.0),
           "distance": (4, 40, 60.0, 0.002, 400.0)}


def balls(robot: kincal.Robot, q: np.ndarray) -> np.ndarray:
    return pp.ball_centres(robot, q, PROBE)


def accuracy(robot: kincal.Robot, truth: kincal.Robot, data: kincal.MeasurementSet, q: np.ndarray) -> float:
    fit = ident.identify(robot, data, effects=["joint_compliance"], k_folds=0, fit=FitOptions(target_start=[PROBE]))
    mine = pp.ball_centres(fit.robot, q, np.asarray(fit.targets)[0])
    return pp.rigid_rms(mine, balls(truth, q))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--kinds", default="sphere,plane,distance")
    ap.add_argument("--candidates", type=int, default=300)
    ap.add_argument("--design", action="append", default=[], metavar="KIND:STATIONS:TOUCHES:CONE:NOISE:BLOCK",
                    help="a design in place of a kind's default (repeatable)")
    args = ap.parse_args()
    for d in args.design:
        kind, *v = d.split(":")
        DESIGNS[kind] = (int(v[0]), int(v[1]), float(v[2]), float(v[3]), float(v[4]))
    robot = kincal.load_robot("kr500")
    lim = np.asarray(robot.limits_deg)
    q = np.random.default_rng(7).uniform(0.9 * lim[:, 0], 0.9 * lim[:, 1], size=(200, 6))
    for kind in args.kinds.split(","):
        stations, touches, cone, noise, block = DESIGNS[kind]
        rows = []
        for seed in range(1, args.seeds + 1):
            t0 = time.perf_counter()
            plan = pp.plan_probe(robot, kind, stations=stations, touches=touches, cone_deg=cone, probe=PROBE,
                                 block_mm=block, noise_mm=noise, candidates=args.candidates, configurations=q,
                                 seed=seed)
            seconds = time.perf_counter() - t0
            truth = ident.default_truth(robot, seed=seed)
            planned = accuracy(robot, truth, pp.measure(truth, plan.data, PROBE, noise, seed=seed), q)
            rand = accuracy(robot, truth, sim.simulate_probe(truth, kind, stations=stations, touches=touches,
                                                             cone_deg=cone, probe=PROBE, block_mm=block,
                                                             noise_mm=noise, seed=seed), q)
            rows.append((plan.tcp_uncertainty_mm, planned, plan.random_tcp_uncertainty_mm, rand, seconds))
            print(f"{kind} seed {seed}: predicted {rows[-1][0]:.4f} measured {planned:.4f} | random: predicted "
                  f"{rows[-1][2]:.4f} measured {rand:.4f} | plan {seconds:.1f} s", flush=True)
        a = np.median(np.asarray(rows), axis=0)
        print(f"{kind}: {stations} stations x {touches} touches, {cone:g} deg cone, noise {noise} mm"
              + (f", a {block:g} mm block" if kind == "plane" else "") + f"; median of "
              f"{args.seeds} seeds: plan predicted {a[0]:.4f} mm, measured {a[1]:.4f} mm (ratio {a[0] / a[1]:.2f}); "
              f"random touches predicted {a[2]:.4f}, measured {a[3]:.4f} mm; plan {a[4]:.1f} s")


if __name__ == "__main__":
    main()
