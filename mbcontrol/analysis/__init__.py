"""Analysis of a plant and of its runs: linearisation, frequency responses, bounds, metrics.

Modules: `linearize` (exact, to a named python-control StateSpace), `frequency` (the
frequency-domain solution straight from the BEM data, state-space responses, RAOs), `bounds`
(complex-conjugate and constrained power bounds), `ports` (the device seen from all its PTOs:
multiport responses and bound), `validity` (the physics checks every reported result
passes), `summary` (a run's metrics, verdict and provenance: the simulate --json contract),
`metrics` (power, PAPR, peaks, limit violations), `reduce` (balanced truncation), `result`
(`Result`: one run with its summary, what `mbcontrol.simulate` returns).
"""
from .bounds import complex_conjugate_bound, pseudo_spectral_bound, pto_thevenin
from .constrained import constrained_figure, window_share
from .electrical import electrical_bound, winding_coefficient
from .envelope import envelope_bound, envelope_items, envelope_response, peak_share
from .frequency import (excitation_transfer, frequency_domain_response, mechanical_matrices,
                        regular_wave_amplitudes, statespace_response)
from .linearize import linearize
from .metrics import analysis_window, electrical_power, pto_metrics
from .mooring_stats import mooring_summary, tension_lines, tension_statistics
from .ports import linear_params, multiport_bound, port_responses
from .power_statistics import law_params, law_responses, record_power_statistics
from .reduce import balanced_truncation
from .result import Result
from .summary import summary
from .validity import (assess, left_linear_range, mean_draft,
                       simulate_checked, split_remedy, wave_at)

# the documented public part; the other names above serve the later stages of the flow
# (controllers, studies, cli), which may enter this package only here (tests/test_layout.py)
__all__ = ["Result", "summary", "assess", "simulate_checked", "linearize",
           "frequency_domain_response", "statespace_response", "regular_wave_amplitudes",
           "complex_conjugate_bound", "pseudo_spectral_bound", "multiport_bound",
           "electrical_bound", "pto_metrics", "electrical_power", "analysis_window",
           "balanced_truncation", "mooring_summary", "tension_statistics"]
