#!/usr/bin/env bash
# Install what is needed, build, then run every test: the kernel's GoogleTest suite (ctest)
# and the Python suite (pytest, serial and MPI cases). On Debian 13 the same script runs
# inside the root: bash scripts/debian13.sh bash scripts/test.sh
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bash "$here/scripts/setup.sh"
cd "$here"
codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-unknown}")
ctest --test-dir "build/$codename" --output-on-failure -j 2
# One pytest worker per core, each taking whole files, so that a file's module fixtures
# (a prepared dam model, a factored 3D block) are built once.
/usr/bin/python3 -m pytest -q -n "$(nproc)" --dist loadfile tests "$@"
