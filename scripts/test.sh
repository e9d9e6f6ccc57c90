#!/usr/bin/env bash
# Install what is needed, build, then run every test: the kernel's GoogleTest suite (ctest)
# and the Python suite (pytest, serial and MPI cases).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bash "$here/scripts/setup.sh"
cd "$here"
ctest --test-dir build --output-on-failure -j 2
/usr/bin/python3 -m pytest -q tests "$@"
