"""The mmrtm wheel in a fresh venv that has nothing but vtk==9.6.0 (and what
pip brings with it) and the wheel: the package imports, reads volumes of
each format the wheel reads (NRRD, NIfTI, MetaImage, VTK XML and legacy),
finds its presets, and renders off screen.

Run by ctest under Testing/headless.sh (its own Xvfb) after the test vtk96-wheel has built the wheel.
Environment: MMRTM_WHEEL_DIR (the folder with mmrtm-*.whl),
MMRTM_SHARED_DATA_DIR. pip needs the package index or its cache for vtk.
"""
import glob
import os
import subprocess
import sys
import tempfile
import textwrap
import unittest

CHECK = textwrap.dedent("""
    import os, sys
    import mmrtm
    from vtkmodules.vtkCommonCore import vtkVersion
    from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow, vtkVolume, vtkVolumeProperty
    from vtkmodules.vtkRenderingCore import vtkColorTransferFunction
    from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
    import vtkmodules.vtkRenderingOpenGL2, vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401
    assert vtkVersion.GetVTKVersion() == "9.6.0", vtkVersion.GetVTKVersion()
    # The readers of the wheel: NRRD, NIfTI, MetaImage, VTK XML and legacy VTK.
    for name in ("mr_head.nii.gz", "frogtissue.mhd", "hydrogen.vti", "iron_protein.vtk"):
        other = mmrtm.vtkMultiMaterialVolumeReader()
        other.SetFileName(os.path.join(sys.argv[1], name))
        other.Update()
        assert other.GetOutput().GetNumberOfPoints() > 1000, name
    reader = mmrtm.vtkMultiMaterialVolumeReader()
    reader.SetFileName(os.path.join(sys.argv[1], "ct_head_headsq.nrrd"))
    reader.Update()
    assert reader.GetOutput().GetDimensions() == (64, 64, 93), reader.GetOutput().GetDimensions()
    materials = mmrtm.vtkMultiMaterialProperty()
    assert materials.SetPreset("ct-bone"), mmrtm.vtkMultiMaterialProperty.GetPresetDirectory()
    mapper = mmrtm.vtkMultiMaterialVolumeMapper()
    mapper.SetInputConnection(reader.GetOutputPort())
    mapper.SetSamplesPerRender(1)
    opacity = vtkPiecewiseFunction()
    opacity.AddPoint(1100, 0.0)
    opacity.AddPoint(2000, 0.8)
    color = vtkColorTransferFunction()
    color.AddRGBPoint(1100, 0.9, 0.6, 0.5)
    prop = vtkVolumeProperty()
    prop.SetScalarOpacity(opacity)
    prop.SetColor(color)
    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    renderer = vtkRenderer()
    renderer.AddVolume(volume)
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.AddRenderer(renderer)
    window.SetSize(64, 64)
    renderer.ResetCamera()
    window.Render()
    assert mapper.GetAccumulatedSamples() == 1, mapper.GetAccumulatedSamples()
    print("mmrtm", mmrtm.__file__, "on VTK", vtkVersion.GetVTKVersion(), "backend", mapper.GetBackendDescription())
""")


class FreshVenv(unittest.TestCase):
    def test_import_read_preset_render(self):
        wheels = glob.glob(os.path.join(os.environ["MMRTM_WHEEL_DIR"], "mmrtm-*.whl"))
        self.assertEqual(len(wheels), 1, wheels)
        with tempfile.TemporaryDirectory() as tmp:
            venv = os.path.join(tmp, "venv")
            subprocess.run(["/usr/bin/python3", "-m", "venv", venv], check=True)
            python = os.path.join(venv, "bin", "python")
            r = subprocess.run([python, "-m", "pip", "install", "--disable-pip-version-check", "--quiet",
                                "vtk==9.6.0", wheels[0]], capture_output=True, text=True, timeout=900)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            listed = subprocess.run([python, "-m", "pip", "list", "--format=freeze"], capture_output=True,
                                    text=True, check=True).stdout
            print(listed)
            self.assertNotIn("slicer", listed.lower(), "a fresh venv: vtk and the wheel only")
            env = dict(os.environ)
            env.pop("PYTHONPATH", None)
            r = subprocess.run([python, "-c", CHECK, os.environ["MMRTM_SHARED_DATA_DIR"]], cwd=tmp, env=env,
                               capture_output=True, text=True, timeout=600)
            print(r.stdout, r.stderr[-3000:], file=sys.stderr)
            self.assertEqual(r.returncode, 0)


if __name__ == "__main__":
    unittest.main()
