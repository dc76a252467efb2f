"""ESyS-Particle's triangle-mesh files (`.msh`, LsmMpi.readMesh) read and written again as OFF for Basalt's
[[mesh_walls]] (docs/esys.md, "Mesh walls").

The format, as ESyS's MeshReader reads it (whitespace-separated tokens; anything before the keywords skipped):

    Triangle                      (ignored: the reader looks for the next two keywords)
    3D-Nodes N                    then N nodes:      id  (unused)  tag  x  y  z
    Tri3 M                        then M triangles:  id  tag  node_id0  node_id1  node_id2

The triangles name their corners by node id (not by position in the list)."""


class MeshFileError(ValueError):
    pass


def read_msh(path):
    """(vertices [(x, y, z)], triangles [(i, j, k)] as indices into vertices) of an ESyS .msh file."""
    with open(path) as f:
        words = f.read().split()
    pos = 0

    def seek(keyword):
        nonlocal pos
        while pos < len(words) and words[pos] != keyword:
            pos += 1
        if pos == len(words):
            raise MeshFileError(f"{path}: no '{keyword}' keyword (an ESyS .msh file has '3D-Nodes N' and 'Tri3 M')")
        pos += 1
        return take(int, f"the number after '{keyword}'")

    def take(kind, what):
        nonlocal pos
        if pos >= len(words):
            raise MeshFileError(f"{path}: the file ends where {what} was expected")
        try:
            value = kind(words[pos])
        except ValueError:
            raise MeshFileError(f"{path}: {what}: {words[pos]!r} is not a number") from None
        pos += 1
        return value

    n = seek("3D-Nodes")
    index, vertices = {}, []
    for k in range(n):
        node = take(int, f"node {k}'s id")
        take(int, f"node {node}'s second field")
        take(int, f"node {node}'s tag")
        xyz = tuple(take(float, f"node {node}'s coordinate") for _ in range(3))
        if node in index:
            raise MeshFileError(f"{path}: node id {node} given twice")
        index[node] = len(vertices)
        vertices.append(xyz)
    m = seek("Tri3")
    triangles = []
    for k in range(m):
        tri = take(int, f"triangle {k}'s id")
        take(int, f"triangle {tri}'s tag")
        corners = [take(int, f"triangle {tri}'s node id") for _ in range(3)]
        for c in corners:
            if c not in index:
                raise MeshFileError(f"{path}: triangle {tri} names node {c}, which the file does not define")
        triangles.append(tuple(index[c] for c in corners))
    if not triangles:
        raise MeshFileError(f"{path}: no triangles")
    return vertices, triangles


def write_off(path, vertices, triangles):
    """The mesh as an OFF file (coordinates as repr writes them: the same doubles read back), each triangle wound
    the other way round, so that Basalt's one-sided mesh pushes towards ESyS's normal (esys_normals)."""
    with open(path, "w") as f:
        f.write(f"OFF\n{len(vertices)} {len(triangles)} 0\n")
        for x, y, z in vertices:
            f.write(f"{x!r} {y!r} {z!r}\n")
        for i, j, k in triangles:
            f.write(f"3 {i} {k} {j}\n")  # reversed: Basalt's counter-clockwise normal is ESyS's normal


def esys_normals(vertices, triangles):
    """ESyS's triangle normals (Triangle.cpp: (p2 - p0) x (p1 - p0), unit): the side a face pushes towards,
    clockwise seen from there; Basalt's one-sided mesh pushes towards the counter-clockwise normal, so the front
    end writes each triangle as (p0, p2, p1)."""
    import numpy as np

    v = np.asarray(vertices, dtype=float)
    t = np.asarray(triangles, dtype=np.int64)
    n = np.cross(v[t[:, 2]] - v[t[:, 0]], v[t[:, 1]] - v[t[:, 0]])
    return n / np.linalg.norm(n, axis=1)[:, None]


def touching_from_behind(vertices, triangles, centres, radii, reach):
    """(particle index, triangle index, signed distance) of the first particle ESyS's one-sided triangle would push
    differently from Basalt's one-sided mesh wall, or None: a centre behind a face (negative distance along ESyS's
    normal) within `reach` with its projection inside the triangle (ESyS pushes it through, k (r - d)), or behind
    the face's plane and within its radius of one of the triangle's edges or corners (ESyS's edge and corner
    contacts push from either side)."""
    import numpy as np

    v = np.asarray(vertices, dtype=float)
    c = np.asarray(centres, dtype=float).reshape(-1, 3)
    r = np.asarray(radii, dtype=float)
    normals = esys_normals(vertices, triangles)
    for k, (i, j, l) in enumerate(triangles):
        p0, e1, e2 = v[i], v[j] - v[i], v[l] - v[i]
        d = (c - p0) @ normals[k]
        # barycentric coordinates of the projection (ESyS's test: both >= 0 and their sum <= 1)
        g = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
        rhs = np.column_stack([(c - p0) @ e1, (c - p0) @ e2])
        a = np.linalg.solve(g, rhs.T).T
        inside = (a[:, 0] >= 0) & (a[:, 1] >= 0) & (a.sum(axis=1) <= 1)
        bad = inside & (d < 0) & (d > -reach)
        edge = np.full(len(c), np.inf)
        for p, q in ((v[i], v[j]), (v[j], v[l]), (v[l], v[i])):
            s = np.clip((c - p) @ (q - p) / ((q - p) @ (q - p)), 0.0, 1.0)
            edge = np.minimum(edge, np.linalg.norm(c - (p + s[:, None] * (q - p)), axis=1))
        bad |= (d < 0) & (edge < r)
        if bad.any():
            m = int(np.argmax(bad))
            return m, k, float(d[m])
    return None


def pushed_twice(vertices, triangles, centres, radii):
    """(particle index, triangle k, triangle l) of the first particle ESyS 2.3.5 would push twice where Basalt pushes
    once, or None: its centre projects into two coplanar triangles at once (exactly onto their shared edge or
    vertex: ESyS's inside test counts the boundary, measured Δv twice a face's) while touching them."""
    import numpy as np

    v = np.asarray(vertices, dtype=float)
    c = np.asarray(centres, dtype=float).reshape(-1, 3)
    r = np.asarray(radii, dtype=float)
    normals = esys_normals(vertices, triangles)
    touch = []
    for k, (i, j, l) in enumerate(triangles):
        p0, e1, e2 = v[i], v[j] - v[i], v[l] - v[i]
        d = (c - p0) @ normals[k]
        g = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
        a = np.linalg.solve(g, np.column_stack([(c - p0) @ e1, (c - p0) @ e2]).T).T
        touch.append((a[:, 0] >= 0) & (a[:, 1] >= 0) & (a.sum(axis=1) <= 1) & (d >= 0) & (d < r))
    touched = [k for k in range(len(triangles)) if touch[k].any()]
    for n, k in enumerate(touched):
        for m in touched[n + 1:]:
            both = touch[k] & touch[m]
            if both.any() and abs(normals[k] @ normals[m]) > 1 - 1e-12:
                return int(np.argmax(both)), k, m
    return None
