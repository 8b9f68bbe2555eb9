#!/usr/bin/env bash
# Inside a FreeCAD environment made by scripts/fc_env.sh (run as `bash scripts/fc_env.sh SUITE bash
# scripts/env_test.sh`): builds the kernel for this environment's python3 (its module has its own ABI tag,
# so it sits beside the host's in tmm_workbench/), links the add-on into this FreeCAD's user Mod folder
# (versioned from 1.1: FreeCAD says where), builds the kernel's wheel for this Python and runs the binding
# tests against it, and runs the FreeCAD tests and the GUI tests. The core tests that need only Python, numpy
# and the kernel ran on the host: here the interpreter is what is checked (the binding tests, through the wheel)
# and FreeCAD's version (the FreeCAD and GUI tests, which run the core through the ops). Extra arguments go to
# pytest.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
ENV_NAME="${TMM_ENV:?run through scripts/fc_env.sh}"
echo "[env_test] $ENV_NAME: $(freecadcmd --version 2>/dev/null | head -1), $(python3 --version)"
cmake -S native -B "build-$ENV_NAME" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3 \
  >/dev/null
cmake --build "build-$ENV_NAME" -j"$(nproc)" --target _native | tail -1
USER_DIR="$(freecadcmd -c 'import FreeCAD; print("TMM_USER_DIR=" + FreeCAD.getUserAppDataDir())' 2>/dev/null \
  | sed -n 's/^TMM_USER_DIR=//p' | tail -1)"
[ -n "$USER_DIR" ] || { echo "[env_test] FreeCAD did not give its user folder" >&2; exit 1; }
mkdir -p "$USER_DIR/Mod"
ln -sfn "$PWD" "$USER_DIR/Mod/TMM"
bash native/wheel_test.sh python3  # the wheel for this Python: built, installed in a venv, binding tests
xvfb-run -a python3 -m pytest -p no:cacheprovider --durations=10 tests/freecad tests/gui "$@"
