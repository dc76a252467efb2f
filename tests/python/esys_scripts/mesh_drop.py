# mesh_drop.py: spheres dropped on a triangle-mesh roof (readMesh + NRotElasticTriMeshPrms), ESyS-Particle
# tutorial style (the hopper's mesh floor, in small), own numbers.
#   python3 -m basalt.esys mesh_drop.py          (or: mpirun -np 2 esysparticle mesh_drop.py)
# The script writes its mesh, pyramid.msh (ESyS's .msh format): a low square pyramid, apex (0, 1, 0), base
# corners (+-3, 0, +-3), four triangles. Four spheres fall on it: onto a face, onto a sloping ridge (edge
# contacts), onto the base's outer edge and near the base's corner (corner contact), then slide off onto a
# planar floor below (NRotElasticWallPrms) and settle under LinDampingPrms.
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox

steps, dt = 2500, 5.0e-4
with open("pyramid.msh", "w") as f:  # node ids need not be their positions: the triangles name ids
    f.write("Triangle\n3D-Nodes 5\n"
            "10 10 0  0.0 1.0  0.0\n"
            "20 20 0 -3.0 0.0 -3.0\n"
            "30 30 0  3.0 0.0 -3.0\n"
            "40 40 0  3.0 0.0  3.0\n"
            "50 50 0 -3.0 0.0  3.0\n"
            "\nTri3 4\n"
            "0 0 10 20 30\n"
            "1 0 10 30 40\n"
            "2 0 10 40 50\n"
            "3 0 10 50 20\n")

sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(steps)
sim.setTimeStepSize(dt)
sim.setSpatialDomain(BoundingBox(Vec3(-8, -3, -8), Vec3(8, 6, 8)))
drops = [(0, Vec3(-1.2, 2.0, 0.3), 0.5),     # onto the face x < 0
         (1, Vec3(1.5, 2.2, 1.45), 0.45),    # onto the ridge from the apex to (3, 0, 3)
         (2, Vec3(0.4, 1.0, -3.3), 0.4),     # onto the base's outer edge z = -3
         (3, Vec3(-3.25, 1.2, 3.2), 0.5)]    # near the base's corner (-3, 0, 3)
for pid, posn, r in drops:
    sim.createParticle(NRotSphere(id=pid, posn=posn, radius=r, mass=r ** 3))
sim.readMesh(fileName="pyramid.msh", meshName="roof")
sim.createWall(name="floor", posn=Vec3(0.0, -2.0, 0.0), normal=Vec3(0.0, 1.0, 0.0))
sim.createInteractionGroup(NRotElasticTriMeshPrms(name="roof_repel", meshName="roof", normalK=1.0e4))
sim.createInteractionGroup(NRotElasticWallPrms(name="floor_repel", wallName="floor", normalK=1.0e4))
sim.createInteractionGroup(GravityPrms(name="earth", acceleration=Vec3(0.0, -9.81, 0.0)))
sim.createInteractionGroup(LinDampingPrms(name="air", viscosity=0.5, maxIterations=100))
sim.createFieldSaver(ParticleVectorFieldSaverPrms(fieldName="position", fileName="drop_posn",
                                                  fileFormat="RAW_WITH_ID", beginTimeStep=0, endTimeStep=steps,
                                                  timeStepIncr=500))
sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="drop_ekin.dat", fileFormat="SUM",
                                                  beginTimeStep=0, endTimeStep=steps, timeStepIncr=10))
sim.createFieldSaver(WallVectorFieldSaverPrms(wallName="floor", fieldName="Force", fileName="floor_force.dat",
                                              fileFormat="RAW_SERIES", beginTimeStep=0, endTimeStep=steps,
                                              timeStepIncr=10))


class Watch(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        t = self.sim.getTimeStep()
        if t % 25 == 0:
            for p in sorted(self.sim.getParticleList(), key=lambda q: q.getId()):  # ESyS: storage order
                x, v = p.getPosn(), p.getVelocity()
                print("drop %d %d %.12g %.12g %.12g %.12g %.12g %.12g" % (t, p.getId(), x[0], x[1], x[2], v[0],
                                                                           v[1], v[2]))


watch = Watch(sim)  # kept: ESyS holds no reference to a Runnable
sim.addPostTimeStepRunnable(watch)
sim.run()
