#!/usr/bin/env bash
# The kernel as a wheel for one Python (default python3, the one FreeCAD runs here): `pip wheel ./native`
# (scikit-build-core + pybind11 from PyPI, the compiler and Eigen from the system), installed into a venv over
# the system packages (numpy from Debian), the binding tests run against it from a copy of the package
# without the in-place module. The wheel is left in dist/ (e.g. dist/tmm_kernel-0.1.0-cp313-...whl).
# Usage: wheel_test.sh [PYTHON] [--in-place]: with --in-place, once its binding tests passed, the wheel's module
# is also put into tmm_workbench/ (as the in-place build names it, e.g. _native.cpython-313-x86_64-linux-gnu.so),
# so that FreeCAD finds this very module without compiling the kernel a second time (scripts/env_test.sh).
set -euo pipefail
PY="${1:-python3}"
IN_PLACE="${2:-}"
source "$(dirname "${BASH_SOURCE[0]}")/test_copy.sh"
VENV="$TMP/venv"
"$PY" -m venv --system-site-packages "$VENV"
TAG="$("$VENV/bin/python" -c 'import sys; print(f"cp{sys.version_info.major}{sys.version_info.minor}")')"
rm -f "$ROOT"/dist/tmm_kernel-*-"$TAG"-*.whl  # only the wheel built now is installed and tested below
"$VENV/bin/python" -m pip wheel -q --no-deps "$ROOT/native" -w "$ROOT/dist"
WHEEL="$(ls "$ROOT"/dist/tmm_kernel-*-"$TAG"-*.whl)"
"$VENV/bin/python" -m pip install -q --no-deps --force-reinstall "$WHEEL"
cd "$TMP"
"$VENV/bin/python" -c "from tmm_workbench.core.kernel import native; f = native.load().__file__; \
assert '/site-packages/tmm_kernel/' in f, f; print('[wheel_test] kernel from the wheel:', f)"
# The OpenCAMLib comparison needs the peer, which only .venv has on the host: it runs there (the in-place
# module and the UBSan one); here it is left out by name rather than skipped.
DESELECT=()
"$VENV/bin/python" -c "import opencamlib" 2>/dev/null || DESELECT=(--deselect tests/core/test_waterline.py::test_opencamlib_waterline_agrees_on_a_real_stl)
"$VENV/bin/python" -m pytest -q -p no:cacheprovider "${DESELECT[@]}" "${TESTS[@]/#/tests/core/}"
if [ "$IN_PLACE" = "--in-place" ]; then
  # The installed module, copied then renamed into the package (atomic, as the in-place build does it).
  MODULE="$("$VENV/bin/python" -c 'import tmm_kernel._native as n; print(n.__file__)')"
  NAME="$(basename "$MODULE")"
  cp "$MODULE" "$ROOT/tmm_workbench/$NAME.part"
  mv -f "$ROOT/tmm_workbench/$NAME.part" "$ROOT/tmm_workbench/$NAME"
  echo "[wheel_test] the wheel's module put in place: tmm_workbench/$NAME"
elif [ -n "$IN_PLACE" ]; then
  echo "wheel_test.sh: unknown option '$IN_PLACE' (--in-place)" >&2; exit 2
fi
