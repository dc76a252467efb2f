"""Basalt's ESyS-Particle front end (python/basalt/esys, docs/esys.md): tutorial-style scripts
(tests/python/esys_scripts/, our own) run through `python3 -m basalt.esys` against closed forms, the savers'
and checkpoints' text formats line by line, refused calls, and no shadowing of a real `esys` elsewhere.
ESyS-Particle itself is not needed (tools/esys/compare_tutorial.py compares with it when installed)."""

import hashlib
import math
import os
import pathlib
import re
import shutil
import struct
import subprocess
import sys

import pytest

from conftest import ROOT

SCRIPTS = ROOT / "tests" / "python" / "esys_scripts"
basalt = pytest.importorskip("basalt")
PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(basalt.__file__)))  # the build's python/


def front(script, cwd, *args, check=True):
    """python3 -m basalt.esys SCRIPT in cwd; returns the CompletedProcess."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_COMM_WORLD", "PMI_RANK", "PMI_SIZE"))}
    env["PYTHONPATH"] = PACKAGE_DIR
    p = subprocess.run([sys.executable, "-m", "basalt.esys", str(script), *args], cwd=cwd, capture_output=True,
                       text=True, env=env, timeout=300)
    if check and p.returncode != 0:
        pytest.fail(f"basalt.esys {script} exited {p.returncode}:\n{p.stdout}\n{p.stderr}")
    return p


@pytest.fixture(scope="module")
def collide(tmp_path_factory):
    d = tmp_path_factory.mktemp("collide")
    return d, front(SCRIPTS / "collide.py", d).stdout


@pytest.fixture(scope="module")
def fall(tmp_path_factory):
    d = tmp_path_factory.mktemp("fall")
    return d, front(SCRIPTS / "fall.py", d).stdout


def lines(out, key):
    return [[float(w) for w in line.split()[1:]] for line in out.splitlines() if line.startswith(key + " ")]


# -- the collision (bingle-like) ------------------------------------------------------------------------------
M1, M2, R1, R2, K, DT = 1.0, 2.0, 1.0, 1.25, 5000.0, 1e-3


def test_collision_rebounds_as_the_closed_form(collide):
    _, out = collide
    final = {int(r[0]): r[1:] for r in lines(out, "final")}
    u1, u2 = 2.0, -1.0  # head-on along x (same y, z): an elastic collision of two masses
    w1 = ((M1 - M2) * u1 + 2 * M2 * u2) / (M1 + M2)
    w2 = ((M2 - M1) * u2 + 2 * M1 * u1) / (M1 + M2)
    assert final[0][0] == pytest.approx(w1, abs=0.02) and final[1][0] == pytest.approx(w2, abs=0.02)
    assert final[0][1] == 0.0 and final[0][2] == 0.0 and final[1][1] == 0.0
    # momentum exactly, energy to symplectic Euler's O(dt) error
    assert M1 * final[0][0] + M2 * final[1][0] == pytest.approx(M1 * u1 + M2 * u2, abs=1e-12)
    e = 0.5 * M1 * final[0][0] ** 2 + 0.5 * M2 * final[1][0] ** 2
    assert e == pytest.approx(3.0, rel=5e-3)
    assert final[0][3:] == [M1, R1] and final[1][3:] == [M2, R2]


def test_contact_stiffness_is_esys_scaled(collide):
    """NRotElasticPrms(scaling=True): k = normalK (r1 + r2)/4. Each contact step's velocity change is
    dt k overlap / m from the previous step's overlap (symplectic Euler), and the contact lasts pi/omega."""
    _, out = collide
    rows = lines(out, "contact")
    k = K * (R1 + R2) / 4
    for prev, cur in zip(rows, rows[1:]):
        if cur[0] != prev[0] + 1:
            continue
        assert cur[2] - prev[2] == pytest.approx(-DT * k * prev[1] / M1, rel=1e-9, abs=1e-12)
        assert cur[3] - prev[3] == pytest.approx(DT * k * prev[1] / M2, rel=1e-9, abs=1e-12)
    omega = math.sqrt(k * (M1 + M2) / (M1 * M2))
    assert len(rows) == pytest.approx(math.pi / omega / DT, abs=2)  # unscaled K would give 36 steps, not 48


def test_energy_saver_and_velocity_files(collide):
    d, _ = collide
    ekin = (d / "ekin.dat").read_text().splitlines()
    assert len(ekin) == 301 and ekin[0] == "3" and all(re.fullmatch(r"-?[0-9.]+(e[-+]\d+)?", v) for v in ekin)
    assert all(len(v.replace(".", "").replace("-", "").lstrip("0")) <= 6 for v in ekin)  # 6 significant digits
    assert [float(v) for v in ekin[:5]] == [3.0] * 5  # before the contact: 1/2 1 2^2 + 1/2 2 1^2
    vel = sorted(p.name for p in d.glob("vel.*.dat"))
    assert vel == ["vel.0.dat", "vel.1.dat", "vel.2.dat", "vel.3.dat"]
    assert (d / "vel.0.dat").read_text() == "0 -3 0.5 0.25 2 0 0\n1 3 0.5 0.25 -1 0 0\n"
    row = (d / "vel.3.dat").read_text().splitlines()[0].split()
    assert len(row) == 7 and row[0] == "0" and float(row[4]) == pytest.approx(-2.0, abs=0.02)


def test_checkpoint_text_format(collide):
    d, _ = collide
    assert sorted(p.name for p in d.glob("collide_t=*_0.txt")) == sorted(
        f"collide_t={t}_0.txt" for t in range(0, 3001, 500))
    head = (d / "collide_t=500_0.txt").read_text()
    assert head == ("V 3\n3000\n0.001\n500\nESyS-Particle_2.3.4_bzr_rev. \nBoundingBox -15 -15 -15 15 15 15\n"
                    "PeriodicBoundaries 0 0 0\nDimension 3D\ncollide_t=500_1.txt")
    rows = (d / "collide_t=0_1.txt").read_text().splitlines()
    assert rows == ["2", "-3 0.5 0.25 1 0 -1 1 -3 0.5 0.25 -3 0.5 0.25 2 0 0 0 0 0 0 0 0",
                    "3 0.5 0.25 1.25 1 -1 2 3 0.5 0.25 3 0.5 0.25 -1 0 0 0 0 0 0 0 0", "0", "TMIG 0"]
    rows = (d / "collide_t=500_1.txt").read_text().splitlines()
    x = [float(w) for w in rows[1].split()]
    assert len(x) == 22 and x[0] == pytest.approx(-3 + 2 * 0.5, abs=1e-9)  # 500 steps at 2: not yet touching
    assert re.fullmatch(r"(\S+ ){21}\S+", rows[1])


def test_checkpoint_old_positions_follow_the_rebuild_rule(collide):
    """Columns 10-12 hold the positions at ESyS's last neighbour rebuild: checked as step s begins, a rebuild
    when a particle has moved more than verletDist/2 (0.2) since the last one. Before the contact both spheres
    move at constant speed (2 and -1), so the rule can be replayed here with the same floating-point steps."""
    d, _ = collide
    x, old = [-3.0, 3.0], [-3.0, 3.0]
    expected = {}
    for step in range(1, 1001):
        if max((a - b) ** 2 for a, b in zip(x, old)) > (0.5 * 0.4) ** 2:
            old = list(x)
        x = [x[0] + 2.0 * DT, x[1] + -1.0 * DT]
        if step % 500 == 0:
            expected[step] = list(old)
    for step, (old0, old1) in expected.items():
        rows = (d / f"collide_t={step}_1.txt").read_text().splitlines()[1:3]
        assert [float(r.split()[10]) for r in rows] == [float("%.9g" % old0), float("%.9g" % old1)]
    assert expected[500][0] != -3.0 + 500 * 2.0 * DT  # a rebuild happened, and not at the checkpoint itself


# -- gravity and a floor ----------------------------------------------------------------------------------------
G = -9.81


def test_free_fall_is_symplectic_euler_exactly(fall):
    """v(n) = v0 + n g dt and y(n) = y0 + n v0 dt + g dt^2 n(n+1)/2 (ESyS's symplectic Euler), to rounding."""
    _, out = fall
    rows = [r for r in lines(out, "pre") if r[1] == 0 and r[0] <= 1001]
    assert len(rows) == 11
    for n1, _, x, y, z, vx, vy, vz in rows:
        n = n1 - 1  # a pre-time-step Runnable of step n + 1 sees the state after step n
        assert vy == pytest.approx(1.5 + n * G * DT, abs=1e-11)
        assert y == pytest.approx(4.0 + n * 1.5 * DT + G * DT * DT * n * (n + 1) / 2, abs=1e-11)
        assert x == pytest.approx(0.5 + n * 0.25 * DT, abs=1e-11) and vx == 0.25 and z == -0.5 and vz == 0.0


def test_particle_leaving_the_domain_is_deleted(fall):
    d, out = fall
    seen = sorted({int(r[0]) for r in lines(out, "pre") if r[1] == 7})
    assert seen and max(seen) < 400  # x = 4 + 12 t leaves x = 8 at t = 1/3
    assert "particles 1" in out.splitlines()
    assert len((d / "disp.0.dat").read_text().splitlines()) == 1  # RAW2 at step 500: ball 0 only


def test_domain_is_grown_to_whole_grid_cells(tmp_path):
    """ESyS keeps a particle until its centre leaves the domain grown to whole gridSpacing cells, centred:
    [-8, 8] with gridSpacing 2.5 is 7 cells, |x| <= 8.75 (measured: ESyS removed it 3 steps after x passed
    8.75, at its next neighbour update). Basalt's front end removes it at the same rebuild (ESyS's rule,
    python/src/esys_watch.hpp): a Runnable sees it gone at the step ESyS's does."""
    script = tmp_path / "leave.py"
    script.write_text(
        "from esys.lsm import *\nfrom esys.lsm.util import Vec3, BoundingBox\n"
        "sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])\n"
        "sim.initNeighbourSearch(particleType='NRotSphere', gridSpacing=2.5, verletDist=0.5)\n"
        "sim.setNumTimeSteps(1800)\nsim.setTimeStepSize(0.001)\n"
        "sim.setSpatialDomain(BoundingBox(Vec3(-8, -8, -8), Vec3(8, 8, 8)))\n"
        "p = NRotSphere(id=0, posn=Vec3(7.0, 0, 0), radius=0.5, mass=1.0)\n"
        "p.setLinearVelocity(Vec3(1.0, 0, 0))\nsim.createParticle(p)\n"
        "sim.createParticle(NRotSphere(id=1, posn=Vec3(0, 0, 0), radius=0.5, mass=1.0))\n"
        "class W(Runnable):\n"
        "    def __init__(self, sim):\n        Runnable.__init__(self)\n        self.sim, self.n = sim, 2\n"
        "    def run(self):\n"
        "        n = len(self.sim.getParticleList())\n"
        "        if n != self.n:\n            print('gone', self.sim.getTimeStep())\n            self.n = n\n"
        "w = W(sim)\nsim.addPostTimeStepRunnable(w)\nsim.run()\n")
    out = front(script, tmp_path).stdout
    assert out == "gone 1754\n"  # x = 7 + n dt passes 8.75 at step 1751 (not 8 at step 1001), 3 steps before


