"""The quantities of interest a study compares: a field saver reduced over the window, or a field of the last
checkpoint reduced over the particles (or bonds).

    fields.COLUMN:REDUCTION        COLUMN a column of the scene's fields.csv (docs/scenes.md, [[output.fields]]),
                                   or a sum of columns joined by '+'; REDUCTION one of
                                     last          interpolated at the window's end
                                     max, min, mean over the rows in the window
                                     argmax, argmin the time of the largest / smallest row in the window
                                     at_max(C), at_min(C)
                                                   the value at the row where column C (a column or sum) is
                                                   largest / smallest in the window; at_max(C)*F: at F times
                                                   that time, interpolated (e.g. broken bonds at 1.2 x the
                                                   time of the peak force)
                                     half_max_slope
                                                   d value / d time at half its peak: the least-squares slope
                                                   over the rows before the peak whose value lies between 0.4
                                                   and 0.6 of the peak (a UCS test's modulus at half peak,
                                                   in force per time)
    checkpoint.DATASET[.C]:REDUCTION
                                   DATASET one of /particles (position, velocity, radius, ...) or bonds.NAME
                                   (bonds.broken); C = x, y, z or norm for a vector; REDUCTION mean, max, min,
                                   sum, pP (percentile P, e.g. p99 or p99.5), count (non-zero entries),
                                   count>V, count<V
Examples: fields.runout_max:last, fields.kinetic_energy:max, checkpoint.position.x:p99,
checkpoint.bonds.broken:count, checkpoint.position.z:count<1.0,
fields.broken_bonds_tension+broken_bonds_shear:at_max(wall_force_top_wall_z)*1.2.
"""
import re


class QuantityError(ValueError):
    """A quantity that cannot be measured; the message names it."""


FIELD_REDUCTIONS = ("last", "max", "min", "mean", "argmax", "argmin", "half_max_slope", "at_max(C)", "at_min(C)")
_AT = re.compile(r"^at_(max|min)\(([^()]+)\)(?:\*([0-9.eE+-]+))?$")
COMPONENTS = {"x": 0, "y": 1, "z": 2}
_CHECKPOINT_REDUCTION = re.compile(r"^(mean|max|min|sum|count|p([0-9.]+)|count([<>])(.+))$")


