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
