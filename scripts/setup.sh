#!/bin/sh
# All set-up on a fresh Debian machine, as root: Debian packages, the Python environment in .venv,
# the Python package (with kincal and kincal-compensate on .venv/bin) and the C++ build for ctest.
set -eu
cd "$(dirname "$0")/.."
export DEBIAN_FRONTEND=noninteractive
PKGS="g++ cmake ninja-build python3 python3-venv python3-dev libeigen3-dev liborocos-kdl-dev libceres-dev \
nlohmann-json3-dev libcli11-dev libgtest-dev chromium"
missing=""
for p in $PKGS; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
if [ -n "$missing" ]; then
  apt-get update -qq
  apt-get install -y -qq $missing >/dev/null
fi
[ -x .venv/bin/python ] || python3 -m venv .venv
.venv/bin/pip install -q --upgrade pip
.venv/bin/pip install -q "scikit-build-core>=0.10" "pybind11>=2.12" numpy scipy matplotlib pytest eaik toppra atheris mypy
# toppra's C++ library (the double-precision peer of eq. 21 in the tests), without its Python deps
.venv/bin/pip install -q --no-deps cmeel-toppra
.venv/bin/pip install -q --no-build-isolation .
PEERS="$(.venv/bin/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')/cmeel.prefix"
PYBIND11="$(.venv/bin/python -m pybind11 --cmakedir)"
cmake -S . -B build/cpp -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PEERS;$PYBIND11" >/dev/null
cmake --build build/cpp -j2
