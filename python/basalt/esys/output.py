"""ESyS-Particle's output files written from a Basalt run: the text checkpoints of createCheckPointer and the
field savers of createFieldSaver, in ESyS 2.3.5's formats (as its Debian build writes them, docs/esys.md).

A `state` is the LsmMpi's snapshot after a step: numpy arrays in id order (id, pos, vel, radius, mass, tag,
init, force, old) and walls {name: (position, force)}."""

from .errors import refuse


def _g(v):
    return "%g" % v  # C++'s default ostream: 6 significant digits (particle fields)


class _Schedule:
    def __init__(self, prms):
        self.begin, self.end, self.incr = prms.beginTimeStep, prms.endTimeStep, max(prms.timeStepIncr, 1)

    def due(self, t):
        return self.begin <= t <= self.end and (t - self.begin) % self.incr == 0

    def next_after(self, t):
        """The first due step > t, or None."""
        if t < self.begin:
            return self.begin
        n = self.begin + ((t - self.begin) // self.incr + 1) * self.incr
        return n if n <= self.end else None


class CheckPointer(_Schedule):
    """PREFIX_t=T_0.txt (the master's header) and PREFIX_t=T_1.txt (the one worker's particles)."""

    def __init__(self, prms, lsm):
        super().__init__(prms)
        self.prefix, self.lsm = prms.fileNamePrefix, lsm

    def write(self, t, state):
        lsm = self.lsm
        lo, hi = lsm._domain_lo, lsm._domain_hi
        data = f"{self.prefix}_t={t}_1.txt"
        with open(f"{self.prefix}_t={t}_0.txt", "w") as f:
            f.write(f"V 3\n{lsm._num_steps}\n{_g(lsm._dt)}\n{t}\nESyS-Particle_2.3.4_bzr_rev. \n"
                    f"BoundingBox {' '.join(_g(v) for v in (*lo, *hi))}\nPeriodicBoundaries 0 0 0\n"
                    f"Dimension 3D\n{data}")
        import numpy as np

        n = len(state["id"])
        # a row: position, radius, id, tag, mass, initial position, position at the last rebuild, velocity,
        # force, three zeros; RotSphere (ESyS 2.3.5, measured): orientation w x y z, angular velocity
        columns = [state["pos"], state["radius"][:, None], state["id"][:, None], state["tag"][:, None],
                   state["mass"][:, None], state["init"], state["old"], state["vel"], state["force"], np.zeros((n, 3))]
        if "quat" in state:
            columns += [state["quat"], state["angvel"]]
        table = np.hstack([np.asarray(c, dtype=np.float64).reshape(n, -1) for c in columns])
        # "%.9g" (9 significant digits, as ESyS), id and tag "%d": formatted in C++ (python/src/esys_format.cpp)
        from .._core_loader import core

        rows = core().esys_format_rows(table, "gggg" + "dd" + "g" * (table.shape[1] - 6))  # bytes
        tail = self._bond_section(t, state) + "TMIG 0\n"
        with open(data, "wb") as f:
            f.write(f"{n}\n".encode() + rows + tail.encode())


    def _bond_section(self, t, state):
        """ESyS's bonded groups: their count, then per group 'Bonded', the bond count and 'id1 id2 tag' lines
        (sorted, as ESyS writes them after createConnections). A bond Basalt broke at step s (found broken by the
        forces computed at the end of step s) is still listed in the checkpoints up to step s + 1 and left out from
        s + 2 on: ESyS finds it broken in the forces of step s + 1 and removes it as step s + 2 begins (measured
        with NRotBondPrms and RotBondPrms, docs/esys.md). A bond whose particle left the spatial domain is left
        out (not compared with ESyS)."""
        lsm = self.lsm
        if not lsm._bond_groups:
            return "0\n"
        if len(lsm._bond_groups) > 1:
            refuse("LsmMpi.createCheckPointer with several bond groups", "one bond group is written so "
                   "far; basalt.Simulation.checkpoint() writes Basalt's checkpoints")
        from .prms import NRotBondPrms

        group = lsm._bond_groups[0]
        kind = "Bonded" if isinstance(group, NRotBondPrms) else "RotBonded"  # RotBond, BrittleBeam (measured)
        bonds = listed_bonds(lsm, group, t, state)
        return f"1\n{kind}\n{len(bonds)}\n" + "".join(f"{i} {j} {tag}\n" for i, j, tag in bonds)


def listed_bonds(lsm, group, t, state):
    """The bonds of a bond group ESyS holds at step t, sorted: a bond Basalt broke at step s is held up to step
    s + 1 (ESyS finds it broken in the forces of step s + 1 and removes it as step s + 2 begins; measured)."""
    broken, present = state.get("broken_bonds", {}), set(state["id"].tolist())
    return sorted(b for b in set(lsm._bonds) if b[2] == group.tag and broken.get((b[0], b[1]), t) >= t - 1
                  and b[0] in present and b[1] in present)


class FieldSaver(_Schedule):
    """One createFieldSaver: its field read from the state and written in its file format."""

    SCALAR = ("e_kin", "e_kin_linear")
    VECTOR = ("velocity", "displacement", "position", "force")
    WALL = ("Position", "Force")
    INTERACTION = ("count", "potential_energy")

    def __init__(self, prms, lsm):
        super().__init__(prms)
        self.prms, self.count, self.lsm = prms, 0, lsm
        kind, field, fmt = prms.kind, prms.fieldName, prms.fileFormat
        call = f"LsmMpi.createFieldSaver({kind}(fieldName={field!r}, fileFormat={fmt!r}))"
        if kind == "ParticleScalarFieldSaverPrms":
            if field not in self.SCALAR:
                refuse(call, f"particle scalar fields here: {', '.join(self.SCALAR)}; Basalt's own "
                             "[[output.fields]] have more (docs/scenes.md)")
            if fmt not in ("SUM", "MAX"):
                refuse(call, "particle scalar fields are written as SUM or MAX here; RAW2/RAW_WITH_ID of "
                             "vectors are")
        elif kind == "ParticleVectorFieldSaverPrms":
            if field not in self.VECTOR:
                refuse(call, f"particle vector fields here: {', '.join(self.VECTOR)}")
            if fmt not in ("RAW2", "RAW_WITH_ID"):
                refuse(call, "particle vector fields are written as RAW2 or RAW_WITH_ID here")
        elif kind == "InteractionScalarFieldSaverPrms":
            groups = {g.name: g for g in lsm._bond_groups}
            if field not in self.INTERACTION or fmt != "SUM":
                refuse(call, "interaction fields here: count of a bond group's bonds and potential_energy of a "
                             "RotBondPrms or BrittleBeamPrms group, format SUM (ESyS 2.3.5's other fields are not "
                             "reproduced; Basalt's energy ledger has bond_potential_energy, docs/scenes.md)")
            if prms.interactionName not in groups:
                refuse(call + f" on {prms.interactionName!r}", f"the {field} of a bond group's bonds "
                       "(NRotBondPrms, RotBondPrms, BrittleBeamPrms created before the saver); a contact group's "
                       f"{field} is not reproduced")
            self.group = groups[prms.interactionName]
            if field == "potential_energy":
                from .prms import NRotBondPrms

                if isinstance(self.group, NRotBondPrms):
                    refuse(call + f" on the NRotBondPrms group {prms.interactionName!r}",
                           "the potential_energy of RotBondPrms and BrittleBeamPrms groups (ESyS's NRotBond counts "
                           "a bond in the step its forces find it broken, Basalt's linear_bond does not: not "
                           "reproduced yet); Basalt's energy ledger has bond_potential_energy, docs/scenes.md")
                if len(lsm._bond_groups) > 1:
                    refuse(call + f" with {len(lsm._bond_groups)} bond groups",
                           "the potential_energy of the run's one bond group (Basalt's bond_potential_energy sums "
                           "every bond model of the run)")
        elif kind == "WallVectorFieldSaverPrms":
            if field not in self.WALL:
                refuse(call, "wall fields here: Position, Force")
            if fmt != "RAW_SERIES":
                refuse(call, "wall fields are written as RAW_SERIES here")
            for w in prms.wallName:
                if w not in lsm._walls:
                    raise ValueError(f"{call}: no wall named {w!r} (createWall first)")
        # ESyS opens its files for appending (ios::app); so does this.

    def write(self, t, state):
        p = self.prms
        if p.kind == "ParticleScalarFieldSaverPrms":
            v = state["vel"]
            e = 0.5 * state["mass"] * (v * v).sum(axis=1)
            if p.fieldName == "e_kin" and "angvel" in state:  # RotSphere: + 1/2 I w^2, I = 2/5 m r^2
                w = state["angvel"]
                e = e + 0.5 * (0.4 * state["mass"] * state["radius"] ** 2) * (w * w).sum(axis=1)
            value = e.sum() if p.fileFormat == "SUM" else (e.max() if len(e) else 0.0)
            with open(p.fileName, "a") as f:
                f.write(_g(value) + "\n")
        elif p.kind == "ParticleVectorFieldSaverPrms":
            value = {"velocity": state["vel"], "position": state["pos"], "force": state["force"],
                     "displacement": state["pos"] - state["init"]}[p.fieldName]
            lines = []
            for i in range(len(state["id"])):
                nums = " ".join(_g(c) for c in (*state["pos"][i], *value[i]))
                lines.append(f"{int(state['id'][i])} {nums}\n" if p.fileFormat == "RAW_WITH_ID" else nums + "\n")
            with open(f"{p.fileName}.{self.count}.dat", "a") as f:
                f.write("".join(lines))
            self.count += 1
        elif p.kind == "InteractionScalarFieldSaverPrms":  # SUM, written as ESyS 2.3.5 does (measured): %.10e
            if p.fieldName == "count":  # the bonds ESyS holds (listed_bonds)
                value = len(listed_bonds(self.lsm, self.group, t, state))
            else:  # potential_energy: the sum over the group's bonds of ESyS's
                value = state["bond_energy"]  # Fn^2/2kn + Fs^2/2ks + Mt^2/2kt + Mb^2/2kb (below)
            with open(p.fileName, "a") as f:
                f.write("%.10e\n" % value)
        else:
            k = 0 if p.fieldName == "Position" else 1
            row = "".join(" ".join("%.10e" % c for c in state["walls"][w][k]) + "  " for w in p.wallName)
            with open(p.fileName, "a") as f:
                f.write(row + "\n")
