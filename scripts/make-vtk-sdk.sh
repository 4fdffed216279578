#!/usr/bin/env bash
# Makes the VTK 9.6.0 SDK (headers, CMake package, wrapping tools) that
# builds MM-RTM against the PyPI `vtk==9.6.0` wheel, and prints its VTK_DIR
# on stdout (progress goes to stderr).
#
# The wheel ships libraries but no headers or CMake files; VTK publishes those
# as the `vtk-sdk` wheel on its own package index. Where `vtk-sdk==9.6.0` is
# installed in the given Python, this script only prints its VTK_DIR.
# Otherwise it configures VTK's source (../shared/vtk/vtk-9.6.0-source.tar.xz)
# as the wheel was configured, builds no VTK library (only the wrapping tools,
# the modules' hierarchy files and the generated headers), installs the
# development files, and points every imported library of the CMake package
# at the wheel's file of the same name, found at configure time through the
# Python that builds the project (Documentation/vtk-flavours.md).
#
# Usage: scripts/make-vtk-sdk.sh [--output DIR] [--python PY] [--cmake CMAKE]
#                                [--ninja NINJA] [--source TARBALL]
#   --output  where the SDK goes (default: $MMRTM_VTK_SDK_DIR, else
#             ~/.cache/mmrtm/vtk-sdk-9.6.0-<python tag>); reused when complete
#   --python  the Python of the wheel (default /usr/bin/python3)
#   --cmake   CMake >= 3.27 (default: cmake on PATH when new enough)
#   --ninja   Ninja (default: ninja on PATH)
#   --source  VTK 9.6.0's source tarball (default ../shared/vtk/...)
set -euo pipefail

here="$(cd "$(dirname "$0")/.." && pwd)"
vtk_version=9.6.0
python=/usr/bin/python3
cmake_exe=""
ninja_exe=""
output="${MMRTM_VTK_SDK_DIR:-}"
tarball="${MMRTM_VTK_SOURCE:-$here/../shared/vtk/vtk-$vtk_version-source.tar.xz}"

die() { echo "make-vtk-sdk: $*" >&2; exit 1; }
say() { echo "make-vtk-sdk: $*" >&2; }

while [ $# -gt 0 ]; do
  case "$1" in
    --output) output="$2"; shift 2 ;;
    --python) python="$2"; shift 2 ;;
    --cmake) cmake_exe="$2"; shift 2 ;;
    --ninja) ninja_exe="$2"; shift 2 ;;
    --source) tarball="$2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown argument '$1' (see --help)" ;;
  esac
done

[ -x "$(command -v "$python")" ] || die "no Python at '$python'"

# 1. An installed vtk-sdk of this version: use it as it is.
installed="$("$python" - "$vtk_version" <<'EOF' 2>/dev/null || true
import importlib.metadata as m, importlib.util as u, os, sys
try:
    if m.version("vtk-sdk") != sys.argv[1]:
        raise SystemExit
except m.PackageNotFoundError:
    raise SystemExit
spec = u.find_spec("vtk_sdk")
d = os.path.join(spec.submodule_search_locations[0], "content",
                 "vtk-%s.data" % sys.argv[1], "headers", "cmake")
if os.path.isfile(os.path.join(d, "vtk-config.cmake")):
    print(d)
EOF
)"
if [ -n "$installed" ]; then
  say "using the installed vtk-sdk==$vtk_version"
  echo "$installed"
  exit 0
fi

pytag="$("$python" -c 'import sys; print("cp%d%d" % sys.version_info[:2])')"
if [ -z "$output" ]; then
  output="${XDG_CACHE_HOME:-$HOME/.cache}/mmrtm/vtk-sdk-$vtk_version-$pytag"
fi
vtk_dir="$output/vtk-$vtk_version.data/headers/cmake"

