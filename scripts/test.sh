#!/usr/bin/env bash
# Sets up what is missing, then runs every test: the kernel's unit tests (ctest, also under UBSan), then pytest
# over tests/ (core and binding, the OpenCAMLib cross-check, FreeCAD 0.20 under freecadcmd, the GUI under Xvfb),
# then the binding (the kernel's wheel), FreeCAD and GUI tests again under FreeCAD 1.0 (Debian 13) and 1.1
# (Debian testing), each in a Debian chroot made once and reused (scripts/fc_env.sh; TMM_ENVS names them, default both).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash scripts/setup.sh
ctest --test-dir build --output-on-failure
# The kernel, its tests and the binding tests again under UBSan (build-ubsan; see TMM_SANITIZE in native/CMakeLists.txt).
cmake -S native -B build-ubsan -G Ninja -DCMAKE_BUILD_TYPE=Release -DTMM_SANITIZE=undefined -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null; cmake --build build-ubsan -j"$(nproc)"; ctest --test-dir build-ubsan -j"$(nproc)" --output-on-failure; bash native/sanitize_bindings.sh
# Bounded fuzzing (native/fuzz): the STL reader's libFuzzer harness for 30 s over its corpus (clang, ASan+UBSan); the binding fuzz script ran above in sanitize_bindings.sh.
cmake -S native/fuzz -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++-14 >/dev/null; cmake --build build-fuzz; mkdir -p build-fuzz/corpus; build-fuzz/fuzz_stl -max_total_time=30 -rss_limit_mb=1024 -print_final_stats=0 build-fuzz/corpus native/fuzz/corpus/stl 2>&1 | tail -1
# The kernel as a wheel (pip install ./native) for FreeCAD's Python, its binding tests run against it.
bash native/wheel_test.sh /usr/bin/python3
.venv/bin/python -m pytest --durations=15 "$@"
for env in ${TMM_ENVS-trixie forky}; do
  bash scripts/fc_env.sh "$env" bash scripts/env_test.sh -q
done
