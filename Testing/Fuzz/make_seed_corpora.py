#!/usr/bin/env python3
"""Seed corpora for the fuzz targets, made at run time from ../shared/data.

The real files are too large to be good seeds (libFuzzer mutates a few bytes
of each input per run), and the project may not copy them. So each seed is
a real file's header (its fields, orientation, types and encodings as the
file has them) over a few voxels of its data: a 4 x 4 x 4 volume, well
formed, in the same format. Written per target under OUT/<target>/.

Usage: /usr/bin/python3 make_seed_corpora.py DATA_DIR PROJECT_DIR OUT_DIR
(VTK's Python, python3-vtk9, writes the VTK XML and legacy seeds.)
"""
import gzip
import io
import os
import re
import struct
import sys
import tarfile
import zlib
from pathlib import Path

NRRD_TYPE_SIZES = {"uchar": 1, "unsigned char": 1, "uint8": 1, "char": 1, "signed char": 1, "int8": 1,
                   "short": 2, "int16": 2, "signed short": 2, "ushort": 2, "unsigned short": 2, "uint16": 2,
                   "int": 4, "int32": 4, "uint": 4, "unsigned int": 4, "uint32": 4, "float": 4, "double": 8}


def as_bytes(text):
    """VTK's writers give str or bytes, by version."""
    return text.encode("latin-1") if isinstance(text, str) else bytes(text)


class Seeds:
    def __init__(self, out):
        self.out = Path(out)
        self.counts = {}

    def add(self, target, name, data):
        folder = self.out / target
        folder.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(data)
        self.counts[target] = self.counts.get(target, 0) + 1


def nrrd_seeds(seeds, data_dir):
    for path in sorted(data_dir.glob("*.nrrd")):
        raw = path.read_bytes()
        end = raw.find(b"\n\n")
        if end < 0:
            continue
        header, body = raw[:end].decode("latin-1").split("\n"), raw[end + 2:]
        fields = {}
        for line in header[1:]:
            if ":" in line and not line.startswith("#"):
                key, value = line.split(":", 1)
                fields[key.strip().lower()] = value.strip()
        size = NRRD_TYPE_SIZES.get(fields.get("type", ""), 0)
        if not size:
            continue
        if fields.get("encoding", "raw") in ("gzip", "gz"):
            body = gzip.decompress(body)
        small = body[: 64 * size]  # 4 x 4 x 4 voxels of the real data

        def with_fields(**replace):
            lines = [header[0]]
            for line in header[1:]:
                key = line.split(":", 1)[0].strip().lower() if ":" in line else ""
                if key.replace(" ", "_") in replace:
                    continue
                lines.append(line)
            for key, value in replace.items():
                if value is not None:
                    lines.append(f"{key.replace('_', ' ')}: {value}")
            return ("\n".join(lines) + "\n\n").encode("latin-1")

        stem = path.stem
        seeds.add("nrrd", f"{stem}-raw.nrrd", with_fields(sizes="4 4 4", encoding="raw") + small)
        seeds.add("nrrd", f"{stem}-gzip.nrrd", with_fields(sizes="4 4 4", encoding="gzip") + gzip.compress(small))
        # Detached: the header names the scratch folder's data.raw (4096 bytes).
        seeds.add("nrrd", f"{stem}.nhdr", with_fields(sizes=f"{16 // size} 16 16", encoding="raw",
                                                       data_file="data.raw")[:-1])


