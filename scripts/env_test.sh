#!/usr/bin/env bash
# Inside a FreeCAD environment made by scripts/fc_env.sh (run as `bash scripts/fc_env.sh SUITE bash
# scripts/env_test.sh`): builds the kernel's wheel for this environment's python3 and runs the binding tests
# against it (native/wheel_test.sh), then puts that wheel's module into tmm_workbench/ (its own ABI tag, so it
# sits beside the host's), so the kernel is compiled once per Python; links the add-on into this FreeCAD's user
# Mod folder (versioned from 1.1: FreeCAD says where), and runs the FreeCAD tests and the GUI tests (one more at a
# time than the cores, pytest-xdist; each worker's Xvfb displays from a number of its own, tests/gui/launch.py). The core tests that
# need only Python, numpy and the kernel ran on the host: here the interpreter is what is checked (the binding
# tests, through the wheel) and FreeCAD's version (the FreeCAD and GUI tests, which run the core through the
# ops). Extra arguments go to pytest.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
ENV_NAME="${TMM_ENV:?run through scripts/fc_env.sh}"
echo "[env_test] $ENV_NAME: $(freecadcmd --version 2>/dev/null | head -1), $(python3 --version)"
# the wheel for this Python: built (through ccache, its cache kept in this chroot), installed in a venv, binding
# tests; then its module in place for FreeCAD
if command -v ccache >/dev/null; then
  export CCACHE_DIR="${CCACHE_DIR:-/var/cache/ccache}" CCACHE_MAXSIZE="${CCACHE_MAXSIZE:-1G}" \
    CMAKE_CXX_COMPILER_LAUNCHER=ccache CCACHE_BASEDIR="$PWD"  # a clone at another path hits too
fi
bash native/wheel_test.sh python3 --in-place
USER_DIR="$(freecadcmd -c 'import FreeCAD; print("TMM_USER_DIR=" + FreeCAD.getUserAppDataDir())' 2>/dev/null \
  | sed -n 's/^TMM_USER_DIR=//p' | tail -1)"
[ -n "$USER_DIR" ] || { echo "[env_test] FreeCAD did not give its user folder" >&2; exit 1; }
mkdir -p "$USER_DIR/Mod"
ln -sfn "$PWD" "$USER_DIR/Mod/TMM"
export OPENBLAS_NUM_THREADS=1   # the workers side by side: no BLAS threads spinning against them (scripts/test.sh)
# the FreeCAD tests marked core work (fc_helpers.core_work: TMM's core through FreeCAD, nothing of FreeCAD's version
# that another test of their module does not check) ran on the host's FreeCAD: here fc_runner leaves them out
export TMM_FC_VERSIONED=1
xvfb-run -a python3 -m pytest -p no:cacheprovider -n "${TMM_TEST_WORKERS:-$(($(nproc) + 1))}" --dist loadgroup --durations=10 \
  tests/freecad tests/gui "$@"
