"""One POV-Ray Scene.render(...) drawn with VTK (python3-vtk9) and written as a PNG (or PNM) file.

The camera is POV-Ray's orthographic camera as ESyS's povray package sets it up: the picture is 2.05/zoom
long units high and as wide as the image's aspect ratio makes it (square pixels); it looks from the camera's
position at its look-at point, with the picture's up the part of +y (POV-Ray's sky) across the line of sight
and its right the line of sight crossed with that up (ESyS flips POV-Ray's right vector so that the picture
shows a right-handed world: from +z, x to the right and y up). Looking along y, POV-Ray keeps the right vector
ESyS gave (-x, then flipped): the picture's right is +x and its up (+x) x (line of sight). Nothing behind the
camera's position is drawn (an orthographic ray starts there). The light is a white light at the camera (ESyS's
LightedCamera, shadowless), with POV-Ray's default finish: ambient 0.1, diffuse 0.6, no highlight."""

import atexit
import math
import os

from .display import ensure_display

AMBIENT, DIFFUSE = 0.1, 0.6  # POV-Ray's default finish

_window = None  # one render window for the process, reused by every picture (its GL set-up made once)


class VtkMissingError(RuntimeError):
    """VTK's Python module (python3-vtk9) is not installed."""


def _vtk():
    try:
        import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL back end's factories)
        from vtkmodules import vtkCommonCore, vtkCommonDataModel, vtkFiltersSources, vtkIOImage, vtkRenderingCore
    except ImportError as e:
        raise VtkMissingError(f"VTK's Python module is not installed ({e}): apt-get install python3-vtk9") from e
    return vtkCommonCore, vtkCommonDataModel, vtkFiltersSources, vtkIOImage, vtkRenderingCore


def _close_window():
    global _window
    if _window is not None:
        _window.Finalize()
        _window = None


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _unit(a):
    n = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    return (a[0] / n, a[1] / n, a[2] / n)


def picture_axes(posn, look_at):
    """The picture's right and up directions (unit vectors, world coordinates) for a camera at `posn` looking
    at `look_at`, as POV-Ray's look_at sets them for ESyS's camera (module docstring)."""
    d = _sub(look_at, posn)
    if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < 1e-10:  # POV-Ray's EPSILON on the squared length
        raise ValueError("esys.lsm.vis.povray camera: the position and the look-at point are the same "
                         "(POV-Ray: \"Camera location and look_at point must be different\")")
    d = _unit(d)
    sky = (0.0, 1.0, 0.0)
    s = _cross(sky, d)
    if max(abs(c) for c in s) < 1e-10:  # looking along y: POV-Ray keeps the right vector given (-x)
        s = (-1.0, 0.0, 0.0)
    s = _unit(s)
    up = _cross(d, s)
    right = (-s[0], -s[1], -s[2])  # ESyS's right vector points the other way: the handedness flip
    return right, up