class Quantity:
    """One parsed quantity: .spec (the user's text), .source ("fields" or "checkpoint"), .name (the column or
    dataset), .component (None, 0-2, "norm"), .reduction."""

    def __init__(self, spec):
        self.spec = spec
        head, sep, self.reduction = spec.rpartition(":")
        if not sep or not head or not self.reduction:
            raise QuantityError(f"quantity '{spec}': expected SOURCE:REDUCTION, e.g. fields.runout_max:last or "
                                "checkpoint.position.x:p99")
        source, _, rest = head.partition(".")
        self.source, self.component = source, None
        if source == "fields":
            if not rest:
                raise QuantityError(f"quantity '{spec}': name the fields.csv column: fields.COLUMN:REDUCTION")
            self.name = rest
            self.at = None
            m = _AT.match(self.reduction)
            if m:
                try:
                    factor = float(m.group(3)) if m.group(3) is not None else 1.0
                except ValueError:
                    factor = -1.0
                if not factor > 0:
                    raise QuantityError(f"quantity '{spec}': at_{m.group(1)}(C)*F needs a positive number F")
                self.at = (m.group(1), m.group(2), factor)
            elif self.reduction not in FIELD_REDUCTIONS[:7]:
                raise QuantityError(f"quantity '{spec}': unknown reduction '{self.reduction}' of a field saver "
                                    f"(one of {', '.join(FIELD_REDUCTIONS)})")
        elif source == "checkpoint":
            parts = rest.split(".")
            if parts and parts[0] == "bonds":
                self.name, parts = "bonds." + (parts[1] if len(parts) > 1 else ""), parts[2:]
            else:
                self.name, parts = parts[0], parts[1:]
            if self.name in ("", "bonds."):
                raise QuantityError(f"quantity '{spec}': name the checkpoint dataset: checkpoint.DATASET:REDUCTION")
            if parts:
                if len(parts) > 1 or (parts[0] not in COMPONENTS and parts[0] != "norm"):
                    raise QuantityError(f"quantity '{spec}': unknown component '{'.'.join(parts)}' "
                                        "(x, y, z or norm)")
                self.component = COMPONENTS.get(parts[0], "norm")
            m = _CHECKPOINT_REDUCTION.match(self.reduction)
            if not m:
                raise QuantityError(f"quantity '{spec}': unknown reduction '{self.reduction}' of a checkpoint field "
                                    "(mean, max, min, sum, pP, count, count>V, count<V)")
            try:
                if m.group(2) is not None and not 0 <= float(m.group(2)) <= 100:
                    raise ValueError
                if m.group(4) is not None:
                    float(m.group(4))
            except ValueError:
                raise QuantityError(f"quantity '{spec}': reduction '{self.reduction}': a percentile in [0, 100] "
                                    "or a count threshold must be a number")
        else:
            raise QuantityError(f"quantity '{spec}': unknown source '{source}' (fields or checkpoint)")

    @property
    def needs_checkpoint(self):
        return self.source == "checkpoint"

    def check_fields(self, columns):
        """Raises QuantityError naming the quantity when `columns` (the scene's fields.csv header) lacks it."""
        if self.source != "fields":
            return
        names = self.name.split("+") + (self.at[1].split("+") if self.at else [])
        for name in names:
            if name not in columns:
                saved = ", ".join(c for c in columns if c not in ("step", "time")) or "none"
                raise QuantityError(f"quantity '{self.spec}': the scene saves no field '{name}' (its fields.csv "
                                    f"columns: {saved}; add an [[output.fields]] saver, docs/scenes.md)")

    def check_checkpoint(self, ckpt):
        """Raises QuantityError naming the quantity when checkpoint `ckpt` (basalt.Checkpoint) lacks it."""
        if self.source == "checkpoint":
            self._array(ckpt)

    def _array(self, ckpt):
        import numpy as np
        if self.name.startswith("bonds."):
            table, key, where = ckpt.bonds or {}, self.name[len("bonds."):], "/bonds"
        else:
            table, key, where = ckpt.particles, self.name, "/particles"
        if key not in table:
            raise QuantityError(f"quantity '{self.spec}': the checkpoint has no dataset {where}/{key} (it has: "
                                f"{', '.join(sorted(table)) or 'none'})")
        a = np.asarray(table[key], dtype=float)
        if self.component is None:
            if a.ndim != 1:
                raise QuantityError(f"quantity '{self.spec}': {where}/{key} is a vector: name a component "
                                    "(.x, .y, .z or .norm)")
            return a
        if a.ndim != 2:
            raise QuantityError(f"quantity '{self.spec}': {where}/{key} is not a vector: leave the component out")
        return np.linalg.norm(a, axis=1) if self.component == "norm" else a[:, self.component]

    def measure(self, fields, ckpt, t_start, t_end):
        """The quantity's value: `fields` {column: numpy array} of the run, `ckpt` its last checkpoint (or None),
        the window [t_start, t_end] in the scene's time unit."""
        import numpy as np
        if self.source == "fields":
            return self._measure_fields(fields, t_start, t_end)
        a = self._array(ckpt)
        r = self.reduction
        if r in ("mean", "max", "min", "sum"):
            return float(getattr(np, r)(a)) if a.size else 0.0
        if r == "count":
            return float(np.count_nonzero(a))
        if r.startswith("count"):
            v = float(r[6:])
            return float(np.count_nonzero(a > v if r[5] == ">" else a < v))
        return float(np.percentile(a, float(r[1:])))

    def _column(self, fields, name):
        """(time, values) of a column or a '+'-joined sum of columns, rows where any is missing left out."""
        import numpy as np
        t = np.asarray(fields["time"], dtype=float)
        y = sum(np.asarray(fields[n], dtype=float) for n in name.split("+"))
        ok = ~np.isnan(y)
        if not ok.any():
            raise QuantityError(f"quantity '{self.spec}': no saved value of '{name}' in the run")
        return t[ok], y[ok]

    def _window(self, t, name, t_start, t_end):
        inside = (t >= t_start - 1e-12 * abs(t_end)) & (t <= t_end * (1 + 1e-9))
        if not inside.any():
            raise QuantityError(f"quantity '{self.spec}': no saved value of '{name}' between t = "
                                f"{t_start:g} and {t_end:g}")
        return inside

    def _measure_fields(self, fields, t_start, t_end):
        import numpy as np
        t, y = self._column(fields, self.name)
        r = self.reduction
        if r == "last":
            return float(np.interp(t_end, t, y))
        if self.at is not None:
            which, other, factor = self.at
            tc, c = self._column(fields, other)
            inside = self._window(tc, other, t_start, t_end)
            pick = np.argmax if which == "max" else np.argmin
            t_at = tc[inside][pick(c[inside])] * factor
            if t_at > t[-1] * (1 + 1e-9):
                raise QuantityError(f"quantity '{self.spec}': t = {t_at:g} is past the last saved row "
                                    f"(t = {t[-1]:g}): lengthen the window")
            return float(np.interp(t_at, t, y))
        inside = self._window(t, self.name, t_start, t_end)
        t, y = t[inside], y[inside]
        if r in ("argmax", "argmin"):
            return float(t[(np.argmax if r == "argmax" else np.argmin)(y)])
        if r == "half_max_slope":
            peak = int(np.argmax(y))
            band = (y[:peak + 1] >= 0.4 * y[peak]) & (y[:peak + 1] <= 0.6 * y[peak])
            if y[peak] <= 0 or np.count_nonzero(band) < 2:
                raise QuantityError(f"quantity '{self.spec}': fewer than 2 saved rows of '{self.name}' between "
                                    "0.4 and 0.6 of its (positive) peak before it: save it more often")
            return float(np.polyfit(t[:peak + 1][band], y[:peak + 1][band], 1)[0])
        return float({"max": np.max, "min": np.min, "mean": np.mean}[r](y))
