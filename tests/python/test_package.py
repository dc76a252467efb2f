"""The package itself: what `import basalt` needs, its version, and scripts/python-path.sh (import basalt in a
new shell with no PYTHONPATH)."""

import os
import re
import subprocess
import sys

import pytest

import basalt

from conftest import BIN, ROOT

BUILD = BIN.parent


def python(code, env=None):
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)


def test_version_is_the_projects():
    text = (ROOT / "CMakeLists.txt").read_text()
    version = re.search(r"project\(Basalt VERSION (\S+)", text).group(1)
    assert basalt.__version__ == version
    from basalt import _core
    assert _core.__version__ == version


def test_import_needs_only_the_standard_library():
    # numpy and h5py made unimportable: import basalt works, and the readers say what is missing
    p = python("import sys\n"
               "sys.modules['h5py'] = None\n"
               "sys.modules['numpy'] = None\n"
               "import basalt\n"
               "print(basalt.__version__, sorted(n for n in sys.modules if n.startswith('basalt')))\n")
    assert p.returncode == 0, p.stderr
    assert p.stdout.split()[0] == basalt.__version__
    assert "basalt._core" not in p.stdout  # the compiled core loads on first use
    p = python("import sys\n"
               "sys.modules['h5py'] = None\n"
               "import basalt\n"
               "g = basalt.read_geometry(sys.argv[1] if len(sys.argv) > 1 else %r)\n"
               "print(len(g))\n"
               "try:\n"
               "    basalt.read_checkpoint(%r)\n"
               "except ImportError as e:\n"
               "    print('ImportError:', e)\n" % (str(ROOT / "tests/data/cube1.geo"), str(ROOT / "tests/data")))
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    assert lines[0] == "8948" and lines[1].startswith("ImportError: basalt's checkpoint reader needs h5py")
    assert "python3-h5py" in lines[1]


def test_public_names():
    for name in ("read_geometry", "read_checkpoint", "read_checkpoints", "read_fields", "Geometry", "Checkpoint",
                 "FormatError", "PackError", "pack"):
        assert name in dir(basalt) and getattr(basalt, name) is not None
    assert issubclass(basalt.FormatError, ValueError) and issubclass(basalt.PackError, ValueError)
    assert callable(basalt.pack.box) and basalt.pack.cylinder.__module__ == "basalt.pack"
    with pytest.raises(AttributeError):
        basalt.no_such_name


def test_h5py_and_the_core_load_in_either_order():
    # h5py links Debian's serial HDF5, _core the parallel one: both in one process, either first
    for first in ("import h5py; import basalt._core", "import basalt._core; import h5py"):
        p = python(first + f"; import basalt; print(basalt.read_checkpoint.__name__, "
                           f"len(basalt.read_geometry({str(ROOT / 'tests/data/cube1.geo')!r})))")
        assert p.returncode == 0 and p.stdout.split() == ["read_checkpoint", "8948"], p.stderr


def test_python_path_script(tmp_path):
    """scripts/python-path.sh writes basalt.pth into the user site-packages (here a scratch PYTHONUSERBASE, so the
    machine's own is untouched), a new shell with no PYTHONPATH imports the build's package, --remove undoes it."""
    env = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "PYTHONUSERBASE": str(tmp_path / "userbase")}
    script = ROOT / "scripts" / "python-path.sh"
    p = subprocess.run(["bash", script, BUILD], capture_output=True, text=True, env=env)
    assert p.returncode == 0, p.stdout + p.stderr
    pth = re.search(r"wrote (\S+basalt\.pth) -> (\S+)", p.stdout)
    assert pth and pth.group(2) == str(BUILD / "python") and pth.group(1).startswith(str(tmp_path / "userbase"))
    assert "--remove" in p.stdout
    new_shell = subprocess.run(["bash", "-c", "python3 -c 'import basalt; print(basalt.__file__)'"],
                               capture_output=True, text=True, env=env)
    assert new_shell.stdout.strip() == str(BUILD / "python" / "basalt" / "__init__.py"), new_shell.stderr
    again = subprocess.run(["bash", script, BUILD], capture_output=True, text=True, env=env)
    assert again.returncode == 0 and "already points at" in again.stdout
    gone = subprocess.run(["bash", script, "--remove", BUILD], capture_output=True, text=True, env=env)
    assert gone.returncode == 0 and f"removed {pth.group(1)}" in gone.stdout
    assert not os.path.exists(pth.group(1))
    new_shell = subprocess.run(["bash", "-c", "python3 -c 'import basalt'"], capture_output=True, text=True, env=env)
    assert new_shell.returncode != 0 and "No module named 'basalt'" in new_shell.stderr
