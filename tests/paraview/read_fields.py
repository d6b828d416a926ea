"""Reads a porompm fields.xdmf with ParaView's own XDMF reader and prints what it sees as JSON.

Run with pvbatch (headless): pvbatch tests/paraview/read_fields.py DIR/fields.xdmf
Output (one JSON object on the last line of standard output): the ParaView version, the reader's
class, the output times, and for the last time per block (`particles`, `grid`) the number of
points and cells, every point array with its components and tuples, the bounds, and the particle
arrays `position`, `displacement` and `p` (if present) as lists.
"""
import json
import sys

from paraview import servermanager as sm
from paraview import simple as pvs

reader = pvs.XDMFReader(FileNames=[sys.argv[1]])
times = list(reader.TimestepValues)
reader.UpdatePipeline(times[-1])
data = sm.Fetch(reader)
out = {
    "paraview_version": sm.vtkSMProxyManager.GetParaViewSourceVersion(),
    "reader": reader.GetXMLName(),
    "times": times,
    "blocks": {},
}
it = data.NewIterator()
it.InitTraversal()
while not it.IsDoneWithTraversal():
    block = it.GetCurrentDataObject()
    name = it.GetCurrentMetaData().Get(data.NAME()).split("[")[0]
    pd = block.GetPointData()
    arrays = {}
    for i in range(pd.GetNumberOfArrays()):
        a = pd.GetArray(i)
        arrays[a.GetName()] = [a.GetNumberOfComponents(), a.GetNumberOfTuples()]
    entry = {
        "points": block.GetNumberOfPoints(),
        "cells": block.GetNumberOfCells(),
        "arrays": arrays,
        "bounds": list(block.GetBounds()),
    }
    if name == "particles":
        n = block.GetNumberOfPoints()
        entry["position"] = [list(block.GetPoint(k)) for k in range(n)]
        for field in ("displacement", "p"):
            a = pd.GetArray(field)
            if a is not None:
                entry[field] = [list(a.GetTuple(k)) for k in range(n)]
    out["blocks"][name] = entry
    it.GoToNextItem()
print(json.dumps(out))