def test_particles_leaving_by_several_sides_go_at_the_same_rebuild(tmp_path):
    """Four spheres cross four different sides of the grown domain (x above, x below, y above, z below) at the
    same step: ESyS removes them all at its next neighbour update, and so does the front end (one deletion of
    every side's particles, esys_watch_leave): the count drops from 6 to 2 at one step, the two spheres inside
    stay."""
    script = tmp_path / "leave4.py"
    script.write_text(
        "from esys.lsm import *\nfrom esys.lsm.util import Vec3, BoundingBox\n"
        "sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])\n"
        "sim.initNeighbourSearch(particleType='NRotSphere', gridSpacing=2.5, verletDist=0.5)\n"
        "sim.setNumTimeSteps(1800)\nsim.setTimeStepSize(0.001)\n"
        "sim.setSpatialDomain(BoundingBox(Vec3(-8, -8, -8), Vec3(8, 8, 8)))\n"
        "for i, (x, v) in enumerate([((7.0, 0, 0), (1.0, 0, 0)), ((-7.0, 0, 0), (-1.0, 0, 0)),\n"
        "                            ((0, 7.0, 0), (0, 1.0, 0)), ((0, 0, -7.0), (0, 0, -1.0)),\n"
        "                            ((0, 0, 0), (0, 0, 0)), ((3.0, 3.0, 3.0), (0, 0, 0))]):\n"
        "    p = NRotSphere(id=i, posn=Vec3(*x), radius=0.5, mass=1.0)\n"
        "    p.setLinearVelocity(Vec3(*v))\n    sim.createParticle(p)\n"
        "class W(Runnable):\n"
        "    def __init__(self, sim):\n        Runnable.__init__(self)\n        self.sim, self.n = sim, 6\n"
        "    def run(self):\n"
        "        ids = [p.getId() for p in self.sim.getParticleList()]\n"
        "        if len(ids) != self.n:\n            print('gone', self.sim.getTimeStep(), ids)\n"
        "            self.n = len(ids)\n"
        "w = W(sim)\nsim.addPostTimeStepRunnable(w)\nsim.run()\n")
    out = front(script, tmp_path).stdout
    assert out == "gone 1754 [4, 5]\n"


def test_wall_savers_raw_series(fall):
    d, _ = fall
    pos = (d / "floor_Position.dat").read_text().splitlines()
    assert len(pos) == 301 and set(pos) == {"0.0000000000e+00 -5.0000000000e+00 0.0000000000e+00  "}
    force = [[float(w) for w in line.split()] for line in (d / "floor_Force.dat").read_text().splitlines()]
    assert all(f == [0.0, 0.0, 0.0] for f in force[:200])  # the ball is in the air until step ~1100
    assert max(f[1] for f in force) > 50.0 and min(f[1] for f in force) >= 0.0  # ESyS: the push on the particles


def test_settled_ball_carries_its_weight(tmp_path):
    out = front(SCRIPTS / "settle.py", tmp_path).stdout
    m, r, k = 1.8, 1.25, 2000.0
    force = (tmp_path / "floor_force.dat").read_text().splitlines()
    fx, fy, fz = (float(w) for w in force[-1].split())
    assert fy == pytest.approx(-m * G, rel=1e-6) and fx == 0.0 and fz == 0.0  # the wall's push on the ball
    y = float(out.split("rest ")[1].split()[0])
    assert y == pytest.approx(-5.0 + r - m * -G / (math.pi * r * k), abs=1e-6)
    saved = sorted(p.name for p in tmp_path.glob("settle_t=*_1.txt"))
    assert saved == sorted(f"settle_t={t}_1.txt" for t in range(1000, 6001, 1000))
    row = [float(w) for w in (tmp_path / "settle_t=6000_1.txt").read_text().splitlines()[1].split()]
    assert row[1] == pytest.approx(y, abs=1e-8) and abs(row[14]) < 1e-6  # at rest
    assert row[17] == pytest.approx(0.0, abs=1e-5)  # the force of the last step: weight and floor balance


def test_rotsphere_e_kin_has_the_rotation(tmp_path):
    """RotSphere: e_kin = 1/2 m v^2 + 1/2 (2/5 m r^2) w^2 (ESyS 2.3.5 prints 0.8355 and 0.0675 here too)."""
    script = tmp_path / "spin.py"
    script.write_text(
        "from esys.lsm import *\nfrom esys.lsm.util import Vec3, BoundingBox\n"
        "sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])\n"
        "sim.initNeighbourSearch(particleType='RotSphere', gridSpacing=2.5, verletDist=0.5)\n"
        "sim.setNumTimeSteps(10)\nsim.setTimeStepSize(0.001)\n"
        "sim.setSpatialDomain(BoundingBox(Vec3(-5, -5, -5), Vec3(5, 5, 5)))\n"
        "p = RotSphere(id=0, posn=Vec3(0, 0, 0), radius=0.8, mass=1.5)\n"
        "p.setLinearVelocity(Vec3(0.3, 0.0, 0.0))\np.setAngularVelocity(Vec3(0.0, 0.0, 2.0))\n"
        "sim.createParticle(p)\n"
        "for f in ('e_kin', 'e_kin_linear'):\n"
        "    sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName=f, fileName=f + '.dat', fileFormat='SUM',\n"
        "                         beginTimeStep=0, endTimeStep=10, timeStepIncr=5))\n"
        "sim.run()\n")
    front(script, tmp_path)
    assert (tmp_path / "e_kin.dat").read_text() == "0.8355\n" * 3
    assert (tmp_path / "e_kin_linear.dat").read_text() == "0.0675\n" * 3


# -- a bonded block (gravity_cube-like) ---------------------------------------------------------------------------
def test_cubic_block_is_close_packed():
    """CubicBlock: touching spheres 2r apart, 12 neighbours inside (a close packing), ids 0.. in order, mass r^3;
    ConnectionFinder bonds exactly the touching pairs; rotate turns by |axis| clockwise about it, as ESyS."""
    import numpy as np

    from basalt.esys.blocks import ConnectionFinder, CubicBlock
    from basalt.esys.vec3 import Vec3

    r = 0.5
    block = CubicBlock(dimCount=[5, 5, 5], radius=r)
    spheres = list(block)
    assert [s.getId() for s in spheres] == list(range(125))
    assert {s.getMass() for s in spheres} == {r ** 3} and {s.getTag() for s in spheres} == {0}
    x = np.array([s.getPosn().toList() for s in spheres])
    d = np.sqrt(((x[:, None, :] - x[None, :, :]) ** 2).sum(axis=2)) + np.eye(len(x)) * 9
    assert d.min() == pytest.approx(2 * r, abs=1e-12)
    touching = {(i, j) for i, j in zip(*np.nonzero(d < 2 * r + 1e-9)) if i < j}
    assert max(np.bincount(np.array(sorted(touching)).ravel())) == 12
    bonds = {(c.getId1(), c.getId2()) for c in ConnectionFinder(maxDist=0.005, bondTag=3, pList=block)}
    assert bonds == touching
    turned = Vec3(1, 0, 0).rotate(axis=Vec3(0, 0, math.pi / 6), axisPt=Vec3(0, 0, 0))
    assert turned.toList() == pytest.approx([math.cos(math.pi / 6), -0.5, 0.0], abs=1e-15)


def test_hexag_block_is_hexagonal_close_packed():
    """HexagBlock (ESyS's name; positions equal to ESyS's own module, docs/esys.md): touching spheres 2r apart, 12
    neighbours inside, layers along y r sqrt(8/3) apart in the sequence ABAB (a sphere and the one two layers up
    share x and z; one layer up they do not, as in CubicBlock's ABC), ids 0.. in order, mass r^3."""
    import numpy as np

    from basalt.esys.blocks import ConnectionFinder, CubicBlock, HexagBlock

    r, n = 0.5, 6
    for kind, period in ((HexagBlock, 2), (CubicBlock, 3)):
        spheres = list(kind(dimCount=[n, n, n], radius=r))
        assert [s.getId() for s in spheres] == list(range(n ** 3)) and {s.getMass() for s in spheres} == {r ** 3}
        x = np.array([s.getPosn().toList() for s in spheres])
        d = np.sqrt(((x[:, None, :] - x[None, :, :]) ** 2).sum(axis=2)) + np.eye(len(x)) * 9
        assert d.min() == pytest.approx(2 * r, abs=1e-12)
        touching = {(i, j) for i, j in zip(*np.nonzero(d < 2 * r + 1e-9)) if i < j}
        assert max(np.bincount(np.array(sorted(touching)).ravel())) == 12
        bonds = {(c.getId1(), c.getId2()) for c in ConnectionFinder(maxDist=0.005, bondTag=1, pList=spheres)}
        assert bonds == touching
        layer = n * n  # ids of one layer along y (k)
        assert x[layer, 1] - x[0, 1] == pytest.approx(r * math.sqrt(8 / 3), rel=1e-14)
        xz = x[:, [0, 2]]
        assert np.allclose(xz[period * layer:2 * period * layer], xz[:period * layer], atol=1e-12)
        assert not np.allclose(xz[layer:2 * layer], xz[:layer], atol=1e-3)
        if period == 3:
            assert not np.allclose(xz[2 * layer:3 * layer], xz[:layer], atol=1e-3)



# -- RandomBoxPacker: ESyS's packing, reproduced ----------------------------------------------------------------
def sphere_lines(text):
    return [line for line in text.splitlines() if line.startswith("sphere ")]


def test_random_box_packer_is_esys_packing(tmp_path):
    """RandomBoxPacker packs as ESyS-Particle 2.3.5 does, to the 17 digits printed: pack_box.py packs two boxes
    one after the other (the second goes on with the first's random stream; minRadius = maxRadius / 4 in the
    first, the default tolerance in the second); data/pack_box_small_wide.txt is what ESyS printed."""
    ref = sphere_lines((SCRIPTS / "data" / "pack_box_small_wide.txt").read_text())
    got = sphere_lines(front(SCRIPTS / "pack_box.py", tmp_path, "small", "wide").stdout)
    assert len(ref) == 196 + 176
    first = next((i for i, (a, b) in enumerate(zip(got, ref)) if a != b), None)
    assert first is None, f"sphere line {first} differs from ESyS's:\n{got[first]}\n{ref[first]}"
    assert len(got) == len(ref)



def test_random_box_packer_generate_twice_adds_as_esys(tmp_path):
    """generate() a second time packs again around the first spheres, the ids going on: ESyS-Particle printed
    `pack_box.py small+` as the 196 spheres of `small` and these four."""
    ref = sphere_lines((SCRIPTS / "data" / "pack_box_small_wide.txt").read_text())[:196] + [
        "sphere 196 3.9674195330978872 3.6503172691271728 4.6946834598791565 0.28046340402215719 0",
        "sphere 197 1.3446440905431101 0.27261494457061097 2.836420394859239 0.27261494457061097 0",
        "sphere 198 0.35871598143558525 2.1992211626841804 0.2560226976275144 0.2560226976275144 0",
        "sphere 199 0.52079825113695932 3.732837831432918 3.3103809053682913 0.26716216856708197 0"]
    assert sphere_lines(front(SCRIPTS / "pack_box.py", tmp_path, "small+").stdout) == ref

def test_random_box_packer_slope_fail_box_is_esys_packing(tmp_path):
    """slope_fail.py's box (10 x 10 x 10, radii 0.2-0.5): the 5,167 spheres ESyS-Particle 2.3.5 printed with
    pack_box.py slope, compared through the SHA-256 of the printed lines (17 digits)."""
    got = sphere_lines(front(SCRIPTS / "pack_box.py", tmp_path, "slope").stdout)
    assert len(got) == 5167
    assert got[0] == "sphere 0 -2.7999999999999998 2.2000000000000002 -2.7999999999999998 0.4444171075709164 0"
    digest = hashlib.sha256(("\n".join(got) + "\n").encode()).hexdigest()
    assert digest == "21b8273227e68885e1d6da65f1b5c09c54802b70a156ac206fd58ed5f211c8ba"


def test_random_box_packer_without_a_positive_radius_is_an_error(tmp_path):
    """minRadius sizes the packer's cell table (8 minRadius): 0 or a maxRadius below it is a clear error naming
    the call, not a crash of the compiled packer."""
    script = tmp_path / "bad_packer.py"
    script.write_text("from esys.lsm.util import Vec3, BoundingBox\nfrom esys.lsm.geometry import RandomBoxPacker\n"
                      "RandomBoxPacker(minRadius=0.0, maxRadius=0.5, cubicPackRadius=2.2, maxInsertFails=100,\n"
                      "                bBox=BoundingBox(Vec3(0, 0, 0), Vec3(4, 4, 4))).generate()\n")
    p = front(script, tmp_path, check=False)
    assert p.returncode != 0
    assert "RandomBoxPacker(minRadius=0.0, maxRadius=0.5): give 0 < minRadius <= maxRadius" in p.stderr


def _gengeo_reference(name):
    """A file GenGeo wrote (tests/python/esys_scripts/data/), without the header lines naming its command."""
    text = (SCRIPTS / "data" / name).read_text()
    return "".join(line for line in text.splitlines(keepends=True) if not line.startswith("# "))


