#!/usr/bin/env bash
# Sets up what is missing, then runs every test: the kernel's unit tests (ctest), then pytest over tests/
# (core and binding, the OpenCAMLib cross-check, FreeCAD under freecadcmd, the GUI under Xvfb).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup.sh
ctest --test-dir build --output-on-failure
# The kernel, its tests and the binding tests again under UBSan (build-ubsan; see TMM_SANITIZE in native/CMakeLists.txt).
cmake -S native -B build-ubsan -G Ninja -DCMAKE_BUILD_TYPE=Release -DTMM_SANITIZE=undefined -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null; cmake --build build-ubsan -j"$(nproc)"; ctest --test-dir build-ubsan -j"$(nproc)" --output-on-failure; bash native/sanitize_bindings.sh
.venv/bin/python -m pytest "$@"
