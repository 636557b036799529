#!/bin/sh
# Every test: the C++ suite (ctest) and the Python suite (pytest). Run scripts/setup.sh first.
set -eu
cd "$(dirname "$0")/.."
ctest --test-dir build/cpp --output-on-failure -j2
.venv/bin/python -m pytest -q
