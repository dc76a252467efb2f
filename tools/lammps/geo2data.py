#!/usr/bin/python3
"""Converts an ESyS-Particle .geo packing into LAMMPS input for the wave benchmark.

    /usr/bin/python3 tools/lammps/geo2data.py cube1.geo OUTDIR [--bond-model table|harmonic]
                                             [--rest-length sum_of_radii|initial_distance]

Writes into OUTDIR:
  data.lmp          atom_style hybrid sphere bond: "id type x y z diameter density molecule",
                    LAMMPS id = .geo id + 1, density 1 (LAMMPS mass = 4/3 pi r^3, as in ESyS),
                    a box padded like the ESyS run (2 r_max at the sides and below, +50 % above),
                    one bond type per distinct (rest length, r1 + r2): r0 = r1 + r2 (ESyS's convention,
                    scenes/wave-esys.toml) or r0 = the initial distance (Basalt's scenes/wave.toml).
  bond_style.in, bond_coeffs.in  the bond_style and bond_coeff commands (included by the input
                    template; table paths are relative to OUTDIR, where LAMMPS must run).
  bond_tables/*.table  (table model) tension-only linear springs, 3-point tables.
  bottom_group.in   a group of the particles that can touch the base wall during the run.
Bond models (s = r1 + r2, the distance below which pair gran/hooke pushes the pair apart with K (s - r);
LAMMPS 2022-01 applies that contact to bonded pairs too, whatever special_bonds says):
  table     the bond force that, added to the contact, gives exactly K (r - r0) in tension and compression
            with no contact on the bonded pair (ESyS's NRotBond + NRotElastic-with-exclusion, Basalt's
            linear_bond + linear_elastic): tension K (r - r0) for r >= s and the constant K (s - r0) for r < s
            (for r0 = s: tension-only). Piecewise linear with its kink on the middle node of a 3-point table.
  harmonic  bond_style harmonic K/2, r0: a compressed bonded pair then feels the bond and the contact,
            K (r0 - r) + K (s - r) (2 K when r0 = s): NOT the same physics. Kept for timing comparisons.
"""

import argparse
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))

from basalt_tools import GeoError, read_geo  # noqa: E402  (tools/basalt_tools.py)

TABLES_PER_FILE = 100  # LAMMPS scans a table file from its start for every bond_coeff


