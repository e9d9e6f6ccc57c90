#!/usr/bin/env bash
# Install the Debian packages flexcontact needs (only those missing), build the kernel, its
# tests and the Python module, and make the package importable by /usr/bin/python3.
# Runs on Debian 12 (DOLFINx 0.5) and Debian 13 (DOLFINx 0.9; see scripts/debian13.sh); each
# builds in its own folder, build/<codename>.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-unknown}")
build="$here/build/$codename"

packages=(
  cmake g++ make pkg-config python3-dev libblas-dev liblapack-dev python3-venv python3-setuptools
  python3-dolfinx libdolfinx-dev petsc-dev python3-petsc4py python3-mpi4py openmpi-bin
  gmsh python3-gmsh libeigen3-dev pybind11-dev
  googletest libgtest-dev python3-pytest python3-pytest-xdist python3-scipy python3-matplotlib
  python3-tqdm python3-distributed libmetis-dev libmumps-dev
  libopenblas0-serial
)
# Peer codes used as oracles by some tests; a distribution without them (Debian 13 has no
# Siconos) skips those tests and says so.
optional=(python3-siconos)

# No `cmd | grep -q` here: under pipefail, grep leaving early can SIGPIPE the command and
# turn a match into a failure.
installed() { [[ "$(dpkg-query -W -f='${Status}' "$1" 2>/dev/null)" == "install ok installed" ]]; }
available() {
  local policy; policy=$(apt-cache policy "$1" 2>/dev/null)
  [[ $policy == *"Candidate: "* && $policy != *"Candidate: (none)"* ]]
}

SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
missing=()
for p in "${packages[@]}"; do installed "$p" || missing+=("$p"); done
updated=0
if [ ${#missing[@]} -gt 0 ]; then
  $SUDO apt-get update -qq || exit 75
  updated=1
fi
if [ ${#missing[@]} -gt 0 ]; then
  echo "Installing Debian packages: ${missing[*]}"
  # Exit status 75: the archive cannot install them today (Debian unstable changes daily);
  # .ci/run skips that release's suite on it and says so.
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null || exit 75
fi
for p in "${optional[@]}"; do
  installed "$p" && continue
  # Known lists say whether this distribution has it; without lists, ask the archive once.
  if [ $updated -eq 0 ] && ! available "$p" && ! compgen -G "/var/lib/apt/lists/*_Packages*" >/dev/null; then
    $SUDO apt-get update -qq
    updated=1
  fi
  if ! available "$p"; then
    echo "Not in this distribution's archive: $p"
  elif ! DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "$p" >/dev/null 2>&1; then
    # An optional oracle that is listed but not installable (its dependencies moved on):
    # the tests that need it skip and say so.
    echo "Not installable in this distribution today: $p"
  fi
done

cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build "$build" -j "$(nproc)"

# Make `import flexcontact` work for /usr/bin/python3 from anywhere (like an editable install).
site=$(/usr/bin/python3 -c "import site; print(site.getsitepackages()[0])")
SUDO=""; [ "$(id -u)" -ne 0 ] && [ ! -w "$site" ] && SUDO="sudo"
$SUDO mkdir -p "$site"
# The second line maps the top-level forms/ and meshes/ in as flexcontact.forms and
# flexcontact.meshes, as the wheel does (dolfinx_ext/python/flexcontact_checkout.py).
printf '%s\nimport flexcontact_checkout\n' "$here/dolfinx_ext/python" | $SUDO tee "$site/flexcontact.pth" >/dev/null
/usr/bin/python3 -c "import flexcontact, sys; print('flexcontact', flexcontact.__version__, 'ready:', flexcontact.__file__)"
