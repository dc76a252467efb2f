# settle.py: a ball dropped on the floor comes to rest under damping, ESyS-Particle tutorial style
# (the tutorial's bouncing ball with LinDampingPrms), own numbers.
#   python3 -m basalt.esys settle.py          (or: mpirun -np 2 esysparticle settle.py)
# At rest the floor carries the ball's weight: wall force (0, -m g, 0), overlap m g / (pi r K).
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.5)
sim.setNumTimeSteps(6000)
sim.setTimeStepSize(0.001)
sim.setSpatialDomain(BoundingBox(Vec3(-10, -10, -10), Vec3(10, 10, 10)))

ball = NRotSphere(id=2, posn=Vec3(0.0, -2.0, 0.0), radius=1.25, mass=1.8)
sim.createParticle(ball)
sim.createInteractionGroup(GravityPrms(name="earth", acceleration=Vec3(0.0, -9.81, 0.0)))
sim.createWall(name="floor", posn=Vec3(0.0, -5.0, 0.0), normal=Vec3(0.0, 1.0, 0.0))
sim.createInteractionGroup(NRotElasticWallPrms(name="floor_contact", wallName="floor", normalK=2000.0))
sim.createInteractionGroup(LinDampingPrms(name="air", viscosity=10.0, maxIterations=100))
sim.createFieldSaver(WallVectorFieldSaverPrms(wallName=["floor"], fieldName="Force", fileName="floor_force.dat",
                                              fileFormat="RAW_SERIES", beginTimeStep=0, endTimeStep=6000,
                                              timeStepIncr=100))
sim.createCheckPointer(CheckPointPrms(fileNamePrefix="settle", beginTimeStep=1000, endTimeStep=6000,
                                      timeStepIncr=1000))


class Rest(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        if self.sim.getTimeStep() == self.sim.getNumTimeSteps():
            p = self.sim.getParticleList()[0]
            print("rest %.12g" % p.getPosn()[1])


rest = Rest(sim)
sim.addPostTimeStepRunnable(rest)
sim.run()
