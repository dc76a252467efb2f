"""ParaView's three XDMF readers open Basalt's checkpoints: the series and one checkpoint's .xmf.

Two modes, run by tests/paraview/xdmf_readers.sh:
  /usr/bin/python3 xdmf_readers.py expect DIR OUT.npz
      what the run wrote, from DIR/ckpt_<step>.h5 through h5py: each checkpoint's step, time, particle
      count, ids and positions, and the particle arrays an .xmf names (kept out of pvpython: its HDF5 is
      not h5py's)
  pvpython xdmf_readers.py check DIR OUT.npz FILE.xmf [FILE.xmf ...]
      opens each FILE with XDMFReader (Xdmf2), Xdmf3ReaderS and Xdmf3ReaderT, and checks against OUT.npz:
      the time steps (exactly the checkpoints the file lists, in order), and at each time the points, the
      cells (one vertex cell per particle, cell i on point i), the point arrays (names, components, ids and
      radii equal to the checkpoint's, positions equal) and that the default Surface representation and the
      Points representation draw particles (pixels off the background). Exit 1 on the first difference.
"""
import sys
from pathlib import Path

ARRAYS = {"velocity": 3, "radius": 1, "mass": 1, "id": 1, "tag": 1}


def expect(folder, out):
    import h5py
    import numpy as np

    data = {}
    steps = []
    for f in sorted(Path(folder).glob("ckpt_[0-9]*.h5")):
        step = int(f.stem[5:])
        with h5py.File(f, "r") as h:
            steps.append(step)
            data[f"time_{step}"] = np.float64(h.attrs["time"])
            data[f"id_{step}"] = h["particles/id"][()]
            data[f"position_{step}"] = h["particles/position"][()]
            data[f"radius_{step}"] = h["particles/radius"][()]
            missing = [a for a in ARRAYS if f"particles/{a}" not in h]
            assert not missing, f"{f}: no {missing}"
    np.savez(out, steps=np.array(steps, dtype=np.int64), **data)
    print(f"expect: {len(steps)} checkpoints in {folder}: steps {steps}")


def check(folder, expected, files):
    import xml.etree.ElementTree as ET

    import numpy as np
    from paraview import servermanager as sm
    from paraview import simple
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader

    want = np.load(expected)
    failures = []

    def fail(msg):
        print("FAIL: " + msg)
        failures.append(msg)

    def pixels_drawn(source, representation, png):
        view = simple.CreateView("RenderView")
        view.OrientationAxesVisibility = 0
        view.Background = [0, 0, 0]
        try:  # 5.11 takes the background from the colour palette unless told
            view.UseColorPaletteForBackground = 0
        except AttributeError:
            pass
        display = simple.Show(source, view)
        display.SetRepresentationType(representation)
        display.AmbientColor = display.DiffuseColor = [1, 1, 1]
        simple.ColorBy(display, None)
        display.PointSize = 3
        simple.ResetCamera(view)
        simple.SaveScreenshot(str(png), view, ImageResolution=[160, 120])
        simple.Delete(view)
        reader = vtkPNGReader()
        reader.SetFileName(str(png))
        reader.Update()
        img = vtk_to_numpy(reader.GetOutput().GetPointData().GetScalars())
        return int(np.count_nonzero(img[:, :3].max(axis=1) > 40))

    for xmf in files:
        xmf = Path(xmf)
        # The steps the file lists (its grids' step information), in order: what each reader must show.
        steps = [int(i.get("Value")) for i in ET.parse(xmf).getroot().iter("Information") if i.get("Name") == "step"]
        times = [float(want[f"time_{s}"]) for s in steps]
        for name in ("XDMFReader", "Xdmf3ReaderS", "Xdmf3ReaderT"):
            what = f"{xmf.name} with {name}"
            if name == "XDMFReader":
                reader = simple.XDMFReader(FileNames=[str(xmf)])
            else:
                reader = getattr(simple, name)(FileName=[str(xmf)])
            reader.UpdatePipelineInformation()
            ts = reader.TimestepValues  # a list, one float, or None/empty for no time
            got_times = [float(ts)] if isinstance(ts, (int, float)) else list(ts or [])
            if len(got_times) != len(times) or not np.allclose(got_times, times, rtol=1e-12, atol=0):
                fail(f"{what}: time steps {got_times}, the run wrote {times}")
                simple.Delete(reader)
                continue
            for step, t in zip(steps, times):
                reader.UpdatePipeline(t)
                d = sm.Fetch(reader)
                while d.IsA("vtkMultiBlockDataSet"):
                    d = d.GetBlock(0)
                n = len(want[f"id_{step}"])
                at = f"{what}, step {step} (t = {t})"
                if d.GetNumberOfPoints() != n or d.GetNumberOfCells() != n:
                    fail(f"{at}: {d.GetNumberOfPoints()} points and {d.GetNumberOfCells()} cells, the run wrote "
                         f"{n} particles")
                    continue
                cells = d.GetCells()
                conn = vtk_to_numpy(cells.GetConnectivityArray())
                offsets = vtk_to_numpy(cells.GetOffsetsArray())
                if not (np.array_equal(conn, np.arange(n)) and np.array_equal(offsets, np.arange(n + 1))):
                    fail(f"{at}: the cells are not one vertex per particle, cell i on point i")
                pd = d.GetPointData()
                names = {pd.GetArrayName(k): pd.GetArray(k) for k in range(pd.GetNumberOfArrays())}
                if set(names) != set(ARRAYS):
                    fail(f"{at}: point arrays {sorted(names)}, the .xmf names {sorted(ARRAYS)}")
                    continue
                for a, comps in ARRAYS.items():
                    if names[a].GetNumberOfComponents() != comps or names[a].GetNumberOfTuples() != n:
                        fail(f"{at}: {a} has {names[a].GetNumberOfTuples()} x {names[a].GetNumberOfComponents()}")
                for a, values in (("id", vtk_to_numpy(names["id"])), ("radius", vtk_to_numpy(names["radius"])),
                                  ("position", vtk_to_numpy(d.GetPoints().GetData()))):
                    if not np.array_equal(values, want[f"{a}_{step}"]):
                        fail(f"{at}: {a} differs from ckpt_{step:06d}.h5")
            # What a user sees on Apply: the default Surface view, and Points, draw the particles.
            reader.UpdatePipeline(times[-1])
            for rep in ("Surface", "Points"):
                drawn = pixels_drawn(reader, rep, Path(folder) / f"draw_{xmf.stem}_{name}_{rep}.png")
                print(f"   {what}: {rep} draws {drawn} pixels of 160 x 120")
                if drawn < 100:
                    fail(f"{what}: the {rep} representation draws {drawn} pixels")
            if not [f for f in failures if f.startswith(what)]:
                print(f"ok: {what}: {len(times)} time steps, {n} points and cells, {len(ARRAYS)} arrays, drawn")
            simple.Delete(reader)
    return not failures


if __name__ == "__main__":
    mode = sys.argv[1] if len(sys.argv) > 1 else ""
    if mode == "expect" and len(sys.argv) == 4:
        expect(sys.argv[2], sys.argv[3])
    elif mode == "check" and len(sys.argv) >= 5:
        sys.exit(0 if check(sys.argv[2], sys.argv[3], sys.argv[4:]) else 1)
    else:
        sys.exit(__doc__)
