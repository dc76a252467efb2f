# pack_box.py: RandomBoxPacker fills a box (ESyS-Particle tutorial style, own numbers) and the script prints
# every sphere: "sphere id x y z radius tag" at 17 digits, in the packing's order.
#   python3 -m basalt.esys pack_box.py [CASE...]     (or: mpirun -np 2 esysparticle pack_box.py [CASE...])
# CASE is small (default; minRadius = maxRadius / 4), wide (the default tolerance) or
# slope (slope_fail's box, 5,167 spheres); CASE+ calls generate() twice (the second adds spheres around the
# first ones) and prints after the second; several cases pack one after the other in the same run (ESyS's
# random stream goes on from one packer to the next). tests/python/esys_scripts/data/pack_box_*.txt hold what
# ESyS-Particle 2.3.5 printed.
import sys

from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.geometry import RandomBoxPacker

CASES = {
    "small": dict(minRadius=0.25, maxRadius=1.0, cubicPackRadius=1.1, maxInsertFails=200,
                  bBox=BoundingBox(Vec3(0, 0, 0), Vec3(6, 4, 5)), circDimList=[False, False, False],
                  tolerance=1.0e-05),
    "wide": dict(minRadius=0.3, maxRadius=0.6, cubicPackRadius=0.6, maxInsertFails=300,
                 bBox=BoundingBox(Vec3(-1, 2, 3), Vec3(4, 6, 9))),
    "slope": dict(minRadius=0.2, maxRadius=0.5, cubicPackRadius=2.2, maxInsertFails=1000,
                  bBox=BoundingBox(Vec3(-5, 0, -5), Vec3(5, 10, 5)), circDimList=[False, False, False],
                  tolerance=1.0e-05),
}

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
for case in sys.argv[1:] or ["small"]:
    packer = RandomBoxPacker(**CASES[case.rstrip("+")])
    packer.generate()
    if case.endswith("+"):
        packer.generate()
    for s in packer.getSimpleSphereCollection():
        c = s.getPosn()
        print("sphere %d %.17g %.17g %.17g %.17g %d" % (s.getId(), c[0], c[1], c[2], s.getRadius(), s.getTag()))
sys.stdout.flush()
sim.exit()  # ends ESyS's worker processes (no run() here)
