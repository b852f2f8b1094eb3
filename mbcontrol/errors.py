"""Exception types. Each names the file, the field and what was expected."""


class MbcontrolError(Exception):
    """Base class of every error this package raises on bad input or failed numerics."""


class SceneError(MbcontrolError, ValueError):
    """A scene file is invalid. The message names the file, the field and what was expected."""


class HydroError(MbcontrolError, ValueError):
    """Hydrodynamic data are missing, inconsistent or unusable. Names the file and the problem."""


class SimulationError(MbcontrolError, RuntimeError):
    """A simulation diverged or could not proceed. Names the time, the step and a remedy."""


class LinearizationError(MbcontrolError, ValueError):
    """An operating point is not an equilibrium, or a requested signal does not exist."""


class FidelityError(MbcontrolError, ValueError):
    """A fidelity option is invalid or does not fit the scene; names the field and the value."""


class ControllerError(MbcontrolError, ValueError):
    """A controller's settings are invalid or its design cannot be met: names the setting,
    the value and what was expected."""


class WaveError(MbcontrolError, ValueError):
    """A wave or sea description is invalid: names the field, the value and what was expected."""


class InputError(MbcontrolError, ValueError):
    """Bad input to a command, a study, an analysis or the simulator: names the option or
    field, the value and what was expected."""


class UnknownName(MbcontrolError, KeyError):
    """A name (a parameter, signal, controller or model) that does not exist; the message
    lists the known ones."""

    def __str__(self):                # KeyError quotes its message; this one is a sentence
        return str(self.args[0]) if self.args else ""


class EnvironmentProblem(MbcontrolError, OSError):
    """The machine, not the input, stopped the work: a full disk, a folder without write
    permission, a read-only file system, a cache entry unreadable even when made again.
    Names the path and what to do. An OSError, so code that handled the raw OSError before
    still handles it."""
