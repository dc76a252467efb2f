# geo_read.py: particles and bonds read from an ESyS .geo file (LsmMpi.readGeometry), ESyS-Particle tutorial style,
# own numbers. The script writes a small LSMGeometry 1.2 file first: a row of four touching spheres of radius
# 0.5 (tag 3, bonds of tag 7 between neighbours) and a loose sphere of radius 0.4 (tag 4) above them; the
# file's bounding box is the spatial domain (no setSpatialDomain). Under gravity the row, held by NRotBondPrms,
# falls onto a floor and the loose sphere onto the row (NRotElastic, excluded from the bonds).
#   python3 -m basalt.esys geo_read.py      (or: mpirun -np 2 esysparticle geo_read.py)
# Prints "particle ID TAG RADIUS MASS" for every particle before the run, "row STEP Y_MEAN VY_MEAN" and
# "ball STEP Y VY" every 100 steps (a post-time-step Runnable); a checkpoint every 500 steps.
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox

with open("row.geo", "w") as f:
    f.write("LSMGeometry 1.2\nBoundingBox -4 -4 -4 6 6 4\nPeriodicBoundaries 0 0 0\nDimension 3D\n"
            "BeginParticles\nSimple\n5\n")
    for k in range(4):
        f.write("%g 0 0 0.5 %d 3\n" % (k, 10 + k))
    f.write("1.6 1.2 0.1 0.4 20 4\nEndParticles\nBeginConnect\n3\n")
    for k in range(3):
        f.write("%d %d 7\n" % (10 + k, 11 + k))
    f.write("EndConnect\n")

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(2000)
sim.setTimeStepSize(0.001)
sim.readGeometry("row.geo")
for p in sorted(sim.getParticleList(), key=lambda q: q.getId()):
    print("particle %d %d %.12g %.12g" % (p.getId(), p.getTag(), p.getRadius(), p.getMass()))
sim.createInteractionGroup(NRotBondPrms(name="row_bonds", normalK=2000.0, breakDistance=10.0, tag=7, scaling=True))
sim.createInteractionGroup(NRotElasticPrms(name="touch", normalK=2000.0, scaling=True))
sim.createExclusion(interactionName1="row_bonds", interactionName2="touch")
sim.createInteractionGroup(GravityPrms(name="g", acceleration=Vec3(0.0, -9.81, 0.0)))
sim.createWall(name="floor", posn=Vec3(0.0, -1.5, 0.0), normal=Vec3(0.0, 1.0, 0.0))
sim.createInteractionGroup(NRotElasticWallPrms(name="floor_push", wallName="floor", normalK=2000.0))
sim.createInteractionGroup(LinDampingPrms(name="damp", viscosity=0.5, maxIterations=100))
sim.createCheckPointer(CheckPointPrms(fileNamePrefix="row", beginTimeStep=0, endTimeStep=2000, timeStepIncr=500))


class Watch(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        t = self.sim.getTimeStep()
        if t % 100 == 0:
            ps = {p.getId(): p for p in self.sim.getParticleList()}
            row = [ps[i] for i in range(10, 14)]
            print("row %d %.12g %.12g" % (t, sum(p.getPosn()[1] for p in row) / 4,
                                         sum(p.getVelocity()[1] for p in row) / 4))
            print("ball %d %.12g %.12g" % (t, ps[20].getPosn()[1], ps[20].getVelocity()[1]))


watch = Watch(sim)
sim.addPostTimeStepRunnable(watch)
sim.run()
