#!/usr/bin/python3
"""Writes the fuzz targets' seed corpus, fuzz/corpus/<target>/: small valid files of every
encoding each reader knows. VTK's own writers (VTK 9.2, /usr/bin/python3) make the .vti,
.vtu, MetaImage and NIfTI files; the NRRD files, NIfTI-2 variants VTK does not write and the
transfer functions are written here. Run it again after changing a format's reader:
    /usr/bin/python3 fuzz/make-corpus.py
"""
import base64
import gzip
import os
import shutil
import struct
import tempfile
import zlib

import vtk
from vtk.util import numpy_support
import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
# Separates a header from its detached data file in a MetaImage or NRRD input
# (DATA_FILE_MARK in fuzz/src/lib.rs).
DATA_FILE_MARK = b"\n#ferrovol-fuzz data file\n"


def put(target, name, data):
    os.makedirs(os.path.join(ROOT, target), exist_ok=True)
    with open(os.path.join(ROOT, target, name), "wb") as f:
        f.write(data)


def with_ramp(data, n, components, vtk_type, cells):
    """`data` with scalars "scalars" on its `n` cells or points: value i is 7 i mod 120."""
    dtype = numpy_support.get_vtk_to_numpy_typemap()[vtk_type]
    values = (np.arange(n * components) * 7 % 120).astype(dtype).reshape(n, components)
    array = numpy_support.numpy_to_vtk(values, deep=True, array_type=vtk_type)
    array.SetName("scalars")
    if cells:
        data.GetCellData().SetScalars(array)
    else:
        data.GetPointData().SetScalars(array)
    return data


def image(dims=(3, 2, 2), vtk_type=vtk.VTK_UNSIGNED_SHORT, components=1, cells=False,
          extent_min=(0, 0, 0)):
    """A small vtkImageData with a ramp of values."""
    img = vtk.vtkImageData()
    lo = extent_min
    span = [d if cells else d - 1 for d in dims]
    img.SetExtent(lo[0], lo[0] + span[0], lo[1], lo[1] + span[1], lo[2], lo[2] + span[2])
    img.SetSpacing(0.5, 1.0, 2.0)
    img.SetOrigin(1.0, -2.0, 3.0)
    n = dims[0] * dims[1] * dims[2]
    return with_ramp(img, n, components, vtk_type, cells)


def written(writer, ext):
    """What `writer` writes to a file ending in `ext` (and the file itself)."""
    d = tempfile.mkdtemp()
    try:
        path = os.path.join(d, "seed" + ext)
        writer.SetFileName(path)
        writer.Write()
        files = {}
        for name in sorted(os.listdir(d)):
            with open(os.path.join(d, name), "rb") as f:
                files[name] = f.read()
        return files
    finally:
        shutil.rmtree(d)


def configured(w, opts):
    """A VTK XML writer set to write as `opts` say: mode (ascii, binary, appended), raw
    (appended data not base64), zlib with its block size, uint64 headers."""
    if opts["mode"] == "ascii":
        w.SetDataModeToAscii()
    elif opts["mode"] == "binary":
        w.SetDataModeToBinary()
    else:
        w.SetDataModeToAppended()
        w.SetEncodeAppendedData(0 if opts.get("raw") else 1)
    if opts.get("zlib"):
        w.SetCompressorTypeToZLib()
        if "block" in opts:
            w.SetBlockSize(opts["block"])  # several blocks, the last one short
    else:
        w.SetCompressorTypeToNone()
    if opts.get("uint64"):
        w.SetHeaderTypeToUInt64()
    else:
        w.SetHeaderTypeToUInt32()
    return w