def nifti_seeds(seeds, data_dir):
    for path in sorted(data_dir.glob("*.nii.gz")):
        with gzip.open(path, "rb") as f:
            head = f.read(352 + 4096)
        if len(head) < 352 or struct.unpack("<i", head[:4])[0] != 348:
            continue  # NIfTI-1, little-endian only
        hdr = bytearray(head[:352])
        bitpix = struct.unpack_from("<h", hdr, 72)[0]
        vox_offset = int(struct.unpack_from("<f", hdr, 108)[0])
        ndim = struct.unpack_from("<h", hdr, 40)[0]
        struct.pack_into("<8h", hdr, 40, ndim, 4, 4, 4 if ndim >= 3 else 1, 1, 1, 1, 1)
        struct.pack_into("<f", hdr, 108, 352.0)
        nbytes = 64 * max(1, bitpix // 8)
        with gzip.open(path, "rb") as f:
            f.read(vox_offset)
            voxels = f.read(nbytes)
        nii = bytes(hdr) + voxels
        stem = path.name[: -len(".nii.gz")]
        seeds.add("nifti", f"{stem}.nii", nii)
        seeds.add("nifti", f"{stem}.nii.gz", gzip.compress(nii))


def metaimage_seeds(seeds, data_dir):
    for path in sorted(data_dir.glob("*.mhd")):
        text = path.read_text("latin-1")
        fields = dict(re.findall(r"^\s*(\w+)\s*=\s*(.*?)\s*$", text, re.M))
        data_file = path.parent / fields.get("ElementDataFile", "")
        if not data_file.is_file():
            continue
        data = data_file.read_bytes()
        if fields.get("CompressedData", "False").lower() == "true":
            data = zlib.decompress(data)
        size = {"MET_UCHAR": 1, "MET_CHAR": 1, "MET_SHORT": 2, "MET_USHORT": 2, "MET_FLOAT": 4}.get(
            fields.get("ElementType", ""), 1)

        def header(**replace):
            lines = []
            for line in text.splitlines():
                key = line.split("=", 1)[0].strip()
                if key in replace or key in ("CompressedDataSize", "ElementDataFile"):
                    continue
                lines.append(line)
            for key, value in replace.items():
                lines.append(f"{key} = {value}")
            return ("\n".join(lines) + "\n").encode("latin-1")

        small = data[: 64 * size]
        stem = path.stem
        seeds.add("metaimage", f"{stem}-local.mha",
                  header(DimSize="4 4 4", CompressedData="False", ElementDataFile="LOCAL") + small)
        packed = zlib.compress(small)
        seeds.add("metaimage", f"{stem}-zlib.mha",
                  header(DimSize="4 4 4", CompressedData="True", CompressedDataSize=len(packed),
                         ElementDataFile="LOCAL") + packed)
        # Detached: the scratch folder's data.raw and data.zraw (4096 bytes of uchar).
        seeds.add("metaimage", f"{stem}-raw.mhd",
                  header(DimSize="16 16 16", ElementType="MET_UCHAR", CompressedData="False",
                         ElementDataFile="data.raw"))
        zraw = zlib.compress(bytes((i * 7) & 255 for i in range(4096)))
        seeds.add("metaimage", f"{stem}-zraw.mhd",
                  header(DimSize="16 16 16", ElementType="MET_UCHAR", CompressedData="True",
                         CompressedDataSize=len(zraw), ElementDataFile="data.zraw"))


def vtk_image_seeds(seeds, data_dir):
    try:
        from vtkmodules.vtkImagingCore import vtkExtractVOI
        from vtkmodules.vtkIOLegacy import vtkStructuredPointsReader, vtkStructuredPointsWriter
        from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLImageDataWriter
    except ImportError as e:
        print(f"vtk-image: no seeds from the data ({e}); the kept seeds only")
        return
    sources = [(p, vtkXMLImageDataReader) for p in sorted(data_dir.glob("*.vti"))]
    sources += [(p, vtkStructuredPointsReader) for p in sorted(data_dir.glob("*.vtk"))]
    for path, reader_class in sources:
        reader = reader_class()
        reader.SetFileName(str(path))
        reader.Update()
        crop = vtkExtractVOI()
        crop.SetInputConnection(reader.GetOutputPort())
        crop.SetVOI(0, 3, 0, 3, 0, 3)
        crop.Update()
        stem = path.stem
        for mode in ("ascii", "binary", "appended", "compressed"):
            writer = vtkXMLImageDataWriter()
            writer.SetInputData(crop.GetOutput())
            writer.WriteToOutputStringOn()
            if mode == "ascii":
                writer.SetDataModeToAscii()
            elif mode == "binary":
                writer.SetDataModeToBinary()
            else:
                writer.SetDataModeToAppended()
                writer.SetEncodeAppendedData(False)
            if mode != "compressed":
                writer.SetCompressorTypeToNone()
            writer.Write()
            seeds.add("vtk-image", f"{stem}-{mode}.vti", as_bytes(writer.GetOutputString()))
        for binary in (False, True):
            writer = vtkStructuredPointsWriter()
            writer.SetInputData(crop.GetOutput())
            writer.WriteToOutputStringOn()
            writer.SetFileType(2 if binary else 1)
            writer.Write()
            seeds.add("vtk-image", f"{stem}-{'binary' if binary else 'ascii'}.vtk", as_bytes(writer.GetOutputStdString()))


def invesalius_seeds(seeds):
    path = Path("/usr/share/doc/invesalius-examples/examples/Cranium.inv3")
    if not path.is_file():
        print("invesalius: Cranium.inv3 not installed; the kept seeds only")
        return
    with tarfile.open(path) as tar:
        members = {Path(m.name).name: m for m in tar.getmembers()}
        plist = tar.extractfile(members["main.plist"]).read().decode()
        dat = tar.extractfile(members["matrix.dat"]).read(128)  # 4 x 4 x 4 int16
    shape = re.compile(r"(<key>shape</key>\s*<array>\s*)(<integer>\d+</integer>\s*){3}")
    plist = shape.sub(lambda m: m.group(1) + "<integer>4</integer><integer>4</integer><integer>4</integer>\n", plist)
    out = io.BytesIO()
    with tarfile.open(fileobj=out, mode="w:gz") as tar:
        for name, data in (("main.plist", plist.encode()), ("matrix.dat", dat)):
            info = tarfile.TarInfo("tmpseed/" + name)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    seeds.add("invesalius", "cranium-4x4x4.inv3", out.getvalue())


def dicom_seeds(seeds, data_dir):
    """One slice of each series, as it is: DICOM's pixel data cannot be cut
    without rewriting its encapsulation, and GDCM reads the header first."""
    for folder in sorted(p for p in data_dir.iterdir() if p.is_dir()):
        files = sorted(f for f in folder.iterdir() if f.is_file())
        if files:
            seeds.add("dicom", folder.name + ".dcm", files[0].read_bytes())


def text_seeds(seeds, data_dir, project_dir):
    for path in sorted(data_dir.glob("*_labels.txt")):
        seeds.add("label-table", path.name, path.read_bytes())
    for folder in ("Data/presets", "Data/benchmarks"):
        for path in sorted((project_dir / folder).glob("*.json")):
            seeds.add("scene-json", f"{Path(folder).name}-{path.name}", path.read_bytes())
    for path in sorted((project_dir / "Data/Baselines").rglob("*.png")):
        if path.stat().st_size < 64 * 1024:
            seeds.add("png", path.name, path.read_bytes())


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    data_dir, project_dir, out = Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3])
    if not data_dir.is_dir():
        sys.exit(f"{data_dir}: no such folder (the shared data)")
    seeds = Seeds(out)
    nrrd_seeds(seeds, data_dir)
    nifti_seeds(seeds, data_dir)
    metaimage_seeds(seeds, data_dir)
    vtk_image_seeds(seeds, data_dir)
    invesalius_seeds(seeds)
    dicom_seeds(seeds, data_dir)
    text_seeds(seeds, data_dir, project_dir)
    print("seeds from the data: " + ", ".join(f"{t} {n}" for t, n in sorted(seeds.counts.items())))


if __name__ == "__main__":
    main()
