"""esys.lsm.vis.povray on Basalt: the calls ESyS-Particle's tutorial snapshots use (POVsnaps: a Scene of Sphere
objects, each with a colour, a camera placed, looking at a point and zoomed, Scene.render(...) to a file),
drawn with VTK instead of POV-Ray (basalt.esys.vis.draw) into the same file name. Every other name of the
package is refused (NotSupportedError naming the call); docs/esys.md, "POV-Ray snapshots"."""

import math
import os
import sys

from ..errors import refuse
from ..vec3 import Vec3

_MODULE = "esys.lsm.vis.povray"
_OFFER_OBJECTS = ("the front end draws Sphere objects with a colour (docs/esys.md, \"POV-Ray snapshots\"); "
                  "basalt-view renders Basalt's own checkpoints (docs/basalt-view.md)")


def _vec(v, what):
    try:
        x, y, z = (float(v[i]) for i in range(3))
    except (TypeError, IndexError, ValueError) as e:
        raise TypeError(f"{_MODULE}: {what} must be 3 numbers, got {v!r}") from e
    return (x, y, z)


# -- colours ----------------------------------------------------------------------------------------------------
class RgbColor:
    """A colour (red, green, blue), each 0..1, with an optional name."""

    def __init__(self, red, green, blue, name=None):
        self.rgb = (red, green, blue)
        self.name = name

    def __len__(self):
        return 3

    def __getitem__(self, i):
        return self.rgb[i]

    def __iter__(self):
        return iter(self.rgb)

    def __mul__(self, fraction):
        return RgbColor(self.rgb[0] * fraction, self.rgb[1] * fraction, self.rgb[2] * fraction)

    def __repr__(self):
        return f"RgbColor({self.rgb[0]!r}, {self.rgb[1]!r}, {self.rgb[2]!r}, name={self.name!r})"

    def getRgb(self):
        return self.rgb

    def getName(self):
        return self.name

    def setName(self, name):
        self.name = name


# POV-Ray's colors.inc (the names ESyS's Colors carries): the plain colours, the greys and a few more
_COLOURS = {
    "Red": (1, 0, 0), "Green": (0, 1, 0), "Blue": (0, 0, 1), "Yellow": (1, 1, 0), "Cyan": (0, 1, 1),
    "Magenta": (1, 0, 1), "White": (1, 1, 1), "Black": (0, 0, 0),
    "Gray": (0.752941, 0.752941, 0.752941), "Grey": (0.752941, 0.752941, 0.752941),
    "DimGray": (0.329412, 0.329412, 0.329412), "DimGrey": (0.329412, 0.329412, 0.329412),
    "LightGray": (0.658824, 0.658824, 0.658824), "LightGrey": (0.658824, 0.658824, 0.658824),
    "VLightGray": (0.8, 0.8, 0.8), "VLightGrey": (0.8, 0.8, 0.8),
    "Orange": (1, 0.5, 0.0), "OrangeRed": (1.0, 0.25, 0.0), "Brown": (0.647059, 0.164706, 0.164706),
    "Gold": (0.8, 0.498039, 0.196078), "Silver": (0.90, 0.91, 0.98), "SkyBlue": (0.196078, 0.6, 0.8),
    "Navy": (0.137255, 0.137255, 0.556863), "NavyBlue": (0.137255, 0.137255, 0.556863),
    "ForestGreen": (0.137255, 0.556863, 0.137255), "Firebrick": (0.556863, 0.137255, 0.137255),
    "Tan": (0.858824, 0.576471, 0.439216), "Wheat": (0.847059, 0.847059, 0.74902),
}
for _pct in range(5, 100, 5):  # Gray05 .. Gray95: White times the percentage
    _COLOURS[f"Gray{_pct:02d}"] = (_pct / 100, _pct / 100, _pct / 100)


class _ColorsType(type):
    def __getattr__(cls, name):
        if name.startswith("__"):
            raise AttributeError(name)
        refuse(f"{_MODULE}.Colors.{name}", "the front end names the plain colours, the greys and a few more "
               f"({', '.join(sorted(_COLOURS))}); any other colour: RgbColor(red, green, blue)")


class Colors(metaclass=_ColorsType):
    """Named colours, as class attributes (Colors.Red); not to be instantiated."""

    def __init__(self):
        raise NotImplementedError("This class is not designed for instantiation.")


for _name, _rgb in _COLOURS.items():
    setattr(Colors, _name, RgbColor(*_rgb, name=_name))


def findColor(colorName):
    """The colour named colorName (any case), or None."""
    for name, rgb in _COLOURS.items():
        if name.upper() == str(colorName).upper():
            return getattr(Colors, name)
    return None


