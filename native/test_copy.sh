# Sourced by sanitize_bindings.sh and wheel_test.sh: the package and the binding tests copied to a temporary
# folder $TMP without the checkout's kernel module (so the test run imports the module under test, never the
# one built in place), the shared benchmark folder found, $TESTS the test files to run there.
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
cp -r "$ROOT/tmm_workbench" "$ROOT/benchmarks" "$TMP/"  # benchmarks: the seed's reference code some tests use
rm -f "$TMP"/tmm_workbench/_native*.so*
mkdir -p "$TMP/tests/core"
cp "$ROOT/tests/__init__.py" "$ROOT/tests/conftest.py" "$TMP/tests/"
cp "$ROOT/tests/core/__init__.py" "$TMP/tests/core/"
TESTS=(test_drop_binding.py test_kernel_cancel.py test_mesh_io.py test_multipoint.py test_native_hardening.py
       test_waterline.py)
for t in "${TESTS[@]}"; do cp "$ROOT/tests/core/$t" "$TMP/tests/core/"; done
export TMM_SHARED_DIR="${TMM_SHARED_DIR:-$(cd "$ROOT" && python3 -c 'from tmm_workbench.core.shared_data import shared_dir; print(shared_dir())' 2>/dev/null || echo "$ROOT/../shared")}"
