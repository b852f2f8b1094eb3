"""Control co-design: the hull, the drivetrain and the controller chosen together
(`mbcontrol codesign`): objectives (`objectives`), the grid or optimiser over them (`study`)
and the figure (`plots`)."""
from .compare import compare_optima
from .compare import describe as describe_comparison
from .objectives import OBJECTIVES, UNLIKE, Spec, cost_proxy, evaluate
from .plots import plot_codesign
from .study import codesign

__all__ = ["codesign", "Spec", "evaluate", "cost_proxy", "OBJECTIVES", "UNLIKE", "compare_optima",
           "describe_comparison", "plot_codesign"]
