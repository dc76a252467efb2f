#!/usr/bin/python3
"""Checks on basalt-run output for the I/O-layer end-to-end tests (h5py + VTK's Python reader).
  same FILE_A FILE_B          every dataset of A equals B's exactly (and vice versa); exit 1 otherwise
  close FILE_A FILE_B TOL     particle positions and velocities agree to TOL relative (same ids)
  complete FILE               the checkpoint carries the completion mark
  old_lists FILE              the checkpoint's lists are older than it: 0 < rebuild_step < step, and
                              position_at_rebuild differs from position
  strip_rebuild FILE          removes position_at_rebuild, rebuild_step and rebuild_pending (an older
                              basalt-run's checkpoint)
  contacts FILE N             the checkpoint holds at least N contacts with a history (/contacts), each pair
                              once per orientation (pairs between two ranks in both, agreeing), with
                              positive ages, and some contacts with an age below the step
  pvd DIR                     every frame of DIR/frames.pvd, read with vtkXMLPPolyDataReader, has the
                              positions of DIR/ckpt_<step>.h5 (same ids), when that checkpoint exists
  compressed FILE             the checkpoint's position, velocity and bond datasets are chunked through the
                              shuffle and deflate (gzip) filters
  xdmf DIR STEPS              DIR/ckpt_series.xmf is a time-ordered temporal collection of exactly the
                              checkpoints STEPS (comma-separated), and each grid, read as an XDMF reader
                              does (the DataItem paths through h5py, their Dimensions and number types),
                              gives the checkpoint's particle count, positions, velocity and radius, and
                              one vertex cell per particle (the topology's HyperSlab of xdmf_vertices.h5:
                              cell i is point i); so does each ckpt_<step>.xmf alone, a temporal collection
                              of its one grid
"""
import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import numpy as np


def datasets(f):
    out = {}
    f.visititems(lambda n, o: out.__setitem__(n, o[()]) if isinstance(o, h5py.Dataset) else None)
    return out


def same(a, b):
    da, db = datasets(h5py.File(a, "r")), datasets(h5py.File(b, "r"))
    bad = sorted(set(da) ^ set(db))
    for k in sorted(set(da) & set(db)):
        if da[k].shape != db[k].shape or not np.array_equal(da[k], db[k]):
            bad.append(k)
    for k in bad:
        print(f"differs: {k}")
    print(f"{len(da)} datasets compared, {len(bad)} differ")
    return not bad


def close(a, b, tol):
    fa, fb = h5py.File(a, "r"), h5py.File(b, "r")
    if not np.array_equal(fa["particles/id"][()], fb["particles/id"][()]):
        print("particle ids differ")
        return False
    ok = True
    for k in ["particles/position", "particles/velocity"]:
        x, y = fa[k][()], fb[k][()]
        rel = np.max(np.abs(x - y)) / max(np.max(np.abs(x)), 1e-300)
        print(f"{k}: max difference {rel:.3g} relative to the largest value")
        ok = ok and rel <= tol
    return ok


def complete(f):
    with h5py.File(f, "r") as h:
        return int(h.attrs.get("complete", 0)) == 1


def old_lists(f):
    with h5py.File(f, "r") as h:
        step, rb = int(h.attrs["step"]), int(h.attrs["rebuild_step"])
        moved = not np.array_equal(h["particles/position_at_rebuild"][()], h["particles/position"][()])
        print(f"step {step}: last rebuild at step {rb}; positions moved since: {moved}")
        return 0 < rb < step and moved