def test_gengeo_box_packing_is_gengeos_byte_for_byte(tmp_path):
    """Our gengeo_box.py (a GenGeo script) through the front end: its whole output (GenGeo's messages, every
    sphere's id, position, radius and tag at 17 digits, the volume) and its .geo files (spheres in GenGeo's order,
    bonds, header) and .vtu are GenGeo 1.4's, byte for byte: a plain box, a box with its faces as planes (spheres fitted
    to them, tag 2), the old seeding and the planes box clustered (spheres tagged by the closest seed, bonds
    tagged inside and between clusters), packed one after the other (GenGeo's random stream and ids go on)."""
    out = front(SCRIPTS / "gengeo_box.py", tmp_path, "plain", "planes", "old", "cluster").stdout
    ref = _gengeo_reference("gengeo_box.txt")
    assert out.splitlines() == ref.splitlines()
    for case in ("plain", "planes", "old", "cluster"):
        got = (tmp_path / f"gengeo_box_{case}.geo").read_text()
        assert got == _gengeo_reference(f"gengeo_box_{case}.geo.txt"), case
    for case in ("planes", "cluster"):
        got = (tmp_path / f"gengeo_box_{case}.vtu").read_text()
        assert got == _gengeo_reference(f"gengeo_box_{case}.vtu.txt"), case


def test_random_box_packer_block_slumps_on_the_floor(tmp_path):
    """slope_collapse.py (slope_fail in small): the 600 packed spheres, given to createParticle one by one, become
    particles with their ids, radii, tags (2 near the floor) and masses r^3 (the checkpoint at step 0), fall onto
    the floor and spread: the front moves out, the top comes down, no sphere sinks into the floor by more than a
    small overlap."""
    out = front(SCRIPTS / "slope_collapse.py", tmp_path).stdout
    assert lines(out, "spheres") == [[600.0]]
    shape = lines(out, "shape")
    assert [row[0] for row in shape] == [500.0 * i for i in range(1, 11)]
    front_x, top, bottom = zip(*[row[1:] for row in shape])
    assert front_x[0] < 3.05 and front_x[-1] > front_x[0] + 0.5
    assert top[0] > 4.9 and top[-1] < top[0] - 0.5
    assert min(bottom) > -0.05
    rows = (tmp_path / "slope_t=0_1.txt").read_text().splitlines()
    assert int(rows[0]) == 600
    first = [float(w) for w in rows[1].split()[:7]]  # position, radius, id, tag, mass (ESyS's 9 digits)
    r = 0.4444171075709164
    assert first == pytest.approx([-1.9, 1.1, -0.9, r, 0, 0, r * r * r], rel=1e-8)
    table = [[float(w) for w in row.split()[:7]] for row in rows[1:601]]
    low = [row for row in table if row[5] == 2]
    assert len(low) > 10 and all(row[1] < 1.1 * row[3] + 1e-8 for row in low)
    assert all(row[5] == 0 for row in table if row[1] > 1.1 * row[3] + 1e-8)

def test_bonded_block_falls_and_bounces(tmp_path):
    out = front(SCRIPTS / "cube_drop.py", tmp_path).stdout
    assert lines(out, "mass") == [[0, 0.125], [1, 0.125], [2, 0.125]]  # ESyS: a block's spheres get r^3
    centre = lines(out, "centre")
    assert len(centre) == 12
    x0, z0 = centre[0][1], centre[0][3]
    for _, x, y, z in centre:  # no force along x or z but internal ones: the centre only moves along y
        assert x == pytest.approx(x0, abs=1e-8) and z == pytest.approx(z0, abs=1e-8)
    ys = [c[2] for c in centre]
    assert ys[1] < ys[0] and max(ys[3:]) > min(ys[:4])  # falls, hits the floor, bounces
    rows = [line.split() for line in (tmp_path / "posn.3.dat").read_text().splitlines()]
    assert len(rows) == 64 and all(len(r) == 7 for r in rows)
    assert min(float(r[2]) for r in rows) > -2.0  # no sphere centre through the floor (y = -2)


# -- refusals, the runner ----------------------------------------------------------------------------------------
_GLUE_SETUP = (  # a bonded wall 'w' (y = 0, normal +y) for particles of tag 2 (_tied(id, posn))
    "sim.initNeighbourSearch(particleType='NRotSphere', gridSpacing=2.5, verletDist=0.5)\n"
    "sim.setTimeStepSize(0.001)\nsim.setNumTimeSteps(10)\n"
    "sim.setSpatialDomain(BoundingBox(Vec3(-5, -5, -5), Vec3(5, 5, 5)))\n"
    "sim.createWall(name='w', posn=Vec3(0, 0, 0), normal=Vec3(0, 1, 0))\n"
    "sim.createInteractionGroup(NRotBondedWallPrms(name='g', wallName='w', normalK=1000.0, particleTag=2))\n"
    "def _tied(i, x):\n    p = NRotSphere(id=i, posn=x, radius=0.5, mass=1.0)\n    p.setTag(2)\n    return p\n")

REFUSED = {
    "sim.createInteractionGroup(HertzMindlinPrms(name='h', youngsModulus=1.0, poissonsRatio=0.25, cor=0.5))":
        ("esys.lsm.HertzMindlinPrms", 'hertz_mindlin'),
    "sim.initNeighbourSearch(particleType='RotSphere', gridSpacing=2.5, verletDist=0.5)\n"
    "sim.createInteractionGroup(RotFrictionPrms(name='f', normalK=1.0, dynamicMu=0.5, staticMu=0.5, shearK=1.0, "
    "meanR_scaling=False))": ("RotFrictionPrms(meanR_scaling=False)", "mean radius"),
    "sim.initNeighbourSearch(particleType='RotSphere', gridSpacing=2.5, verletDist=0.5)\n"
    "sim.createInteractionGroup(RotFrictionPrms(name='f', normalK=1.0, dynamicMu=0.5, staticMu=0.5, shearK=1.0))\n"
    "sim.createInteractionGroup(NRotElasticPrms(name='e', normalK=1.0))": ("a second contact group", "'f'"),
    "from esys.lsm.geometry import SimpleBlock\nSimpleBlock(dimCount=[2, 2, 2], radius=0.5)":
        ("esys.lsm.geometry.SimpleBlock", "basalt.pack"),
    "sim.createInteractionGroup(NRotElasticPrms(name='e', normalK=1.0, scaling=True))\n"
    "sim.createInteractionGroup(NRotBondPrms(name='b', normalK=1.0, breakDistance=1.0, tag=1))\n"
    "sim.initNeighbourSearch(particleType='NRotSphere', gridSpacing=2.5, verletDist=0.5)\n"
    "sim.setTimeStepSize(0.001)\nsim.setSpatialDomain(BoundingBox(Vec3(-5, -5, -5), Vec3(5, 5, 5)))\n"
    "sim.createParticle(NRotSphere(id=0, posn=Vec3(0, 0, 0), radius=0.5, mass=1.0))\nsim.run()":
        ("contact group 'e' together with the bond group 'b' without createExclusion('b', 'e')",),
    "sim.setParticleDensity(tag=0, mask=-1, Density=2.0)": ("LsmMpi.setParticleDensity", "mass="),
    # InteractionScalarFieldSaverPrms: the count of a bond group's bonds, the potential energy of a RotBond or
    # BrittleBeam group that is the run's only bond group
    "sim.createFieldSaver(InteractionScalarFieldSaverPrms(interactionName='b', fieldName='e_pot_normal', "
    "fileName='e', fileFormat='SUM', beginTimeStep=0, endTimeStep=1, timeStepIncr=1))":
        ("InteractionScalarFieldSaverPrms(fieldName='e_pot_normal'", "count of a bond group",
         "potential_energy of a RotBondPrms or BrittleBeamPrms group"),
    "sim.createFieldSaver(InteractionScalarFieldSaverPrms(interactionName='b', fieldName='potential_energy', "
    "fileName='e', fileFormat='MAX', beginTimeStep=0, endTimeStep=1, timeStepIncr=1))":
        ("fileFormat='MAX'", "format SUM"),
    "sim.createInteractionGroup(NRotBondPrms(name='b', normalK=1.0, breakDistance=1.0, tag=1))\n"
    "sim.createFieldSaver(InteractionScalarFieldSaverPrms(interactionName='b', fieldName='potential_energy', "
    "fileName='e', fileFormat='SUM', beginTimeStep=0, endTimeStep=1, timeStepIncr=1))":
        ("on the NRotBondPrms group 'b'", "RotBondPrms and BrittleBeamPrms", "linear_bond"),
    "sim.initNeighbourSearch(particleType='RotSphere', gridSpacing=2.5, verletDist=0.5)\n"
    "sim.createInteractionGroup(RotBondPrms(name='b', normalK=1.0, shearK=1.0, torsionK=1.0, bendingK=1.0, "
    "normalBrkForce=1.0, shearBrkForce=1.0, torsionBrkForce=1.0, bendingBrkForce=1.0, tag=1))\n"
    "sim.createInteractionGroup(BrittleBeamPrms(name='c', youngsModulus=1.0, poissonsRatio=0.25, cohesion=1.0, "
    "tanAngle=1.0, tag=2))\n"
    "sim.createFieldSaver(InteractionScalarFieldSaverPrms(interactionName='b', fieldName='potential_energy', "
    "fileName='e', fileFormat='SUM', beginTimeStep=0, endTimeStep=1, timeStepIncr=1))":
        ("with 2 bond groups", "the run's one bond group"),
    "sim.createFieldSaver(InteractionScalarFieldSaverPrms(interactionName='b', fieldName='potential_energy', "
    "fileName='e', fileFormat='SUM', beginTimeStep=0, endTimeStep=1, timeStepIncr=1))":
        ("on 'b'", "the potential_energy of a bond group's bonds"),
    "sim.createInteractionGroup(NRotElasticPrms(name='c', normalK=1.0))\n"
    "sim.createFieldSaver(InteractionScalarFieldSaverPrms(interactionName='c', fieldName='count', "
    "fileName='e', fileFormat='SUM', beginTimeStep=0, endTimeStep=1, timeStepIncr=1))":
        ("on 'c'", "a contact group's count is not reproduced"),
    # NRotBondedWallPrms: what Basalt's bonded wall cannot do as ESyS does
    "sim.createWall(name='w', posn=Vec3(0, 0, 0), normal=Vec3(0, 1, 0))\n"
    "sim.createInteractionGroup(NRotBondedWallPrms(name='g', wallName='w', normalK=1.0, particleTag=2, tagMask=1))":
        ("NRotBondedWallPrms(tagMask=1)", "particleTag"),
    _GLUE_SETUP + "sim.createParticle(_tied(0, Vec3(0, 2.6, 0)))\nsim.run()":
        ("particle 0 of tag 2 is 2.6 from wall 'w', not within gridSpacing 2.5", "ties every particle of the tag"),
    _GLUE_SETUP + "sim.createParticle(_tied(0, Vec3(0, 0.5, 0)))\nsim.moveWallBy('w', Vec3(0, 0.1, 0))\nsim.run()":
        ("LsmMpi.moveWallBy('w') before the run", "from a Runnable"),
    _GLUE_SETUP + "p = _tied(0, Vec3(0, 0.5, 0))\np.setLinearVelocity(Vec3(0, 400, 0))\nsim.createParticle(p)\n"
    "sim.run()": ("particle 0 tied to wall 'w'", "drops such a bond"),
    "from esys.lsm.geometry import RandomBoxPacker\nRandomBoxPacker(minRadius=0.2, maxRadius=0.5, "
    "cubicPackRadius=1.1, maxInsertFails=100, bBox=BoundingBox(Vec3(0, 0, 0), Vec3(4, 4, 4)), "
    "circDimList=[True, False, False])": ("RandomBoxPacker(circDimList=[True, False, False])", "basalt.pack.box"),
    "from esys.lsm.geometry import RandomBoxPacker\nRandomBoxPacker(minRadius=0.2, maxRadius=0.5, "
    "cubicPackRadius=1.1, maxInsertFails=100, bBox=BoundingBox(Vec3(0, 0, 0), Vec3(4, 4, 0)))":
        ("RandomBoxPacker with a 2-D box", "basalt.pack"),
    "sim.setVelocityOfWall('w', Vec3(0, 1, 0))": ("LsmMpi.setVelocityOfWall", "ViscWallPrms", "moveWallBy"),
    "sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName='sigma_xx_2d', fileName='s', fileFormat='SUM', "
    "beginTimeStep=0, endTimeStep=1, timeStepIncr=1))": ("fieldName='sigma_xx_2d'", "e_kin"),
    "from esys.lsm import SomethingElse": ("esys.lsm.SomethingElse", "not provided"),
    # esys.lsm.vis: povray's Scene of spheres only (docs/esys.md, "POV-Ray snapshots")
    "from esys.lsm.vis import vtk": ("esys.lsm.vis.vtk", "esys.lsm.vis.povray"),
    "from esys.lsm.vis import povray\npovray.Box(Vec3(0, 0, 0), Vec3(1, 1, 1))": ("esys.lsm.vis.povray.Box", "Sphere"),
    "from esys.lsm.vis import povray\npovray.Scene().render(offScreen=True, interactive=False)":
        ("Scene.render(fileName=None)", "files only"),
    "from esys.lsm.vis import povray\n"
    "povray.Sphere(Vec3(0, 0, 0), 1.0).apply(povray.Pigment(povray.Colors.Red, 0.5))":
        ("Pigment(transmit=0.5)", "opaque"),
    "from esys.lsm.vis import povray\nc = povray.Colors.Aquamarine":
        ("Colors.Aquamarine", "RgbColor(red, green, blue)"),
    "from esys.lsm.vis import povray\npovray.Scene().getCamera().setLightSource(None)":
        ("LightedCamera.setLightSource", "at the camera's position"),
    # gengeo: GenGeo's box packing only (docs/esys.md, "GenGeo"); other volumes and packers refused, never
    # packed differently under GenGeo's names
    "from gengeo import *\nCylinderVol(Vector3(0, 0, 0), Vector3(0, 1, 0), 1.0, 1.0)":
        ("gengeo.CylinderVol", "BoxWithPlanes3D", "basalt.pack"),
    "import gengeo\ngengeo.HexAggregateInsertGenerator3D(0.2, 1.0, 100, 100, 1e-6)":
        ("gengeo.HexAggregateInsertGenerator3D", "basalt.pack"),
    "from gengeo import *\nt = MNTable3D(Vector3(0, 0, 0), Vector3(2, 2, 2), 2.5, 1)\nt.write('x.txt', 3)":
        ("MNTable3D.write(..., 3)", ".geo", ".vtu"),
    "from gengeo import *\nt = MNTable3D(Vector3(0, 0, 0), Vector3(2, 2, 2), 2.5, 2)\nt.tagParticlesInSphere(0, 1)":
        ("MNTable3D.tagParticlesInSphere", "BoxWithPlanes3D", "basalt.pack"),
}


