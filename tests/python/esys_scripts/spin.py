# spin.py: two free RotSpheres, thrown and spun, slowed by LinDampingPrms and RotDampingPrms, ESyS-Particle
# tutorial style, own numbers.   python3 -m basalt.esys spin.py   (or mpirun -np 2 esysparticle spin.py)
# With nothing else acting, ESyS's damping rule (docs/reference-runs.md: 2 or 3 iterations here) multiplies v and w
# by about 1 - nu dt (1 - nu dt) each step.
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="RotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(1000)
sim.setTimeStepSize(1.0e-3)
sim.setSpatialDomain(BoundingBox(Vec3(-10, -10, -10), Vec3(10, 10, 10)))
for i, (x, v, w) in enumerate([(-3.0, (0.5, 0.2, 0.0), (0.0, 0.0, 4.0)), (3.0, (0.0, -0.3, 0.1), (2.0, -1.0, 0.5))]):
    p = RotSphere(id=i, posn=Vec3(x, 0.0, 0.0), radius=0.5 + 0.25 * i, mass=1.0 + i)
    p.setLinearVelocity(Vec3(*v))
    p.setAngularVelocity(Vec3(*w))
    sim.createParticle(p)
sim.createInteractionGroup(RotFrictionPrms(name="friction", normalK=1000.0, dynamicMu=0.4, staticMu=0.6,
                                           shearK=500.0, scaling=True))
sim.createInteractionGroup(LinDampingPrms(name="lin", viscosity=2.0, maxIterations=100))
sim.createInteractionGroup(RotDampingPrms(name="rot", viscosity=3.0, maxIterations=100))
sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin.dat", fileFormat="SUM",
                                                  beginTimeStep=0, endTimeStep=1000, timeStepIncr=10))


class Watch(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        t = self.sim.getTimeStep()
        if t % 50 == 0:
            for p in sorted(self.sim.getParticleList(), key=lambda q: q.getId()):
                v, w = p.getVelocity(), p.getAngularVelocity()
                print("spin %d %d %.12g %.12g %.12g %.12g %.12g %.12g" % (t, p.getId(), v[0], v[1], v[2], w[0],
                                                                         w[1], w[2]))


watch = Watch(sim)
sim.addPostTimeStepRunnable(watch)
sim.run()
