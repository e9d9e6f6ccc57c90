#!/usr/bin/env bash
# Install what is needed, build, and run the main job (the dam–log demo); outputs land in
# results/dam_debris/.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bash "$here/scripts/setup.sh"
cd "$here"
/usr/bin/python3 demos/dam_debris.py "$@"
echo "Outputs: $here/results/dam_debris/ (report.md, XDMF for ParaView, PNG pictures, summary.json)"
