#!/usr/bin/env bash
# Sets up what is missing, then runs the main job headless under FreeCAD: real models to G-code,
# FreeCAD documents and pictures in out/ (or $TMM_OUT).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup.sh
freecadcmd scripts/demo.py