def convert(geo, outdir, stiffness, bond_model, pad_top, table_span, bottom_band, rest_length="sum_of_radii",
            type_order="spatial", sort_bin=1.0):
    box_lo, box_hi, particles, bonds = read_geo(geo)
    radius = {p[0]: p[4] for p in particles}
    rmax = max(radius.values())
    lo = [min(box_lo[i], min(p[i + 1] - p[4] for p in particles)) for i in range(3)]
    hi = [max(box_hi[i], max(p[i + 1] + p[4] for p in particles)) for i in range(3)]
    pad = 2.0 * rmax
    dom_lo = [lo[0] - pad, lo[1] - pad, lo[2] - pad]
    dom_hi = [hi[0] + pad, hi[1] + pad, hi[2] + pad_top * (hi[2] - lo[2])]

    position = {p[0]: p[1:4] for p in particles}

    def rest(a, b):
        if rest_length == "initial_distance":
            return math.dist(position[a], position[b])
        return radius[a] + radius[b]

    # one bond type per distinct (r0, r1 + r2), printed with 17 significant digits (exact doubles)
    # Spatial order (type_order "spatial"): atoms are written in bins of sort_bin (z slowest, x fastest),
    # and bonds, which LAMMPS keeps with their first atom and walks atom by atom, in their first atom's
    # order; bond types are numbered in that order, so the table lookups of consecutive bonds touch
    # neighbouring tables in memory. Run with LAMMPS's own atom sorting off (in.wave.lmp, sort 0) to
    # keep it. type_order "file": the .geo's order.
    order = list(range(len(bonds)))
    if type_order == "spatial":
        def bin_key(p):
            return (int((p[3] - dom_lo[2]) // sort_bin), int((p[2] - dom_lo[1]) // sort_bin),
                    int((p[1] - dom_lo[0]) // sort_bin), p[0])
        particles = sorted(particles, key=bin_key)
        rank = {p[0]: i for i, p in enumerate(particles)}
        order.sort(key=lambda i: (rank[bonds[i][0]], i))
    type_of_r0 = {}
    bond_types = [0] * len(bonds)
    for i in order:
        a, b, _ = bonds[i]
        key = (f"{rest(a, b):.17g}", f"{radius[a] + radius[b]:.17g}")
        if key not in type_of_r0:
            type_of_r0[key] = len(type_of_r0) + 1
        bond_types[i] = type_of_r0[key]

    os.makedirs(outdir, exist_ok=True)
    tmp = os.path.join(outdir, "data.lmp.tmp")
    with open(tmp, "w") as f:
        f.write(f"LAMMPS data file from {os.path.abspath(geo)} (tools/lammps/geo2data.py)\n\n")
        f.write(f"{len(particles)} atoms\n{len(bonds)} bonds\n1 atom types\n{len(type_of_r0)} bond types\n\n")
        for i, axis in enumerate("xyz"):
            f.write(f"{dom_lo[i]:.10g} {dom_hi[i]:.10g} {axis}lo {axis}hi\n")
        f.write("\nAtoms # hybrid sphere bond\n\n")
        for pid, x, y, z, r, tag in particles:
            f.write(f"{pid + 1} 1 {x:.10g} {y:.10g} {z:.10g} {2.0 * r:.12g} 1 1\n")
        f.write("\nBonds\n\n")
        for n, i in enumerate(order):
            a, b, _ = bonds[i]
            f.write(f"{n + 1} {bond_types[i]} {a + 1} {b + 1}\n")
    os.replace(tmp, os.path.join(outdir, "data.lmp"))

    with open(os.path.join(outdir, "bond_style.in"), "w") as f:
        f.write("bond_style harmonic\n" if bond_model == "harmonic" else "bond_style table linear 3\n")
    with open(os.path.join(outdir, "bond_coeffs.in"), "w") as f:
        if bond_model == "harmonic":
            for (r0, _), t in type_of_r0.items():
                f.write(f"bond_coeff {t} {0.5 * stiffness:.17g} {r0}\n")
        else:
            tdir = os.path.join(outdir, "bond_tables")
            os.makedirs(tdir, exist_ok=True)
            files = {}
            for (key, skey), t in type_of_r0.items():
                r0, s = float(key), float(skey)
                name = os.path.join(tdir, f"b{(t - 1) // TABLES_PER_FILE:05d}.table")
                if name not in files:
                    files[name] = open(name, "w")
                    files[name].write("# linear springs K (r - r0) less the contact K (s - r) that pair gran/hooke adds "
                                      "below s = r1 + r2: f = -K (r - r0) for r >= s, -K (s - r0) below\n\n")
                lo_r, hi_r = s * (1.0 - table_span), s * (1.0 + table_span)
                k = stiffness

                def energy(r):  # bond + contact energy = K/2 (r - r0)^2
                    return 0.5 * k * (r - r0) ** 2 - (0.5 * k * (s - r) ** 2 if r < s else 0.0)

                rows = [(lo_r, -k * (s - r0)), (s, -k * (s - r0)), (hi_r, -k * (hi_r - r0))]
                files[name].write(f"T{t}\nN 3\n\n" + "".join(f"{i + 1} {r:.17g} {energy(r):.17g} {fr:.17g}\n"
                                                              for i, (r, fr) in enumerate(rows)) + "\n")
                f.write(f"bond_coeff {t} {os.path.relpath(name, outdir)} T{t}\n")
            for fh in files.values():
                fh.close()

    bottom = [p[0] + 1 for p in particles if p[3] - p[4] - lo[2] < bottom_band]
    with open(os.path.join(outdir, "bottom_group.in"), "w") as f:
        for i in range(0, len(bottom), 50):
            f.write("group bottom id " + " ".join(str(v) for v in bottom[i:i + 50]) + "\n")
    return {"particles": len(particles), "bonds": len(bonds), "bond_types": len(type_of_r0),
            "bottom": len(bottom), "rmax": rmax, "lo": lo, "hi": hi}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("geometry", help=".geo file")
    p.add_argument("outdir")
    p.add_argument("--stiffness", type=float, default=1000.0, help="bond K, N/mm")
    p.add_argument("--bond-model", choices=("table", "harmonic"), default="table")
    p.add_argument("--rest-length", choices=("sum_of_radii", "initial_distance"), default="sum_of_radii",
                   help="bond rest length: r1 + r2 (ESyS, scenes/wave-esys.toml) or the initial distance "
                        "(Basalt's scenes/wave.toml)")
    p.add_argument("--type-order", choices=("spatial", "file"), default="spatial",
                   help="bond type numbering: spatial (as LAMMPS walks its bonds; faster table lookups) or file")
    p.add_argument("--pad-top", type=float, default=0.5, help="box padding above, fraction of the height")
    p.add_argument("--table-span", type=float, default=0.2,
                   help="bond tables cover r0 (1 +- span); LAMMPS stops if a bond leaves it")
    p.add_argument("--bottom-band", type=float, default=0.1,
                   help="particles whose lowest point is within this of the base may touch the wall, mm")
    args = p.parse_args()
    try:
        info = convert(args.geometry, args.outdir, args.stiffness, args.bond_model, args.pad_top, args.table_span,
                       args.bottom_band, args.rest_length,
                       args.type_order)
    except GeoError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"error: cannot write into {args.outdir}: {e}", file=sys.stderr)
        return 2
    print(f"{args.outdir}: {info['particles']} atoms, {info['bonds']} bonds in {info['bond_types']} bond types "
          f"({args.bond_model}, r0 = {args.rest_length}), {info['bottom']} atoms in group bottom")
    return 0


if __name__ == "__main__":
    sys.exit(main())
