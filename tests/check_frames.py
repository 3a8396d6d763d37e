"""Reads a run's ParaView output (frames.xdmf and its HDF5 frames) with meshio's XDMF time
series reader and h5py (independent readers) and checks it. Frames written in parts (one
directory of part files per frame, a spatial collection per step in frames.xdmf) are read with
VTK's XDMF reader (PyPI vtk), ParaView's own library, which meshio does not cover.

Usage: python3 tests/check_frames.py OUTPUT_DIR [--same-as OTHER_DIR]

With --same-as, the last frames of the two runs (say, threads and MPI ranks) must hold the
same particles with the same damage and, to round-off, the same positions and forces.
"""
import csv
import sys
from pathlib import Path

import h5py
import meshio
import numpy as np


def in_parts(out):
    return any(p.is_dir() for p in (out / "frames").glob("frame_*"))


def read_series_parts(out):
    """Times and point data of frames.xdmf when its frames are in parts: VTK's reader."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    reader = vtk.vtkXdmfReader()
    reader.SetFileName(str(out / "frames.xdmf"))
    reader.UpdateInformation()
    times = reader.GetOutputInformation(0).Get(vtk.vtkStreamingDemandDrivenPipeline.TIME_STEPS())
    frames = []
    for t in times:
        reader.UpdateTimeStep(t)
        blocks = reader.GetOutputDataObject(0)
        parts = {}
        for k in range(blocks.GetNumberOfBlocks()):
            b = blocks.GetBlock(k)
            assert b.GetNumberOfCells() == b.GetNumberOfPoints(), "one vertex cell per particle"
            pd = b.GetPointData()
            for i in range(pd.GetNumberOfArrays()):
                parts.setdefault(pd.GetArrayName(i), []).append(vtk_to_numpy(pd.GetArray(i)))
            parts.setdefault("points", []).append(vtk_to_numpy(b.GetPoints().GetData()))
        data = {name: np.concatenate(v) for name, v in parts.items()}
        assert np.array_equal(data.pop("points"), data["pos"]), "VTK's points are the positions"
        frames.append((t, data))
    return frames


def read_series(out):
    """Times, and per frame the point data, of an output directory's frames.xdmf."""
    if in_parts(out):
        return read_series_parts(out)
    frames = []
    with meshio.xdmf.TimeSeriesReader(out / "frames.xdmf") as reader:
        points, cells = reader.read_points_cells()
        assert cells and cells[0].type == "vertex", cells
        assert len(cells[0].data) == len(points), "one vertex cell per particle"
        for k in range(reader.num_steps):
            t, point_data, _ = reader.read_data(k)
            frames.append((t, point_data))
    return frames


out = Path(sys.argv[1])
frames = read_series(out)
assert len(frames) >= 2, "a time series needs several frames"
times = [t for t, _ in frames]
assert times == sorted(times), "frame times must increase"
h5_files = sorted((out / "frames").glob("frame_*"))
assert len(h5_files) == len(frames), (len(h5_files), len(frames))
for (t, data), path in zip(frames, h5_files):
    n = len(data["id"])
    for name, comps in [("id", 1), ("material", 1), ("damage", 1), ("displacement", 3),
                        ("pos", 3), ("vel", 3), ("force", 3)]:
        a = data[name]
        assert a.shape[0] == n and (a.ndim == 1 or a.shape[1] == comps), (name, a.shape)
    files = sorted(path.glob("part_*.h5")) if path.is_dir() else [path]
    points = []
    for file in files:
        with h5py.File(file, "r") as f:
            assert abs(f.attrs["time"] - t) <= 1e-12 * max(abs(t), 1e-300), "time attribute"
            if len(f["points"]):
                points.append(f["points"][()])
    assert np.array_equal(np.concatenate(points), data["pos"]), "points are current positions"
    d = data["damage"]
    assert ((d >= 0) & (d <= 1)).all(), "damage lies in [0, 1]"
    assert sorted(data["id"]) == list(range(n)), "ids are 0..n-1"
first, last = frames[0][1], frames[-1][1]
# Frames carry each step's forces, not the ones of the first step.
assert not np.allclose(first["force"], last["force"]), \
    "the force array does not change between the first and the last frame"
assert np.abs(last["displacement"]).max() > 0, "nothing moved"
rows = list(csv.DictReader(open(out / "history.csv")))
assert abs(float(rows[-1]["max_damage"]) - last["damage"].max()) < 1e-9
if len(sys.argv) > 3 and sys.argv[2] == "--same-as":
    other_dir = Path(sys.argv[3])
    other = read_series(other_dir)[-1][1]
    a = np.argsort(last["id"])
    b = np.argsort(other["id"])
    assert (last["id"][a] == other["id"][b]).all(), "different particles"
    assert (last["damage"][a] == other["damage"][b]).all(), "damage differs"
    scale = np.abs(last["pos"]).max()
    dp = np.abs(last["pos"][a] - other["pos"][b]).max() / scale
    assert dp <= 1e-12, f"positions differ by {dp:e}"
    fs = np.abs(last["force"]).max()
    df = np.abs(last["force"][a] - other["force"][b]).max() / fs
    # Summation order differs between layouts; in a cracking run round-off grows to ~1e-9.
    assert df <= 1e-8, f"forces differ by {df:e}"
    print(f"same as {other_dir}: positions within {dp:.1e}, forces within {df:.1e}")
print(f"frames ok: {len(frames)} frames of {len(last['id'])} particles, "
      f"max damage {last['damage'].max():.3f}, "
      f"{int(float(rows[-1]['broken_bonds']))} broken bonds")
