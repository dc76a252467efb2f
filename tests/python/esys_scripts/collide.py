# collide.py: two spheres meet head-on, ESyS-Particle tutorial style (bingle-like), own numbers.
#   python3 -m basalt.esys collide.py        (or: mpirun -np 2 esysparticle collide.py)
# Prints "contact STEP OVERLAP V1 V2" for every step in contact (a post-time-step Runnable) and the final
# velocities (at the last step); writes collide_t=*_0.txt/_1.txt checkpoints, ekin.dat (SUM) and vel.N.dat (RAW_WITH_ID).
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=3.0, verletDist=0.4)
sim.setNumTimeSteps(3000)
sim.setTimeStepSize(0.001)
sim.setSpatialDomain(BoundingBox(Vec3(-15, -15, -15), Vec3(15, 15, 15)))

particle = NRotSphere(id=0, posn=Vec3(-3.0, 0.5, 0.25), radius=1.0, mass=1.0)
particle.setLinearVelocity(Vec3(2.0, 0.0, 0.0))
sim.createParticle(particle)
particle = NRotSphere(id=1, posn=Vec3(3.0, 0.5, 0.25), radius=1.25, mass=2.0)
particle.setLinearVelocity(Vec3(-1.0, 0.0, 0.0))
sim.createParticle(particle)

sim.createInteractionGroup(NRotElasticPrms(name="repel", normalK=5000.0, scaling=True))

sim.createCheckPointer(CheckPointPrms(fileNamePrefix="collide", beginTimeStep=0, endTimeStep=3000,
                                      timeStepIncr=500))
sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin.dat", fileFormat="SUM",
                                                  beginTimeStep=0, endTimeStep=3000, timeStepIncr=10))
sim.createFieldSaver(ParticleVectorFieldSaverPrms(fieldName="velocity", fileName="vel", fileFormat="RAW_WITH_ID",
                                                  beginTimeStep=0, endTimeStep=3000, timeStepIncr=1000))


class ContactWatch(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        ps = sorted(self.sim.getParticleList(), key=lambda p: p.getId())
        gap = (ps[1].getPosn() - ps[0].getPosn()).norm() - ps[0].getRadius() - ps[1].getRadius()
        if gap < 0.0:
            print("contact %d %.12g %.12g %.12g" % (self.sim.getTimeStep(), -gap, ps[0].getVelocity()[0],
                                                    ps[1].getVelocity()[0]))
        if self.sim.getTimeStep() == self.sim.getNumTimeSteps():  # the last step: the final state
            for p in ps:
                v = p.getVelocity()
                print("final %d %.12g %.12g %.12g %g %g" % (p.getId(), v[0], v[1], v[2], p.getMass(), p.getRadius()))


watch = ContactWatch(sim)
sim.addPostTimeStepRunnable(watch)
sim.run()
