"""The study's geometries: the scene's own, and the perturbed copies of its reference ensemble.

Each member of the ensemble starts from the scene's geometry with every particle moved by `scale` (1e-9) of its
radius in a random direction (seeded by the member's number), so that the spread of the members' answers is the
scene's own chaos floor: what a difference in the ninth digit of the positions does by itself. Basalt-run has
no such key; the copy is written with basalt's own writer (basalt.Geometry.write), ids, tags, bonds and masses
kept. Member 0 is the geometry rewritten unchanged, which every setting and the reference run from, so that the
members differ from the reference by the nudge alone.
"""


def write_member(source, target, member, scale=1e-9):
    """Writes `source` (.h5 or .geo) to `target` (.h5), positions nudged when member > 0. Returns the largest
    displacement over radius (0 for member 0)."""
    import numpy as np
    import basalt
    g = basalt.read_geometry(source)
    largest = 0.0
    if member > 0:
        rng = np.random.default_rng(member)
        x = g.particles["position"]
        d = rng.normal(size=x.shape)
        d /= np.linalg.norm(d, axis=1)[:, None]
        r = g.particles["radius"]
        x += d * (scale * r)[:, None]
        largest = float(np.max(np.linalg.norm(d * (scale * r)[:, None], axis=1) / r))
    g.write(target)
    return largest
