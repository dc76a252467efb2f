# cube_drop.py: a bonded block dropped on the floor, ESyS-Particle tutorial style (gravity_cube-like), own
# numbers. A CubicBlock of 4 x 4 x 4 spheres, turned about z, bonded by ConnectionFinder (NRotBondPrms,
# scaling=True), falls under gravity onto an elastic floor, with linear damping.
#   python3 -m basalt.esys cube_drop.py       (or: mpirun -np 2 esysparticle cube_drop.py)
# Prints "mass ID M" at the first step and "centre STEP X Y Z" every 250 steps (a post-time-step Runnable);
# savers: e_kin (SUM), positions (RAW_WITH_ID), the floor's force (RAW_SERIES).
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.geometry import CubicBlock, ConnectionFinder

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.5)
sim.setNumTimeSteps(3000)
sim.setTimeStepSize(0.001)
sim.setSpatialDomain(BoundingBox(Vec3(-12, -12, -12), Vec3(12, 12, 12)))

block = CubicBlock(dimCount=[4, 4, 4], radius=0.5)
block.rotate(axis=Vec3(0.0, 0.0, 0.4), axisPt=Vec3(1.0, 1.0, 1.0))
sim.createParticles(block)
sim.createConnections(ConnectionFinder(maxDist=0.005, bondTag=2, pList=block))
sim.createInteractionGroup(NRotBondPrms(name="glue", normalK=8000.0, breakDistance=50.0, tag=2, scaling=True))
sim.createInteractionGroup(GravityPrms(name="earth", acceleration=Vec3(0.0, -9.81, 0.0)))
sim.createWall(name="floor", posn=Vec3(0.0, -2.0, 0.0), normal=Vec3(0.0, 1.0, 0.0))
sim.createInteractionGroup(NRotElasticWallPrms(name="floor_contact", wallName="floor", normalK=8000.0))
sim.createInteractionGroup(LinDampingPrms(name="air", viscosity=0.2, maxIterations=100))

sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin.dat", fileFormat="SUM",
                                                  beginTimeStep=0, endTimeStep=3000, timeStepIncr=20))
sim.createFieldSaver(ParticleVectorFieldSaverPrms(fieldName="position", fileName="posn", fileFormat="RAW_WITH_ID",
                                                  beginTimeStep=0, endTimeStep=3000, timeStepIncr=1000))
sim.createFieldSaver(WallVectorFieldSaverPrms(wallName=["floor"], fieldName="Force", fileName="floor_force.dat",
                                              fileFormat="RAW_SERIES", beginTimeStep=0, endTimeStep=3000,
                                              timeStepIncr=20))


class Centre(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        n = self.sim.getTimeStep()
        ps = sorted(self.sim.getParticleList(), key=lambda p: p.getId())
        if n == 1:
            for p in ps[:3]:
                print("mass %d %.12g" % (p.getId(), p.getMass()))
        if n % 250 == 0:
            m = sum(p.getMass() for p in ps)
            c = [sum(p.getMass() * p.getPosn()[k] for p in ps) / m for k in range(3)]
            print("centre %d %.12g %.12g %.12g" % (n, c[0], c[1], c[2]))


centre = Centre(sim)
sim.addPostTimeStepRunnable(centre)
sim.run()
