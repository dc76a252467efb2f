# slide.py: a ball thrown sliding along the top of a huge, heavy sphere resting on the floor, ESyS-Particle
# tutorial style, own numbers.   python3 -m basalt.esys slide.py [rot|nrot]   (or mpirun -np 2 esysparticle ...)
#   rot:  RotSpheres, RotFrictionPrms: the slide decelerates at mu g while the spin grows at 2.5 mu g / r, until
#         the ball rolls at 5/7 of its throw; m v + I w / lever stays m v0 (friction's impulse about the contact)
#   nrot: NRotSpheres, NRotFrictionPrms: the slide decelerates at mu g and stops after v0^2 / (2 mu g)
# ESyS finds pairs and wall contacts within one gridSpacing: it must exceed the big sphere's diameter.
import sys

from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox

kind = sys.argv[1] if len(sys.argv) > 1 else "rot"
g, mu, v0, r, m, K = 10.0, 0.5, 1.0, 0.5, 1.0, 1.0e4
R, M, KW = 1000.0, 1.0e6, 1.0e4
sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="RotSphere" if kind == "rot" else "NRotSphere", gridSpacing=2 * R + 100,
                        verletDist=0.2)
sim.setNumTimeSteps(3000)
sim.setTimeStepSize(1.0e-4)
sim.setSpatialDomain(BoundingBox(Vec3(-20, -2 * R - 20, -20), Vec3(20, 20, 20)))
Sphere = RotSphere if kind == "rot" else NRotSphere
big_sink = (M + m) * g / (3.141592654 * R * KW)            # the heavy sphere at rest on the floor
big = Sphere(id=1, posn=Vec3(0.0, -R - 5.0 - big_sink, 0.0), radius=R, mass=M)
ball = Sphere(id=2, posn=Vec3(0.0, big.getPosn()[1] + R + r - m * g / K, 0.0), radius=r, mass=m)
ball.setLinearVelocity(Vec3(v0, 0.0, 0.0))
sim.createParticle(big)
sim.createParticle(ball)
sim.createWall(name="floor", posn=Vec3(0.0, -2 * R - 5.0, 0.0), normal=Vec3(0.0, 1.0, 0.0))
sim.createInteractionGroup(NRotElasticWallPrms(name="floor_contact", wallName="floor", normalK=KW))
sim.createInteractionGroup(GravityPrms(name="earth", acceleration=Vec3(0.0, -g, 0.0)))
if kind == "rot":
    sim.createInteractionGroup(RotFrictionPrms(name="friction", normalK=K, dynamicMu=mu, staticMu=mu, shearK=K,
                                               scaling=False))
else:
    sim.createInteractionGroup(NRotFrictionPrms(name="friction", normalK=K, dynamicMu=mu, shearK=K,
                                                scaling=False))


class Watch(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        t = self.sim.getTimeStep()
        if t % 100 == 0:
            p = [q for q in self.sim.getParticleList() if q.getId() == 2][0]
            w = p.getAngularVelocity()[2] if kind == "rot" else 0.0
            print("ball %d %.12g %.12g %.12g %.12g" % (t, p.getPosn()[0], p.getPosn()[1], p.getVelocity()[0], w))


watch = Watch(sim)
sim.addPostTimeStepRunnable(watch)
sim.run()
