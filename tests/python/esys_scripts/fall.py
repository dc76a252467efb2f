# fall.py: gravity and a floor, ESyS-Particle tutorial style (gravity-like), own numbers.
#   python3 -m basalt.esys fall.py            (or: mpirun -np 2 esysparticle fall.py)
# Ball 0 falls freely from y = 4 (it reaches the floor after step ~1200); ball 7 is thrown sideways out of
# the spatial domain (x > 8) and is deleted. A pre-time-step Runnable prints "pre STEP ID X Y Z VX VY VZ"
# every 100 steps and the particle count at the last step; savers: wall position and force (RAW_SERIES), e_kin (SUM),
# displacement (RAW2), force (RAW_WITH_ID).
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.5)
sim.setNumTimeSteps(1500)
sim.setTimeStepSize(0.001)
sim.setSpatialDomain(BoundingBox(Vec3(-8, -8, -8), Vec3(8, 8, 8)))

ball = NRotSphere(id=0, posn=Vec3(0.5, 4.0, -0.5), radius=1.5, mass=1.3)
ball.setLinearVelocity(Vec3(0.25, 1.5, 0.0))
sim.createParticle(ball)
thrown = NRotSphere(id=7, posn=Vec3(4.0, 0.0, 3.0), radius=0.5, mass=0.125)
thrown.setLinearVelocity(Vec3(12.0, 0.0, 0.0))
thrown.setTag(3)
sim.createParticle(thrown)

sim.createInteractionGroup(GravityPrms(name="earth", acceleration=Vec3(0.0, -9.81, 0.0)))
sim.createWall(name="floor", posn=Vec3(0.0, -5.0, 0.0), normal=Vec3(0.0, 1.0, 0.0))
sim.createInteractionGroup(NRotElasticWallPrms(name="floor_contact", wallName="floor", normalK=4000.0))

for field in ("Position", "Force"):
    sim.createFieldSaver(WallVectorFieldSaverPrms(wallName=["floor"], fieldName=field, fileName="floor_%s.dat" % field,
                                                  fileFormat="RAW_SERIES", beginTimeStep=0, endTimeStep=1500,
                                                  timeStepIncr=5))
sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin.dat", fileFormat="SUM",
                                                  beginTimeStep=0, endTimeStep=1500, timeStepIncr=50))
sim.createFieldSaver(ParticleVectorFieldSaverPrms(fieldName="displacement", fileName="disp", fileFormat="RAW2",
                                                  beginTimeStep=500, endTimeStep=1500, timeStepIncr=500))
sim.createFieldSaver(ParticleVectorFieldSaverPrms(fieldName="force", fileName="force", fileFormat="RAW_WITH_ID",
                                                  beginTimeStep=0, endTimeStep=1500, timeStepIncr=300))


class Report(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        n = self.sim.getTimeStep()
        if n % 100 == 1:
            for p in sorted(self.sim.getParticleList(), key=lambda p: p.getId()):
                x, v = p.getPosn(), p.getVelocity()
                print("pre %d %d %.12g %.12g %.12g %.12g %.12g %.12g" % (n, p.getId(), x[0], x[1], x[2],
                                                                         v[0], v[1], v[2]))
        if n == self.sim.getNumTimeSteps():
            print("particles", len(self.sim.getParticleList()))


report = Report(sim)
sim.addPreTimeStepRunnable(report)
sim.run()
