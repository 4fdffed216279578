"""The folder mmrtm-web may open studies from: every path the page sends
is resolved (symbolic links and `..` followed) and must stay inside it."""
import os

# Files Slicer's volumes reader opens; any folder may be a DICOM series.
VOLUME_SUFFIXES = (".nrrd", ".nhdr", ".nii", ".nii.gz", ".mha", ".mhd")


class DataRoot:
    def __init__(self, folder):
        self.folder = os.path.realpath(folder)
        if not os.path.isdir(self.folder):
            raise ValueError("%s: the data root is not a folder" % folder)

    def resolve(self, path):
        """The real path of `path` (relative to the root, or absolute).
        Raises ValueError, naming the path, when it leads outside the root
        or to nothing."""
        if not isinstance(path, str) or not path.strip():  # the page's state may hold anything
            raise ValueError("no study named")
        real = os.path.realpath(os.path.join(self.folder, path.strip()))
        if os.path.commonpath([real, self.folder]) != self.folder:
            raise ValueError("'%s' is outside the data root: refused" % path)
        if not os.path.exists(real):
            raise ValueError("'%s': no such file or folder in the data root" % path)
        return real

    def studies(self):
        """The studies to offer, relative to the root: volume files and
        folders (DICOM series) in the root and one level below it, that do
        not lead outside it."""
        found = []
        for top in sorted(os.listdir(self.folder)):
            candidates = [top]
            if os.path.isdir(os.path.join(self.folder, top)):
                candidates += [os.path.join(top, f) for f in sorted(os.listdir(os.path.join(self.folder, top)))
                               if os.path.isdir(os.path.join(self.folder, top, f))
                               or f.lower().endswith(VOLUME_SUFFIXES)]
            for relative in candidates:
                full = os.path.join(self.folder, relative)
                if not (os.path.isdir(full) or relative.lower().endswith(VOLUME_SUFFIXES)):
                    continue
                try:
                    self.resolve(relative)
                except ValueError:
                    continue
                found.append(relative)
        return found
