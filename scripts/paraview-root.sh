#!/usr/bin/env bash
# A Debian 12 root with ParaView 5.11 (Debian's), where the ParaView plugin
# builds and its tests run, apart from the host.
#
# Why a separate root: Debian's python3-paraview conflicts with python3-vtk9,
# and libvtk9-dev (the project's own VTK) depends on python3-vtk9; installing
# ParaView on the build machine would remove the project's VTK.
# Documentation/paraview.md has the whole story.
#
#   scripts/paraview-root.sh ensure        make the root, or unpack the cached one
#   scripts/paraview-root.sh run CMD...    run CMD in the root (as root, clean env)
#
# The repository is bound into the root at its own path, and the shared data
# folder (../shared) beside it, read-only, so that paths are the same inside
# and out. Commands run in a network namespace of their own with only
# loopback up: the root's X servers and MPI cannot meet the host's.
#
# Environment:
#   MMRTM_PARAVIEW_ROOT        the root (default: <repo>/build-paraview/root)
#   MMRTM_PARAVIEW_ROOT_CACHE  the packed root (default:
#                              ${XDG_CACHE_HOME:-~/.cache}/mmrtm/paraview-root-<key>.tar.zst)
#   MMRTM_DEBIAN_MIRROR        the Debian mirror (default: the host's, else deb.debian.org)
# Needs root (debootstrap, chroot, mount and network namespaces).
set -euo pipefail

here="$(cd "$(dirname "$0")/.." && pwd)"
root="${MMRTM_PARAVIEW_ROOT:-$here/build-paraview/root}"

# What the root holds. ParaView's development package does not depend on
# every development package its CMake files ask for: the second line.
packages=(
  paraview paraview-dev python3-paraview openmpi-bin libopenmpi-dev
  libx11-dev libgl-dev libglew-dev libfreetype-dev libpng-dev libjpeg-dev libtiff-dev
  liblz4-dev liblzma-dev libdouble-conversion-dev libutfcpp-dev libexpat1-dev libeigen3-dev
  cmake g++ ninja-build xvfb xauth nlohmann-json3-dev zlib1g-dev python3-numpy
)
# The key names the cache: a different package list makes a different root.
key="$(printf '%s\n' bookworm "${packages[@]}" | sha256sum | cut -c1-16)"
cache="${MMRTM_PARAVIEW_ROOT_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/mmrtm/paraview-root-$key.tar.zst}"

die() { echo "paraview-root.sh: $*" >&2; exit 1; }
[ "$(id -u)" -eq 0 ] || die "needs root (debootstrap, chroot, mounts); run it with sudo"

host_mirror() {
  local uri
  uri="$(awk '/^URIs:/ && $2 ~ /\/debian\/?$/ {print $2; exit}' /etc/apt/sources.list.d/*.sources 2>/dev/null || true)"
  [ -n "$uri" ] || uri="$(awk '$1=="deb" && $2 ~ /^http/ && $2 ~ /\/debian\/?$/ {print $2; exit}' /etc/apt/sources.list 2>/dev/null || true)"
  echo "${uri:-http://deb.debian.org/debian}"
}

# Runs "$@" inside the root, in new mount and network namespaces: the mounts
# vanish with the namespace (nothing to unmount on failure), and only
# loopback is up.
in_root() {
  local shared_dir
  shared_dir="$(cd "$here/.." && pwd)/shared"
  unshare --mount --net --fork -- bash -euo pipefail -c '
    root="$1"; here="$2"; shared="$3"; shift 3
    mount --make-rprivate /
    ip link set lo up
    mount -t proc proc "$root/proc"
    mount -t sysfs -o ro sysfs "$root/sys"
    mkdir -p "$root/dev/shm" "$root/dev/pts"
    mount -t tmpfs -o mode=1777 tmpfs "$root/dev/shm"
    mount -t devpts -o newinstance,ptmxmode=0666 devpts "$root/dev/pts"
    mkdir -p "$root$here"
    mount --bind "$here" "$root$here"
    if [ -d "$shared" ]; then
      mkdir -p "$root$(dirname "$here")/shared"
      mount --bind "$(readlink -f "$shared")" "$root$(dirname "$here")/shared"
      mount -o remount,bind,ro "$root$(dirname "$here")/shared"
    fi
    exec chroot "$root" /usr/bin/env -i \
      PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
      HOME=/root LANG=C.UTF-8 TERM=dumb DEBIAN_FRONTEND=noninteractive \
      OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
      OMPI_MCA_plm=isolated OMPI_MCA_btl_vader_single_copy_mechanism=none \
      MMRTM_SOURCE_DIR="$here" \
      "$@"
  ' in_root "$root" "$here" "$shared_dir" "$@"
}

