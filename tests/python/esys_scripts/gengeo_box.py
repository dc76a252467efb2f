# GenGeo-style geometry script (our own numbers): InsertGenerator3D fills a box, the table bonds the touching
# spheres and writes a .geo (and for `planes` and `cluster` a .vtu); every sphere is printed at 17 digits.
# Cases (several run one after the other, as GenGeo's random stream and sphere ids go on):
#   plain   a 6 x 5 x 4 box without planes, radii 0.2-1.0, 200 failed tries to stop (tag 0, group 0)
#   planes  a 5 x 4 x 6 box with its six faces as planes (the spheres touch them), radii 0.25-0.8, tag 2
#   old     the plain box with GenGeo's old seeding (setOldSeeding(True): the lattice spheres unshifted)
#   cluster the planes box in two groups: 2 x 2 x 3 skewed seed points (group 1, radius 0) tag the spheres by
#           the closest one, bonds tagged 1 inside a cluster and 3 between clusters, the seeds removed
# Runs on GenGeo (python3 gengeo_box.py CASE...) and on Basalt (python3 -m basalt.esys gengeo_box.py CASE...).
import sys

from gengeo import *


def pack(case):
    if case in ("planes", "cluster"):
        lo, hi, rmin, rmax, fails = Vector3(0.0, 0.0, 0.0), Vector3(5.0, 4.0, 6.0), 0.25, 0.8, 150
    else:
        lo, hi, rmin, rmax, fails = Vector3(0.0, 0.0, 0.0), Vector3(6.0, 5.0, 4.0), 0.2, 1.0, 200
    table = MNTable3D(lo, hi, 2.5 * rmax, 2 if case == "cluster" else 1)
    box = BoxWithPlanes3D(lo, hi)
    if case in ("planes", "cluster"):
        for point, normal in ((lo, (0, 1, 0)), (lo, (1, 0, 0)), (lo, (0, 0, 1)),
                              (hi, (0, -1, 0)), (hi, (-1, 0, 0)), (hi, (0, 0, -1))):
            box.addPlane(Plane(point, Vector3(*normal)))
        packer = InsertGenerator3D(rmin, rmax, fails, 1000, 1.0e-6, False)
        packer.generatePacking(box, table, 0, 2)
    else:
        packer = InsertGenerator3D(rmin, rmax, fails, 1000, 1.0e-6)
        packer.setOldSeeding(case == "old")
        packer.generatePacking(box, table)
    if case == "cluster":
        for i in range(2):
            for j in range(2):
                for k in range(3):
                    at = Vector3(0.7 + 2.9 * i + 0.3 * k, 0.9 + 2.2 * j + 0.2 * i, 0.8 + 1.9 * k + 0.4 * j)
                    seed = Sphere(at, 0.0)
                    seed.setTag(i * 6 + j * 3 + k)
                    table.insert(seed, 1)
        table.tagParticlesToClosest(0, 1)
        table.generateClusterBonds(0, 1.0e-5, 1, 3)
        table.removeParticlesInGroup(1)
    else:
        table.generateBonds(0, 1.0e-5, 0)
    for s in table.getSphereListFromGroup(0):
        c = s.Centre()
        print("sphere %d %.17g %.17g %.17g %.17g %d" % (s.Id(), c.X(), c.Y(), c.Z(), s.Radius(), s.Tag()))
    print("volume %.17g" % table.getSumVolume(groupID=0))
    table.write("gengeo_box_%s.geo" % case, 1)
    if case in ("planes", "cluster"):
        table.write("gengeo_box_%s.vtu" % case, 2)


for case in sys.argv[1:] or ["plain"]:
    pack(case)
