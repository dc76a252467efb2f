"""python3 -m basalt.esys SCRIPT.py [ARGS...]: an ESyS-Particle script on Basalt (docs/esys.md)."""

import sys

USAGE = """usage: python3 -m basalt.esys SCRIPT.py [ARGS...]   (or: basalt-esys SCRIPT.py [ARGS...])
Runs an ESyS-Particle script (from esys.lsm import *, esys.lsm.util, esys.lsm.geometry) on Basalt. The esys
modules are Basalt's in this process only; docs/esys.md lists the supported and the refused calls."""


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv or argv[0] in ("-h", "--help"):
        print(USAGE, file=sys.stdout if argv else sys.stderr)
        return 0 if argv else 2
    from . import run_script

    run_script(argv[0], argv[1:])
    return 0


if __name__ == "__main__":
    sys.exit(main())
