# twist.py: a row of four RotSpheres bonded 0-1, 1-2, 2-3 (tag 2), started with small gaps (the bonds rest at
# r1 + r2), sphere 3 thrown sideways and spun: the bonds stretch, shear, bend and twist, and the last one breaks.
# ESyS-Particle tutorial style, own numbers.
#   python3 -m basalt.esys twist.py [beam|rot|rotscaled] [STEPS]   (or: mpirun -np 2 esysparticle twist.py ...)
# beam: BrittleBeamPrms; rot: RotBondPrms scaling=False; rotscaled: RotBondPrms scaled per bond (ESyS's default).
# Savers every step: the bonds' potential_energy and count (InteractionScalarFieldSaverPrms, SUM) and e_kin.
import sys

from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.geometry import TaggedIdConnection

mode = sys.argv[1] if len(sys.argv) > 1 else "beam"
steps = int(sys.argv[2]) if len(sys.argv) > 2 else 60
sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="RotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(steps)
sim.setTimeStepSize(1.0e-3)
sim.setSpatialDomain(BoundingBox(Vec3(-10, -10, -10), Vec3(10, 10, 10)))
xs = [0.0, 1.003, 1.904, 2.7025]
rs = [0.5, 0.5, 0.4, 0.4]
for k in range(4):
    p = RotSphere(id=k, posn=Vec3(xs[k], 0.001 * k, 0.0), radius=rs[k], mass=rs[k] ** 3)
    if k == 3:
        p.setLinearVelocity(Vec3(0.2, 0.6, -0.3))
        p.setAngularVelocity(Vec3(3.0, 1.0, -2.0))
    if k == 0:
        p.setAngularVelocity(Vec3(-0.5, 0.0, 0.4))
    sim.createParticle(p)
sim.createConnections([TaggedIdConnection(0, 1, 2), TaggedIdConnection(1, 2, 2), TaggedIdConnection(2, 3, 2)])
if mode == "beam":
    sim.createInteractionGroup(BrittleBeamPrms(name="b", youngsModulus=1000.0, poissonsRatio=0.25, cohesion=6.0,
                                               tanAngle=1.0, tag=2))
elif mode == "rot":
    sim.createInteractionGroup(RotBondPrms(name="b", normalK=500.0, shearK=100.0, torsionK=20.0, bendingK=30.0,
                                           normalBrkForce=2.0, shearBrkForce=1.5, torsionBrkForce=0.4,
                                           bendingBrkForce=0.5, tag=2, scaling=False))
else:
    sim.createInteractionGroup(RotBondPrms(name="b", normalK=2000.0, shearK=800.0, torsionK=500.0, bendingK=900.0,
                                           normalBrkForce=9.0, shearBrkForce=5.0, torsionBrkForce=8.0,
                                           bendingBrkForce=8.0, tag=2))
for field, name in (("potential_energy", "epot.dat"), ("count", "nbonds.dat")):
    sim.createFieldSaver(InteractionScalarFieldSaverPrms(interactionName="b", fieldName=field, fileName=name,
                                                         fileFormat="SUM", beginTimeStep=0, endTimeStep=steps,
                                                         timeStepIncr=1))
sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin.dat", fileFormat="SUM",
                                                  beginTimeStep=0, endTimeStep=steps, timeStepIncr=1))
sim.run()