def vti():
    cases = [
        ("ascii-uint8.vti", image(vtk_type=vtk.VTK_UNSIGNED_CHAR), dict(mode="ascii")),
        ("binary-float32.vti", image(vtk_type=vtk.VTK_FLOAT), dict(mode="binary")),
        ("binary-zlib-int16-2c.vti", image(vtk_type=vtk.VTK_SHORT, components=2),
         dict(mode="binary", zlib=True, block=16)),
        ("appended-raw-uint16.vti", image(), dict(mode="appended", raw=True)),
        ("appended-raw-zlib-float64-bigheader.vti", image(vtk_type=vtk.VTK_DOUBLE),
         dict(mode="appended", raw=True, zlib=True, uint64=True, block=16)),
        ("appended-raw-zlib-uint8-oneblock.vti", image(vtk_type=vtk.VTK_UNSIGNED_CHAR),
         dict(mode="appended", raw=True, zlib=True)),
        ("appended-base64-int32-cells.vti", image(vtk_type=vtk.VTK_INT, cells=True,
                                                 extent_min=(2, -1, 0)),
         dict(mode="appended", raw=False)),
        ("binary-uint32-4c.vti", image(dims=(2, 2, 1), vtk_type=vtk.VTK_UNSIGNED_INT,
                                       components=4), dict(mode="binary", uint64=True)),
    ]
    for name, img, opts in cases:
        w = configured(vtk.vtkXMLImageDataWriter(), opts)
        w.SetInputData(img)
        put("vti", name, written(w, ".vti")["seed.vti"])
    # Big-endian binary data, written by hand (VTK writes the machine's byte order).
    values = struct.pack(">6h", *[-300, -2, 0, 1, 250, 32000])
    block = struct.pack(">I", len(values)) + values
    put("vti", "binary-bigendian-int16-direction.vti", (
        '<?xml version="1.0"?>\n<VTKFile type="ImageData" version="1.0" '
        'byte_order="BigEndian" header_type="UInt32">\n'
        '<ImageData WholeExtent="0 2 0 1 0 0" Origin="0 0 0" Spacing="1 1 1" '
        'Direction="0 1 0 -1 0 0 0 0 1">\n<Piece Extent="0 2 0 1 0 0">\n'
        '<PointData Scalars="s"><DataArray type="Int16" Name="other" format="ascii">'
        '1 2 3 4 5 6</DataArray>\n'
        '<DataArray type="Int16" Name="s" format="binary">'
        + base64.b64encode(block).decode()
        + '<InformationKey name="L2_NORM_RANGE"><Value index="0">1 2</Value>'
        '</InformationKey></DataArray>\n'
        '</PointData>\n<CellData></CellData>\n</Piece>\n</ImageData>\n</VTKFile>\n'
    ).encode())


def mesh(cells=False, components=1, vtk_type=vtk.VTK_FLOAT, quadratic=False, each=False):
    """A small vtkUnstructuredGrid: a hexahedron with a pyramid on top, one cell of each
    linear 3D type the reader takes (`each`, each on its own 9 points, 2 apart along x),
    or a quadratic tetra, with a ramp of point or cell values."""
    cube = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1),
            (0, 1, 1), (0.5, 0.5, 2)]
    cells_of = [[(vtk.VTK_HEXAHEDRON, list(range(8))), (vtk.VTK_PYRAMID, [4, 5, 6, 7, 8])]]
    if each:
        cells_of = [[(vtk.VTK_TETRA, [0, 1, 3, 4])], [(vtk.VTK_VOXEL, [0, 1, 3, 2, 4, 5, 7, 6])],
                    [(vtk.VTK_HEXAHEDRON, list(range(8)))], [(vtk.VTK_WEDGE, [0, 1, 3, 4, 5, 7])],
                    [(vtk.VTK_PYRAMID, [4, 5, 6, 7, 8])]]
    if quadratic:
        cube += [(0.5, 0, 0), (0.5, 0.5, 0), (0, 0.5, 0), (0, 0, 0.5), (0.5, 0, 0.5),
                 (0, 0.5, 0.5)]
        cells_of = [[(vtk.VTK_QUADRATIC_TETRA, [0, 1, 3, 4] + list(range(9, 15)))]]
    grid = vtk.vtkUnstructuredGrid()
    points = vtk.vtkPoints()
    # Each group of cells on its own copy of the points, 2 apart along x.
    for k, group in enumerate(cells_of):
        base = points.GetNumberOfPoints()
        for x, y, z in cube:
            points.InsertNextPoint(x + 2 * k, y, z)
        for cell_type, ids in group:
            grid.InsertNextCell(cell_type, len(ids), [base + i for i in ids])
    grid.SetPoints(points)
    n = grid.GetNumberOfCells() if cells else grid.GetNumberOfPoints()
    return with_ramp(grid, n, components, vtk_type, cells)


