"""Basalt's stand-in for ESyS-Particle's `esys` package: on sys.path only inside `python3 -m basalt.esys`."""
