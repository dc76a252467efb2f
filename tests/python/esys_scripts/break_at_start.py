# break_at_start.py: three RotSpheres bonded 0-1 and 1-2 by BrittleBeamPrms (tag 2), the bonds resting at r1 + r2:
# 0-1 starts with a gap of 0.05 and breaks in the first force computation, 1-2 (gap 0.001) holds. ESyS applies a
# breaking bond's force in the step whose forces find it broken, so its step 1 kicks spheres 0 and 1 apart. With
# the bonds' potential_energy and count savers and a WallLoader-style pre-time-step Runnable moving a wall no
# sphere touches by zero (ESyS-Particle tutorial style, own numbers).
#   python3 -m basalt.esys break_at_start.py       (or: mpirun -np 2 esysparticle break_at_start.py)
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.geometry import TaggedIdConnection

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="RotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(20)
sim.setTimeStepSize(1.0e-3)
sim.setSpatialDomain(BoundingBox(Vec3(-10, -10, -10), Vec3(10, 10, 10)))
for k, (x, y) in enumerate([(0.0, 0.0), (1.05, 0.01), (2.051, 0.0)]):
    sim.createParticle(RotSphere(id=k, posn=Vec3(x, y, 0.0), radius=0.5, mass=0.125))
sim.createConnections([TaggedIdConnection(0, 1, 2), TaggedIdConnection(1, 2, 2)])
sim.createInteractionGroup(BrittleBeamPrms(name="b", youngsModulus=1000.0, poissonsRatio=0.25, cohesion=2.0,
                                           tanAngle=1.0, tag=2))
sim.createWall(name="far", posn=Vec3(0.0, -9.0, 0.0), normal=Vec3(0.0, 1.0, 0.0))
for field, name in (("potential_energy", "epot.dat"), ("count", "nbonds.dat")):
    sim.createFieldSaver(InteractionScalarFieldSaverPrms(interactionName="b", fieldName=field, fileName=name,
                                                         fileFormat="SUM", beginTimeStep=0, endTimeStep=20,
                                                         timeStepIncr=1))
sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin.dat", fileFormat="SUM",
                                                  beginTimeStep=0, endTimeStep=20, timeStepIncr=1))


class Still(Runnable):
    """Moves the far wall by nothing before every step (as WallLoader does while its ramp starts)."""

    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        self.sim.moveWallBy("far", Vec3(0.0, 0.0, 0.0))


still = Still(sim)  # kept: ESyS holds only a weak reference
sim.addPreTimeStepRunnable(still)
sim.run()
