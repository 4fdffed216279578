#!/usr/bin/env bash
# The test "vtk96-wheel": builds the mmrtm wheel for the PyPI VTK 9.6 as a
# user's `pip wheel .` does (in VENV, whose pinned scikit-build-core, CMake
# and Ninja it uses instead of an isolated build environment, with the build
# folder kept so that a rebuild is incremental), checks what is in it, and
# installs it into VENV for the tests that follow. The build folder also gets
# the regression image program (not part of the wheel), linked against the
# wheel's VTK, for the image tests of that flavour.
#
# Usage: build_vtk96_wheel.sh VENV SOURCE_DIR OUT_DIR
set -euo pipefail
venv="$1" source="$2" out="$3"
rm -rf "$out/dist"
mkdir -p "$out"
start=$SECONDS
"$venv/bin/python" -m pip wheel "$source" --no-build-isolation --no-deps --disable-pip-version-check \
  -w "$out/dist" --config-settings=build-dir="$out/build" \
  --config-settings=cmake.define.MMRTM_VTK_WHEEL_IMAGE_TEST=ON
echo "built in $((SECONDS - start)) s"
wheel=("$out"/dist/mmrtm-*.whl)
[ -f "${wheel[0]}" ] || { echo "no wheel in $out/dist" >&2; exit 1; }
# What a user gets: the two modules, their libraries and the presets; no
# headers, no library twice under a versioned name.
"$venv/bin/python" - "${wheel[0]}" <<'EOF'
import re, sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
print("\n".join(sorted(names)))
for pattern in (r"mmrtm/__init__\.py", r"mmrtm/mmrtmRendering\.cpython-.*\.so", r"mmrtm/mmrtmIO\.cpython-.*\.so",
                r"mmrtm/libmmrtmRendering\.so", r"mmrtm/libmmrtmIO\.so", r"mmrtm/presets/ct-bone\.json"):
    assert any(re.fullmatch(pattern, n) for n in names), "the wheel lacks " + pattern
assert not any(n.endswith((".h", ".cmake", ".a")) or re.search(r"\.so\.\d", n) for n in names), \
    "headers, static or versioned libraries"
# With slicer-core-sdk and slicer-layer-dm-sdk in the venv: the Slicer classes.
kits = ("MRML", "Logic", "MRMLDisplayableManager")
for pattern in (r"mmrtm_slicer/__init__\.py", r"slicer/slicer_mmrtm\.py") + tuple(
        r"mmrtm_slicer/libvtkSlicerMultiMaterialVolumeRenderingModule%s\.so" % k for k in kits):
    assert any(re.fullmatch(pattern, n) for n in names), "the wheel lacks " + pattern
EOF
"$venv/bin/python" -m pip install --no-deps --force-reinstall --disable-pip-version-check "${wheel[0]}"
