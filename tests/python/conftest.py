"""Shared fixtures: the built-in robot, a simulated calibrated one, and a command runner."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import kincal

SHARED = Path(__file__).resolve().parents[2].parent / "shared"


def count(default: int) -> int:
    """Number of random cases; KINCAL_TEST_COUNT raises it (as for the C++ tests)."""
    return int(os.environ.get("KINCAL_TEST_COUNT", default))


@pytest.fixture(scope="session")
def kr500() -> kincal.Robot:
    return kincal.load_robot("kr500")


@pytest.fixture(scope="session")
def calibrated(kr500) -> kincal.Robot:
    # truth of the synthetic tests: 1 mm / 0.05 deg geometric errors and joint compliance, seed 9
    return kr500.with_calibrated(seed=9, sigma_mm=1.0, sigma_deg=0.05, compliance=0.003)


def _tool(name: str) -> str:
    exe = Path(sys.executable).parent / name
    found = str(exe) if exe.exists() else shutil.which(name)
    assert found, f"{name} is not installed (pip install .)"
    return found


def run(name: str, *args: str, stdin: str | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([_tool(name), *args], input=stdin, capture_output=True, text=True, timeout=300)


def random_q(robot: kincal.Robot, rng: np.random.Generator, n: int, margin: float = 0.0) -> np.ndarray:
    lim = np.asarray(robot.limits_deg)
    return rng.uniform(lim[:, 0] + margin, lim[:, 1] - margin, size=(n, robot.dof))
