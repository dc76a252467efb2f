#!/usr/bin/env python3
"""The stable time step of ESyS rotational bonds (rot_bond, BrittleBeam) against basalt-run's estimate.

    /usr/bin/python3 tools/studies/rot_bond_limit.py [--build build] [--steps 5000] [--out out/rot-bond-limit]

Writes two test specimens and bisects each with tools/studies/stability_limit.py (double, 1 rank):
  * pair:    two spheres of radius 0.5, one bond, the second sphere 1e-3 off its rest position;
  * lattice: 4 x 4 x 4 spheres of radius 0.5 on a cubic lattice (bonds to the 6 nearest), every position
             jittered by 1e-3 of the radius (seeded);
with the UCS scene's bond parameters (scenes/ucs-esys.toml: E = 1e5, nu = 0.25, mean radius scaling, ESyS's
rest length r1 + r2), strengths made unreachable, no damping, symplectic Euler. Prints each estimate, the
measured limit and their ratio (docs/stability.md, "Rotational bonds and the critical step").
"""
import argparse
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

SCENE = """
[geometry]
file = "{geometry}"
[particles]
rotation = true
[run]
dt = 1.0e-3
steps = 1000
skin = 0.1
integrator = "symplectic_euler"
[[interactions]]
name = "bonds"
type = "rot_bond"
youngs_modulus = 1.0e5
poissons_ratio = 0.25
radius_scaling = "mean"
cohesion = 1.0e9
tan_friction_angle = 1.0
criterion = "esys"
angles = "{angles}"
rest_length = "sum_of_radii"
[output]
directory = "out"
[[output.fields]]
type = "kinetic_energy"
"""


def specimens(out):
    sys.path.insert(0, os.path.join(ROOT, "build", "python"))
    import basalt
    r = 0.5
    pair = np.array([[0.0, 0.0, 0.0], [2 * r + 1e-3, 2e-3, -1e-3]])
    basalt.Geometry(pair, np.full(2, r), bonds=[(0, 1)]).write(os.path.join(out, "pair.h5"))
    n = 4
    idx = np.array([(i, j, k) for i in range(n) for j in range(n) for k in range(n)])
    pos = idx * 2 * r + np.random.default_rng(1).normal(scale=1e-3 * r, size=idx.shape)
    lin = lambda i, j, k: (i * n + j) * n + k  # noqa: E731
    bonds = [(lin(i, j, k), lin(i + a, j + b, k + c)) for i, j, k in idx
             for a, b, c in ((1, 0, 0), (0, 1, 0), (0, 0, 1)) if i + a < n and j + b < n and k + c < n]
    basalt.Geometry(pos, np.full(len(pos), r), bonds=bonds).write(os.path.join(out, "lattice.h5"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--steps", type=int, default=5000)
    ap.add_argument("--out", default="out/rot-bond-limit")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    specimens(a.out)
    for name in ("pair", "lattice"):
        for angles in ("esys", "atan2"):
            scene = os.path.join(a.out, f"{name}-{angles}.toml")
            with open(scene, "w") as f:
                f.write(SCENE.format(geometry=os.path.abspath(os.path.join(a.out, name + ".h5")), angles=angles))
            print(f"== {name}, angles = {angles}", flush=True)
            subprocess.run([sys.executable, os.path.join(HERE, "stability_limit.py"), "--build", a.build,
                            "--scene", scene, "--geometry", os.path.join(a.out, name + ".h5"),
                            "--steps", str(a.steps), "--rtol", "1e-2"], check=False)


if __name__ == "__main__":
    main()
