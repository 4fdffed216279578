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
  qt6-base-dev libqt6opengl6-dev libqt6openglwidgets6 libxkbcommon-dev   # the Qt 6 viewer
  ninja-build              # the VTK 9.6 SDK and the wheel build (scripts/make-vtk-sdk.sh)
  python3-venv             # .venv: Mitsuba 3, numpy, matplotlib (accuracy checks and charts)
  libllvm16                # Mitsuba's vectorised llvm_ad_rgb variant (Testing/Accuracy)
  clang-14 libclang-rt-14-dev   # libFuzzer + sanitizer runtimes (Testing/Fuzz)
  invesalius-examples   # the default input: Cranium.inv3
  debootstrap           # the ParaView root of the plugin's build and tests (scripts/paraview-root.sh)
  chromium chromium-driver   # mmrtm-web's test: a real browser, headless, driven by selenium
  openssl                    # mmrtm-web's TLS test: a certificate made at test time
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
# independent renderer), numpy and matplotlib; and the `pyoidn` wheel, whose
# Open Image Denoise library the denoised display loads. CMake finds it at .venv.
here="$(cd "$(dirname "$0")/.." && pwd)"
venv="$here/.venv"
# Reinstalled when the pins change (a dry run that needs no download says
# whether what is installed satisfies them).
requirements="$here/Testing/Accuracy/requirements.txt"
if ! "$venv/bin/python" -m pip install --dry-run --no-index --disable-pip-version-check --quiet \
       -r "$requirements" >/dev/null 2>&1; then
  echo "Setting up $venv (mitsuba, numpy, matplotlib, pyoidn)" >&2
  [ -x "$venv/bin/python" ] || /usr/bin/python3 -m venv "$venv"
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$requirements"
fi

# The VTK 9.6 flavour (Documentation/vtk-flavours.md): a venv of Debian's
# Python with the PyPI VTK and the Slicer core that runs on it, and the tools
# that build the mmrtm wheel (pinned in Testing/Python/requirements-vtk96.txt);
# then the VTK 9.6 SDK that the wheel builds against (once; it is cached).
venv96="$here/.venv-vtk96"
requirements96="$here/Testing/Python/requirements-vtk96.txt"
if ! "$venv96/bin/python" -m pip install --dry-run --no-index --disable-pip-version-check --quiet \
       -r "$requirements96" >/dev/null 2>&1; then
  echo "Setting up $venv96 ($(grep -c '^[a-z]' "$requirements96") pinned packages: vtk 9.6, the Slicer core, build tools)" >&2
  [ -x "$venv96/bin/python" ] || /usr/bin/python3 -m venv "$venv96"
  "$venv96/bin/python" -m pip install --quiet --disable-pip-version-check -r "$requirements96"
fi
"$here/scripts/make-vtk-sdk.sh" --python "$venv96/bin/python" \
  --cmake "$venv96/bin/cmake" --ninja "$venv96/bin/ninja" >/dev/null
