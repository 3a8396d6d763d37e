"""Reads a run's ParaView output with meshio (an independent VTK reader) and checks it.

Usage: python3 tests/check_frames.py OUTPUT_DIR [--same-as OTHER_DIR]

With --same-as, the last frames of the two runs (say, threads and MPI ranks) must hold the
same particles with the same damage and, to round-off, the same positions and forces.
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
first = meshio.read(out / entries[0].get("file"))
last = meshio.read(out / entries[-1].get("file"))
# Frames carry each step's forces, not the ones of the first step.
assert not np.allclose(first.point_data["force"], last.point_data["force"]), \
    "the force array does not change between the first and the last frame"
assert np.abs(last.point_data["displacement"]).max() > 0, "nothing moved"
rows = list(csv.DictReader(open(out / "history.csv")))
assert abs(float(rows[-1]["max_damage"]) - last.point_data["damage"].max()) < 1e-9
if len(sys.argv) > 3 and sys.argv[2] == "--same-as":
    other_dir = Path(sys.argv[3])
    o_series = ET.parse(other_dir / "frames.pvd").getroot().find("Collection").findall("DataSet")
    other = meshio.read(other_dir / o_series[-1].get("file"))
    a = np.argsort(last.point_data["id"])
    b = np.argsort(other.point_data["id"])
    assert (last.point_data["id"][a] == other.point_data["id"][b]).all(), "different particles"
    assert (last.point_data["damage"][a] == other.point_data["damage"][b]).all(), "damage differs"
    scale = np.abs(last.point_data["pos"]).max()
    dp = np.abs(last.point_data["pos"][a] - other.point_data["pos"][b]).max() / scale
    assert dp <= 1e-12, f"positions differ by {dp:e}"
    fs = np.abs(last.point_data["force"]).max()
    df = np.abs(last.point_data["force"][a] - other.point_data["force"][b]).max() / fs
    assert df <= 1e-9, f"forces differ by {df:e}"
    print(f"same as {other_dir}: positions within {dp:.1e}, forces within {df:.1e}")
print(f"frames ok: {len(entries)} frames of {len(last.points)} particles, "
      f"max damage {last.point_data['damage'].max():.3f}, "
      f"{int(float(rows[-1]['broken_bonds']))} broken bonds")
