#!/usr/bin/env bash
# Install what is needed, build, and run the main job: the dam–log impact demo (outputs in
# results/dam_debris/), then a short sweep of 32 impacts of crushing logs on the 3D dam block
# (outputs in results/sweep/sweep_3d_crushing/, with the dam model it prepares once in
# dam_model/ there; run again after an interruption, it resumes).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bash "$here/scripts/setup.sh"
# The report's picture needs ParaView's pvbatch and a virtual screen (xvfb-run); the tests
# do not. Without recommends: pvbatch needs neither the GUI's extras nor documentation.
installed() { [[ "$(dpkg-query -W -f='${Status}' "$1" 2>/dev/null)" == "install ok installed" ]]; }
missing=()
for p in paraview python3-paraview xvfb; do installed "$p" || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "Installing Debian packages for the report's picture: ${missing[*]}"
  if ! { $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install \
         -y -qq --no-install-recommends "${missing[@]}" >/dev/null; }; then
    echo "Could not install ${missing[*]}: the report will say why its picture is missing"
  fi
fi
cd "$here"
/usr/bin/python3 demos/dam_debris.py "$@"
/usr/bin/python3 -m flexcontact sweep examples/sweep_3d_crushing.toml
echo "Outputs: $here/results/dam_debris/ (report.md, XDMF for ParaView, PNG pictures, summary.json)"
echo "         $here/results/sweep/sweep_3d_crushing/ (report.md, results.csv, summary.json, exceedance and envelope plots)"