class Pigment:
    """A colour for an object (Sphere.apply takes it, or an RgbColor, which it wraps in one)."""

    def __init__(self, pigment, transmit=0.0):
        if transmit:
            refuse(f"{_MODULE}.Pigment(transmit={transmit!r})", "opaque pigments only (transmit=0.0)")
        if not isinstance(pigment, RgbColor):
            refuse(f"{_MODULE}.Pigment({type(pigment).__name__})", "a pigment of an RgbColor (or a Colors name)")
        self.pigment = pigment
        self.transmit = transmit


# -- objects ----------------------------------------------------------------------------------------------------
class Sphere:
    """A sphere of the scene: centre, radius and (Sphere.apply) a colour; without one POV-Ray draws it black."""

    def __init__(self, center, radius):
        self.center = center
        self.radius = radius
        self.pigment = None

    def getCenter(self):
        return self.center

    def getRadius(self):
        return self.radius

    def applySingle(self, modifier):
        if modifier is None:
            return
        if isinstance(modifier, RgbColor):
            modifier = Pigment(modifier)
        if not isinstance(modifier, Pigment):
            refuse(f"{_MODULE}.Sphere.apply({type(modifier).__name__})", "a colour (RgbColor, Colors.NAME or "
                   "Pigment): finishes, textures, scaling and orientation are not drawn")
        self.pigment = modifier  # a later colour replaces an earlier one, as in ESyS (one modifier per class)

    def applySequence(self, sequence):
        for modifier in sequence:
            self.applySingle(modifier)

    def apply(self, modifiers):
        if modifiers is not None and hasattr(modifiers, "__iter__") and not isinstance(modifiers, RgbColor):
            self.applySequence(modifiers)
        else:
            self.applySingle(modifiers)

    def _colour(self):
        return tuple(self.pigment.pigment) if self.pigment is not None else (0.0, 0.0, 0.0)


# -- camera -----------------------------------------------------------------------------------------------------
class Camera:
    """ESyS's POV-Ray camera: orthographic, at posn, looking at lookAt; the picture is 2.05/zoom long units high
    (zoom 1 by default). `angle` has no effect (ESyS leaves it out of POV-Ray's input), nor setDirection (an
    orthographic camera with a look-at point ignores the direction's length)."""

    def __init__(self, posn, lookAt, angle=70.0):
        self.posn = posn
        self.lookAt = lookAt
        self.angle = angle
        self.direction = (0.0, 0.0, 0.1)
        self.zoomFactor = 1.0

    def getPosn(self):
        return self.posn

    def setPosn(self, posn):
        self.posn = posn

    def getLookAt(self):
        return self.lookAt

    def setLookAt(self, lookAt):
        self.lookAt = lookAt

    def setDirection(self, dir):
        self.direction = dir

    def setZoom(self, factor):
        self.zoomFactor = factor

    def getZoom(self):
        return self.zoomFactor

    def rotatePosn(self, axis, axisPt):
        """Turns the position about the axis through axisPt by abs(axis) radians (Vec3.rotate)."""
        self.setPosn(Vec3(self.getPosn()).rotate(Vec3(axis), Vec3(axisPt)))

    def rotate(self, axis, axisPt):
        """Turns the position and the look-at point about the axis through axisPt by abs(axis) radians."""
        self.setPosn(Vec3(self.getPosn()).rotate(Vec3(axis), Vec3(axisPt)))
        self.setLookAt(Vec3(self.getLookAt()).rotate(Vec3(axis), Vec3(axisPt)))


class LightedCamera(Camera):
    """The scene's camera, with a white light at its position (the light follows setPosn)."""

    def setLightSource(self, lightSource):
        refuse(f"{_MODULE}.LightedCamera.setLightSource", "the light is white and at the camera's position")


# -- the scene --------------------------------------------------------------------------------------------------
class RenderDefaults:
    """The values Scene.render uses for the arguments it is not given."""

    def __init__(self, defaultOffScreen, defaultSize, defaultInteractive):
        self.defaultOffScreen = defaultOffScreen
        self.defaultSize = defaultSize
        self.defaultInteractive = defaultInteractive

    def get(self, offScreen=None, size=None, interactive=None):
        return (self.defaultOffScreen if offScreen is None else offScreen,
                self.defaultSize if size is None else size,
                self.defaultInteractive if interactive is None else interactive)


_DEFAULTS = RenderDefaults(defaultOffScreen=False, defaultSize=[256, 256], defaultInteractive=True)
_FORMATS = ("PNG", "PNM")
_window_note = []


def _image_format(file_name, image_format):
    if image_format is not None:
        name = str(getattr(image_format, "getName", lambda: image_format)()).upper()
    else:
        ext = os.path.splitext(file_name)[1]
        if not ext:
            raise ValueError(f"Could not determine image format from file name {file_name}, no extension.")
        name = ext.lstrip(".").upper()
    if name not in _FORMATS:
        raise ValueError(f"No image format found which matched extension '{name.lower()}'; valid image file "
                         f"formats are: {', '.join(_FORMATS)}")
    return name


