#!/usr/bin/env bash
# Run a command inside the Debian 13 (trixie) root: DOLFINx 0.9, PETSc 3.22, Open MPI 5,
# Python 3.13 (scripts/debian-root.sh, which also makes the Debian unstable root).
#
#   bash scripts/debian13.sh bash scripts/test.sh      # the whole suite on DOLFINx 0.9
#   bash scripts/debian13.sh                           # a shell in the root
#   bash scripts/debian13.sh --remove                  # delete the root
exec bash "$(dirname "$0")/debian-root.sh" trixie "$@"
