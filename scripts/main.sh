#!/usr/bin/env bash
# Install what is needed, build, and run the main job: the dam–log impact demo (outputs in
# results/dam_debris/), then a short sweep of 32 impact scenarios on the same dam (outputs in
# results/sweep/sweep_small/; run again after an interruption, it resumes).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bash "$here/scripts/setup.sh"
cd "$here"
/usr/bin/python3 demos/dam_debris.py "$@"
/usr/bin/python3 -m flexcontact sweep examples/sweep_small.toml
echo "Outputs: $here/results/dam_debris/ (report.md, XDMF for ParaView, PNG pictures, summary.json)"
echo "         $here/results/sweep/sweep_small/ (report.md, results.csv, summary.json, exceedance and envelope plots)"
