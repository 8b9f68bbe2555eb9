#!/usr/bin/env bash
# The Python binding tests against the UBSan-built module (build-ubsan, see TMM_SANITIZE in CMakeLists.txt):
# the package and the tests copied to a temporary folder with the sanitized module in place of the normal
# one, pytest run there (so neither the checkout's package nor its module is imported), the sanitizer
# runtime preloaded, any report fatal; then the binding fuzz script (native/fuzz/fuzz_binding.py) the same way.
# Run after `cmake --build build-ubsan`.
set -euo pipefail
BUILD="$(cd "${1:-$(dirname "${BASH_SOURCE[0]}")/../build-ubsan}" && pwd)"
MODULE="$(ls "$BUILD"/_native*.so)"
source "$(dirname "${BASH_SOURCE[0]}")/test_copy.sh"
cp "$MODULE" "$TMP/tmm_workbench/"
cd "$TMP"
# The runtimes of the sanitizers the folder was built with (ASan's first: it must come first in the process).
SANITIZE="$(sed -n 's/^TMM_SANITIZE:STRING=//p' "$BUILD/CMakeCache.txt")"
PRELOAD=()
[[ "$SANITIZE" == *address* ]] && PRELOAD+=("$(gcc -print-file-name=libasan.so)")
[[ "$SANITIZE" == *undefined* ]] && PRELOAD+=("$(gcc -print-file-name=libubsan.so)")
export LD_PRELOAD="${PRELOAD[*]}"
export UBSAN_OPTIONS="halt_on_error=1:abort_on_error=1:print_stacktrace=1"
# Python's own allocations are not ours to report as leaks.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1"
# The module found must be the sanitized copy: checked before the tests run.
"$ROOT/.venv/bin/python" -c "import tmm_workbench._native as n, sys; assert n.__file__.startswith('$TMP'), n.__file__"
"$ROOT/.venv/bin/python" -m pytest -q -p no:cacheprovider "${TESTS[@]/#/tests/core/}"
# The binding fuzz script, bounded (TMM_FUZZ_CALLS calls, fixed seed), on the same sanitized module.
PYTHONPATH="$TMP" "$ROOT/.venv/bin/python" "$ROOT/native/fuzz/fuzz_binding.py" --calls "${TMM_FUZZ_CALLS:-3000}"
