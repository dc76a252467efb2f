# press.py: a platen lowered onto a heavy ball by a WallLoader-style Runnable (LsmMpi.moveWallBy before each
# step), ESyS-Particle tutorial style, own numbers.   python3 -m basalt.esys press.py   (or mpirun -np 2 esysparticle)
# The platen starts touching the ball's top and moves down by d each step from step 1: after N moves it is
# N d lower, and the force of step N (from the ball where it was after step N - 1, the platen moved N times)
# is pi r K N d: the ball is too heavy (1e9) to give way noticeably.
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox

d, r, K, steps = 1.0e-4, 0.5, 1000.0, 400
sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(steps)
sim.setTimeStepSize(1.0e-3)
sim.setSpatialDomain(BoundingBox(Vec3(-5, -5, -5), Vec3(5, 5, 5)))
sim.createParticle(NRotSphere(id=0, posn=Vec3(0.0, 0.0, 0.0), radius=r, mass=1.0e9))
sim.createWall(name="platen", posn=Vec3(0.0, 2.0, 0.0), normal=Vec3(0.0, -1.0, 0.0))
sim.moveWallBy("platen", Vec3(0.0, r - 2.0, 0.0))          # before the run: now touching the ball's top
sim.createInteractionGroup(NRotElasticWallPrms(name="platen_contact", wallName="platen", normalK=K))
sim.createFieldSaver(WallVectorFieldSaverPrms(wallName="platen", fieldName="Position", fileName="platen.dat",
                                              fileFormat="RAW_SERIES", beginTimeStep=0, endTimeStep=steps,
                                              timeStepIncr=50))


class WallLoader(Runnable):
    def __init__(self, sim, wallName, displacement):
        Runnable.__init__(self)
        self.sim, self.wallName, self.displacement = sim, wallName, displacement

    def run(self):
        self.sim.moveWallBy(self.wallName, self.displacement)


class Watch(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        t = self.sim.getTimeStep()
        if t % 20 == 0:
            w, f = self.sim.getWallPosition("platen"), self.sim.getWallForce("platen")
            p = self.sim.getParticleList()[0]
            print("platen %d %.12g %.12g %.12g" % (t, w[1], f[1], p.getPosn()[1]))


loader = WallLoader(sim, "platen", Vec3(0.0, -d, 0.0))
watch = Watch(sim)
sim.addPreTimeStepRunnable(loader)
sim.addPostTimeStepRunnable(watch)
sim.run()
