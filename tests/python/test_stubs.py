"""The `.pyi` stubs of the private core agree with the compiled module (mypy's stubtest) and the
typed package (also with --strict) and its benchmarks pass mypy."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("module", ["kincal._core", "kincal._benchmarks._bench"])
def test_stubs_match_the_module(module):
    pytest.importorskip("mypy")
    # the allowlist names what stubtest cannot check in the core (pybind11's generated members)
    allow = ["--allowlist", str(ROOT / "tests" / "stubtest_allowlist.txt")] if module == "kincal._core" else []
    r = subprocess.run([sys.executable, "-m", "mypy.stubtest", module, *allow], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-2000:]


def test_package_passes_mypy():
    pytest.importorskip("mypy")
    r = subprocess.run([sys.executable, "-m", "mypy", "--ignore-missing-imports", str(ROOT / "python" / "kincal")],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-3000:]


def test_package_passes_mypy_strict():
    """The package stays fully typed: every function annotated, every generic with its arguments, no
    Any returned where a type is declared, no name used through an implicit re-export."""
    pytest.importorskip("mypy")
    r = subprocess.run([sys.executable, "-m", "mypy", "--strict", "--ignore-missing-imports",
                        str(ROOT / "python" / "kincal")], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-3000:]


def test_benchmarks_pass_mypy():
    """The benchmarks (shipped as the private kincal._benchmarks) against the installed, typed kincal."""
    pytest.importorskip("mypy")
    r = subprocess.run([sys.executable, "-m", "mypy", "--ignore-missing-imports", "-p", "kincal._benchmarks"],
                       capture_output=True, text=True, timeout=300, cwd=str(ROOT / "benchmarks"))
    assert r.returncode == 0, r.stdout[-3000:]
