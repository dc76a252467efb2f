# slope_collapse.py: a block of spheres packed by RandomBoxPacker collapses on the floor under gravity
# (ESyS-Particle tutorial style, as its slope_fail.py, own numbers and a smaller block).
#   python3 -m basalt.esys slope_collapse.py      (or: mpirun -np 2 esysparticle slope_collapse.py)
# The spheres nearest the floor get tag 2. Prints the number of spheres, then every 500 steps the block's front (largest x + radius), top (largest
# y + radius) and lowest bottom (smallest y - radius); checkpoints every 1000 steps.
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.geometry import RandomBoxPacker

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.1)
sim.setNumTimeSteps(5000)
sim.setTimeStepSize(1.0e-4)
sim.setSpatialDomain(BoundingBox(Vec3(-12, -2, -12), Vec3(12, 12, 12)))

packer = RandomBoxPacker(minRadius=0.2, maxRadius=0.5, cubicPackRadius=1.1, maxInsertFails=400,
                         bBox=BoundingBox(Vec3(-3.0, 0.0, -2.0), Vec3(3.0, 5.0, 2.0)),
                         circDimList=[False, False, False], tolerance=1.0e-5)
packer.generate()
spheres = packer.getSimpleSphereCollection()
for s in spheres:  # one at a time, those nearest the floor tagged (as the tutorial's slope_friction_floor)
    if s.getPosn()[1] < 1.1 * s.getRadius():
        s.setTag(2)
    sim.createParticle(s)
print("spheres %d" % spheres.getNumSpheres())

sim.createWall(name="floor", posn=Vec3(0.0, 0.0, 0.0), normal=Vec3(0.0, 1.0, 0.0))
sim.createInteractionGroup(NRotElasticPrms(name="repulsion", normalK=1.0e3, scaling=True))
sim.createInteractionGroup(NRotElasticWallPrms(name="floor_contact", wallName="floor", normalK=1.0e4))
sim.createInteractionGroup(GravityPrms(name="earth", acceleration=Vec3(0.0, -9.81, 0.0)))
sim.createInteractionGroup(LinDampingPrms(name="viscosity", viscosity=0.1, maxIterations=100))
sim.createCheckPointer(CheckPointPrms(fileNamePrefix="slope", beginTimeStep=0, endTimeStep=5000,
                                      timeStepIncr=1000))


class Shape(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        if self.sim.getTimeStep() % 500 == 0:
            ps = self.sim.getParticleList()
            front = max(p.getPosn()[0] + p.getRadius() for p in ps)
            top = max(p.getPosn()[1] + p.getRadius() for p in ps)
            bottom = min(p.getPosn()[1] - p.getRadius() for p in ps)
            print("shape %d %.12g %.12g %.12g" % (self.sim.getTimeStep(), front, top, bottom))


shape = Shape(sim)  # ESyS keeps no reference to its Runnables: the script must
sim.addPostTimeStepRunnable(shape)
sim.run()
