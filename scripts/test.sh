#!/usr/bin/env bash
# Sets up what is missing, then runs every test: the kernel's unit tests (ctest), then pytest over tests/
# (core and binding, the OpenCAMLib cross-check, FreeCAD under freecadcmd, the GUI under Xvfb).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup.sh
ctest --test-dir build --output-on-failure
.venv/bin/python -m pytest "$@"