make_root() {
  local mirror tmp
  mirror="${MMRTM_DEBIAN_MIRROR:-$(host_mirror)}"
  command -v debootstrap >/dev/null || die "debootstrap is missing (scripts/install-dependencies.sh installs it)"
  tmp="$root.partial"
  rm -rf "$tmp"
  mkdir -p "$tmp"
  echo "paraview-root.sh: debootstrap bookworm from $mirror into $tmp" >&2
  debootstrap --variant=minbase bookworm "$tmp" "$mirror" >"$tmp.log" 2>&1 \
    || { tail -20 "$tmp.log" >&2; die "debootstrap failed (log: $tmp.log)"; }
  cat >"$tmp/etc/apt/sources.list" <<EOF
deb $mirror bookworm main
deb $mirror bookworm-updates main
deb ${mirror%/debian*}/debian-security bookworm-security main
EOF
  echo "paraview-root.sh: installing ${#packages[@]} packages (ParaView 5.11, Open MPI, build tools)" >&2
  # apt needs the network: this step runs in the host's network namespace.
  unshare --mount --fork -- bash -euo pipefail -c '
    tmp="$1"; shift
    mount --make-rprivate /
    mount -t proc proc "$tmp/proc"
    mount -t tmpfs tmpfs "$tmp/dev/shm" 2>/dev/null || true
    cp /etc/resolv.conf "$tmp/etc/resolv.conf" 2>/dev/null || true
    chroot "$tmp" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root DEBIAN_FRONTEND=noninteractive \
      apt-get update -qq
    chroot "$tmp" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root DEBIAN_FRONTEND=noninteractive \
      apt-get install -y -qq --no-install-recommends "$@"
    chroot "$tmp" apt-get clean
  ' make_root "$tmp" "${packages[@]}" >>"$tmp.log" 2>&1 \
    || { tail -20 "$tmp.log" >&2; die "installing the packages failed (log: $tmp.log)"; }
  echo "$key" >"$tmp/.mmrtm-root-key"
  rm -rf "$root"
  mv "$tmp" "$root"
  rm -f "$tmp.log"
  mkdir -p "$(dirname "$cache")"
  echo "paraview-root.sh: packing the root into $cache" >&2
  tar -C "$root" -I 'zstd -3 -T0' -cf "$cache.partial" . && mv "$cache.partial" "$cache"
}

ensure() {
  if [ -f "$root/.mmrtm-root-key" ] && [ "$(cat "$root/.mmrtm-root-key")" = "$key" ]; then
    return
  fi
  if [ -f "$cache" ]; then
    echo "paraview-root.sh: unpacking $cache" >&2
    rm -rf "$root" "$root.partial"
    mkdir -p "$root.partial"
    tar -C "$root.partial" -I zstd -xf "$cache"
    mv "$root.partial" "$root"
  else
    make_root
  fi
}

case "${1:-}" in
  ensure) ensure ;;
  run)
    shift
    [ $# -gt 0 ] || die "run: no command"
    [ -f "$root/.mmrtm-root-key" ] || die "no root at $root: run '$0 ensure' first"
    in_root "$@" ;;
  *) die "usage: $0 ensure | run CMD..." ;;
esac
