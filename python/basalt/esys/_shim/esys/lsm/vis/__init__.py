"""esys.lsm.vis (POV-Ray snapshots) is absent from Debian's ESyS-Particle build and from Basalt's front end."""
raise ImportError("esys.lsm.vis: not supported by Basalt's ESyS-Particle front end (Debian's ESyS-Particle "
                  "lacks it too): render Basalt's frames and checkpoints with basalt-view (docs/basalt-view.md)")
