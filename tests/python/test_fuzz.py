"""The readers fuzzed for a bounded time through the Python bindings with atheris (see
tests/fuzz/fuzz_readers.py; the sanitizer run of the same readers is the ctest fuzz_readers)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest


def test_readers_survive_atheris(tmp_path):
    pytest.importorskip("atheris")
    harness = Path(__file__).resolve().parents[1] / "fuzz" / "fuzz_readers.py"
    r = subprocess.run([sys.executable, str(harness), "-max_total_time=15", "-timeout=5", "-seed=1",
                        f"-artifact_prefix={tmp_path}/"], capture_output=True, text=True, timeout=120)
    tail = "\n".join(l for l in r.stderr.splitlines() if not l.startswith("INFO: Instrumenting"))[-3000:]
    assert r.returncode == 0, tail
    assert "Done" in tail and not list(tmp_path.glob("crash-*"))
