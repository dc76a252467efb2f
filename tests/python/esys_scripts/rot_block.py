# rot_block.py: a small bonded rock specimen crushed between two walls, ESyS-Particle rot_compress style, own
# numbers and no GenGeo. A CubicBlock of 4 x 8 x 4 RotSpheres (radius 0.5, mass r^3) bonded by ConnectionFinder
# with BrittleBeamPrms, FrictionPrms for the unbonded pairs (excluded from the bonds: createExclusion), linear
# and rotational damping; two walls at the block's ends along y, pushed together by a pre-time-step Runnable
# calling moveWallBy (its speed ramped up, WallLoader style).
#   python3 -m basalt.esys rot_block.py [STEPS [NUDGE]]   (or: mpirun -np 2 esysparticle rot_block.py ...)
# NUDGE shifts the block and the walls along x (a perturbation of the roundings only, for ESyS's own spread).
# Prints "walls STEP FY_BOTTOM FY_TOP" (getWallForce, from a post-time-step Runnable) every 100 steps; savers:
# both walls' Force and Position (RAW_SERIES) every 10 steps, e_kin (SUM) every 50; checkpoints at 0, 150, 300.
import sys

from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.geometry import CubicBlock, ConnectionFinder

STEPS = int(sys.argv[1]) if len(sys.argv) > 1 else 1500
NUDGE = float(sys.argv[2]) if len(sys.argv) > 2 else 0.0
DT = 1e-4
SPEED = 0.1        # each wall's speed after the ramp
RAMP = 500         # steps of the ramp

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="RotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(STEPS)
sim.setTimeStepSize(DT)
sim.setSpatialDomain(BoundingBox(Vec3(-5, -5, -5), Vec3(10, 15, 10)))

block = CubicBlock(dimCount=[4, 8, 4], radius=0.5)
if NUDGE:
    block.translate(Vec3(NUDGE, 0.0, 0.0))
sim.createParticles(block)
sim.createConnections(ConnectionFinder(maxDist=0.005, bondTag=1, pList=block))
low = min(p.getPosn()[1] - p.getRadius() for p in block)
high = max(p.getPosn()[1] + p.getRadius() for p in block)

sim.createWall(name="bottom", posn=Vec3(0.0, low, 0.0), normal=Vec3(0.0, 1.0, 0.0))
sim.createWall(name="top", posn=Vec3(0.0, high, 0.0), normal=Vec3(0.0, -1.0, 0.0))
sim.createInteractionGroup(BrittleBeamPrms(name="rock", youngsModulus=100000.0, poissonsRatio=0.25,
                                           cohesion=40.0, tanAngle=1.0, tag=1))
sim.createInteractionGroup(FrictionPrms(name="grains", youngsModulus=100000.0, poissonsRatio=0.25,
                                        dynamicMu=0.4, staticMu=0.6))
sim.createExclusion(interactionName1="rock", interactionName2="grains")
sim.createInteractionGroup(NRotElasticWallPrms(name="bottom_push", wallName="bottom", normalK=100000.0))
sim.createInteractionGroup(NRotElasticWallPrms(name="top_push", wallName="top", normalK=100000.0))
sim.createInteractionGroup(LinDampingPrms(name="damp", viscosity=0.05, maxIterations=50))
sim.createInteractionGroup(RotDampingPrms(name="rdamp", viscosity=0.05, maxIterations=50))


class Platens(Runnable):
    """Moves both walls towards each other by f v dt each step, f ramping from 0 to 1 over RAMP steps."""

    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim, self.n = sim, 0

    def run(self):
        f = min(self.n / float(RAMP), 1.0)
        d = f * SPEED * DT
        self.sim.moveWallBy("bottom", Vec3(0.0, d, 0.0))
        self.sim.moveWallBy("top", Vec3(0.0, -d, 0.0))
        self.n += 1


class Watch(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        t = self.sim.getTimeStep()
        if t % 100 == 0:
            fb, ft = self.sim.getWallForce("bottom"), self.sim.getWallForce("top")
            print("walls %d %.12g %.12g" % (t, fb[1], ft[1]))


platens = Platens(sim)  # kept: ESyS holds only a weak reference
sim.addPreTimeStepRunnable(platens)
watch = Watch(sim)
sim.addPostTimeStepRunnable(watch)
for field in ("Force", "Position"):
    sim.createFieldSaver(WallVectorFieldSaverPrms(wallName=["bottom", "top"], fieldName=field,
                                                  fileName="walls_%s.dat" % field, fileFormat="RAW_SERIES",
                                                  beginTimeStep=0, endTimeStep=STEPS, timeStepIncr=10))
sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin.dat", fileFormat="SUM",
                                                  beginTimeStep=0, endTimeStep=STEPS, timeStepIncr=50))
# checkpoints before the first bond breaks (about step 350)
sim.createCheckPointer(CheckPointPrms(fileNamePrefix="rock", beginTimeStep=0, endTimeStep=300, timeStepIncr=150))
sim.run()
