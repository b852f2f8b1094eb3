"""Controller design, a study: tune a law by name for a sea, bound it, simulate it in closed
loop and score it (`design`, the CLI's `mbcontrol design`); the same tuning for each sea of a
sweep or a co-design point (`design_for_sea`). The laws and their tuners are in
`mbcontrol.controllers`; this package only calls them."""
from .fallback import NoLawForSea, no_law_design, saturated_damper, tune_with_fallback
from .sea import DESIGNABLE, design_for_sea
from .study import DesignResult, design
from .tuning import CONTRACT, tune

__all__ = ["design", "DesignResult", "design_for_sea", "DESIGNABLE", "tune", "CONTRACT",
           "tune_with_fallback", "saturated_damper", "NoLawForSea", "no_law_design"]