def vtu():
    """vtkXMLUnstructuredGridWriter in every mode; io/src/vtu/tests.rs reads these."""
    cases = [
        ("ascii-float32-each-type.vtu", mesh(each=True), dict(mode="ascii")),
        ("binary-uint8-cells.vtu", mesh(cells=True, vtk_type=vtk.VTK_UNSIGNED_CHAR),
         dict(mode="binary")),
        ("binary-zlib-int16-2c.vtu", mesh(components=2, vtk_type=vtk.VTK_SHORT),
         dict(mode="binary", zlib=True, block=64)),
        ("appended-raw-float64.vtu", mesh(vtk_type=vtk.VTK_DOUBLE),
         dict(mode="appended", raw=True)),
        ("appended-raw-zlib-uint16-bigheader-pieces.vtu", mesh(vtk_type=vtk.VTK_UNSIGNED_SHORT),
         dict(mode="appended", raw=True, zlib=True, uint64=True, block=64, pieces=2)),
        ("appended-base64-int32-cells-4c.vtu",
         mesh(cells=True, components=4, vtk_type=vtk.VTK_INT), dict(mode="appended")),
        ("ascii-quadratic-tetra.vtu", mesh(quadratic=True), dict(mode="ascii")),
    ]
    for name, grid, opts in cases:
        w = configured(vtk.vtkXMLUnstructuredGridWriter(), opts)
        w.SetInputData(grid)
        # An input not split into pieces is written whole into each piece.
        w.SetNumberOfPieces(opts.get("pieces", 1))
        put("vtu", name, written(w, ".vtu")["seed.vtu"])


def metaimage():
    cases = [
        ("short.mha", image(vtk_type=vtk.VTK_SHORT), False, ".mha"),
        ("zlib-uchar-rgb.mha", image(vtk_type=vtk.VTK_UNSIGNED_CHAR, components=3), True,
         ".mha"),
        ("float.mhd", image(vtk_type=vtk.VTK_FLOAT), False, ".mhd"),
        ("zlib-double.mhd", image(vtk_type=vtk.VTK_DOUBLE), True, ".mhd"),
    ]
    for name, img, compressed, ext in cases:
        w = vtk.vtkMetaImageWriter()
        w.SetInputData(img)
        w.SetCompression(compressed)
        files = written(w, ext)
        header = files.pop("seed" + ext)
        data = b""
        if files:  # .mhd: the detached data file follows the mark
            (data_name, data), = files.items()
            data = DATA_FILE_MARK + data
        put("metaimage", name, header + data)
    # What VTK does not write: ASCII data, a 2D image, a transform, HeaderSize, byte order.
    put("metaimage", "ascii-2d-transform.mha", (
        b"ObjectType = Image\nNDims = 2\nDimSize = 3 2\nBinaryData = False\n"
        b"TransformMatrix = 0 1 -1 0\nOffset = 1 2\nElementSpacing = 0.5 2\n"
        b"ElementType = MET_INT\nElementDataFile = LOCAL\n-3 -2 -1 0 1 2\n"))
    raw = b"\x09\x09\x09" + struct.pack(">6H", 1, 2, 3, 400, 500, 600)
    put("metaimage", "msb-headersize.mhd", (
        b"ObjectType = Image\r\nNDims = 3\r\nDimSize = 3 2 1\r\nElementSize = 1 1 4\r\n"
        b"Position = -1 -2 -3\r\nElementByteOrderMSB = True\r\nHeaderSize = 3\r\n"
        b"ElementNumberOfChannels = 1\r\nElementType = MET_USHORT_ARRAY\r\n"
        b"ElementDataFile = vol.raw\r\n") + DATA_FILE_MARK + raw)
    put("metaimage", "headersize-minus-one.mhd", (
        b"NDims = 3\nDimSize = 2 2 1\nHeaderSize = -1\nElementType = MET_CHAR\n"
        b"ElementDataFile = vol.raw\n") + DATA_FILE_MARK + b"junk" + bytes([1, 0xff, 3, 4]))