@pytest.mark.parametrize("call", list(REFUSED))
def test_unsupported_call_is_refused_with_a_message(tmp_path, call):
    script = tmp_path / "refused.py"
    script.write_text("from esys.lsm import *\nfrom esys.lsm.util import Vec3, BoundingBox\n"
                      "sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])\n" + call + "\nprint('not refused')\n")
    p = front(script, tmp_path, check=False)
    assert p.returncode != 0 and "not refused" not in p.stdout
    assert "NotSupportedError" in p.stderr and "Basalt's ESyS-Particle front end" in p.stderr
    for word in REFUSED[call]:
        assert word in p.stderr


# -- POV-Ray snapshots: esys.lsm.vis.povray drawn with VTK (snap_pair.py, snaps.py) ---------------------------
def _no_rendering():
    """Why pictures cannot be drawn here, or None: VTK's Python module and an X display (DISPLAY, or Xvfb for
    the front end's own virtual server) are needed."""
    try:
        import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL back end)
    except ImportError as e:
        return f"VTK's Python module (python3-vtk9) is not installed ({e})"
    if not os.environ.get("DISPLAY") and not shutil.which("Xvfb"):
        return "no X display: DISPLAY is unset and Xvfb (package xvfb) is not installed"
    return None


def png_size(path):
    """(width, height) from a PNG file's header."""
    head = pathlib.Path(path).read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR", f"{path} is not a PNG file"
    return struct.unpack(">II", head[16:24])


def png_pixels(path):
    """The picture as rows of (r, g, b), top row first (numpy array height x width x 3)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOImage import vtkPNGReader
    reader = vtkPNGReader()
    reader.SetFileName(str(path))
    reader.Update()
    w, h, _ = reader.GetOutput().GetDimensions()
    a = vtk_to_numpy(reader.GetOutput().GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3]
    return a[::-1].astype(int)  # VTK's first row is the bottom one


def pov_projection(camera, look_at, zoom, size, point):
    """Where POV-Ray puts `point` in ESyS's orthographic camera, in pixels from the top left (column, row):
    the picture is 2.05/zoom high; its up is +y (POV-Ray's sky) made square to the line of sight d, its right
    d x up (ESyS flips POV-Ray's left-handed right vector); looking along y, right is +x and up is (+x) x d."""
    import numpy as np
    d = np.subtract(look_at, camera, dtype=float)
    d /= np.linalg.norm(d)
    sky = np.array([0.0, 1.0, 0.0])
    if np.linalg.norm(np.cross(sky, d)) < 1e-10:
        right = np.array([1.0, 0.0, 0.0])
        up = np.cross(right, d)
    else:
        up = sky - sky.dot(d) * d
        up /= np.linalg.norm(up)
        right = np.cross(d, up)
    w, h = size
    scale = h * zoom / 2.05  # pixels per length unit
    rel = np.subtract(point, look_at, dtype=float)
    return w / 2 + rel.dot(right) * scale, h / 2 - rel.dot(up) * scale, scale


SNAP_CAMERAS = {  # camera, look-at, zoom, size, background
    "front": ((0, 0, 20), (0, 0, 0), 0.1, (320, 240), "white"),
    "moved_and_zoomed": ((2, 1, 20), (2, 1, 0), 0.2, (320, 240), "white"),
    "behind_black": ((0, 0, -20), (0, 0, 0), 0.2, (300, 200), "black"),
    "side": ((20, 0, 0), (0, 0, 0), 0.1, (256, 256), "white"),
    "above": ((0, 20, 0), (0, 0, 0), 0.1, (240, 320), "white"),
}


@pytest.mark.parametrize("view", list(SNAP_CAMERAS))
def test_povray_snapshots_drawn_where_the_camera_puts_them(tmp_path, view):
    """snap_pair.py's Snaps Runnable (POVsnaps-style) renders a red sphere (tag 1) and a blue one (tag 2) at
    steps 10 and 20: each snapshot is a PNG of the requested size under ESyS's file name, and each sphere's
    pixels are a disc of its radius centred where POV-Ray's camera puts its centre (within half a pixel):
    the camera's position, look-at point and zoom all move them; the background is the scene's."""
    why = _no_rendering()
    if why:
        pytest.skip(why)
    import numpy as np
    cam, look, zoom, size, bg = SNAP_CAMERAS[view]
    args = [str(v) for v in (*cam, *look, zoom, *size)] + ([bg] if bg == "black" else [])
    out = front(SCRIPTS / "snap_pair.py", tmp_path, *args).stdout
    assert sorted(os.listdir(tmp_path)) == ["snap_0000.png", "snap_0001.png"]  # nothing else (no temporaries)
    rows = [line.split()[1:] for line in out.splitlines() if line.startswith("snap ")]
    assert [(r[0], r[1], r[2]) for r in rows] == [("snap_0000.png", "10", "1"), ("snap_0000.png", "10", "2"),
                                                  ("snap_0001.png", "20", "1"), ("snap_0001.png", "20", "2")]
    reds = [float(r[3]) for r in rows if r[2] == "1"]
    assert reds[1] - reds[0] == pytest.approx(1.0, abs=1e-9)  # the red sphere moved between the snapshots
    for r in rows:
        name, tag, centre, radius = r[0], int(r[2]), [float(v) for v in r[3:6]], float(r[6])
        assert png_size(tmp_path / name) == size
        img = png_pixels(tmp_path / name)
        assert img.shape == (size[1], size[0], 3)
        corner = 0 if bg == "black" else 255
        assert (img[0, 0] == corner).all() and (img[-1, -1] == corner).all()
        red, green, blue = img[:, :, 0], img[:, :, 1], img[:, :, 2]
        main, other = (red, blue) if tag == 1 else (blue, red)
        mask = (main > 12) & (3 * other < main) & (3 * green < main)
        col, row, scale = pov_projection(cam, look, zoom, size, centre)
        ys, xs = np.nonzero(mask)
        assert len(xs) > 0, f"{name}: no pixels of the {'red' if tag == 1 else 'blue'} sphere"
        assert xs.mean() + 0.5 == pytest.approx(col, abs=0.5) and ys.mean() + 0.5 == pytest.approx(row, abs=0.5)
        assert len(xs) == pytest.approx(math.pi * (radius * scale) ** 2, rel=0.08)


def test_povray_render_names_and_formats(tmp_path):
    """Scene.render's file: the name given (a PNM from .pnm), ESyS's defaults (256 x 256, white); a name
    without an image extension is ESyS's ValueError; a sphere behind the camera is not drawn (an orthographic
    POV-Ray ray starts at the camera)."""
    why = _no_rendering()
    if why:
        pytest.skip(why)
    script = tmp_path / "vis.py"
    script.write_text(
        "from esys.lsm.vis import povray\n"
        "scene = povray.Scene()\n"
        "s = povray.Sphere([0, 0, 0], 1.0)\n"
        "s.apply(povray.RgbColor(0.0, 1.0, 0.0))\n"
        "scene.add(s)\n"
        "scene.render(offScreen=True, interactive=False, fileName='a.png')\n"
        "scene.render(offScreen=True, interactive=False, fileName='b.pnm', size=[64, 48])\n"
        "scene.render(fileName='c.png', size=[40, 30])\n"
        "try:\n"
        "    scene.render(offScreen=True, interactive=False, fileName='d.jpg')\n"
        "except ValueError as e:\n"
        "    print('refused:', e)\n"
        "behind = povray.Sphere([0, 0, 12], 3.0)\n"  # behind a camera at (0, 0, 5): not drawn, as POV-Ray's
        "behind.apply(povray.Colors.Red)\n"
        "scene.add(behind)\n"
        "scene.getCamera().setPosn([0, 0, 5])\n"
        "scene.render(offScreen=True, interactive=False, fileName='e.png', size=[100, 100])\n")
    p = front(script, tmp_path)
    assert sorted(os.listdir(tmp_path)) == ["a.png", "b.pnm", "c.png", "e.png", "vis.py"]
    img = png_pixels(tmp_path / "e.png")
    assert ((img[:, :, 0] > 12) & (3 * img[:, :, 1] < img[:, :, 0])).sum() == 0  # no red: behind the camera
    assert img[50, 50, 1] > 100 and img[50, 50, 0] < 30  # the green sphere, seen from +z now
    assert png_size(tmp_path / "a.png") == (256, 256) and png_size(tmp_path / "c.png") == (40, 30)
    pnm = (tmp_path / "b.pnm").read_bytes()  # binary PPM: P6, a comment, width height, 255, the pixels
    assert pnm.startswith(b"P6\n") and re.search(rb"\n64 48\n255\n", pnm) and len(pnm) >= 64 * 48 * 3
    assert "refused: No image format found which matched extension 'jpg'" in p.stdout
    # ESyS's default render (offScreen=False, interactive=True) opens POV-Ray's window: said once
    assert p.stderr.count("no window is opened") == 1
    img = png_pixels(tmp_path / "a.png")
    # the default camera (zoom 1: 2.05 units high) at (0, 0, -10): the green sphere of radius 1 in the middle
    assert (img[128, 128, 1] > 100) and img[128, 128, 0] < 30 and (img[0, 0] == 255).all()
    green = (img[:, :, 1] > 12) & (3 * img[:, :, 0] < img[:, :, 1])
    assert green.sum() == pytest.approx(math.pi * (256 / 2.05) ** 2, rel=0.08)


def test_povray_render_with_a_dead_display_says_so(tmp_path):
    """DISPLAY naming a display nobody serves: a NoDisplayError saying so (VTK itself would abort the process)."""
    pytest.importorskip("vtkmodules.vtkRenderingOpenGL2", reason="VTK's Python module (python3-vtk9) is not installed")
    script = tmp_path / "vis.py"
    script.write_text("from esys.lsm.vis import povray\n"
                      "povray.Scene().render(offScreen=True, interactive=False, fileName='a.png')\n")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_COMM_WORLD", "PMI_RANK", "PMI_SIZE"))}
    env.update(PYTHONPATH=PACKAGE_DIR, DISPLAY=":7919")
    p = subprocess.run([sys.executable, "-m", "basalt.esys", str(script)], cwd=tmp_path, capture_output=True,
                       text=True, env=env, timeout=300)
    assert p.returncode == 1 and "NoDisplayError: cannot open the X display DISPLAY=:7919" in p.stderr
    assert not (tmp_path / "a.png").exists()


def test_script_sees_its_arguments_and_folder(tmp_path):
    (tmp_path / "helper.py").write_text("VALUE = 42\n")
    script = tmp_path / "args.py"
    script.write_text("import sys\nfrom helper import VALUE\nfrom esys.lsm.util import Vec3\n"
                      "print(sys.argv[1:], VALUE, Vec3(1, 2.5, -0.125), __name__)\n")
    assert front(script, tmp_path, "--steps", "3").stdout == "['--steps', '3'] 42 1 2.5 -0.125 __main__\n"


def test_no_esys_outside_the_runner(tmp_path):
    """Imported normally, Basalt adds no `esys`: `import esys` fails, or finds a real ESyS-Particle."""
    code = ("import basalt, basalt.esys, sys\n"
            "assert basalt.esys.SHIM_ROOT not in sys.path\n"
            "try:\n    import esys\nexcept ImportError:\n    print('no esys')\n"
            "else:\n    print('real' if 'basalt' not in (esys.__file__ or '') + str(esys.__path__) else 'shim')\n")
    env = {**os.environ, "PYTHONPATH": PACKAGE_DIR}
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=60, env=env)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() in ("no esys", "real")
    if not pathlib.Path("/usr/lib/python3/dist-packages/esys").exists():
        assert p.stdout.strip() == "no esys"


def test_no_gengeo_outside_the_runner(tmp_path):
    """The shim's gengeo exists inside `python3 -m basalt.esys` only: imported normally, `import gengeo` finds
    a real GenGeo (Debian's python3-gengeo) or nothing."""
    code = ("import basalt, basalt.esys\n"
            "try:\n    import gengeo\nexcept ImportError:\n    print('no gengeo')\n"
            "else:\n    print('shim' if 'basalt' in str(gengeo.__path__) else 'real')\n")
    env = {**os.environ, "PYTHONPATH": PACKAGE_DIR}
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=60, env=env)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() in ("no gengeo", "real")


