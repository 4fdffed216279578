"""Reading what the page opens: a study of the data root (a volume file, a
DICOM folder or one of its series, an InVesalius project), an uploaded
file, a segmentation. Every failure is a ValueError that says what is
wrong without naming the server's folders (the caller names the path as
the page knows it)."""
import os
import re
import shutil
import tempfile

from .dicom_series import folder_series

# The default study of mmrtm-render: the head CT of Debian's
# invesalius-examples package (an InVesalius project, read by our reader).
DEFAULT_STUDY = "/usr/share/doc/invesalius-examples/examples/Cranium.inv3"
# Files an upload may be: one file that holds the whole volume (a detached
# header's data file cannot come with it).
UPLOAD_SUFFIXES = (".nrrd", ".nii", ".nii.gz", ".mha", ".inv3")


def folder_files(folder):
    files = sorted(os.path.join(folder, f) for f in os.listdir(folder) if os.path.isfile(os.path.join(folder, f)))
    if not files:
        raise ValueError("the folder holds no files")
    return files


class StudyLoader:
    def __init__(self, slicer, data_root, upload_limit_mb):
        self.slicer = slicer
        self.data_root = data_root
        self.upload_limit = int(upload_limit_mb * 1024 * 1024)

    def series_of(self, study):
        """The DICOM series of the data root's folder `study`."""
        path = self.data_root.resolve(study)
        if not os.path.isdir(path):
            raise ValueError("not a folder")
        return folder_series(path)

    def load(self, path, series=None):
        """A volume node of the study at `path` (resolved in the data root);
        of a DICOM folder, the series whose UID is `series` (None: the
        whole folder, as Slicer's reader takes it)."""
        if os.path.isdir(path):
            files = folder_files(path)
            if series is not None:
                chosen = [s for s in folder_series(path) if s.uid == series]
                if not chosen:
                    raise ValueError("the folder has no series %s" % series)
                files = chosen[0].files
        elif os.path.isfile(path):
            if path.lower().endswith(".inv3"):
                return self.load_with_our_reader(path)
            files = [path]
        else:
            raise ValueError("no such file or folder")
        try:
            nodes = self.slicer.io_manager.load_volumes(files)
        except Exception as e:  # Slicer's reader raises what it likes on damaged input
            raise ValueError("Slicer's volumes reader could not read it (%s)" % type(e).__name__) from e
        if not nodes or nodes[0] is None or nodes[0].GetImageData() is None:
            raise ValueError("Slicer's volumes reader could not read it (damaged, or not a volume)")
        return nodes[0]

    def load_with_our_reader(self, path):
        """What Slicer's reader does not read (InVesalius projects), read by
        vtkMultiMaterialVolumeReader into a volume node: its output is in
        LPS millimetres, Slicer's nodes in RAS."""
        from mmrtm import vtkMultiMaterialVolumeReader
        from vtkmodules.vtkCommonDataModel import vtkImageData
        from vtkmodules.vtkCommonMath import vtkMatrix4x4

        reader = vtkMultiMaterialVolumeReader()
        reader.SetFileName(path)
        reader.GlobalWarningDisplayOff()
        reader.Update()
        image = reader.GetOutput()
        if image is None or image.GetNumberOfPoints() == 0:
            raise ValueError("the reader could not read it (damaged, or not a volume)")
        ijk_to_ras = vtkMatrix4x4()
        direction, spacing, origin = image.GetDirectionMatrix(), image.GetSpacing(), image.GetOrigin()
        for row in range(3):
            flip = -1.0 if row < 2 else 1.0  # LPS to RAS
            for column in range(3):
                ijk_to_ras.SetElement(row, column, flip * direction.GetElement(row, column) * spacing[column])
            ijk_to_ras.SetElement(row, 3, flip * origin[row])
        voxels = vtkImageData()
        voxels.SetDimensions(image.GetDimensions())
        voxels.GetPointData().SetScalars(image.GetPointData().GetScalars())
        node = self.slicer.scene.AddNewNodeByClass("vtkMRMLScalarVolumeNode",
                                                   os.path.splitext(os.path.basename(path))[0])
        node.SetAndObserveImageData(voxels)
        node.SetIJKToRASMatrix(ijk_to_ras)
        node.CreateDefaultDisplayNodes()
        return node

    def load_upload(self, upload):
        """A volume node of a file sent by the page (trame's file state:
        name, size, content). Returns (node, the file's name)."""
        from trame.app.file_upload import ClientFile

        if not isinstance(upload, dict):
            raise ValueError("the upload did not arrive as a file")
        file = ClientFile(upload)
        name = os.path.basename(str(file.name or ""))
        if self.upload_limit <= 0:
            raise ValueError("uploads are off on this server (--upload-limit-mb 0)")
        if not name.lower().endswith(UPLOAD_SUFFIXES):
            raise ValueError("'%s': an upload must be one file: %s" % (name, ", ".join(UPLOAD_SUFFIXES)))
        if file.is_empty or len(file.content) > self.upload_limit:
            raise ValueError("'%s': %s" % (name, "empty" if file.is_empty else "%.0f MiB, over the limit of %.0f MiB"
                                           % (len(file.content) / 2**20, self.upload_limit / 2**20)))
        folder = tempfile.mkdtemp(prefix="mmrtm-web-upload-")
        try:
            path = os.path.join(folder, re.sub(r"[^A-Za-z0-9._-]", "_", name))
            with open(path, "wb") as f:
                f.write(file.content)
            try:
                return self.load(path), name
            except ValueError as e:
                raise ValueError("'%s': %s" % (name, e)) from e
        finally:
            shutil.rmtree(folder, ignore_errors=True)

    def load_segmentation(self, path, volume):
        """A segmentation node of a label map or segmentation file, its
        segments named from a label table beside it (`NAME.txt`: "id name"
        lines) where there is one."""
        if volume is None:
            raise ValueError("open a study first")
        if not os.path.isfile(path):
            raise ValueError("not a file")
        try:
            segmentation = self.slicer.io_manager.load_segmentation(path)
        except Exception as e:
            raise ValueError("Slicer's segmentation reader could not read it (%s)" % type(e).__name__) from e
        if segmentation is None or segmentation.GetSegmentation().GetNumberOfSegments() == 0:
            if segmentation is not None:
                self.slicer.scene.RemoveNode(segmentation)
            raise ValueError("Slicer's segmentation reader found no segments in it")
        segmentation.CreateDefaultDisplayNodes()
        name_segments(segmentation, label_table(path))
        return segmentation


def label_table(path):
    """{label: name} of the table beside a label map, {} when none."""
    stem = path[:-len(".nii.gz")] if path.endswith(".nii.gz") else os.path.splitext(path)[0]
    names = {}
    try:
        with open(stem + ".txt") as f:
            for line in f:
                parts = line.split(None, 1)
                if len(parts) == 2 and parts[0].isdigit():
                    names[int(parts[0])] = parts[1].strip()
    except OSError:
        pass
    return names


def name_segments(segmentation, names):
    """Slicer names a label map's segments by their label value."""
    if not names:
        return
    segments = segmentation.GetSegmentation()
    for index in range(segments.GetNumberOfSegments()):
        segment = segments.GetNthSegment(index)
        try:
            label = int(segment.GetLabelValue()) if hasattr(segment, "GetLabelValue") else int(segment.GetName())
        except ValueError:
            continue
        if label in names:
            segment.SetName(names[label])
