#!/usr/bin/env python3
"""Reads a floesim ParaView series (DIR/results.pvd) with VTK's own XML PolyData reader (Debian's python3-vtk9) and
prints, per frame, its time, field data and each cell's body id, kind and centre, and the cell's first point, as
JSON: what sim_results_python_test compares with FrameReplay."""
import json
import os
import sys
import xml.etree.ElementTree as ET

from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
from vtkmodules.util.numpy_support import vtk_to_numpy

pvd = sys.argv[1]
frames = []
for ds in ET.parse(pvd).getroot().iter("DataSet"):
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(os.path.join(os.path.dirname(pvd), ds.get("file")))
    reader.Update()
    poly = reader.GetOutput()
    cd, fd = poly.GetCellData(), poly.GetFieldData()
    points = vtk_to_numpy(poly.GetPoints().GetData())
    first = []
    for c in range(poly.GetNumberOfCells()):
        first.append([float(x) for x in points[poly.GetCell(c).GetPointId(0)]])
    frames.append({
        "timestep": float(ds.get("timestep")),
        "time_value": float(vtk_to_numpy(fd.GetArray("TimeValue"))[0]),
        "surge_ice_load_n": float(vtk_to_numpy(fd.GetArray("surge_ice_load_n"))[0]),
        "body_id": vtk_to_numpy(cd.GetArray("body_id")).tolist(),
        "kind": vtk_to_numpy(cd.GetArray("kind")).tolist(),
        "in_contact": vtk_to_numpy(cd.GetArray("in_contact")).tolist(),
        "centre_m": vtk_to_numpy(cd.GetArray("centre_m")).tolist(),
        "first_point": first,
    })
json.dump(frames, sys.stdout)
