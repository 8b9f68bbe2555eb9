#!/usr/bin/env bash
# Sets up what is missing, then runs every test: the kernel's unit tests (ctest, also under UBSan), then pytest
# over tests/ (core and binding, the OpenCAMLib cross-check, FreeCAD 0.20 under freecadcmd, the GUI under Xvfb),
# then the binding (the kernel's wheel), FreeCAD and GUI tests again under FreeCAD 1.0 (Debian 13) and 1.1
# (Debian testing), each in a Debian chroot made once and reused (scripts/fc_env.sh; TMM_ENVS names them, default both).
# pytest runs TMM_TEST_WORKERS tests at a time (pytest-xdist; default one more than the cores: the FreeCAD and GUI
# tests wait on FreeCAD's start and event loop a quarter of their time; 0 for one process); each step prints
# its time. The compilers run through ccache, its cache beside the chroots ($TMM_ENV_CACHE/ccache; each chroot
# keeps its own inside), so a run recompiles only what changed; an empty or missing cache only costs time.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
T0=$SECONDS
TIMES="$(mktemp)"
trap 'rm -f "$TIMES"' EXIT
cpu() {  # the CPU seconds this shell's finished child processes took so far (user + system), into CPU
  times > "$TIMES"  # in this shell: in a $(...) subshell it would count that subshell's children only
  CPU="$(tail -1 "$TIMES" | awk '{ s = 0; for (i = 1; i <= 2; i++) { split($i, a, /[ms]/); s += 60 * a[1] + a[2] }; printf "%d", s }')"
}
step() {  # step NAME COMMAND...: runs it, then says how long it took (wall clock, and CPU: the machine is shared)
  local name="$1" t=$SECONDS c
  cpu; c=$CPU
  shift
  "$@"
  cpu
  echo "[test] $name: $((SECONDS - t)) s, CPU $((CPU - c)) s (total $((SECONDS - T0)) s)"
}
CACHE="${TMM_ENV_CACHE:-/var/cache/tmm-envs}"
if [ -z "${CCACHE_DIR:-}" ] && mkdir -p "$CACHE/ccache" 2>/dev/null && [ -w "$CACHE/ccache" ]; then
  export CCACHE_DIR="$CACHE/ccache" CCACHE_MAXSIZE="${CCACHE_MAXSIZE:-3G}"
fi
# paths under the checkout hashed relative to it: a clone at another path (CI's) hits the objects of this one's
export CCACHE_BASEDIR="$PWD"
step setup bash scripts/setup.sh
# the side builds below (UBSan, fuzz, the wheel) through ccache too, when there is a cache (setup installed it)
[ -n "${CCACHE_DIR:-}" ] && command -v ccache >/dev/null && export CMAKE_CXX_COMPILER_LAUNCHER=ccache
WORKERS="${TMM_TEST_WORKERS:-$(($(nproc) + 1))}"
JOBS="$(nproc)"
step ctest ctest --test-dir build -j"$JOBS" --output-on-failure
# The kernel, its tests and the binding tests again under UBSan (build-ubsan; see TMM_SANITIZE in native/CMakeLists.txt):
# what the tests run (the kernel's tests and the module), not the profiling drivers.
ubsan() {
  cmake -S native -B build-ubsan -G Ninja -DCMAKE_BUILD_TYPE=Release -DTMM_SANITIZE=undefined \
    -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
  cmake --build build-ubsan -j"$JOBS" --target tmm_kernel_tests _native
  ctest --test-dir build-ubsan -j"$JOBS" --output-on-failure
  bash native/sanitize_bindings.sh
}
step ubsan ubsan
# Bounded fuzzing (native/fuzz): the STL reader's libFuzzer harness for 30 s over its corpus (clang, ASan+UBSan); the binding fuzz script ran above in sanitize_bindings.sh.
fuzz() {
  cmake -S native/fuzz -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++-14 >/dev/null
  cmake --build build-fuzz
  mkdir -p build-fuzz/corpus
  build-fuzz/fuzz_stl -max_total_time=30 -rss_limit_mb=1024 -print_final_stats=0 build-fuzz/corpus \
    native/fuzz/corpus/stl 2>&1 | tail -1
}
step fuzz fuzz
# The kernel as a wheel (pip install ./native) for FreeCAD's Python, its binding tests run against it. With
# ccache, the wheel's kernel objects are build/'s (same flags): the same compiler named as setup's build names it
# (scikit-build-core would take Python's x86_64-linux-gnu-g++, the same GCC, but ccache hashes the name).
wheel() {
  if [ -n "${CMAKE_CXX_COMPILER_LAUNCHER:-}" ]; then
    CXX="$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' build/CMakeCache.txt)" bash native/wheel_test.sh /usr/bin/python3
  else
    bash native/wheel_test.sh /usr/bin/python3
  fi
}
step wheel wheel
# pytest's workers (and the FreeCAD they start) run side by side on the cores: OpenBLAS's own threads would only
# spin against them (a fifth to a third more CPU for the same numpy tests, measured)
export OPENBLAS_NUM_THREADS=1
step pytest .venv/bin/python -m pytest -n "$WORKERS" --dist loadgroup --durations=15 "$@"
for env in ${TMM_ENVS-trixie forky}; do
  step "$env" bash scripts/fc_env.sh "$env" bash scripts/env_test.sh -q
done
