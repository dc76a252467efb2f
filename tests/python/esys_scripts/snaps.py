# snaps.py: a Runnable taking POV-Ray snapshots in the style of ESyS-Particle's tutorial (its POVsnaps), our
# own: every `interval` steps a Scene of one Sphere per particle, coloured by the particle's tag, a camera
# placed by configure(), rendered to snap_NNNN.png. On Basalt the picture is drawn with VTK (docs/esys.md).
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.vis import povray

TAG_COLOURS = {1: povray.Colors.Red, 2: povray.Colors.Blue}


class Snaps(Runnable):
    def __init__(self, sim, interval):
        Runnable.__init__(self)
        self.sim = sim
        self.interval = interval
        self.count = 0
        self.configure()

    def configure(self, lookAt=Vec3(0, 0, 0), camPosn=Vec3(0, 0, 20), zoomFactor=0.1, imageSize=[800, 600],
                  background=None):
        self.lookAt = lookAt
        self.camPosn = camPosn
        self.zoomFactor = zoomFactor
        self.imageSize = imageSize
        self.background = background

    def run(self):
        if self.sim.getTimeStep() % self.interval == 0:
            self.snapshot()
            self.count += 1

    def snapshot(self):
        scene = povray.Scene()
        if self.background is not None:
            scene.setBackground(self.background)
        fname = "snap_{0:04d}.png".format(self.count)
        for pp in self.sim.getParticleList():
            sphere = povray.Sphere(pp.getPosn(), pp.getRadius())
            sphere.apply(TAG_COLOURS.get(pp.getTag(), povray.Colors.Green))
            scene.add(sphere)
            x = pp.getPosn()
            print("snap %s %d %d %.12g %.12g %.12g %.12g" % (fname, self.sim.getTimeStep(), pp.getTag(), x[0], x[1],
                                                            x[2], pp.getRadius()))
        camera = scene.getCamera()
        camera.setLookAt(self.lookAt)
        camera.setPosn(self.camPosn)
        camera.setZoom(self.zoomFactor)
        scene.render(offScreen=True, interactive=False, fileName=fname, size=self.imageSize)