def nifti_header(version, dims, datatype, bitpix, vox_offset, be=False, slope=0.0,
                 inter=0.0, qform=0, sform=0, pixdim=(1, 0.5, 1, 2, 0, 0, 0, 0)):
    """A NIfTI-1 (348 bytes + 4-byte extension flag) or NIfTI-2 (540 + 4) header."""
    e = ">" if be else "<"
    dim = [len(dims)] + list(dims) + [1] * (7 - len(dims))
    if version == 1:
        h = bytearray(352)
        struct.pack_into(e + "i", h, 0, 348)
        struct.pack_into(e + "8h", h, 40, *dim)
        struct.pack_into(e + "hh", h, 70, datatype, bitpix)
        struct.pack_into(e + "8f", h, 76, *pixdim)
        struct.pack_into(e + "fff", h, 108, vox_offset, slope, inter)
        struct.pack_into(e + "hh", h, 252, qform, sform)
        struct.pack_into(e + "6f", h, 256, 0.0, 0.0, 0.7071068, 10, 20, 30)
        struct.pack_into(e + "12f", h, 280, 0, -0.5, 0, 1, 1, 0, 0, 2, 0, 0, 2, 3)
        h[344:348] = b"n+1\0"
    else:
        h = bytearray(544)
        struct.pack_into(e + "i", h, 0, 540)
        h[4:12] = b"n+2\0\r\n\x1a\n"
        struct.pack_into(e + "hh", h, 12, datatype, bitpix)
        struct.pack_into(e + "8q", h, 16, *dim)
        struct.pack_into(e + "8d", h, 104, *pixdim)
        struct.pack_into(e + "qdd", h, 168, vox_offset, slope, inter)
        struct.pack_into(e + "ii", h, 344, qform, sform)
        struct.pack_into(e + "6d", h, 352, 0.0, 0.0, 0.7071068, 10, 20, 30)
        struct.pack_into(e + "12d", h, 400, 0, -0.5, 0, 1, 1, 0, 0, 2, 0, 0, 2, 3)
    return bytes(h)


def nifti():
    for name, img, version in [
        ("vtk-int16.nii", image(vtk_type=vtk.VTK_SHORT), 1),
        ("vtk-float32.nii.gz", image(vtk_type=vtk.VTK_FLOAT), 1),
        ("vtk-nifti2-uint16.nii", image(), 2),
        ("vtk-rgb.nii", image(vtk_type=vtk.VTK_UNSIGNED_CHAR, components=3), 1),
    ]:
        w = vtk.vtkNIFTIImageWriter()
        w.SetInputData(img)
        w.SetNIFTIVersion(version)
        ext = ".nii.gz" if name.endswith(".gz") else ".nii"
        put("nifti", name, written(w, ext)["seed" + ext])
    u8 = bytes(range(0, 240, 20))
    put("nifti", "uint8-qform.nii", nifti_header(1, (3, 2, 2), 2, 8, 352, qform=1) + u8)
    be16 = struct.pack(">12h", *range(-6, 6))
    put("nifti", "bigendian-int16-sform.nii.gz",
        gzip.compress(nifti_header(1, (3, 2, 2), 4, 16, 352, be=True, sform=1) + be16,
                      mtime=0))
    put("nifti", "scaled-uint16.nii",
        nifti_header(1, (3, 2, 2), 512, 16, 352, slope=0.5, inter=-3)
        + struct.pack("<12H", *range(12)))
    put("nifti", "vector-float32-dim5.nii",
        nifti_header(1, (2, 2, 1, 1, 2), 16, 32, 352) + struct.pack("<8f", *range(8)))
    put("nifti", "nifti2-bigendian-float64-qform.nii.gz",
        gzip.compress(nifti_header(2, (2, 2, 2), 64, 64, 544, be=True, qform=2,
                                   pixdim=(-1, 1, 1, 1, 0, 0, 0, 0))
                      + struct.pack(">8d", *[x / 4 for x in range(8)]), mtime=0))
    put("nifti", "nifti2-rgba.nii",
        nifti_header(2, (2, 1, 1), 2304, 32, 544) + bytes(range(8)))


