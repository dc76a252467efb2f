# block_large.py: a large bonded block dropped on the floor, ESyS-Particle tutorial style (gravity_cube at
# scale), own numbers: N x N x N spheres (N = 12 unless given: 1,728), 5,000 steps, no Runnable (timing runs,
# docs/esys.md). NUDGE (default 0) shifts the block along x before it is created (a perturbation, to measure
# how far ESyS's own runs spread).
#   python3 -m basalt.esys block_large.py [N [NUDGE]]     (or: mpirun -np 2 esysparticle block_large.py [N [NUDGE]])
# Savers: e_kin (SUM every 100 steps), positions (RAW_WITH_ID at steps 0 and 5,000), the floor's position.
import sys

from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.geometry import CubicBlock, ConnectionFinder

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.5)
sim.setNumTimeSteps(5000)
sim.setTimeStepSize(0.001)
n = int(sys.argv[1]) if len(sys.argv) > 1 else 12
nudge = float(sys.argv[2]) if len(sys.argv) > 2 else 0.0
top = 5.0 + 1.25 * n
sim.setSpatialDomain(BoundingBox(Vec3(-5, -5, -5), Vec3(top, top, top)))

block = CubicBlock(dimCount=[n, n, n], radius=0.5)
block.rotate(axis=Vec3(0.0, 0.0, 0.3), axisPt=Vec3(0.5 * n, 0.41 * n, 0.5 * n))
if nudge != 0.0:
    block.translate(Vec3(nudge, 0.0, 0.0))
sim.createParticles(block)
sim.createConnections(ConnectionFinder(maxDist=0.005, bondTag=1, pList=block))
sim.createInteractionGroup(NRotBondPrms(name="glue", normalK=5000.0, breakDistance=50.0, tag=1, scaling=True))
sim.createInteractionGroup(GravityPrms(name="earth", acceleration=Vec3(0.0, -9.81, 0.0)))
sim.createWall(name="floor", posn=Vec3(0.0, -(0.15 * n + 0.7), 0.0), normal=Vec3(0.0, 1.0, 0.0))  # below the block
sim.createInteractionGroup(NRotElasticWallPrms(name="floor_contact", wallName="floor", normalK=5000.0))
sim.createInteractionGroup(LinDampingPrms(name="air", viscosity=0.5, maxIterations=100))

sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin.dat", fileFormat="SUM",
                                                  beginTimeStep=0, endTimeStep=5000, timeStepIncr=100))
sim.createFieldSaver(ParticleVectorFieldSaverPrms(fieldName="position", fileName="posn", fileFormat="RAW_WITH_ID",
                                                  beginTimeStep=0, endTimeStep=5000, timeStepIncr=5000))
sim.createFieldSaver(WallVectorFieldSaverPrms(wallName=["floor"], fieldName="Position", fileName="floor.dat",
                                              fileFormat="RAW_SERIES", beginTimeStep=0, endTimeStep=5000,
                                              timeStepIncr=1000))
sim.run()
