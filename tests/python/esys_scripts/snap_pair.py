# snap_pair.py: two spheres drift apart and a Snaps Runnable (snaps.py, POVsnaps-style) renders them twice,
# ESyS-Particle tutorial style (bingle_Runnable-like), own numbers.
#   python3 -m basalt.esys snap_pair.py [CX CY CZ  LX LY LZ  ZOOM  WIDTH HEIGHT [black]]
# The camera at (CX, CY, CZ) looks at (LX, LY, LZ) with zoom ZOOM (default: from (0, 0, 20) at the origin,
# 0.1, 320 x 240, ESyS's white background; "black" sets a black one). A red sphere (tag 1, radius 1) starts at
# (-3, 0, 0) moving along +x at 10, a blue one (tag 2, radius 0.5) sits at (3, 1.5, -2.5). Snapshots at steps 10
# and 20 (snap_0000.png, snap_0001.png); each prints "snap FILE STEP TAG X Y Z R" per sphere.
import sys

from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.vis import povray
from snaps import Snaps

args = [float(a) for a in sys.argv[1:10]] if len(sys.argv) > 9 else [0, 0, 20, 0, 0, 0, 0.1, 320, 240]

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.5)
sim.setNumTimeSteps(20)
sim.setTimeStepSize(0.01)
sim.setSpatialDomain(BoundingBox(Vec3(-10, -10, -10), Vec3(10, 10, 10)))

red = NRotSphere(id=0, posn=Vec3(-3.0, 0.0, 0.0), radius=1.0, mass=1.0)
red.setLinearVelocity(Vec3(10.0, 0.0, 0.0))
red.setTag(1)
sim.createParticle(red)
blue = NRotSphere(id=1, posn=Vec3(3.0, 1.5, -2.5), radius=0.5, mass=0.125)
blue.setTag(2)
sim.createParticle(blue)
sim.createInteractionGroup(NRotElasticPrms(name="elastic", normalK=1000.0, scaling=True))

snaps = Snaps(sim=sim, interval=10)
snaps.configure(camPosn=Vec3(args[0], args[1], args[2]), lookAt=Vec3(args[3], args[4], args[5]),
                zoomFactor=args[6], imageSize=[int(args[7]), int(args[8])],
                background=povray.Colors.Black if "black" in sys.argv[10:] else None)
sim.addPostTimeStepRunnable(snaps)
sim.run()
