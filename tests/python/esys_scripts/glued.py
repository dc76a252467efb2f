# glued.py: a platen dragging spheres glued to it (NRotBondedWallPrms), ESyS-Particle tutorial style (the
# shear cell's bonded walls, in small), own numbers.
#   python3 -m basalt.esys glued.py          (or: mpirun -np 2 esysparticle glued.py)
# Three spheres of tag 2 sit on the platen and are glued to it; one of them starts with a sideways velocity
# and swings on its bond. A loose sphere (tag 1) slides off the middle glued one (NRotElasticPrms), another
# (tag 1) on the platen itself (the bonded wall's elastic part). A pre-time-step Runnable drags the platen
# sideways and lifts it a little every step; gravity pulls everything down.
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox

steps, r, K, dt = 1500, 0.5, 1000.0, 1.0e-3
sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(steps)
sim.setTimeStepSize(dt)
sim.setSpatialDomain(BoundingBox(Vec3(-10, -5, -5), Vec3(10, 10, 5)))

glued = [(0, -1.5, 0.0), (1, 0.0, 0.0), (2, 1.5, 0.3)]  # id, x, initial velocity along z
for pid, x, vz in glued:
    p = NRotSphere(id=pid, posn=Vec3(x, r, 0.0), radius=r, mass=1.0)
    p.setTag(2)
    p.setLinearVelocity(Vec3(0.0, 0.0, vz))
    sim.createParticle(p)
for pid, posn, radius in [(3, Vec3(0.3, 1.39, 0.0), 0.45), (4, Vec3(3.5, 0.38, 0.0), 0.4)]:
    p = NRotSphere(id=pid, posn=posn, radius=radius, mass=0.5)
    p.setTag(1)
    sim.createParticle(p)

sim.createWall(name="platen", posn=Vec3(0.0, 0.0, 0.0), normal=Vec3(0.0, 1.0, 0.0))
sim.createInteractionGroup(NRotBondedWallPrms(name="glue", wallName="platen", normalK=K, particleTag=2))
sim.createInteractionGroup(NRotElasticPrms(name="contact", normalK=2000.0, scaling=True))
sim.createInteractionGroup(GravityPrms(name="earth", acceleration=Vec3(0.0, -9.81, 0.0)))
sim.createFieldSaver(WallVectorFieldSaverPrms(wallName="platen", fieldName="Force", fileName="platen_force.dat",
                                              fileFormat="RAW_SERIES", beginTimeStep=0, endTimeStep=steps,
                                              timeStepIncr=10))
sim.createFieldSaver(WallVectorFieldSaverPrms(wallName="platen", fieldName="Position", fileName="platen_posn.dat",
                                              fileFormat="RAW_SERIES", beginTimeStep=0, endTimeStep=steps,
                                              timeStepIncr=100))
sim.createFieldSaver(ParticleVectorFieldSaverPrms(fieldName="position", fileName="glued_posn",
                                                  fileFormat="RAW_WITH_ID", beginTimeStep=0, endTimeStep=steps,
                                                  timeStepIncr=300))
sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="glued_ekin.dat", fileFormat="SUM",
                                                  beginTimeStep=0, endTimeStep=steps, timeStepIncr=10))


class Drag(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        self.sim.moveWallBy("platen", Vec3(2.0e-4, 2.0e-5, 0.0))


class Watch(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        t = self.sim.getTimeStep()
        if t % 25 == 0:
            f = self.sim.getWallForce("platen")
            for p in sorted(self.sim.getParticleList(), key=lambda q: q.getId()):  # ESyS: storage order
                x, v = p.getPosn(), p.getVelocity()
                print("glued %d %d %.12g %.12g %.12g %.12g %.12g %.12g" % (t, p.getId(), x[0], x[1], x[2], v[0],
                                                                            v[1], v[2]))
            print("force %d %.12g %.12g %.12g" % (t, f[0], f[1], f[2]))


drag, watch = Drag(sim), Watch(sim)  # kept: ESyS holds no reference to a Runnable (it crashes without these)
sim.addPreTimeStepRunnable(drag)
sim.addPostTimeStepRunnable(watch)
sim.run()