def test_basalt_esys_launcher(tmp_path):
    """build/bin/basalt-esys: the same runner, next to basalt-run."""
    launcher = pathlib.Path(os.environ.get("BASALT_BIN") or ROOT / "build" / "bin") / "basalt-esys"
    if not launcher.exists():
        pytest.skip(f"{launcher} not built")
    script = tmp_path / "hello.py"
    script.write_text("from esys.lsm.util import Vec3\nprint(Vec3(1, 2, 3).norm() ** 2)\n")
    p = subprocess.run([str(launcher), str(script)], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0 and p.stdout == "14.0\n", p.stderr


def test_compare_tool_skips_without_esys(tmp_path):
    """tools/esys/compare_tutorial.py without ESyS-Particle's interpreter: Basalt's run only, exit 3, says why."""
    env = {**os.environ, "PYTHONPATH": PACKAGE_DIR}
    p = subprocess.run([sys.executable, str(ROOT / "tools" / "esys" / "compare_tutorial.py"), "--scripts", "fall",
                        "--workdir", str(tmp_path / "cmp"), "--esys", "esysparticle-not-here",
                        "--pythonpath", PACKAGE_DIR],
                       capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 3, p.stdout + p.stderr
    assert "ESyS-Particle comparison skipped: esysparticle-not-here not on PATH" in p.stdout
    assert (tmp_path / "cmp" / "basalt" / "fall" / "ekin.dat").exists()


# -- friction (slide.py): closed forms of a sliding ball -------------------------------------------------------
def _ball_rows(out):
    return [[float(v) for v in line.split()[1:]] for line in out.splitlines() if line.startswith("ball ")]


def test_rot_friction_slides_at_mu_g_then_rolls_at_five_sevenths(tmp_path):
    g, mu, v0, r, m, R = 10.0, 0.5, 1.0, 0.5, 1.0, 1000.0
    rows = _ball_rows(front(SCRIPTS / "slide.py", tmp_path, "rot").stdout)
    assert [int(t) for t, *_ in rows] == list(range(100, 3001, 100))
    by = {int(t): (x, y, v, w) for t, x, y, v, w in rows}
    dt = 1.0e-4
    # sliding (steps 100-400): friction mu m g against the slide, its moment spins the ball up (I = 2/5 m r^2;
    # ESyS's lever: the contact point at r d/(r + R) from the centre, d = r + R - overlap)
    assert (by[400][2] - by[100][2]) / (300 * dt) == pytest.approx(-mu * g, rel=1e-3)
    assert (by[400][3] - by[100][3]) / (300 * dt) == pytest.approx(-2.5 * mu * g / r, rel=1e-3)
    # friction's impulse about the contact point is zero: m v - I w_z / lever = m v0 at every row (within 5e-4:
    # gravity's pull along the big sphere's curved top, g x / R, adds up to 3e-4 over the run)
    lever = r * (r + R - 1e-3) / (r + R)
    for t, (x, y, v, w) in by.items():
        assert m * v - 0.4 * m * r * r * w / lever == pytest.approx(m * v0, abs=5e-4), t
    # then it rolls (v = -w_z r) at 5/7 v0, the shear spring ringing around it
    late = [by[t] for t in range(1000, 3001, 100)]
    assert sum(v for _, _, v, _ in late) / len(late) == pytest.approx(5.0 / 7.0 * v0, rel=0.02)
    assert abs(sum(v + w * r for _, _, v, w in late) / len(late)) < 0.02
    assert by[700][2] < 0.72  # the rolling began (at t = v0 / (3.5 mu g) = 571 steps)


def test_nrot_friction_stops_the_slide_after_v0_squared_over_2_mu_g(tmp_path):
    g, mu, v0 = 10.0, 0.5, 1.0
    rows = _ball_rows(front(SCRIPTS / "slide.py", tmp_path, "nrot").stdout)
    by = {int(t): (x, y, v, w) for t, x, y, v, w in rows}
    assert (by[1000][2] - by[100][2]) / (900 * 1.0e-4) == pytest.approx(-mu * g, rel=1e-3)
    assert all(w == 0.0 for _, _, _, w in by.values())
    late = [by[t] for t in range(2200, 3001, 100)]
    assert sum(x for x, _, _, _ in late) / len(late) == pytest.approx(v0 * v0 / (2 * mu * g), rel=0.02)


# -- moveWallBy (press.py): a platen moved by a pre-time-step Runnable ------------------------------------------
def test_move_wall_by_moves_the_platen_before_the_step_forces(tmp_path):
    d, r, K = 1.0e-4, 0.5, 1000.0
    out = front(SCRIPTS / "press.py", tmp_path).stdout
    rows = [[float(v) for v in line.split()[1:]] for line in out.splitlines() if line.startswith("platen ")]
    assert [int(t) for t, *_ in rows] == list(range(20, 401, 20))
    for t, y, fy, ball_y in rows:
        assert y == pytest.approx(r - t * d, abs=1e-12)  # moved N times by d (after the set-up move to r)
        # the force of step N sees the platen moved N times (ESyS's order), not N - 1: pi r K N d on the ball
        assert fy == pytest.approx(-math.pi * r * K * t * d, rel=1e-6)
        assert abs(ball_y) < 1e-8  # the heavy ball gives way by ~1e-9
    saved = [line.split() for line in (tmp_path / "platen.dat").read_text().splitlines()]
    assert [float(s[1]) for s in saved] == pytest.approx([r - 50 * k * d for k in range(9)], abs=1e-12)


# -- NRotBondedWallPrms: particles glued to a wall -------------------------------------------------------------
def test_bonded_wall_swings_a_tied_particle_as_esys(tmp_path):
    """NRotBondedWallPrms(normalK=K, particleTag=2): a tied particle thrown sideways (along the wall) swings on
    the bond F = -k (u_p - u_w), k = 3.1415926536 r K, ESyS's full-vector spring: symplectic Euler's discrete
    oscillation x_n = A sin(n theta), cos theta = 1 - dt^2 k/(2m), A = dt v0/sin theta, exactly (1e-10 of A);
    it never moves along the normal. A particle of another tag overlapping the wall by 0.1 feels the group's
    elastic part, 3.141592654 r K overlap, in its first step. k = K (no pi r), the normal part only, or every
    particle tied fails it."""
    r, K, m, dt, v0, steps = 0.5, 1000.0, 2.0, 1e-3, 0.4, 400
    script = tmp_path / "swing.py"
    script.write_text(
        "from esys.lsm import *\nfrom esys.lsm.util import Vec3, BoundingBox\n"
        "sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])\n"
        "sim.initNeighbourSearch(particleType='NRotSphere', gridSpacing=2.5, verletDist=0.2)\n"
        f"sim.setTimeStepSize({dt})\nsim.setNumTimeSteps({steps})\n"
        "sim.setSpatialDomain(BoundingBox(Vec3(-5, -5, -5), Vec3(5, 5, 5)))\n"
        f"p = NRotSphere(id=0, posn=Vec3(0, {r}, 0), radius={r}, mass={m})\np.setTag(2)\n"
        f"p.setLinearVelocity(Vec3({v0}, 0, 0))\nsim.createParticle(p)\n"
        f"q = NRotSphere(id=1, posn=Vec3(3, {r - 0.1}, 0), radius={r}, mass={m})\nq.setTag(1)\n"
        "sim.createParticle(q)\n"
        "sim.createWall(name='w', posn=Vec3(0, 0, 0), normal=Vec3(0, 1, 0))\n"
        f"sim.createInteractionGroup(NRotBondedWallPrms(name='g', wallName='w', normalK={K}, particleTag=2))\n"
        "class Watch(Runnable):\n"
        "    def run(self):\n"
        "        for p in sim.getParticleList():\n"
        "            x, v = p.getPosn(), p.getVelocity()\n"
        "            print('p%d %d %.17g %.17g %.17g %.17g' % (p.getId(), sim.getTimeStep(), x[0], x[1], v[0], v[1]))\n"
        "w = Watch()\nsim.addPostTimeStepRunnable(w)\nsim.run()\n")
    out = front(script, tmp_path).stdout
    k = 3.1415926536 * r * K
    theta = math.acos(1 - dt * dt * k / (2 * m))
    amp = dt * v0 / math.sin(theta)
    rows = lines(out, "p0")
    assert [int(t) for t, *_ in rows] == list(range(1, steps + 1))
    assert max(x for _, x, *_ in rows) == pytest.approx(amp, rel=1e-3)  # it swings: several periods
    for t, x, y, vx, vy in rows:
        assert x == pytest.approx(amp * math.sin(t * theta), abs=1e-10 * amp)
        assert y == r and vy == 0.0
    t, x, y, vx, vy = lines(out, "p1")[0]
    assert vy == pytest.approx(dt * 3.141592654 * r * K * 0.1 / m, rel=1e-12)
    assert y == pytest.approx(r - 0.1 + dt * vy, rel=1e-12) and x == 3.0


# -- readMesh + NRotElasticTriMeshPrms: a triangle-mesh floor ---------------------------------------------------
_FLAT_MSH = ("Triangle\n3D-Nodes 4\n"  # a 10 x 10 square at y = 0, node ids out of order; ESyS's normal +y
             "7 0 0 -5 0 -5\n3 0 0 5 0 -5\n9 0 0 5 0 5\n1 0 0 -5 0 5\n\nTri3 2\n0 0 7 3 9\n1 0 7 9 1\n")


def _mesh_script(tmp_path, particles, extra=""):
    (tmp_path / "flat.msh").write_text(_FLAT_MSH)
    script = tmp_path / "mesh.py"
    script.write_text(
        "from esys.lsm import *\nfrom esys.lsm.util import Vec3, BoundingBox\n"
        "sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])\n"
        "sim.initNeighbourSearch(particleType='NRotSphere', gridSpacing=2.5, verletDist=0.2)\n"
        "sim.setTimeStepSize(0.001)\nsim.setNumTimeSteps(1)\n"
        "sim.setSpatialDomain(BoundingBox(Vec3(-8, -3, -8), Vec3(8, 6, 8)))\n"
        + "".join(f"sim.createParticle(NRotSphere(id={i}, posn=Vec3{tuple(x)}, radius={r}, mass=1.0))\n"
                  for i, x, r in particles)
        + "sim.readMesh(fileName='flat.msh', meshName='m')\n" + extra
        + "class W(Runnable):\n    def run(self):\n"
          "        for p in sim.getParticleList():\n"
          "            print('v %d %.17g %.17g %.17g' % ((p.getId(),) + tuple(p.getVelocity().toList())))\n"
          "w = W()\nsim.addPostTimeStepRunnable(w)\nsim.run()\n")
    return script


def test_mesh_floor_pushes_as_esys_2_3_5(tmp_path):
    """readMesh of an ESyS .msh (nodes named by id, out of order) + NRotElasticTriMeshPrms(normalK=K): after one
    step each sphere's velocity is dt k overlap/m along the line from the mesh's nearest point to the centre, with
    k = r K (ESyS 2.3.5 as Debian builds it, measured: its source's pi r is not in it): on a face (two radii), beyond
    the square's rim (an edge) and beyond its corner (a vertex); a sphere not touching is left alone. Without the
    group the mesh pushes nothing. pi r K, or the triangles' node ids taken as positions, fails it."""
    K, dt = 1000.0, 1e-3
    spheres = [(0, (-2.3, 0.24, 0.7), 0.25), (1, (2.3, 0.49, 0.7), 0.5), (2, (5.3, 0.3, 1.0), 0.5),
               (3, (5.2, 0.3, 5.2), 0.5), (4, (0.0, 0.6, 0.0), 0.5)]
    group = "sim.createInteractionGroup(NRotElasticTriMeshPrms(name='r', meshName='m', normalK=1000.0))\n"
    out = front(_mesh_script(tmp_path, spheres, group), tmp_path).stdout
    v = {int(r[0]): r[1:] for r in lines(out, "v")}
    nearest = {0: (-2.3, 0.0, 0.7), 1: (2.3, 0.0, 0.7), 2: (5.0, 0.0, 1.0), 3: (5.0, 0.0, 5.0)}
    for i, x, r in spheres[:4]:
        gap = [a - b for a, b in zip(x, nearest[i])]
        d = math.sqrt(sum(g * g for g in gap))
        for c in range(3):
            assert v[i][c] == pytest.approx(dt * r * K * (r - d) * gap[c] / d, rel=1e-9, abs=1e-15)
    assert v[4] == [0.0, 0.0, 0.0]
    out = front(_mesh_script(tmp_path, spheres), tmp_path).stdout
    assert all(row[1:] == [0.0, 0.0, 0.0] for row in lines(out, "v"))


def test_mesh_refusals(tmp_path):
    """A sphere behind the mesh (ESyS pushes it through the face, Basalt's one-sided mesh leaves it), one exactly
    over the edge two coplanar triangles share (ESyS pushes it twice), and readMesh with a tag are refused, naming
    the call."""
    group = "sim.createInteractionGroup(NRotElasticTriMeshPrms(name='r', meshName='m', normalK=1000.0))\n"
    p = front(_mesh_script(tmp_path, [(0, (0.3, -0.49, -2.7), 0.5)], group), tmp_path, check=False)
    assert p.returncode != 0 and "particle 0 behind triangle" in p.stderr and "pushed through it" in p.stderr
    # exactly over the diagonal the two triangles share: ESyS pushes twice (measured: dt 2 r K overlap/m)
    p = front(_mesh_script(tmp_path, [(0, (1.0, 0.49, 1.0), 0.5)], group), tmp_path, check=False)
    assert p.returncode != 0 and "exactly over the shared edge" in p.stderr and "once per triangle" in p.stderr
    script = _mesh_script(tmp_path, [(0, (0.3, 0.6, 0.0), 0.5)])
    script.write_text(script.read_text().replace("meshName='m')", "meshName='m', tag=3)"))
    p = front(script, tmp_path, check=False)
    assert p.returncode != 0 and "NotSupportedError" in p.stderr and "readMesh('flat.msh', 'm', tag)" in p.stderr


# -- LinDampingPrms and RotDampingPrms on RotSpheres (spin.py) ---------------------------------------------------
def _esys_damped(x, nu, dt, steps):
    """ESyS's damping rule (docs/reference-runs.md) on a free particle's v or w: u0 = 0; u <- x - nu dt u while
    e^2 > 1e-12, e = |u_new - u|^2 (so 2 or 3 iterations here); then x -= dt nu u, each step."""
    for _ in range(steps):
        u, count = [0.0, 0.0, 0.0], 0
        while True:
            new = [c - nu * dt * a for c, a in zip(x, u)]
            e = sum((a - b) ** 2 for a, b in zip(new, u))
            u, count = new, count + 1
            if not (e * e > 1e-12 and count < 100):
                break
        x = [c - dt * nu * a for c, a in zip(x, u)]
    return x


def test_lin_and_rot_damping_follow_esys_iteration_rule(tmp_path):
    dt, nu_lin, nu_rot = 1.0e-3, 2.0, 3.0
    start = {0: ((0.5, 0.2, 0.0), (0.0, 0.0, 4.0)), 1: ((0.0, -0.3, 0.1), (2.0, -1.0, 0.5))}
    out = front(SCRIPTS / "spin.py", tmp_path).stdout
    rows = [line.split()[1:] for line in out.splitlines() if line.startswith("spin ")]
    assert len(rows) == 40
    for t, i, *vals in rows:
        t, i = int(t), int(i)
        v0, w0 = start[i]
        assert [float(x) for x in vals[:3]] == pytest.approx(_esys_damped(v0, nu_lin, dt, t), rel=1e-9, abs=1e-15)
        assert [float(x) for x in vals[3:]] == pytest.approx(_esys_damped(w0, nu_rot, dt, t), rel=1e-9, abs=1e-15)
    # the rule is told apart: the converged damping 1/(1 + nu dt) per step is 1e-5 off after 1,000 steps, one
    # iteration (1 - nu dt) 3e-3
    assert rows[-1][:2] == ["1000", "1"]
    wz = float(rows[-1][7])
    assert abs(wz / (0.5 / (1.0 + nu_rot * dt) ** 1000) - 1.0) > 1e-6
    assert abs(wz / (0.5 * (1.0 - nu_rot * dt) ** 1000) - 1.0) > 1e-3


ROT_PAIR = """from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox
from esys.lsm.geometry import TaggedIdConnection
sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="RotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(STEPS)
sim.setTimeStepSize(0.001)
sim.setSpatialDomain(BoundingBox(Vec3(-5, -5, -5), Vec3(5, 5, 5)))
sim.createParticle(RotSphere(id=3, posn=Vec3(0, 0, 0), radius=0.5, mass=2.0))
sim.createParticle(RotSphere(id=5, posn=Vec3(0.95, 0, 0), radius=0.4, mass=1.0))
sim.createConnections([TaggedIdConnection(3, 5, 2)])
sim.createInteractionGroup(BOND)
CHECKPOINT
sim.runTimeStep()
print("v1 %.17g" % sorted(sim.getParticleList(), key=lambda p: p.getId())[0].getVelocity()[0])
"""


def rot_pair(tmp_path, name, bond, steps=1, checkpoint=""):
    d = tmp_path / name
    d.mkdir()
    (d / "pair.py").write_text(ROT_PAIR.replace("BOND", bond).replace("STEPS", str(steps))
                               .replace("CHECKPOINT", checkpoint))
    return d, float(front(d / "pair.py", d).stdout.split("v1")[1])


def test_rot_bond_prms_scale_per_bond_as_esys(tmp_path):
    """Two RotSpheres 0.95 apart, bonded (rest length r1 + r2 = 0.9): after one step sphere 3 has
    v = dt kn 0.05 / m with kn = normalK R^2/L (scaling, R = L/2 or min r) or normalK; BrittleBeamPrms with
    E = normalK / pi is RotBondPrms with kn = kb = pi E, ks = kt = pi G (the same bits)."""
    dt, L, m, K = 0.001, 0.95, 2.0, 1000.0
    strengths = "normalBrkForce=1e9, shearBrkForce=1e9, torsionBrkForce=1e9, bendingBrkForce=1e9, tag=2"
    for name, scaling, kn in (("mean", "", K * (L / 2) ** 2 / L),
                              ("min", ", meanR_scaling=False", K * 0.4 ** 2 / L),
                              ("plain", ", scaling=False", K)):
        bond = (f"RotBondPrms(name='b', normalK={K}, shearK=400.0, torsionK=400.0, bendingK={K}, {strengths}"
                f"{scaling if name != 'plain' else ''}{', scaling=False' if name == 'plain' else ''})")
        _, v = rot_pair(tmp_path, name, bond)
        assert v == pytest.approx(dt * kn * (L - 0.9) / m, rel=1e-12), name
        if name == "mean":
            v_rb = v
    nu = K / (2 * 400.0) - 1
    _, v_bb = rot_pair(tmp_path, "bb", f"BrittleBeamPrms(name='b', youngsModulus={K / math.pi!r}, "
                                       f"poissonsRatio={nu!r}, cohesion=1e9, tanAngle=1.0, tag=2)")
    assert v_bb == pytest.approx(v_rb, rel=1e-14)


def test_rotsphere_checkpoint_has_orientation_and_angular_velocity(tmp_path):
    """ESyS 2.3.5's RotSphere checkpoint (measured): the 22 columns, then the orientation w x y z and the
    angular velocity; a BrittleBeam group's bonds under "RotBonded"."""
    spin = ("sim.createCheckPointer(CheckPointPrms(fileNamePrefix='cp', beginTimeStep=0, endTimeStep=1, "
            "timeStepIncr=1))")
    d, _ = rot_pair(tmp_path, "cp", "BrittleBeamPrms(name='b', youngsModulus=1000.0, poissonsRatio=0.25, "
                                    "cohesion=1e9, tanAngle=1.0, tag=2)", checkpoint=spin)
    rows = (d / "cp_t=0_1.txt").read_text().splitlines()
    assert rows[0] == "2" and rows[3:] == ["1", "RotBonded", "1", "3 5 2", "TMIG 0"]
    assert rows[1].split()[22:] == ["1", "0", "0", "0", "0", "0", "0"]
    after = [[float(w) for w in r.split()] for r in (d / "cp_t=1_1.txt").read_text().splitlines()[1:3]]
    assert all(len(r) == 29 for r in after)
    # the stretched bond turns nothing (to the acos floor of ESyS's angles, 1.5e-8 rad): orientation the
    # identity, no spin; sphere 3 pulled along +x
    assert after[0][22:29] == pytest.approx([1, 0, 0, 0, 0, 0, 0], abs=1e-7) and after[0][13] > 0


def test_exclusion_needs_a_bond_and_a_contact_group(tmp_path):
    script = tmp_path / "excl.py"
    script.write_text("from esys.lsm import *\nsim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])\n"
                      "sim.initNeighbourSearch(particleType='NRotSphere', gridSpacing=2.5, verletDist=0.5)\n"
                      "sim.createInteractionGroup(GravityPrms(name='g', acceleration=Vec3(0, -1, 0)))\n"
                      "sim.createInteractionGroup(NRotElasticPrms(name='e', normalK=1.0))\n"
                      "sim.createExclusion('g', 'e')\n")
    p = front(script, tmp_path, check=False)
    assert p.returncode != 0 and "no contact or bond group named 'g'" in p.stderr


def test_brittle_beam_block_between_walls(tmp_path):
    """rot_block.py (BrittleBeam block, FrictionPrms excluded from the bonds, two walls moved by a Runnable):
    the walls at the block's ends move by V dt sum f_k (f the ramp), the force of step 2 is 16 spheres' pi r K
    times the first move (1e-9), then the pushes grow and the two walls' forces stay opposite."""
    front(SCRIPTS / "rot_block.py", tmp_path, "300")
    force = [[float(w) for w in r.split()] for r in (tmp_path / "walls_Force.dat").read_text().splitlines()]
    posn = [[float(w) for w in r.split()] for r in (tmp_path / "walls_Position.dat").read_text().splitlines()]
    assert len(force) == len(posn) == 31
    moved = 0.1 * 1e-4 * sum(k / 500 for k in range(300))  # after 300 pre-time-step moves
    assert posn[-1][1] - posn[0][1] == pytest.approx(moved, rel=1e-9)
    assert posn[-1][4] - posn[0][4] == pytest.approx(-moved, rel=1e-9)
    fy = [r[1] for r in force]
    assert all(b > a for a, b in zip(fy[1:], fy[2:]))
    assert all(r[4] == pytest.approx(-r[1], rel=2e-2) for r in force[5:])


def test_read_geometry_takes_the_geo_file(tmp_path):
    """geo_read.py: readGeometry's particles keep the file's ids, tags and radii with mass 4/3 pi r^3 (ESyS's
    reader), its bounding box is the domain, its bonds (tag 7) hold the row together (NRotBond, excluded from
    the elastic contacts); the NRotSphere checkpoint lists them."""
    out = front(SCRIPTS / "geo_read.py", tmp_path).stdout
    parts = [line.split()[1:] for line in out.splitlines() if line.startswith("particle ")]
    assert [p[:3] for p in parts] == [["10", "3", "0.5"], ["11", "3", "0.5"], ["12", "3", "0.5"],
                                      ["13", "3", "0.5"], ["20", "4", "0.4"]]
    for p in parts:
        r = float(p[2])
        assert float(p[3]) == pytest.approx(4 / 3 * math.pi * r ** 3, rel=1e-11)
    head = (tmp_path / "row_t=500_0.txt").read_text()
    assert "BoundingBox -4 -4 -4 6 6 4\n" in head
    rows = (tmp_path / "row_t=2000_1.txt").read_text().splitlines()
    assert rows[6:] == ["1", "Bonded", "3", "10 11 7", "11 12 7", "12 13 7", "TMIG 0"]
    row = [line.split() for line in out.splitlines() if line.startswith("row ")]
    assert len(row) == 20 and float(row[0][2]) < 0  # the row falls


def test_set_velocity_of_wall_hint_says_esys_never_moves_the_wall():
    from basalt.esys.lsmmpi import _HINTS
    assert "never moves the wall" in _HINTS["setVelocityOfWall"]


def test_rotsphere_checkpoint_orientation_turns_with_the_spin(tmp_path):
    """A free RotSphere spinning at w = (1, 2, 3): after 2 steps its checkpoint holds w and the orientation turned
    by |w| 2 dt about w (Basalt's exact turn, docs/esys.md: ESyS's first-order update differs by (|w| dt)^2)."""
    script = tmp_path / "spin1.py"
    script.write_text("from esys.lsm import *\nfrom esys.lsm.util import Vec3, BoundingBox\n"
                      "sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])\n"
                      "sim.initNeighbourSearch(particleType='RotSphere', gridSpacing=2.5, verletDist=0.5)\n"
                      "sim.setNumTimeSteps(2)\nsim.setTimeStepSize(0.001)\n"
                      "sim.setSpatialDomain(BoundingBox(Vec3(-12, -12, -12), Vec3(12, 12, 12)))\n"
                      "p = RotSphere(id=3, posn=Vec3(0.1, 0.2, 0.3), radius=0.5, mass=0.7)\n"
                      "p.setAngularVelocity(Vec3(1.0, 2.0, 3.0))\nsim.createParticle(p)\n"
                      "sim.createCheckPointer(CheckPointPrms(fileNamePrefix='cp', beginTimeStep=0, endTimeStep=2, "
                      "timeStepIncr=1))\nsim.run()\n")
    front(script, tmp_path)
    row = [float(w) for w in (tmp_path / "cp_t=2_1.txt").read_text().splitlines()[1].split()]
    assert len(row) == 29 and row[26:29] == [1.0, 2.0, 3.0]
    w = math.sqrt(14.0)
    half = w * 0.002 / 2
    expect = [math.cos(half)] + [c / w * math.sin(half) for c in (1.0, 2.0, 3.0)]
    assert row[22:26] == pytest.approx(expect, rel=2e-8)


def test_scaled_nrot_bonds_of_several_sizes_each_have_their_k(tmp_path):
    """chain.py: bonds of r1 + r2 = 0.8, 0.7, 0.7 (tag 1, scaling=True) and one unscaled (tag 2), all stretched
    by 0.05: after one step each sphere has v = dt (sum of k_b 0.05 along its bonds)/m, k_b = normalK r0/4 per bond
    (ESyS's scaling; one K for the group would fail) and 20 for the unscaled bond."""
    out = front(SCRIPTS / "chain.py", tmp_path).stdout
    rows = {int(w[2]): [float(v) for v in w[3:]] for w in (line.split() for line in out.splitlines())
            if w[0] == "chain" and w[1] == "1"}
    dt, s, m = 0.001, 0.05, [0.125, 0.027, 0.064, 0.027, 0.027]
    k01, k12, k23 = 100 * 0.8 / 4, 100 * 0.7 / 4, 100 * 0.7 / 4
    expect_vx = [k01 * s / m[0], (k12 - k01) * s / m[1], (k23 - k12) * s / m[2], -k23 * s / m[3], 0.0]
    for i in range(5):
        assert rows[i][2] == pytest.approx(dt * expect_vx[i], rel=1e-9, abs=1e-15), i
    # the hanging bond (unscaled K = 20, rest 0.6, length 0.62) pulls 3 down and 4 up
    assert rows[4][3] == pytest.approx(dt * 20 * 0.02 / m[4], rel=1e-9)
    assert rows[3][3] == pytest.approx(-dt * 20 * 0.02 / m[3], rel=1e-9)


# -- several ranks (mpirun -np 2) --------------------------------------------------------------------------------
def front_mpi(script, cwd, ranks, *args, launcher=None):
    """mpirun -np RANKS python3 -m basalt.esys SCRIPT (or the basalt-esys launcher) in cwd."""
    import basalt_tools

    env = basalt_tools.mpi_env(PYTHONPATH=PACKAGE_DIR)
    cmd = [*basalt_tools.mpirun(ranks), *([str(launcher)] if launcher else [sys.executable, "-m", "basalt.esys"]),
           str(script), *args]
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=env, timeout=300)
    if p.returncode != 0:
        pytest.fail(f"{' '.join(cmd)} exited {p.returncode}:\n{p.stdout}\n{p.stderr}")
    return p


# Files whose numbers are sums over the ranks (a wall's force: each rank's particles' share, added in another
# order on two ranks): equal to rounding; every other file and printed line is the same bytes.
SUMMED_OVER_RANKS = {"cube_drop.py": {"floor_force.dat"}, "glued.py": {"platen_force.dat"}}


@pytest.mark.skipif(subprocess.run(["which", "mpirun"], capture_output=True).returncode != 0, reason="needs mpirun")
@pytest.mark.parametrize("script", ["collide.py", "press.py", "cube_drop.py", "pull.py", "snap_pair.py",
                                    "geo_read.py", "own_files.py", "glued.py"])
def test_two_ranks_write_what_one_rank_writes(tmp_path, script):
    """mpirun -np 2: every saver file, checkpoint and printed line once and as on one rank (the same bytes; wall
    forces, summed over the ranks, to 1e-10). Each rank writing its own copy doubles the appended savers and the
    prints; a rank's particles missing changes the checkpoints, the particle savers and the Runnables' prints."""
    if script == "snap_pair.py" and _no_rendering():  # POV-Ray snapshots: drawn by rank 0
        pytest.skip(_no_rendering())
    one, two = tmp_path / "one", tmp_path / "two"
    one.mkdir()
    two.mkdir()
    if script == "own_files.py":  # the script's own files: written once, read back by every rank
        for d in (one, two):
            (d / script).write_text(OWN_FILES)
    a = front(SCRIPTS / script if script != "own_files.py" else one / script, one).stdout
    launcher = (pathlib.Path(os.environ.get("BASALT_BIN") or ROOT / "build" / "bin") / "basalt-esys").resolve()
    b = front_mpi(SCRIPTS / script if script != "own_files.py" else two / script, two, 2,
                  launcher=launcher if script == "press.py" and launcher.exists() else None).stdout
    assert b == a
    files = sorted(f.name for f in one.iterdir())
    assert files and sorted(f.name for f in two.iterdir()) == files
    for name in files:
        if name not in SUMMED_OVER_RANKS.get(script, ()):
            assert (one / name).read_bytes() == (two / name).read_bytes(), name
            continue
        x, y = (one / name).read_text(), (two / name).read_text()
        rx, ry = ([[float(w) for w in line.split()] for line in t.splitlines()] for t in (x, y))
        assert len(rx) == len(ry) and all(len(u) == len(v) for u, v in zip(rx, ry)), name
        for u, v in zip(rx, ry):
            assert v == pytest.approx(u, rel=1e-10, abs=1e-12), name


# A script writing its own files (ESyS runs it once, on its master): a log appended by a Runnable, a table
# written with numpy and read back by every rank, a file written in two goes.
OWN_FILES = """import numpy as np
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox

with open("notes.txt", "w") as f:
    f.write("start\\n")
np.savetxt("table.txt", np.arange(6.0).reshape(3, 2))
speeds = np.loadtxt("table.txt")[:, 1]  # every rank reads what rank 0 wrote
sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(30)
sim.setTimeStepSize(1.0e-3)
sim.setSpatialDomain(BoundingBox(Vec3(-20, -5, -5), Vec3(20, 5, 5)))
for k in range(8):
    p = NRotSphere(id=k, posn=Vec3(-14.0 + 4.0 * k, 0.0, 0.0), radius=0.5, mass=1.0)
    p.setLinearVelocity(Vec3(speeds[k % 3], 0.0, 0.0))
    sim.createParticle(p)


class Log(Runnable):
    def __init__(self, sim):
        Runnable.__init__(self)
        self.sim = sim

    def run(self):
        if self.sim.getTimeStep() % 10 == 0:
            x = sum(p.getPosn()[0] for p in self.sim.getParticleList())
            with open("log.txt", "a") as f:
                f.write("%d %.12g\\n" % (self.sim.getTimeStep(), x))


log = Log(sim)
sim.addPostTimeStepRunnable(log)
sim.run()
with open("notes.txt", "a") as f:
    f.write("done\\n")
print(open("notes.txt").read().split())
"""


@pytest.mark.skipif(subprocess.run(["which", "mpirun"], capture_output=True).returncode != 0, reason="needs mpirun")
def test_random_box_packer_same_on_two_ranks(tmp_path):
    """mpirun -np 2 slope_collapse.py: every rank runs the script and packs; the step-0 checkpoint is the same
    bytes as on one rank (the same 600 spheres), later rows and prints equal to rounding (forces summed over the
    ranks in another order)."""
    one, two = tmp_path / "one", tmp_path / "two"
    one.mkdir()
    two.mkdir()
    a = front(SCRIPTS / "slope_collapse.py", one).stdout
    b = front_mpi(SCRIPTS / "slope_collapse.py", two, 2).stdout
    for name in ("slope_t=0_0.txt", "slope_t=0_1.txt"):
        assert (one / name).read_bytes() == (two / name).read_bytes(), name
    rows = [[[float(w) for w in line.split()[1:]] for line in t.splitlines() if line.startswith("shape ")]
            for t in (a, b)]
    assert len(rows[0]) == len(rows[1]) == 10
    for u, v in zip(*rows):
        assert v == pytest.approx(u, rel=1e-9)


SEEN = """import os, sys
from esys.lsm import *
from esys.lsm.util import Vec3, BoundingBox

rank = os.environ.get("OMPI_COMM_WORLD_RANK", "0")
sim = LsmMpi(numWorkerProcesses=1, mpiDimList=[1, 1, 1])
sim.initNeighbourSearch(particleType="NRotSphere", gridSpacing=2.5, verletDist=0.2)
sim.setNumTimeSteps(10)
sim.setTimeStepSize(1.0e-3)
sim.setSpatialDomain(BoundingBox(Vec3(-20, -5, -5), Vec3(20, 5, 5)))
for k in range(16):
    p = NRotSphere(id=100 + k, posn=Vec3(-15.0 + 2.0 * k, 0.1 * k, 0.0), radius=0.5, mass=1.0)
    p.setLinearVelocity(Vec3(0.5 * (k % 3 - 1), 0.0, 0.0))
    sim.createParticle(p)


class Seen(Runnable):
    def __init__(self, sim, when):
        Runnable.__init__(self)
        self.sim, self.when = sim, when

    def run(self):
        ps = self.sim.getParticleList()
        owned = len(self.sim._sim.particles)  # this rank's own particles (the test's view of the decomposition)
        sys.stderr.write("seen %s %s %d %d %d %s\\n" % (rank, self.when, self.sim.getTimeStep(), owned, len(ps),
                                                       ",".join(str(p.getId()) for p in ps)))
        print("%s %d %.17g" % (self.when, self.sim.getTimeStep(), sum(p.getPosn()[0] for p in ps)))


sim.addPreTimeStepRunnable(Seen(sim, "pre"))
sim.addPostTimeStepRunnable(Seen(sim, "post"))
sim.run()
"""


@pytest.mark.skipif(subprocess.run(["which", "mpirun"], capture_output=True).returncode != 0, reason="needs mpirun")
def test_runnables_see_every_ranks_particles(tmp_path):
    """mpirun -np 2: 16 spheres in a row split between the ranks (each owns some); the pre- and post-time-step
    Runnables on each rank see all 16 (ids 100-115, in order) at every step, and print once, as on one rank."""
    script = tmp_path / "seen.py"
    script.write_text(SEEN)
    one = front(script, tmp_path).stdout
    p = front_mpi(script, tmp_path, 2)
    assert p.stdout == one and len(one.splitlines()) == 20
    rows = [line.split()[1:] for line in p.stderr.splitlines() if line.startswith("seen ")]
    assert len(rows) == 2 * 2 * 10  # two ranks, two runnables, ten steps
    ids = ",".join(str(100 + k) for k in range(16))
    owned = {}
    for rank, when, step, mine, seen, listed in rows:
        assert (int(seen), listed) == (16, ids), (rank, when, step)
        owned.setdefault((when, step), {})[rank] = int(mine)
    for counts in owned.values():
        assert sorted(counts) == ["0", "1"] and sum(counts.values()) == 16 and min(counts.values()) > 0, counts


# -- checkpoints after a bond broke -------------------------------------------------------------------------------
# pull.py MODE on ESyS-Particle 2.3.5 (mpirun -np 2 esysparticle pull.py MODE, measured): the last checkpoint
# whose bonds' section lists the broken bond 0-1. Basalt's front end writes the same section at every step, and
# every checkpoint file is ESyS's byte for byte (nrot too, since NRotBondPrms maps to linear_bond's ESyS
# convention: the bond still pulls in the step whose forces find it broken, docs/esys.md).
ESYS_LAST_LISTED = {"nrot": 7, "rot": 5, "beam": 7}


@pytest.mark.parametrize("mode", sorted(ESYS_LAST_LISTED))
def test_checkpoint_after_a_bond_broke_lists_the_bonds_left(tmp_path, mode):
    """pull.py: bond 0-1 breaks, 1-2 holds; each step's checkpoint lists 0-1 up to ESyS's last step for it and
    then only 1-2, with the count and the group kind (Bonded for NRotBondPrms, RotBonded otherwise). The
    InteractionScalarFieldSaverPrms count (SUM) of every step says the same, in ESyS's %.10e (its file is ESyS's
    byte for byte, measured)."""
    front(SCRIPTS / "pull.py", tmp_path, mode)
    kind = "Bonded" if mode == "nrot" else "RotBonded"
    counts = (tmp_path / "nbonds.dat").read_text().splitlines()
    assert len(counts) == 21
    for t in range(21):
        section = (tmp_path / f"pull_t={t}_1.txt").read_text().splitlines()[4:]
        bonds = ["0 1 3", "1 2 3"] if t <= ESYS_LAST_LISTED[mode] else ["1 2 3"]
        assert section == ["1", kind, str(len(bonds)), *bonds, "TMIG 0"], (t, section)
        assert counts[t] == "%.10e" % len(bonds), (t, counts[t])
    if mode == "nrot":
        # the step whose forces find 0-1 broken (stretch 0.00599 > breakDistance 0.005, from the positions they
        # were computed at: the checkpoint before's, ESyS's order): sphere 0 still feels its pull, K (r - r0)
        # towards sphere 1 (ESyS: 0.59930028); from the next step on, nothing
        def rows(t):
            lines = (tmp_path / f"pull_t={t}_1.txt").read_text().splitlines()
            return {int(r.split()[4]): [float(v) for v in r.split()] for r in lines[1:1 + int(lines[0])]}
        before, at, after = rows(6), rows(7), rows(8)
        stretch = (before[1][0] - before[0][0]) - 1.0
        assert stretch > 0.005
        assert at[0][16] == pytest.approx(100.0 * stretch, rel=1e-6)
        assert after[0][16] == 0.0


def _twist_reference(mode):
    """What ESyS-Particle wrote for twist.py MODE (data/twist_MODE.txt): [(step, epot.dat line, nbonds.dat line)]."""
    text = (SCRIPTS / "data" / f"twist_{mode}.txt").read_text().splitlines()
    return [tuple(line.split()) for line in text if not line.startswith("#")]


@pytest.mark.parametrize("mode", ["beam", "rot", "rotscaled"])
def test_bond_potential_energy_saver_is_esys(tmp_path, mode):
    """twist.py: four RotSpheres in a row bonded by BrittleBeamPrms, RotBondPrms unscaled or scaled per bond, the
    last one thrown sideways and spun (the bonds stretch, shear, bend and twist; one or two break).
    InteractionScalarFieldSaverPrms potential_energy (SUM) at every step against what ESyS-Particle 2.3.5 wrote for
    the same script (data/twist_MODE.txt): row 0 is 0 (ESyS's bonds hold no loads before its first force
    computation), row t the bonds' Fn^2/2kn + Fs^2/2ks + Mt^2/2kt + Mb^2/2kb of the forces from the positions after
    step t - 1, a bond counted in the row of the forces that find it broken and gone from the next; the count's
    file is ESyS's line for line. Row 1, from the start's positions (no turn, no shear: the normal springs only,
    each stretched from r1 + r2 to its length L), is also the closed form sum of kn (L - r1 - r2)^2 / 2."""
    front(SCRIPTS / "twist.py", tmp_path, mode)
    ref = _twist_reference(mode)
    epot = (tmp_path / "epot.dat").read_text().splitlines()
    assert len(epot) == len(ref) == 61
    assert epot[0] == "0.0000000000e+00"
    assert all(re.fullmatch(r"\d\.\d{10}e[-+]\d\d", line) for line in epot)
    # row 1 to rounding; then within 2e-6 (measured up to 9.5e-7): the spheres spin at up to 3.7 rad per unit
    # time, and ESyS turns orientations by a first-order step where Basalt takes the exact turn (docs/esys.md,
    # "RotSphere orientation"); a row off by one step is 1e-2 away, the bond left out of its breaking row 0.6
    worst = max(abs(float(line) - float(e)) / float(e) for line, (_, e, _) in zip(epot[1:], ref[1:]))
    assert worst < 2e-6, worst
    assert float(epot[1]) == pytest.approx(float(ref[1][1]), rel=1e-9)
    assert (tmp_path / "nbonds.dat").read_text().splitlines() == [n for _, _, n in ref]
    assert len({n for _, _, n in ref}) > 1  # a bond broke
    # twist.py's spheres: x, y = 0.001 k, radius; kn per bond as ESyS scales it (R = L/2)
    x, r = [0.0, 1.003, 1.904, 2.7025], [0.5, 0.5, 0.4, 0.4]
    closed = 0.0
    for k in range(3):
        length = math.hypot(x[k + 1] - x[k], 0.001)
        kn = {"beam": math.pi * 1000.0 * (length / 2) ** 2 / length, "rot": 500.0,
              "rotscaled": 2000.0 * (length / 2) ** 2 / length}[mode]
        closed += 0.5 * kn * (length - r[k] - r[k + 1]) ** 2
    assert float(epot[1]) == pytest.approx(closed, rel=1e-9)


def test_bond_broken_by_the_start_pulls_in_step_1(tmp_path):
    """break_at_start.py: bond 0-1 starts 0.05 beyond its rest length and breaks in the first force computation;
    ESyS applies its force in step 1 (a breaking bond's last pull), so e_kin after step 1 is sum m (F dt/m)^2 / 2
    of the two bonds' normal forces kn (L - r1 - r2) along their offsets (kn = pi E L/4), and the whole e_kin file
    is what ESyS-Particle 2.3.5 wrote (data/break_at_start.txt), every line. The front end keeps that pull: no
    force recomputation at the start without initial velocities, none for a Runnable's moveWallBy by zero, and the
    potential_energy saver's reading of the start's energy (energies()) leaves the forces as they were.
    potential_energy from row 2 on is ESyS's; row 1 lacks the broken bond (docs/esys.md)."""
    front(SCRIPTS / "break_at_start.py", tmp_path)
    ref = [line.split() for line in (SCRIPTS / "data" / "break_at_start.txt").read_text().splitlines()
           if not line.startswith("#")]
    assert (tmp_path / "ekin.dat").read_text().splitlines() == [r[1] for r in ref]
    assert (tmp_path / "nbonds.dat").read_text().splitlines() == [r[3] for r in ref]
    epot = (tmp_path / "epot.dat").read_text().splitlines()
    assert epot[0] == ref[0][2]
    for line, r in zip(epot[2:], ref[2:]):
        assert float(line) == pytest.approx(float(r[2]), rel=1e-9)
    centres, dt, m, kick = [(0.0, 0.0), (1.05, 0.01), (2.051, 0.0)], 1e-3, 0.125, [[0.0, 0.0] for _ in range(3)]
    for a in (0, 1):
        dx, dy = centres[a + 1][0] - centres[a][0], centres[a + 1][1] - centres[a][1]
        length = math.hypot(dx, dy)
        f = math.pi * 1000.0 * length / 4 * (length - 1.0)  # pulls a towards a + 1
        for k, sign in ((a, 1.0), (a + 1, -1.0)):
            kick[k][0] += sign * f * dx / length * dt / m
            kick[k][1] += sign * f * dy / length * dt / m
    assert float(ref[1][1]) == pytest.approx(sum(0.5 * m * (u * u + v * v) for u, v in kick), rel=1e-5)


def test_slope_runout_reads_the_quantities_of_a_checkpoint(tmp_path):
    """tools/esys/slope_runout.py: particles left, mean height and runout from a checkpoint's rows (three spheres at
    horizontal distances 0, 5 and 13 from the axis, heights 1, 2 and 6)."""
    run = tmp_path / "run"
    run.mkdir()
    rows = ["0 1 0 0.5 0 0", "3 2 4 0.5 1 0", "-5 6 12 0.5 2 0"]
    (run / "slope_data_t=100_1.txt").write_text("3\n" + "\n".join(rows) + "\nTMIG 0\n")
    p = subprocess.run([sys.executable, str(ROOT / "tools" / "esys" / "slope_runout.py"), "--step", "100", str(run)],
                       capture_output=True, text=True, check=True)
    last = p.stdout.strip().splitlines()[-1]
    assert [c.strip() for c in last.split("|")[2:-1]] == ["3", "3", "13", "13"]
