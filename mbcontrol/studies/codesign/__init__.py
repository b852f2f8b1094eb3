"""Control co-design: the hull, the drivetrain and the controller chosen together
(`mbcontrol codesign`): objectives (`objectives`), the grid or optimiser over them (`study`)
and the figure (`plots`)."""
from .objectives import OBJECTIVES, Spec, cost_proxy, evaluate
from .study import codesign

__all__ = ["codesign", "Spec", "evaluate", "cost_proxy", "OBJECTIVES"]
