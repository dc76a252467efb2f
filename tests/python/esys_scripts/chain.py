# chain.py: NRotBondPrms(scaling=True) on bonds of several sizes, ESyS-Particle tutorial style, own numbers.
# Four spheres of radii 0.5, 0.3, 0.4, 0.3 in a row along x, each pair bonded (tag 1) and started 0.05 further
# apart than r1 + r2, so every bond pulls from the first step with its own k = normalK (r1 + r2)/4 (ESyS's
# scaling); a fifth sphere bonded to the last with tag 2 (another group, unscaled) hangs below it.
#   python3 -m basalt.esys chain.py      (or: mpirun -np 2 esysparticle chain.py)
# Prints "chain STEP ID X Y VX VY" for every sphere every 50 steps (a post-time-step Runnable).
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.geometry import TaggedIdConnection

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(500)
sim.setTimeStepSize(0.001)
sim.setSpatialDomain(BoundingBox(Vec3(-5, -5, -5), Vec3(8, 5, 5)))
radii = [0.5, 0.3, 0.4, 0.3]
x = 0.0
for k, r in enumerate(radii):
    if k:
        x += radii[k - 1] + r + 0.05
    sim.createParticle(NRotSphere(id=k, posn=Vec3(x, 0.0, 0.0), radius=r, mass=r * r * r))
sim.createParticle(NRotSphere(id=4, posn=Vec3(x, -0.62, 0.0), radius=0.3, mass=0.027))
sim.createConnections([TaggedIdConnection(k, k + 1, 1) for k in range(3)] + [TaggedIdConnection(3, 4, 2)])
sim.createInteractionGroup(NRotBondPrms(name="row", normalK=100.0, breakDistance=10.0, tag=1, scaling=True))
sim.createInteractionGroup(NRotBondPrms(name="hang", normalK=20.0, breakDistance=10.0, tag=2, scaling=False))


class Watch(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        t = self.sim.getTimeStep()
        if t == 1 or t % 50 == 0:
            for p in sorted(self.sim.getParticleList(), key=lambda q: q.getId()):
                print("chain %d %d %.12g %.12g %.12g %.12g" % (t, p.getId(), p.getPosn()[0], p.getPosn()[1],
                                                                p.getVelocity()[0], p.getVelocity()[1]))


watch = Watch(sim)
sim.addPostTimeStepRunnable(watch)
sim.run()
