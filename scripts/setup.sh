#!/usr/bin/env bash
# One-shot set-up for a Debian 12 machine (run as root, or with sudo available).
# Installs what is missing, builds the native kernel for Debian's /usr/bin/python3 (the one FreeCAD runs),
# creates a venv (with system packages) for the test-only pip packages, and links the add-on into FreeCAD.
# Quick when everything is already in place.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

# contourpy: the 3D offset's passes (core.footprint.offset_field); scipy: the verification's buckets on them
# (core.footprint.variable_step); pytest-xdist: the tests two at a time (scripts/test.sh); ccache: the compiled
# objects kept between test runs (scripts/test.sh sets CCACHE_DIR); distributed: `tmm batch` (Dask); fastapi, uvicorn,
# multipart: the web front (tmm_workbench/web); selenium, chromium, chromium-driver: its browser test (tests/web)
DEBS=(freecad-python3 libeigen3-dev pybind11-dev python3-dev python3-numpy python3-pytest python3-venv
      python3-pip python3-matplotlib python3-pyclipper xvfb xauth cmake g++ make ninja-build libgtest-dev
      python3-contourpy python3-scipy clang-14 libclang-rt-14-dev python3-pytest-xdist ccache
      python3-distributed python3-fastapi python3-uvicorn python3-multipart python3-selenium chromium chromium-driver)
missing=()
for p in "${DEBS[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  echo "[setup] installing Debian packages: ${missing[*]}"
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
fi

# Python packages Debian 12 lacks go into a venv on top of Debian's python3: OpenCAMLib (the test peer) and bokeh
# (Dask's dashboard for `tmm batch`, which runs this venv's python: below 3 for Debian 12's distributed 2022.12).
if [ ! -x .venv/bin/python ]; then
  /usr/bin/python3 -m venv --system-site-packages .venv
fi
if ! .venv/bin/python -c "import opencamlib" >/dev/null 2>&1; then
  echo "[setup] pip install opencamlib (test peer)"
  .venv/bin/python -m pip install -q opencamlib
fi
if ! .venv/bin/python -c "import bokeh" >/dev/null 2>&1; then
  echo "[setup] pip install bokeh (Dask's dashboard)"
  .venv/bin/python -m pip install -q "bokeh>=2.4.2,<3"
fi

# Native kernel for /usr/bin/python3 (FreeCAD's interpreter). Through ccache when CCACHE_DIR names its cache
# (scripts/test.sh; taken when the folder is first configured).
[ -n "${CCACHE_DIR:-}" ] && command -v ccache >/dev/null && export CMAKE_CXX_COMPILER_LAUNCHER=ccache
cmake -S native -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build -j"$(nproc)"

# Make the add-on visible to FreeCAD 0.20 (user Mod folder).
MOD="${HOME}/.local/share/FreeCAD/Mod"
mkdir -p "$MOD"
ln -sfn "$ROOT" "$MOD/TMM"
# The `tmm` command (tmm plan, tmm batch) on the PATH.
if [ -w /usr/local/bin ]; then ln -sfn "$ROOT/scripts/tmm" /usr/local/bin/tmm; fi
echo "[setup] ready: kernel built, add-on linked at $MOD/TMM"
