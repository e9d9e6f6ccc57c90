#!/usr/bin/env bash
# Install what is needed, build, and run the main demo; outputs land in results/.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bash "$here/scripts/setup.sh"
cd "$here"
/usr/bin/python3 demos/hertz2d.py "$@"
echo "Outputs: $here/results/hertz2d/ (hertz2d.xdmf for ParaView, hertz2d.png, summary.json)"