class Scene:
    """Spheres, a background (white unless set) and a camera (at (0, 0, -10) looking at the origin, zoom 1
    unless set); render() draws them into a file."""

    def __init__(self, renderDefaults=None):
        self.renderDefaults = renderDefaults if renderDefaults is not None else _DEFAULTS
        self.objectList = []
        self.camera = LightedCamera(posn=[0, 0, -10], lookAt=[0, 0, 0])
        self.background = Colors.White

    def add(self, object):
        if not isinstance(object, Sphere):
            refuse(f"{_MODULE}.Scene.add({type(object).__name__})", _OFFER_OBJECTS)
        self.objectList.append(object)

    def clear(self):
        """Removes the objects; the camera and the background stay."""
        self.objectList = []

    def setBackground(self, color):
        self.background = RgbColor(color[0], color[1], color[2], getattr(color, "getName", lambda: None)())

    def getCamera(self):
        return self.camera

    def setCamera(self, camera):
        if not isinstance(camera, Camera):
            refuse(f"{_MODULE}.Scene.setCamera({type(camera).__name__})", "a povray Camera")
        self.camera = camera

    def getRenderDefaults(self, offScreen=None, size=None, interactive=None):
        return self.renderDefaults.get(offScreen, size, interactive)

    def render(self, offScreen=None, interactive=None, fileName=None, imageFormat=None, size=None):
        """Draws the scene into fileName (PNG or PNM, from imageFormat or the name's extension), size
        [width, height] pixels (256 x 256 unless given), with VTK. No window is ever opened: offScreen=False
        and interactive=True (POV-Ray's window, and its pause) only write the file, and say so once."""
        offScreen, size, interactive = self.getRenderDefaults(offScreen, size, interactive)
        if fileName is None:
            refuse(f"{_MODULE}.Scene.render(fileName=None)", "pictures are written to files only (no window): "
                   "give fileName")
        fmt = _image_format(str(fileName), imageFormat)
        if (not offScreen or interactive) and not _window_note:
            _window_note.append(True)
            print(f"basalt.esys: {_MODULE}.Scene.render(offScreen={offScreen}, interactive={interactive}): no "
                  f"window is opened; the picture is written to {fileName}", file=sys.stderr)
        try:
            width, height = size
        except (TypeError, ValueError) as e:
            raise TypeError(f"{_MODULE}.Scene.render: size must be [width, height], got {size!r}") from e
        spheres = []
        for s in self.objectList:
            radius = float(s.getRadius())
            if not (radius > 0 and math.isfinite(radius)):
                raise ValueError(f"{_MODULE}.Sphere: radius {s.getRadius()!r} is not a positive number")
            spheres.append((_vec(s.getCenter(), "a sphere's centre"), radius, s._colour()))
        from .. import world

        if world()[0] != 0:  # several ranks: each builds the same scene, rank 0 draws it (the file appears once)
            return
        from .draw import draw
        cam = self.camera
        draw(str(fileName), fmt, (width, height), tuple(self.background), spheres,
             _vec(cam.getPosn(), "the camera's position"), _vec(cam.getLookAt(), "the camera's look-at point"),
             float(cam.getZoom()))


# -- the rest of ESyS's povray package: refused -----------------------------------------------------------------
REFUSED = ("Arrow", "ArrowExtractor", "Box", "Capsule", "Cone", "Cylinder", "CylinderExtractor", "EdgeData",
           "EdgeExtractor", "GlyphData", "SphereExtractor", "TriangulatedSurface", "SurfaceData",
           "PointExtractor", "Union", "Intersection", "Difference", "Merge", "Plane", "LightSource",
           "Background", "Finish", "Scale", "Orientation", "Checker", "Modifier", "PovRenderer", "Renderer")


def _stub(name):
    def __init__(self, *args, **kwargs):
        refuse(f"{_MODULE}.{name}", _OFFER_OBJECTS)
    return type(name, (), {"__init__": __init__, "__doc__": f"Refused by Basalt's ESyS front end: {_OFFER_OBJECTS}."})


globals().update({name: _stub(name) for name in REFUSED})

SUPPORTED = ["Scene", "Sphere", "Camera", "LightedCamera", "RgbColor", "Colors", "findColor", "Pigment",
             "RenderDefaults"]
__all__ = SUPPORTED + list(REFUSED)


def module_getattr(name):
    if name.startswith("__"):
        raise AttributeError(name)
    refuse(f"{_MODULE}.{name}", _OFFER_OBJECTS)
