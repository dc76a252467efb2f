# pull.py: a row of three spheres bonded 0-1 and 1-2 (tag 3), sphere 0 thrown away from the others: bond 0-1
# breaks after a few steps, bond 1-2 holds. ESyS-Particle tutorial style, own numbers.
#   python3 -m basalt.esys pull.py [nrot|rot|beam]      (or: mpirun -np 2 esysparticle pull.py [nrot|rot|beam])
# nrot: NRotSpheres and NRotBondPrms (breakDistance); rot: RotSpheres and RotBondPrms (a normal breaking force);
# beam: RotSpheres and BrittleBeamPrms. A checkpoint every step (pull_t=T_0.txt, pull_t=T_1.txt): the bonds'
# section lists the bonds that have not broken, as ESyS writes it; nbonds.dat their count at every step
# (InteractionScalarFieldSaverPrms, count, SUM).
import sys

from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.geometry import TaggedIdConnection

mode = sys.argv[1] if len(sys.argv) > 1 else "nrot"
rot = mode in ("rot", "beam")
sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="RotSphere" if rot else "NRotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(20)
sim.setTimeStepSize(1.0e-3)
sim.setSpatialDomain(BoundingBox(Vec3(-10, -10, -10), Vec3(10, 10, 10)))
kind = RotSphere if rot else NRotSphere
for k in range(3):
    p = kind(id=k, posn=Vec3(1.0 * k, 0, 0), radius=0.5, mass=1.0)
    if k == 0:
        p.setLinearVelocity(Vec3(-1.0, 0, 0))
    sim.createParticle(p)
sim.createConnections([TaggedIdConnection(0, 1, 3), TaggedIdConnection(1, 2, 3)])
if mode == "beam":
    sim.createInteractionGroup(BrittleBeamPrms(name="b", youngsModulus=100.0, poissonsRatio=0.25, cohesion=0.5,
                                               tanAngle=1.0, tag=3))
elif rot:
    sim.createInteractionGroup(RotBondPrms(name="b", normalK=100.0, shearK=10.0, torsionK=1.0, bendingK=1.0,
                                           normalBrkForce=0.3, shearBrkForce=100.0, torsionBrkForce=100.0,
                                           bendingBrkForce=100.0, tag=3, scaling=False))
else:
    sim.createInteractionGroup(NRotBondPrms(name="b", normalK=100.0, breakDistance=0.005, tag=3, scaling=False))
sim.createCheckPointer(CheckPointPrms(fileNamePrefix="pull", beginTimeStep=0, endTimeStep=20, timeStepIncr=1))
sim.createFieldSaver(InteractionScalarFieldSaverPrms(interactionName="b", fieldName="count", fileName="nbonds.dat",
                                                     fileFormat="SUM", beginTimeStep=0, endTimeStep=20,
                                                     timeStepIncr=1))
sim.run()
sim.exit()
