"""Converts an InVesalius project (.inv3: gzip tar with main.plist + matrix.dat) into a VTK
XML image (.vti, raw appended int16), standard library only.

InVesalius stores slices top row first (image rows run downwards); VTK's y axis points up,
so rows are flipped to keep the patient upright (anterior up in an axial slice)."""
import array
import io
import plistlib
import sys
import tarfile


def main(src, dst):
    with tarfile.open(src, "r:gz") as tar:
        members = {m.name.split("/")[-1]: m for m in tar.getmembers()}
        meta = plistlib.load(tar.extractfile(members["main.plist"]))
        mat = meta["matrix"]
        if mat["dtype"] != "int16":
            sys.exit(f"{src}: matrix dtype {mat['dtype']} is not int16")
        nz, ny, nx = mat["shape"]
        raw = tar.extractfile(members[mat["filename"]]).read()
    expected = nx * ny * nz * 2
    if len(raw) != expected:
        sys.exit(f"{src}: matrix.dat has {len(raw)} bytes, expected {expected}")
    data = array.array("h")
    data.frombytes(raw)
    if sys.byteorder != "little":
        data.byteswap()
    flipped = array.array("h")
    for z in range(nz):
        for y in range(ny - 1, -1, -1):
            start = (z * ny + y) * nx
            flipped.extend(data[start:start + nx])
    sx, sy, sz = meta["spacing"]
    header = (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n'
        f'  <ImageData WholeExtent="0 {nx-1} 0 {ny-1} 0 {nz-1}" Origin="0 0 0" Spacing="{sx} {sy} {sz}">\n'
        f'    <Piece Extent="0 {nx-1} 0 {ny-1} 0 {nz-1}">\n'
        '      <PointData Scalars="HU">\n'
        '        <DataArray type="Int16" Name="HU" NumberOfComponents="1" format="appended" offset="0"/>\n'
        '      </PointData>\n'
        '    </Piece>\n'
        '  </ImageData>\n'
        '  <AppendedData encoding="raw">\n   _'
    )
    body = flipped.tobytes()
    with open(dst, "wb") as f:
        f.write(header.encode())
        f.write(len(body).to_bytes(8, "little"))
        f.write(body)
        f.write(b"\n  </AppendedData>\n</VTKFile>\n")
    print(f"{dst}: {nx}x{ny}x{nz} int16, spacing {sx} {sy} {sz}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
