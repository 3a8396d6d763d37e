"""Reads a run's ParaView output with meshio (an independent VTK reader) and checks it.

Usage: python3 tests/check_frames.py OUTPUT_DIR
"""
import csv
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np

out = Path(sys.argv[1])
series = ET.parse(out / "frames.pvd").getroot().find("Collection")
entries = series.findall("DataSet")
assert len(entries) >= 2, "a time series needs several frames"
times = [float(e.get("timestep")) for e in entries]
assert times == sorted(times), "frame times must increase"
for e in entries:
    mesh = meshio.read(out / e.get("file"))
    n = len(mesh.points)
    for name, comps in [("id", 1), ("material", 1), ("damage", 1), ("displacement", 3),
                        ("pos", 3), ("vel", 3), ("force", 3)]:
        a = mesh.point_data[name]
        assert a.shape[0] == n and (a.ndim == 1 or a.shape[1] == comps), (name, a.shape)
    assert np.allclose(mesh.points, mesh.point_data["pos"]), "points are current positions"
    d = mesh.point_data["damage"]
    assert ((d >= 0) & (d <= 1)).all(), "damage lies in [0, 1]"
    assert sorted(mesh.point_data["id"]) == list(range(n)), "ids are 0..n-1"
last = meshio.read(out / entries[-1].get("file"))
rows = list(csv.DictReader(open(out / "history.csv")))
assert abs(float(rows[-1]["max_damage"]) - last.point_data["damage"].max()) < 1e-9
print(f"frames ok: {len(entries)} frames of {len(last.points)} particles, "
      f"max damage {last.point_data['damage'].max():.3f}, "
      f"{int(float(rows[-1]['broken_bonds']))} broken bonds")