def contacts(f, n):
    with h5py.File(f, "r") as h:
        if "contacts" not in h:
            print("no /contacts group")
            return False
        ids, hist = h["contacts/ids"][()], h["contacts/history"][()]
        step = int(h.attrs["step"])
        # Each (pair, orientation) once: a pair between two ranks comes from both, each with its own
        # record in its own orientation (the age is the same either way).
        rows = {(int(a), int(b)): float(v) for (a, b), v in zip(ids, hist[:, 0])}
        pairs = {(min(a, b), max(a, b)) for a, b in rows}
        twice = [(a, b) for a, b in rows if a < b and (b, a) in rows]
        same = all(rows[(a, b)] == rows[(b, a)] for a, b in twice)
        print(f"{len(ids)} contacts with history ({len(pairs)} pairs, {len(twice)} between two ranks, "
              f"both orientations agreeing: {same}), ages {hist.min():g} .. {hist.max():g}, step {step}")
        return (len(pairs) >= n and len(rows) == len(ids) and same and hist.min() > 0 and hist.max() <= step
                and hist.min() < step)


def break_overlap(f):
    """Some bond broke at the checkpoint's own step (flag 2) while its spheres still overlap."""
    with h5py.File(f, "r") as h:
        ids, pos, r = h["particles/id"][()], h["particles/position"][()], h["particles/radius"][()]
        pairs, flag = h["bonds/pairs"][()], h["bonds/broken"][()]
    a, b = pairs[:, 0], pairs[:, 1]
    at = {int(i): k for k, i in enumerate(ids)}
    n = 0
    for ia, ib in zip(a[flag == 2], b[flag == 2]):
        i, j = at[int(ia)], at[int(ib)]
        n += np.linalg.norm(pos[i] - pos[j]) < r[i] + r[j]
    print(f"{int(np.sum(flag == 2))} bonds broke at this step, {n} of them between overlapping spheres")
    return n > 0


def strip_rebuild(f):
    with h5py.File(f, "r+") as h:
        del h["particles/position_at_rebuild"]
        del h.attrs["rebuild_step"]
        del h.attrs["rebuild_pending"]
    return True


def pvd(folder):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    folder = Path(folder)
    root = ET.parse(folder / "frames.pvd").getroot()
    entries = root.findall(".//DataSet")
    compared = 0
    for e in entries:
        pvtp = folder / e.get("file")
        step = int(pvtp.stem.split("_")[-1])
        ck = folder / f"ckpt_{step:06d}.h5"
        r = vtk.vtkXMLPPolyDataReader()
        r.SetFileName(str(pvtp))
        r.Update()
        poly = r.GetOutput()
        if poly.GetNumberOfPoints() == 0:
            print(f"{pvtp}: no points read")
            return False
        pos = vtk_to_numpy(poly.GetPoints().GetData())
        ids = vtk_to_numpy(poly.GetPointData().GetArray("id"))
        if not ck.exists():
            continue
        with h5py.File(ck, "r") as h:
            cid, cpos = h["particles/id"][()], h["particles/position"][()]
        order = np.argsort(ids)
        if not np.array_equal(ids[order], cid) or not np.array_equal(pos[order], cpos):
            print(f"{pvtp}: positions differ from {ck}")
            return False
        compared += 1
    print(f"{len(entries)} frames in the .pvd, {compared} compared with checkpoints")
    return compared > 0


def compressed(f):
    with h5py.File(f, "r") as h:
        for d in ("particles/position", "particles/velocity", "bonds/pairs"):
            ds = h[d]
            if ds.compression != "gzip" or not ds.shuffle:
                print(f"{f}: {d} is not shuffled and deflated (compression {ds.compression}, shuffle {ds.shuffle})")
                return False
        print(f"{f}: deflate level {h['particles/position'].compression_opts}, with shuffle")
    return True


