"""Reads .vtu / .pvd files with VTK's own XML reader and dumps what VTK sees, for test_vtu.cpp.

Usage: vtu_check.py FILE...   (FILE ends in .vtu, .pvtu or .pvd)

A .pvtu is read by VTK's parallel reader, which joins its pieces into one grid (cells piece
after piece; a point shared by pieces appears once per piece).

Output (stdout): whitespace-separated tokens, one record per line; strings (paths, array
names) are hex-encoded UTF-8 so they never contain whitespace; numbers use Python's repr
(shortest round-trip, 'nan' / 'inf' for non-finite values).

  PVD <path> <n>                   a collection with n DataSets, followed by n lines
  STEP <time> <file>               (file as listed; checked: times strictly increase)
                                   and then one GRID block per listed file
  GRID <path>                      start of an unstructured grid as read by VTK
  NPOINTS <n>
  NCELLS <m>
  POINTSTYPE <vtk type name>
  POINTS x0 y0 z0 x1 y1 z1 ...
  CELL <vtk type> <npts> <id>...   one line per cell
  POINTDATA <name> <type> <ncomp> <ntuples> values...
  CELLDATA <name> <type> <ncomp> <ntuples> values...
  PROBE <cell> x y z <v...>        VTK's interpolation inside the cell at the parametric point
                                   (0.2, 0.3, 0.1): the physical location, then the
                                   interpolated tuple of every POINTDATA array, in order
  END

Exit status 1 (with a message on stderr) if a file does not exist, VTK reports any error or
warning while reading, the grid is empty, or a .pvd is malformed.
"""
import os
import sys
import xml.etree.ElementTree as ET

import vtk

PCOORDS = (0.2, 0.3, 0.1)


def hexs(s):
    return s.encode("utf-8").hex()


def fail(msg):
    sys.stderr.write("vtu_check: " + msg + "\n")
    sys.exit(1)


def num(x):
    return repr(float(x))


def read_grid(path, out):
    if not os.path.isfile(path):
        fail("no such file: " + path)
    log_window = vtk.vtkStringOutputWindow()  # collects VTK's errors and warnings for this file
    vtk.vtkOutputWindow.SetInstance(log_window)
    parallel = path.endswith(".pvtu")
    reader = vtk.vtkXMLPUnstructuredGridReader() if parallel else vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    if not reader.CanReadFile(path):
        fail(reader.GetClassName() + " cannot read " + path)
    reader.Update()
    log = log_window.GetOutput()
    if log.strip():
        fail("VTK reported problems reading %s:\n%s" % (path, log))
    grid = reader.GetOutput()
    npts, ncells = grid.GetNumberOfPoints(), grid.GetNumberOfCells()
    if npts == 0 or ncells == 0:
        fail("empty grid in " + path)

    out.append("GRID " + hexs(path))
    out.append("NPOINTS %d" % npts)
    out.append("NCELLS %d" % ncells)
    pts = grid.GetPoints()
    out.append("POINTSTYPE " + pts.GetData().GetDataTypeAsString())
    out.append("POINTS " + " ".join(num(c) for i in range(npts) for c in pts.GetPoint(i)))
    ids = vtk.vtkIdList()
    for c in range(ncells):
        grid.GetCellPoints(c, ids)
        n = ids.GetNumberOfIds()
        out.append("CELL %d %d %s" % (grid.GetCellType(c), n, " ".join(str(ids.GetId(k)) for k in range(n))))

    def dump(tag, data):
        arrays = []
        for a in range(data.GetNumberOfArrays()):
            arr = data.GetArray(a)
            if arr is None:
                fail("non-numeric array in " + path)
            nc, nt = arr.GetNumberOfComponents(), arr.GetNumberOfTuples()
            vals = " ".join(num(arr.GetComponent(t, k)) for t in range(nt) for k in range(nc))
            out.append("%s %s %s %d %d %s" % (tag, hexs(arr.GetName() or ""), arr.GetDataTypeAsString(), nc, nt, vals))
            arrays.append(arr)
        return arrays

    point_arrays = dump("POINTDATA", grid.GetPointData())
    dump("CELLDATA", grid.GetCellData())

    for c in range(ncells):
        cell = grid.GetCell(c)
        n = cell.GetNumberOfPoints()
        pc = PCOORDS if cell.GetCellDimension() == 3 else (PCOORDS[0], PCOORDS[1], 0.0)
        weights = [0.0] * n
        x = [0.0, 0.0, 0.0]
        cell.EvaluateLocation(vtk.mutable(0), pc, x, weights)
        vals = []
        for arr in point_arrays:
            for k in range(arr.GetNumberOfComponents()):
                vals.append(sum(weights[i] * arr.GetComponent(cell.GetPointId(i), k) for i in range(n)))
        out.append("PROBE %d %s" % (c, " ".join(num(v) for v in list(x) + vals)))
    out.append("END")


def read_pvd(path, out):
    if not os.path.isfile(path):
        fail("no such file: " + path)
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as e:
        fail("%s is not well-formed XML: %s" % (path, e))
    if root.tag != "VTKFile" or root.get("type") != "Collection":
        fail(path + ": root is not <VTKFile type=\"Collection\">")
    coll = root.find("Collection")
    if coll is None:
        fail(path + ": no <Collection>")
    steps = []
    for ds in coll:
        if ds.tag != "DataSet" or ds.get("file") is None or ds.get("timestep") is None:
            fail(path + ": bad element <%s %s>" % (ds.tag, ds.attrib))
        steps.append((float(ds.get("timestep")), ds.get("file")))
    for (t0, _), (t1, _) in zip(steps, steps[1:]):
        if not t1 > t0:
            fail("%s: times do not increase (%r then %r)" % (path, t0, t1))
    out.append("PVD %s %d" % (hexs(path), len(steps)))
    for t, f in steps:
        out.append("STEP %s %s" % (num(t), hexs(f)))
    base = os.path.dirname(path)
    for _, f in steps:
        read_grid(os.path.join(base, f), out)


def main(argv):
    if not argv:
        fail("usage: vtu_check.py FILE.vtu|FILE.pvd ...")
    out = []
    for path in argv:
        if path.endswith(".pvd"):
            read_pvd(path, out)
        else:
            read_grid(path, out)
    sys.stdout.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