def draw(file_name, image_format, size, background, spheres, posn, look_at, zoom):
    """Draws `spheres` ((centre, radius, (r, g, b)) with colours in 0..1) on `background` (r, g, b) as seen by
    the camera (posn, look_at, zoom) into `file_name`, an image of size (width, height), format "PNG" or
    "PNM"; written under a temporary name and renamed."""
    core, data, sources, io, rendering = _vtk()
    global _window
    width, height = int(size[0]), int(size[1])
    if width <= 0 or height <= 0:
        raise ValueError(f"esys.lsm.vis.povray Scene.render: size {list(size)} is not a picture size")
    if not zoom > 0:
        raise ValueError(f"esys.lsm.vis.povray Camera.setZoom: the zoom factor {zoom} must be above 0")
    _, up = picture_axes(posn, look_at)  # VTK's right is the line of sight x up: the same
    ensure_display()

    # positions relative to the look-at point (subtracted in double precision, as basalt-view does)
    points = core.vtkPoints()
    points.SetDataTypeToDouble()
    radii = core.vtkDoubleArray()
    radii.SetName("radius")
    colours = core.vtkUnsignedCharArray()
    colours.SetName("colour")
    colours.SetNumberOfComponents(3)
    for centre, radius, rgb in spheres:
        points.InsertNextPoint(*_sub(centre, look_at))
        radii.InsertNextValue(float(radius))
        colours.InsertNextTuple3(*(round(255 * min(max(float(c), 0.0), 1.0)) for c in rgb))
    cloud = data.vtkPolyData()
    cloud.SetPoints(points)
    cloud.GetPointData().AddArray(radii)
    cloud.GetPointData().SetScalars(colours)

    # triangulated spheres with segments of at most about 4 pixels along the largest sphere's outline
    # (between 12 and 64 around): Mesa's software rasteriser, which Xvfb gives, pays for every triangle
    r_px = max((r for _, r, _ in spheres), default=0.0) * height * zoom / 2.05
    around = min(max(math.ceil(2 * math.pi * r_px / 4), 12), 64)
    sphere = sources.vtkSphereSource()
    sphere.SetRadius(1.0)
    sphere.SetThetaResolution(around)
    sphere.SetPhiResolution(max(around // 2, 6))
    mapper = rendering.vtkGlyph3DMapper()
    mapper.SetInputData(cloud)
    mapper.SetSourceConnection(sphere.GetOutputPort())
    mapper.SetScaleArray("radius")
    mapper.SetScaleModeToScaleByMagnitude()
    mapper.SetScaleFactor(1.0)
    mapper.OrientOff()
    mapper.SetColorModeToDirectScalars()
    mapper.ScalarVisibilityOn()
    actor = rendering.vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    prop.SetAmbient(AMBIENT)
    prop.SetDiffuse(DIFFUSE)
    prop.SetSpecular(0.0)

    renderer = rendering.vtkRenderer()
    renderer.SetBackground(*(float(c) for c in background))
    renderer.AutomaticLightCreationOff()
    light = rendering.vtkLight()
    light.SetLightTypeToHeadlight()
    light.SetColor(1.0, 1.0, 1.0)
    light.SetIntensity(1.0)
    renderer.AddLight(light)
    if spheres:
        renderer.AddActor(actor)
    cam = renderer.GetActiveCamera()
    cam.ParallelProjectionOn()
    cam.SetFocalPoint(0.0, 0.0, 0.0)
    cam.SetPosition(*_sub(posn, look_at))
    cam.SetViewUp(*up)
    cam.SetParallelScale(1.025 / zoom)  # half of the picture's height, 2.05/zoom
    if spheres:
        renderer.ResetCameraClippingRange()

    if _window is None:
        _window = rendering.vtkRenderWindow()
        _window.SetOffScreenRendering(1)
        _window.SetMultiSamples(0)
        # closed before the virtual X server stops (atexit runs the later registration first): a window
        # still connected when its server goes makes Xlib end the process with a fatal I/O error
        atexit.register(_close_window)
    window = _window
    window.GetRenderers().RemoveAllItems()
    window.AddRenderer(renderer)
    window.SetSize(width, height)
    window.Render()
    grab = rendering.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.ShouldRerenderOff()  # drawn just above
    grab.Update()
    got = grab.GetOutput().GetDimensions()
    if (got[0], got[1]) != (width, height):
        raise RuntimeError(f"esys.lsm.vis.povray Scene.render: VTK drew {got[0]}x{got[1]} pixels, not "
                           f"{width}x{height}")
    writer = io.vtkPNGWriter() if image_format == "PNG" else io.vtkPNMWriter()
    directory, base = os.path.split(os.path.abspath(file_name))
    tmp = os.path.join(directory, f".{base}.{os.getpid()}.tmp")
    writer.SetFileName(tmp)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    if writer.GetErrorCode() != 0 or not os.path.exists(tmp):
        if os.path.exists(tmp):
            os.remove(tmp)
        raise OSError(f"esys.lsm.vis.povray Scene.render: could not write {file_name}")
    os.replace(tmp, file_name)
    window.RemoveRenderer(renderer)