def xdmf_grid(grid, folder):
    """Reads one particle grid the way an XDMF reader does; returns (time, n, arrays by name) or raises."""
    types = {("Float", "8"): np.float64, ("Float", "4"): np.float32, ("Int", "8"): np.int64, ("Int", "4"): np.int32}

    def heavy(d):
        assert d.get("Format") == "HDF", d.attrib
        file, path = d.text.strip().split(":", 1)
        with h5py.File(folder / file, "r") as h:
            data = h[path][()]
        dims = tuple(int(x) for x in d.get("Dimensions").split())
        assert data.shape == dims, f"{d.text}: shape {data.shape}, Dimensions {dims}"
        want = types[(d.get("NumberType"), d.get("Precision"))]
        assert data.dtype == want, f"{d.text}: {data.dtype}, the XML says {want}"
        return data

    def item(parent):
        d = parent.find("DataItem")
        if d.get("ItemType") != "HyperSlab":
            return heavy(d)
        # start, stride and count (one column each: a one-dimensional selection) of the second item.
        selection, source = d.findall("DataItem")
        assert selection.get("Format") == "XML" and selection.get("Dimensions") == "3 1", selection.attrib
        start, stride, count = (int(x) for x in selection.text.split())
        data = heavy(source)[start::stride][:count]
        assert data.shape == (count,) and d.get("Dimensions") == str(count), d.attrib
        return data

    assert grid.get("GridType") == "Uniform"
    time = float(grid.find("Time").get("Value"))
    topo = grid.find("Topology")
    assert topo.get("TopologyType") == "Polyvertex" and topo.get("NodesPerElement") == "1"
    n = int(topo.get("NumberOfElements"))
    # ParaView's Xdmf3 readers make cells only from an explicit connectivity: particle i is vertex i.
    assert np.array_equal(item(topo), np.arange(n)), "the connectivity is not 0..N-1"
    assert grid.find("Geometry").get("GeometryType") == "XYZ"
    arrays = {"position": item(grid.find("Geometry"))}
    for a in grid.findall("Attribute"):
        assert a.get("Center") == "Node"
        arrays[a.get("Name")] = item(a)
        comps = 3 if a.get("AttributeType") == "Vector" else 1
        assert arrays[a.get("Name")].shape == ((n, 3) if comps == 3 else (n,)), a.get("Name")
    assert arrays["position"].shape == (n, 3)
    return time, n, arrays


def temporal_grids(file):
    """The grids of the temporal collection that is the file's one grid (the form all of ParaView's readers
    take time from)."""
    collections = ET.parse(file).getroot().findall("Domain/Grid")
    assert len(collections) == 1, f"{file}: {len(collections)} top-level grids"
    c = collections[0]
    assert c.get("GridType") == "Collection" and c.get("CollectionType") == "Temporal", f"{file}: {c.attrib}"
    return c.findall("Grid")


def xdmf(folder, steps):
    folder = Path(folder)
    want = [int(s) for s in steps.split(",")]
    grids = temporal_grids(folder / "ckpt_series.xmf")
    got = [int(g.find("Information[@Name='step']").get("Value")) for g in grids]
    if got != want:
        print(f"ckpt_series.xmf lists steps {got}, expected {want}")
        return False
    times = []
    for step, grid in zip(got, grids):
        alone = temporal_grids(folder / f"ckpt_{step:06d}.xmf")
        assert len(alone) == 1, f"ckpt_{step:06d}.xmf: {len(alone)} grids"
        for g in (grid, alone[0]):
            time, n, arrays = xdmf_grid(g, folder)
            with h5py.File(folder / f"ckpt_{step:06d}.h5", "r") as h:
                if n != h["particles/id"].shape[0] or time != h.attrs["time"]:
                    print(f"step {step}: {n} particles at time {time}, the checkpoint says otherwise")
                    return False
                for name, path in (("position", "particles/position"), ("velocity", "particles/velocity"),
                                   ("radius", "particles/radius"), ("id", "particles/id")):
                    if not np.array_equal(arrays[name], h[path][()]):
                        print(f"step {step}: {name} differs from {path}")
                        return False
        times.append(time)
    if times != sorted(times) or len(set(times)) != len(times):
        print(f"times not increasing: {times}")
        return False
    print(f"ckpt_series.xmf: {len(grids)} checkpoints in time order {times}, {n} particles and cells each, "
          "read back equal")
    return True


