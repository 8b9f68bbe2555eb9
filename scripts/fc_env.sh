#!/usr/bin/env bash
# A Debian chroot with another FreeCAD, made once and reused: trixie (Debian 13, FreeCAD 1.0) or forky
# (Debian testing, FreeCAD 1.1). Usage: bash scripts/fc_env.sh SUITE [COMMAND...]
#   without COMMAND: makes sure the environment exists (about 6 minutes and 3 GB the first time, seconds after);
#   with COMMAND: runs it inside as root, in this checkout (bind-mounted at the same path, with the shared
#   benchmark folder), and unmounts on every exit path.
# The cache folder is $TMM_ENV_CACHE (default /var/cache/tmm-envs); delete SUITE/ there to start over.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SUITE="${1:?usage: fc_env.sh trixie|forky [command...]}"
shift
CACHE="${TMM_ENV_CACHE:-/var/cache/tmm-envs}"
DIR="$CACHE/$SUITE"
MIRROR="${TMM_DEBIAN_MIRROR:-http://deb.debian.org/debian}"
SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"

case "$SUITE" in
  trixie) SCRIPT=""; SOURCES="deb $MIRROR trixie main
deb $MIRROR trixie-updates main
deb http://deb.debian.org/debian-security trixie-security main" ;;
  forky) SCRIPT="/usr/share/debootstrap/scripts/sid"; SOURCES="deb $MIRROR forky main" ;;
  *) echo "fc_env.sh: unknown suite '$SUITE' (trixie or forky)" >&2; exit 2 ;;
esac
# What the tests need inside: FreeCAD, the kernel's build tools (ccache: its cache in the chroot's
# /var/cache/ccache, kept with it), the test runners (pytest-xdist: two at a time), Xvfb for the GUI test.
DEBS=(freecad-python3 libeigen3-dev pybind11-dev python3-dev python3-numpy python3-pytest python3-venv
      python3-pip python3-matplotlib xvfb xauth cmake g++ ninja-build libgtest-dev ca-certificates
      python3-opencamlib python3-pyclipper python3-contourpy python3-scipy python3-pytest-xdist ccache)

MOUNTS=()
cleanup() {
  local i
  for ((i = ${#MOUNTS[@]} - 1; i >= 0; i--)); do $SUDO umount -l "${MOUNTS[$i]}" 2>/dev/null || true; done
}
trap cleanup EXIT
mount_in() {  # mount_in SRC TARGET [options]: bind SRC at DIR/TARGET
  local target="$DIR$2"
  mkdir -p "$target"
  # a run killed before its cleanup leaves its mounts: one still showing an older SRC (a checkout deleted and
  # cloned again at the same path) is made again, or the chroot would see the deleted, empty folder
  if mountpoint -q "$target" && [ "$(stat -c %d:%i "$1")" != "$(stat -c %d:%i "$target")" ]; then
    $SUDO umount -l "$target"
  fi
  mountpoint -q "$target" || $SUDO mount ${3:-} --bind "$1" "$target"
  MOUNTS+=("$target")
}
enter() {
  mount_in /proc /proc; mount_in /sys /sys; mount_in /dev /dev; mount_in /dev/pts /dev/pts
  cp -L /etc/resolv.conf "$DIR/etc/resolv.conf" 2>/dev/null || true
}

if [ ! -x "$DIR/usr/bin/apt-get" ] || [ ! -f "$DIR/.tmm-bootstrapped" ]; then
  command -v debootstrap >/dev/null || { $SUDO apt-get update -qq; $SUDO apt-get install -y -qq debootstrap; }
  echo "[fc_env] debootstrap $SUITE into $DIR"
  $SUDO rm -rf "$DIR"; $SUDO mkdir -p "$DIR"
  $SUDO debootstrap --variant=minbase "$SUITE" "$DIR" "$MIRROR" $SCRIPT >/dev/null
  printf '%s\n' "$SOURCES" > "$DIR/etc/apt/sources.list"
  # the testing suite's Release files are sometimes past their Valid-Until on the mirror
  echo 'Acquire::Check-Valid-Until "false";' > "$DIR/etc/apt/apt.conf.d/99tmm"
  touch "$DIR/.tmm-bootstrapped"
fi
missing=()
for p in "${DEBS[@]}"; do $SUDO chroot "$DIR" dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  enter
  echo "[fc_env] installing in $SUITE: ${missing[*]}"
  $SUDO chroot "$DIR" /usr/bin/env DEBIAN_FRONTEND=noninteractive bash -c \
    "apt-get update -qq && apt-get install -y -qq --no-install-recommends ${missing[*]} >/dev/null && apt-get clean"
  echo "[fc_env] $SUITE ready: $(du -sh "$DIR" 2>/dev/null | cut -f1)"
fi

# The host's own certificate authorities (a proxy's, for PyPI), so pip inside trusts what the host trusts.
if compgen -G "/usr/local/share/ca-certificates/*.crt" >/dev/null && \
   ! diff -rq /usr/local/share/ca-certificates "$DIR/usr/local/share/ca-certificates" >/dev/null 2>&1; then
  $SUDO mkdir -p "$DIR/usr/local/share/ca-certificates"
  $SUDO cp /usr/local/share/ca-certificates/*.crt "$DIR/usr/local/share/ca-certificates/"
  $SUDO chroot "$DIR" update-ca-certificates >/dev/null 2>&1
fi

[ $# -eq 0 ] && exit 0
enter
mount_in "$ROOT" "$ROOT"
SHARED="$(cd "$ROOT/.." && pwd)/shared"
[ -d "$SHARED" ] && mount_in "$SHARED" "$SHARED" "-o ro"
[ -n "${TMM_SHARED_DIR:-}" ] && [ -d "$TMM_SHARED_DIR" ] && mount_in "$TMM_SHARED_DIR" "$TMM_SHARED_DIR" "-o ro"
$SUDO chroot "$DIR" /usr/bin/env -i HOME=/root PATH=/usr/local/bin:/usr/bin:/bin LANG=C.UTF-8 \
  TMM_SHARED_DIR="${TMM_SHARED_DIR:-}" TMM_ENV="$SUITE" CI="${CI:-}" bash -c "cd '$ROOT' && $*"
