"""The exceptions of the package basalt. Both are ValueErrors, so ``except ValueError`` catches them too.

The compiled core (basalt._core) raises them with the C++ tools' messages unchanged; the pure-Python readers
raise FormatError with messages of the same form, ``<file>: <where>: <what>``.
"""


class FormatError(ValueError):
    """A file Basalt cannot read or write. The message names the file and the line (text files) or the
    dataset or attribute (HDF5), as basalt-run's and basalt-pack's do: ``cube.geo: line 10: radius must be
    finite and > 0, got -0.5``. ``file`` and ``where`` hold those two parts (``where`` may be empty)."""

    def __init__(self, message, file=None, where=None):
        super().__init__(message)
        self.file = file
        self.where = where

    @classmethod
    def at(cls, file, where, what):
        """The error ``<file>: <where>: <what>`` (``<file>: <what>`` when where is empty)."""
        file = str(file)
        return cls(f"{file}: {where}: {what}" if where else f"{file}: {what}", file, where or "")


class PackError(ValueError):
    """An impossible packing request (bad radii, a volume too small, an unwritable output ...), with
    basalt-pack's message; options are named as on its command line (``--bond-tolerance must be >= 0``)."""


class InputError(ValueError):
    """A bad scene, geometry or argument of basalt.Simulation, with basalt-run's message (naming the file, line
    and key: ``<scene text>:12: run.dt: must be positive``)."""


class RunError(RuntimeError):
    """A run that stopped: a blow-up, an output error, a stop signal, or (on the other ranks) a callback's
    exception on one rank. The rank whose callback raised gets its own exception back."""


# Shown as basalt.FormatError ... in tracebacks, where users catch them.
FormatError.__module__ = PackError.__module__ = InputError.__module__ = RunError.__module__ = "basalt"
