#!/usr/bin/env bash
# Install the Debian packages flexcontact needs (only those missing), build the kernel, its
# tests and the Python module, and make the package importable by /usr/bin/python3.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)

packages=(
  cmake g++ make pkg-config python3-dev libblas-dev
  python3-dolfinx libdolfinx-dev petsc-dev python3-petsc4py python3-mpi4py openmpi-bin
  gmsh python3-gmsh libeigen3-dev pybind11-dev python3-pybind11
  googletest libgtest-dev python3-pytest python3-scipy python3-matplotlib python3-tqdm
  python3-siconos libopenblas0-serial
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "Installing Debian packages: ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi

cmake -S "$here" -B "$here/build" -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build "$here/build" -j "$(nproc)"

# Make `import flexcontact` work for /usr/bin/python3 from anywhere (like an editable install).
site=$(/usr/bin/python3 -c "import site; print(site.getsitepackages()[0])")
SUDO=""; [ "$(id -u)" -ne 0 ] && [ ! -w "$site" ] && SUDO="sudo"
$SUDO mkdir -p "$site"
echo "$here/dolfinx_ext/python" | $SUDO tee "$site/flexcontact.pth" >/dev/null
/usr/bin/python3 -c "import flexcontact, sys; print('flexcontact', flexcontact.__version__, 'ready:', flexcontact.__file__)"