# basalt-view's pictures (tests/tools/test_basalt_view.cpp): background, the ends of the colour map, and
# the part of the width left of the colour bar.
BACKGROUND, LOW, HIGH, SCENE = (82, 87, 110), (59, 76, 192), (180, 4, 38), 0.8


def picture_ok(png, width, height, ends=True):
    """The PNG has the size asked for, is not blank, and (with `ends`) shows both ends of the colour map in
    the scene."""
    from PIL import Image
    img = Image.open(png).convert("RGB")
    if img.size != (width, height):
        print(f"{png}: {img.size}, expected {(width, height)}")
        return False
    a = np.asarray(img, dtype=int)[:, : int(SCENE * width)]
    near = lambda c, tol: int(np.sum(np.all(np.abs(a - np.array(c)) <= tol, axis=2)))
    scene = a.shape[0] * a.shape[1]
    background, low, high = near(BACKGROUND, 3), near(LOW, 30), near(HIGH, 30)
    least = max(10, scene // 2000)  # 30 pixels of a 320x240 picture, fewer for a smaller one
    if scene - background < scene // 10 or (ends and (low < least or high < least)):
        print(f"{png}: {scene - background} of {scene} pixels not background, {low} near the low end, "
              f"{high} near the high end of the colour map: blank or one-coloured")
        return False
    return True


def pictures(folder, steps, log, size, ends="ends"):
    """In-situ pictures: one PNG per step asked for, or the step is in the report's skipped list, and
    the report's counts agree with the files."""
    folder, steps = Path(folder), [int(s) for s in steps.split(",")]
    width, height = (int(v) for v in size.split("x"))
    text = Path(log).read_text()
    m = re.search(r"pictures +(\d+) files .* (\d+) of (\d+) drawn, (\d+) skipped(?: \(steps ([0-9, .]+):)?", text)
    if not m:
        print(f"{log}: no pictures line in the report")
        return False
    files, drawn, due, skipped = (int(m.group(k)) for k in range(1, 5))
    listed = [int(v) for v in (m.group(5) or "").replace(" ", "").split(",") if v and v != "..."]
    pngs = sorted((folder / "pictures").glob("*.png"))
    made = [int(p.stem.split("_")[-1]) for p in pngs]
    if due != len(steps) or files != drawn or drawn + skipped != due or len(pngs) != drawn:
        print(f"{len(steps)} steps asked, report: {drawn} of {due} drawn, {skipped} skipped, {files} files; "
              f"{len(pngs)} PNGs in {folder / 'pictures'}")
        return False
    if sorted(made + listed) != steps and not (len(listed) == 20 and set(made + listed) <= set(steps)):
        print(f"asked {steps}; drawn {made}; skipped {listed}")
        return False
    if list((folder / "pictures").glob("*.partial")):
        print("a .partial file is left")
        return False
    for png in pngs:
        if not picture_ok(png, width, height, ends == "ends"):
            return False
    print(f"{drawn} pictures drawn (steps {made}), {skipped} skipped (steps {listed}); each {width}x{height}, "
          f"not blank{', both ends of the colour map' if ends == 'ends' else ''}")
    return True


if __name__ == "__main__":
    cmd, args = sys.argv[1], sys.argv[2:]
    ok = {"same": lambda: same(*args), "close": lambda: close(args[0], args[1], float(args[2])),
          "complete": lambda: complete(args[0]),
          "contacts": lambda: contacts(args[0], int(args[1])),
          "old_lists": lambda: old_lists(args[0]), "break_overlap": lambda: break_overlap(args[0]),
          "strip_rebuild": lambda: strip_rebuild(args[0]), "pvd": lambda: pvd(args[0]),
          "xdmf": lambda: xdmf(args[0], args[1]), "compressed": lambda: compressed(args[0]),
          "pictures": lambda: pictures(*args), "picture": lambda: picture_ok(args[0], int(args[1]), int(args[2]))}[cmd]()
    sys.exit(0 if ok else 1)
