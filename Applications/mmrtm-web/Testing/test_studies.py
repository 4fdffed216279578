"""mmrtm-web's readers without a browser: the default study (an InVesalius
project, read by our reader into a Slicer volume node), a DICOM folder's
series, a label table.

Run by ctest with the .venv-vtk96 interpreter and MMRTM_SHARED_DATA_DIR.
"""
import os
import shutil
import tempfile
import unittest

import numpy
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonMath import vtkMatrix4x4

from mmrtm_web.data_root import DataRoot
from mmrtm_web.dicom_series import folder_series
from mmrtm_web.studies import DEFAULT_STUDY, StudyLoader, label_table

DATA = os.environ["MMRTM_SHARED_DATA_DIR"]


def ijk_to_ras(node):
    matrix = vtkMatrix4x4()
    node.GetIJKToRASMatrix(matrix)
    return numpy.array([[matrix.GetElement(r, c) for c in range(4)] for r in range(4)])


class StudiesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import mmrtm_slicer  # noqa: F401
        from trame_slicer.core import SlicerApp

        cls.slicer = SlicerApp()

    def test_the_default_study_is_placed_as_our_reader_places_it(self):
        """The InVesalius head CT, read by our reader (LPS) into a volume
        node (RAS): each corner voxel lands where the reader's image puts
        it (vtkImageData's index-to-physical, x and y negated), and the
        voxels are those of ct_head_cranium.nrrd (the same voxels
        repacked) read by Slicer's reader. Catches a missing LPS-to-RAS
        flip, spacing, direction or origin left out, and voxels lost on the
        way to the node."""
        if not os.path.exists(DEFAULT_STUDY):
            self.skipTest("%s is missing: scripts/install-dependencies.sh installs invesalius-examples"
                          % DEFAULT_STUDY)
        from mmrtm import vtkMultiMaterialVolumeReader

        loader = StudyLoader(self.slicer, DataRoot(os.path.dirname(DEFAULT_STUDY)), 0)
        ours = loader.load(DEFAULT_STUDY)
        reader = vtkMultiMaterialVolumeReader()
        reader.SetFileName(DEFAULT_STUDY)
        reader.Update()
        image = reader.GetOutput()
        matrix = ijk_to_ras(ours)
        n = image.GetDimensions()
        for corner in ((0, 0, 0), (n[0] - 1, 0, 0), (0, n[1] - 1, 0), (0, 0, n[2] - 1), (n[0] - 1, n[1] - 1, n[2] - 1)):
            lps = [0.0, 0.0, 0.0]
            image.TransformIndexToPhysicalPoint(corner, lps)
            ras = matrix @ numpy.array(list(corner) + [1.0])
            numpy.testing.assert_allclose(ras[:3], [-lps[0], -lps[1], lps[2]], atol=1e-3, err_msg=str(corner))
        slicers = loader.load(os.path.join(DATA, "ct_head_cranium.nrrd"))
        self.assertEqual(ours.GetImageData().GetDimensions(), slicers.GetImageData().GetDimensions())
        numpy.testing.assert_array_equal(vtk_to_numpy(ours.GetImageData().GetPointData().GetScalars()),
                                         vtk_to_numpy(slicers.GetImageData().GetPointData().GetScalars()))

    def test_a_folder_of_two_series_is_told_apart(self):
        """The chest CT's and the abdomen CT's files in one folder make two
        series, largest first, each with its own files. Catches a folder
        taken as one series and files given to the wrong one."""
        with tempfile.TemporaryDirectory() as folder:
            for source in ("ct_chest_dicom", "ct_abdomen_dicom_j2k"):
                for name in os.listdir(os.path.join(DATA, source)):
                    shutil.copy(os.path.join(DATA, source, name), os.path.join(folder, source + "_" + name))
            with open(os.path.join(folder, "notes.txt"), "w") as f:
                f.write("not DICOM")
            series = folder_series(folder)
            self.assertEqual([len(s.files) for s in series], [92, 20])
            self.assertTrue(all(os.path.basename(f).startswith("ct_chest_dicom") for f in series[0].files))
            self.assertEqual(series[1].description, "CT Body 3.0")
        with tempfile.TemporaryDirectory() as folder:
            with self.assertRaisesRegex(ValueError, "no DICOM series"):
                folder_series(folder)

    def test_a_label_table_names_labels(self):
        """The table beside a label map: "id name" lines, comments left
        out."""
        names = label_table(os.path.join(DATA, "cta_chest_aorta_labels.nii.gz"))
        self.assertEqual(names[1], "aorta")
        self.assertEqual(len(names), 7)
        self.assertEqual(label_table(os.path.join(DATA, "ct_head_cranium.nrrd")), {})


if __name__ == "__main__":
    unittest.main()
