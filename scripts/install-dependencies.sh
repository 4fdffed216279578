#!/usr/bin/env bash
# Installs what the project needs on Debian 12, by package name.
# Runs apt-get as root (directly, or through sudo when not root).
set -euo pipefail
packages=(
  build-essential cmake git pkg-config
  nlohmann-json3-dev libpng-dev zlib1g-dev libgtest-dev
  libvtk9-dev python3-vtk9
  libinsighttoolkit5-dev   # DICOM through ITK + GDCM (JPEG 2000 included)
  python3-dev              # the Python wrapping of the VTK module
  xvfb xauth
  python3-venv             # .venv: Mitsuba 3, numpy, matplotlib (accuracy checks and charts)
  invesalius-examples   # the default input: Cranium.inv3
)
as_root=()
if [ "$(id -u)" -ne 0 ]; then as_root=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "Installing: ${missing[*]}" >&2
  "${as_root[@]}" apt-get update -qq
  "${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The accuracy checks and charts (Testing/Accuracy) run in a virtual
# environment of Debian's Python with pinned PyPI packages: Mitsuba 3 (the
# independent renderer), numpy and matplotlib. CMake finds it at .venv.
here="$(cd "$(dirname "$0")/.." && pwd)"
venv="$here/.venv"
if ! "$venv/bin/python" -c "import mitsuba, numpy, matplotlib" 2>/dev/null; then
  echo "Setting up $venv (mitsuba, numpy, matplotlib)" >&2
  /usr/bin/python3 -m venv "$venv"
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    -r "$here/Testing/Accuracy/requirements.txt"
fi
