#!/usr/bin/env bash
# Run a command inside a Debian root of another release, made once and reused:
#   trixie  Debian 13: DOLFINx 0.9, PETSc 3.22, Open MPI 5, Python 3.13
#   sid     Debian unstable: DOLFINx 0.11, PETSc 3.25 (it changes daily)
#
#   bash scripts/debian-root.sh sid bash scripts/test.sh    # the whole suite on DOLFINx 0.11
#   bash scripts/debian-root.sh trixie                      # a shell in the Debian 13 root
#   bash scripts/debian-root.sh sid --remove                # delete that root
#
# The repository is bind-mounted at its own path inside the root, so builds and results land
# in the working tree (build/<codename>, a separate build folder per release). Every mount is
# made in a private mount namespace: it disappears with the command, whatever happens, and
# never shows on the host. FLEXCONTACT_ROOTS chooses where the roots live
# (default /var/cache/flexcontact; the Debian 13 root keeps its older variable
# FLEXCONTACT_DEBIAN13_ROOT). Exit status 75 means the root could not be made today (the
# archive refused, or a package is not installable): the caller may skip that suite.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
suite=${1:?usage: debian-root.sh trixie|sid [command ...] | --remove}
shift
case "$suite" in
  trixie) root=${FLEXCONTACT_DEBIAN13_ROOT:-${FLEXCONTACT_ROOTS:-/var/cache/flexcontact}/debian13} ;;
  sid) root=${FLEXCONTACT_ROOTS:-/var/cache/flexcontact}/sid ;;
  *) echo "debian-root.sh: unknown release '$suite' (trixie or sid)" >&2; exit 2 ;;
esac
ready="$root/.flexcontact-root-ready"
CANNOT_MAKE=75

if [ "$(id -u)" -ne 0 ]; then
  exec sudo -E bash "$0" "$suite" "$@"
fi

if [ "${1:-}" = "--remove" ]; then
  # Only this process's namespaces ever mount inside the root, so nothing is mounted now;
  # --one-file-system still refuses to cross into anything that would be.
  if findmnt -rno TARGET | grep -q "^$root/"; then
    echo "refusing to remove $root: something is mounted inside it" >&2
    exit 1
  fi
  rm -rf --one-file-system "$root"
  echo "removed $root"
  exit 0
fi

# The host's archive, so that the root installs from the same mirror apt already uses.
mirror=$(awk '/^URIs:/ {print $2; exit}' /etc/apt/sources.list.d/debian.sources 2>/dev/null || true)
mirror=${mirror:-http://deb.debian.org/debian}

make_root() {
  echo "Making the Debian $suite root in $root (once; a few minutes)"
  if ! command -v debootstrap >/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap >/dev/null
  fi
  rm -rf --one-file-system "$root.partial"
  mkdir -p "$root.partial"
  # In its own mount namespace: debootstrap mounts /proc and /sys in the target, and a
  # failure half-way must not leave them mounted.
  if ! unshare --mount --propagation private \
      debootstrap --variant=minbase "$suite" "$root.partial" "$mirror" > "$root.partial.log" 2>&1; then
    tail -20 "$root.partial.log" >&2
    echo "debootstrap $suite failed (log: $root.partial.log)" >&2
    exit $CANNOT_MAKE
  fi
  # The host's apt settings (this machine's relaxed Check-Valid-Until and Check-Date; without
  # them apt in the root may reject an archive snapshot). Sid's Release file is often past
  # its Valid-Until date on the archive these machines reach.
  cp -n /etc/apt/apt.conf.d/* "$root.partial/etc/apt/apt.conf.d/" 2>/dev/null || true
  if [ "$suite" = sid ]; then
    echo 'Acquire::Check-Valid-Until "false";' > "$root.partial/etc/apt/apt.conf.d/99flexcontact-valid-until"
  fi
  mv "$root.partial" "$root"
  rm -f "$root.partial.log"
  touch "$ready"
}

[ -f "$ready" ] || make_root

[ $# -gt 0 ] || set -- bash
# Runs inside the private namespace: mount, chroot, and let the namespace's end unmount.
inner=$(cat <<'EOF'
set -euo pipefail
root=$1; repo=$2; shift 2
mount -t proc proc "$root/proc"
mount -t sysfs sys "$root/sys"
mount --bind /dev "$root/dev"
mount --bind /dev/pts "$root/dev/pts"
mount -t tmpfs shm "$root/dev/shm"
mount -t tmpfs tmp "$root/tmp"           # a private /tmp: a shared one breaks Open MPI
mkdir -p "$root$repo"
mount --bind "$repo" "$root$repo"
cp /etc/resolv.conf "$root/etc/resolv.conf" 2>/dev/null || true
cd /
exec chroot "$root" /usr/bin/env -i \
  PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin HOME=/root LANG=C.UTF-8 \
  TERM="${TERM:-dumb}" CI="${CI:-}" \
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl=self,sm \
  ${OPENBLAS_CORETYPE:+OPENBLAS_CORETYPE=$OPENBLAS_CORETYPE} \
  ${OPENBLAS_L2_SIZE:+OPENBLAS_L2_SIZE=$OPENBLAS_L2_SIZE} \
  ${FLEXCONTACT_RESULTS:+FLEXCONTACT_RESULTS=$FLEXCONTACT_RESULTS} \
  bash -c 'cd "$0" && exec "$@"' "$repo" "$@"
EOF
)
unshare --mount --propagation private bash -c "$inner" inner "$root" "$here" "$@"
