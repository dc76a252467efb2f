"""ESyS-Particle's esys.lsm.vis on Basalt: the POV-Ray snapshots of the tutorial (POVsnaps) drawn with VTK.

`povray` holds the classes a script builds a picture with (Scene, Sphere, Colors, RgbColor, Pigment, the camera);
`draw` turns one Scene.render(...) into an image file through VTK's Python module (python3-vtk9), the same
toolkit basalt-view draws with; `display` gives VTK an X display on a machine without one (its own Xvfb, as
basalt-view does). docs/esys.md, "POV-Ray snapshots", says what is honoured and what is refused."""
