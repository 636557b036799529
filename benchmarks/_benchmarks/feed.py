"""The derivative analysis of joint programs (kincal.feed) on synthetic programs."""

from __future__ import annotations

import time

import numpy as np

from kincal.programs import feed as feedmod


def bench_feed(seed: int) -> dict:
    """The derivative analysis (spline resampling at the paper's 2900/297 samples per pose,
    derivatives, feed limits, violations and the time-optimal profile) of a smooth synthetic 6-axis
    joint program of 297 and of 100,000 poses: milliseconds, and per pose."""
    rng = np.random.default_rng(seed)
    amp, w, ph = rng.uniform(10, 60, 6), rng.uniform(0.5, 2.0, 6), rng.uniform(0, 6.28, 6)
    lim = ([80.0] * 6, [160.0] * 6, [1600.0] * 6)
    out = {}
    for n in (297, 100_000):
        t = np.linspace(0, 1, n)[:, None]
        q = amp * np.sin(w * t * 6.28 + ph)
        samples = max(feedmod.DEFAULT_SAMPLES, int(round(n * feedmod.DEFAULT_SAMPLES / 297)))
        feedmod.analyse(q[:50], *lim, samples=500)  # imports warm
        times = []
        for _ in range(3 if n < 1000 else 1):
            t0 = time.perf_counter()
            feedmod.analyse(q, *lim, samples=samples)
            times.append(time.perf_counter() - t0)
        out[f"feed_{n}_poses_ms"] = float(np.median(times)) * 1e3
        out[f"feed_{n}_poses_us_per_pose"] = float(np.median(times)) * 1e6 / n
    return out