# The modules whose headers and CMake targets the SDK carries: what the
# mapper, the reader and their tests use, and what the Slicer core's CMake
# package names (slicer-core-sdk and slicer-layer-dm-sdk link these).
modules=(
  CommonCore CommonDataModel CommonExecutionModel CommonMath CommonSystem
  CommonComputationalGeometry
  ImagingCore ImagingColor ImagingGeneral ImagingSources ImagingStatistics ImagingStencil
  IOCore IOImage IOXML IOLegacy IOExport IOGeometry IOInfovis IOPLY IOSQL
  FiltersExtraction FiltersHybrid FiltersModeling FiltersSources
  RenderingCore RenderingVolume RenderingVolumeOpenGL2 RenderingOpenGL2
  RenderingAnnotation RenderingContextOpenGL2 RenderingFreeType RenderingLabel
  InteractionStyle InteractionWidgets ChartsCore TestingRendering
  WrappingPythonCore
)
[ -f "$tarball" ] || die "VTK's source is not at '$tarball' (set --source or MMRTM_VTK_SOURCE)"
# An SDK is reused while its source, its recipe (this script and the file it
# adds) and the module list are the same.
stamp="$(cat "$tarball" "$0" "$here/scripts/vtk-wheel-libraries.cmake" | sha256sum | cut -d' ' -f1); $pytag; ${modules[*]}"

if [ -f "$output/.mmrtm-sdk-stamp" ] && [ "$(cat "$output/.mmrtm-sdk-stamp")" = "$stamp" ] \
   && [ -f "$vtk_dir/vtk-config.cmake" ]; then
  say "reusing $output"
  echo "$vtk_dir"
  exit 0
fi

# 2. Tools: VTK's wheel configuration wants CMake >= 3.27 (X11 deferred
# loading; with older CMake the generated headers also depend on every
# module's objects).
version_ok() {  # version_ok CMAKE: its version is at least 3.27
  local v
  v="$("$1" --version 2>/dev/null | sed -n 's/^cmake version \([0-9]*\.[0-9]*\).*/\1/p')"
  [ -n "$v" ] && [ "$(printf '%s\n3.27\n' "$v" | sort -V | head -1)" = "3.27" ]
}
if [ -z "$cmake_exe" ]; then
  cmake_exe="$(command -v cmake || true)"
fi
[ -n "$cmake_exe" ] && version_ok "$cmake_exe" \
  || die "needs CMake >= 3.27 (found '${cmake_exe:-none}'): pass --cmake, e.g. from 'pip install cmake'"
if [ -z "$ninja_exe" ]; then
  ninja_exe="$(command -v ninja || true)"
fi
[ -n "$ninja_exe" ] || die "needs Ninja (Debian: ninja-build; PyPI: ninja)"

work="$output.work"
partial="$output.partial"
rm -rf "$work" "$partial"
mkdir -p "$work"
cleanup() { rm -rf "$partial"; }
trap cleanup EXIT

start=$SECONDS
say "unpacking $(basename "$tarball")"
tar -xf "$tarball" -C "$work"
src="$work/vtk-$vtk_version"
[ -f "$src/CMakeLists.txt" ] || die "'$tarball' does not hold vtk-$vtk_version/"
# IOSQL names VTK::sqlite, whose generated sqlite3.c is not in the archive.
# No VTK library is compiled, so an empty file lets the configure pass.
touch "$src/ThirdParty/sqlite/vtksqlite/sqlite3.c"

enable=()
for m in "${modules[@]}"; do enable+=("-DVTK_MODULE_ENABLE_VTK_$m=YES"); done
say "configuring VTK $vtk_version as the wheel was (log: $work/configure.log)"
# As VTK's .gitlab/ci/configure_wheel.cmake: VTK_WHEEL_BUILD, the old
# libstdc++ ABI of manylinux2014, STDThread SMP; every module group off
# except the modules above.
"$cmake_exe" -G Ninja -S "$src" -B "$work/build" \
  -DCMAKE_MAKE_PROGRAM="$ninja_exe" \
  -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_INSTALL_PREFIX="$partial" \
  -DCMAKE_CXX_FLAGS=-D_GLIBCXX_USE_CXX11_ABI=0 \
  -DPython3_EXECUTABLE="$("$python" -c 'import sys; print(sys.executable)')" \
  -DVTK_WHEEL_BUILD=ON -DVTK_INSTALL_SDK=ON \
  -DVTK_LEGACY_REMOVE=ON -DVTK_DEBUG_LEAKS=OFF \
  -DVTK_SMP_IMPLEMENTATION_TYPE=STDThread -DVTK_SMP_ENABLE_STDTHREAD=ON \
  -DVTK_ENABLE_REMOTE_MODULES=OFF \
  -DVTK_GROUP_ENABLE_StandAlone=DONT_WANT -DVTK_GROUP_ENABLE_Rendering=DONT_WANT \
  -DVTK_GROUP_ENABLE_Imaging=DONT_WANT -DVTK_GROUP_ENABLE_MPI=DONT_WANT \
  -DVTK_GROUP_ENABLE_Views=DONT_WANT -DVTK_GROUP_ENABLE_Web=DONT_WANT \
  -DVTK_GROUP_ENABLE_Qt=NO \
  "${enable[@]}" > "$work/configure.log" 2>&1 \
  || die "VTK's configure failed; see $work/configure.log"