def nrrd():
    shorts = struct.pack("<12h", *range(-600, 600, 100))
    put("nrrd", "raw-short-directions.nrrd", (
        b"NRRD0004\n# a comment\ntype: short\ndimension: 3\nspace: left-posterior-superior\n"
        b"sizes: 3 2 2\nspace directions: (0,0.5,0) (-1,0,0) (0,0,2)\nkinds: domain domain domain\n"
        b"endian: little\nencoding: raw\nspace origin: (1,2,3)\nkey:=value\n\n") + shorts)
    floats = struct.pack(">12f", *[i * 0.5 for i in range(12)])
    put("nrrd", "gzip-bigendian-float-spacings.nrrd", (
        b"NRRD0005\ntype: float\ndimension: 3\nsizes: 3 2 2\nspacings: 0.5 nan 2\n"
        b"endian: big\nencoding: gzip\n\n") + gzip.compress(floats, mtime=0))
    put("nrrd", "ascii-uchar-2d.nrrd", (
        b"NRRD0001\ntype: unsigned char\ndimension: 2\nsizes: 3 2\nencoding: ascii\n\n"
        b"0 50 100\n150 200 250\n"))
    put("nrrd", "hex-uint16.nrrd", (
        b"NRRD0004\ntype: uint16\ndimension: 1\nsizes: 4\nendian: little\nencoding: hex\n\n"
        b"0100 0200\n ff00 10ff\n"))
    put("nrrd", "rgb-color-kinds.nrrd", (
        b"NRRD0004\ntype: uint8\ndimension: 4\nsizes: 3 2 2 1\n"
        b"kinds: RGB-color space space space\nspace dimension: 3\n"
        b"space directions: none (1,0,0) (0,1,0) (0,0,1)\nencoding: raw\n\n")
        + bytes(range(0, 240, 20)))
    put("nrrd", "detached-skips.nhdr", (
        b"NRRD0004\ntype: int\ndimension: 3\nsizes: 2 2 1\nendian: big\nencoding: raw\n"
        b"line skip: 1\nbyte skip: 2\ndata file: vol.raw\n")
        + DATA_FILE_MARK + b"a text line\nxx" + struct.pack(">4i", -1, 2, -3, 4))
    put("nrrd", "detached-gzip-byteskip.nhdr", (
        b"NRRD0004\ntype: double\ndimension: 2\nsizes: 2 2\nendian: little\n"
        b"encoding: gz\nbyte skip: 4\ndatafile: vol.raw.gz\n")
        + DATA_FILE_MARK
        + gzip.compress(b"skip" + struct.pack("<4d", 1.5, -2, 3, 4), mtime=0))
    put("nrrd", "byteskip-minus-one.nrrd", (
        b"NRRD0003\ntype: signed char\ndimension: 3\nsizes: 2 1 1\nbyte skip: -1\n"
        b"encoding: raw\n\n") + b"padding" + bytes([0x80, 0x7f]))


def transfer():
    put("transfer", "full.json", (
        b'{"color": [[0, 0, 0, 0], [500, 1, 0.5, 0.25], [1000, 1, 1, 1]],\n'
        b' "opacity": [[0, 0], [400, 0.05], [1000, 0.8]],\n'
        b' "gradient_opacity": [[0, 0], [10, 1]], "unit_distance": 2.5}\n'))
    put("transfer", "minimal.json", b'{"color": [[-1e3, 1, 1, 1]], "opacity": [[0, 1]]}')


if __name__ == "__main__":
    shutil.rmtree(ROOT, ignore_errors=True)
    vti()
    vtu()
    metaimage()
    nifti()
    nrrd()
    transfer()
    for target in sorted(os.listdir(ROOT)):
        files = os.listdir(os.path.join(ROOT, target))
        size = sum(os.path.getsize(os.path.join(ROOT, target, f)) for f in files)
        print(f"{target}: {len(files)} files, {size} bytes")
