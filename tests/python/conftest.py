"""Shared fixtures: the built-in robot, a simulated calibrated one, a command runner, and the check
that every JSON file a test leaves in its tmp_path is strict JSON (no NaN or Infinity)."""

from __future__ import annotations

import fnmatch
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Sequence

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


def _no_constant(name: str):
    raise ValueError(f"{name} is not JSON (undefined figures are written as null)")


def strict_json_error(text: str) -> str | None:
    """Why ``text`` is not strict JSON (NaN, Infinity, -Infinity, or not JSON at all), or None."""
    try:
        json.loads(text, parse_constant=_no_constant)
    except ValueError as e:  # json.JSONDecodeError is a ValueError
        return str(e)
    return None


def non_strict_json_files(root: Path, exempt: Sequence[str] = (), skip: Sequence[Path] = ()) -> list:
    """Every *.json file under ``root`` (recursively) that is not strict JSON, as "path: why".
    ``exempt``: fnmatch patterns of paths relative to root (files a test wrote on purpose as bad
    input); ``skip``: folders already checked."""
    bad = []
    for f in sorted(Path(root).rglob("*.json")):
        rel = f.relative_to(root).as_posix()
        if not f.is_file() or any(fnmatch.fnmatch(rel, e) for e in exempt) or any(d in f.parents for d in skip):
            continue
        why = strict_json_error(f.read_text(encoding="utf-8-sig", errors="replace"))
        if why is not None:
            bad.append(f"{f}: {why}")
    return bad


_CHECKED: list = []  # tmp_path folders the per-test check has seen (the session's check skips them)


@pytest.fixture(autouse=True)
def _strict_json_files(request):
    """After each test that uses tmp_path: every *.json file in it is strict JSON (the contract:
    kincal writes no NaN or Infinity). A test that writes a bad JSON input on purpose names it with
    ``@pytest.mark.bad_json_input("pattern", ...)`` (fnmatch patterns relative to tmp_path)."""
    root = request.getfixturevalue("tmp_path") if "tmp_path" in request.fixturenames else None
    yield
    if root is None:
        return
    _CHECKED.append(root)
    exempt = [n for m in request.node.iter_markers("bad_json_input") for n in m.args]
    bad = non_strict_json_files(root, exempt)
    if bad:
        pytest.fail("not strict JSON (NaN/Infinity or malformed):\n" + "\n".join(bad), pytrace=False)


@pytest.fixture(autouse=True, scope="session")
def _strict_json_files_of_fixtures(tmp_path_factory):
    """At the end of the session: the same for the folders of module and session fixtures
    (tmp_path_factory), which no single test owns."""
    yield
    bad = non_strict_json_files(tmp_path_factory.getbasetemp(), skip=_CHECKED)
    if bad:
        pytest.fail("not strict JSON (NaN/Infinity or malformed), in a fixture's folder:\n" + "\n".join(bad),
                    pytrace=False)