# Build the wrapping tools (the CMake package checks that each exists), the
# hierarchy files of the wrapped modules and the generated headers; nothing
# else.
say "building the wrapping tools, hierarchy files and generated headers"
targets=()
while IFS= read -r t; do targets+=("$t"); done < <(
  "$ninja_exe" -C "$work/build" -t targets all | sed -n \
    -e 's/^\(bin\/vtk\(Wrap\|Parse\)[A-Za-z]*\): .*/\1/p' \
    -e 's/^\(vtk-[0-9.]*\.data\/headers\/hierarchy\/[^:]*\): .*/\1/p' \
    -e 's/^\([^/][^:]*\.h\(xx\)\{0,1\}\): CUSTOM_COMMAND$/\1/p')
"$ninja_exe" -C "$work/build" "${targets[@]}" > "$work/build.log" 2>&1 \
  || die "building VTK's tools failed; see $work/build.log"
# Only the tools' own objects (Wrapping/Tools) are compiled.
if grep "Building C" "$work/build.log" | grep -qv " Wrapping/Tools/"; then
  die "VTK objects were compiled: this CMake makes the generated headers depend on them"
fi

say "installing the development files"
"$cmake_exe" --install "$work/build" --component development > "$work/install.log" 2>&1 \
  || die "installing VTK's development files failed; see $work/install.log"
mkdir -p "$partial/bin"
cp "$work/build"/bin/vtk* "$partial/bin/"
# The tools load libvtkWrappingTools.so from beside them ($ORIGIN).
cp "$work/build"/build/lib.*/vtkmodules/libvtkWrappingTools.so "$partial/bin/"

# Point the package's libraries at the wheel's files of the same name
# (VTK_WHEEL_BUILD gives them the wheel's names and SONAMEs).
cmake_dir="$partial/vtk-$vtk_version.data/headers/cmake"
[ -f "$cmake_dir/vtk-config.cmake" ] || die "no vtk-config.cmake was installed"
# Libraries were installed to build/lib.<platform>/vtkmodules, the Python
# modules to ./vtkmodules: both are the wheel's vtkmodules folder.
for f in "$cmake_dir"/VTK-targets-release.cmake "$cmake_dir"/VTKPython-targets-release.cmake; do
  sed -i -E \
    -e 's#\$\{_IMPORT_PREFIX\}/build/lib\.[^/]*/vtkmodules/#${VTK_WHEEL_LIBRARY_DIR}/#g' \
    -e 's#\$\{_IMPORT_PREFIX\}/\./vtkmodules/#${VTK_WHEEL_LIBRARY_DIR}/#g' "$f"
done
# vtkProbeOpenGLVersion links RenderingOpenGL2 and is not built here; nothing
# downstream runs it, so its file is not checked.
sed -i '/_cmake_import_check_files_for_VTK::vtkProbeOpenGLVersion/d' "$cmake_dir/VTK-targets-release.cmake"
if grep -qE '_IMPORT_PREFIX\}/(build|\./vtkmodules)/' "$cmake_dir"/*.cmake; then
  die "some imported files still point into VTK's build tree"
fi
cp "$here/scripts/vtk-wheel-libraries.cmake" "$cmake_dir/"
sed -i '1i include("${CMAKE_CURRENT_LIST_DIR}/vtk-wheel-libraries.cmake")  # MM-RTM: the wheel'"'"'s libraries' \
  "$cmake_dir/vtk-config.cmake"

echo "$stamp" > "$partial/.mmrtm-sdk-stamp"
rm -rf "$output"
mv "$partial" "$output"
trap - EXIT
rm -rf "$work"
say "made $output ($(du -sh "$output" | cut -f1), $((SECONDS - start)) s)"
echo "$vtk_dir"
