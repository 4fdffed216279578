"""The DICOM series of a folder, told apart by SeriesInstanceUID, so that
the page can offer a choice where Slicer's volumes reader would take the
files of a folder as one series."""
import os


class Series:
    def __init__(self, uid, description, files):
        self.uid = uid
        self.description = description
        self.files = files

    def label(self):
        return "%s (%d files)" % (self.description or self.uid or "a series without a UID", len(self.files))


def folder_series(folder):
    """The series in `folder` (its files, not its sub-folders), largest
    first; files that are not DICOM are left out. Raises ValueError when
    none is DICOM."""
    import pydicom

    series = {}
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if not os.path.isfile(path):
            continue
        try:
            header = pydicom.dcmread(path, stop_before_pixels=True,
                                     specific_tags=["SeriesInstanceUID", "SeriesDescription"])
        except Exception:  # pydicom raises several kinds on files that are not DICOM
            continue
        # Anonymised files may have lost their series UID: one series then.
        uid = str(header.get("SeriesInstanceUID", "") or "")
        entry = series.setdefault(uid, Series(uid, str(header.get("SeriesDescription", "") or ""), []))
        entry.files.append(path)
    if not series:
        raise ValueError("the folder holds no DICOM series")
    return sorted(series.values(), key=lambda s: (-len(s.files), s.uid))
