"""Analysis of a plant and of its runs: linearisation, frequency responses, bounds, metrics.

Modules: `linearize` (exact, to a named python-control StateSpace), `frequency` (the
frequency-domain solution straight from the BEM data, state-space responses, RAOs), `bounds`
(complex-conjugate and constrained power bounds), `ports` (the device seen from all its PTOs:
multiport responses and bound), `validity` (the physics checks every reported result
passes), `summary` (a run's metrics, verdict and provenance: the simulate --json contract),
`metrics` (power, PAPR, peaks, limit violations), `reduce` (balanced truncation).
"""
from .bounds import complex_conjugate_bound, pseudo_spectral_bound, pto_thevenin
from .constrained import constrained_figure, window_share
from .electrical import electrical_bound, winding_coefficient
from .envelope import ENVELOPE_SHARE, PEAK_SHARE, envelope_bound, envelope_items, envelope_response
from .frequency import (excitation_transfer, frequency_domain_response, mechanical_matrices,
                        regular_wave_amplitudes, statespace_response)
from .linearize import linearize
from .metrics import analysis_window, electrical_power, pto_metrics
from .mooring_stats import mooring_summary, tension_lines, tension_statistics
from .ports import linear_params, multiport_bound, port_responses
from .power_statistics import law_params, law_responses, record_power_statistics
from .reduce import balanced_truncation
from .summary import summary
from .validity import (ANGLE_MAX_RAD, DRAFT_FACTOR, assess, left_linear_range, mean_draft,
                       simulate_checked, split_remedy, wave_at)

__all__ = ["analysis_window", "mooring_summary", "tension_lines", "tension_statistics",
           "linearize", "frequency_domain_response", "statespace_response", "excitation_transfer",
           "regular_wave_amplitudes", "mechanical_matrices", "complex_conjugate_bound",
           "pseudo_spectral_bound", "pto_thevenin", "pto_metrics", "electrical_power", "summary",
           "balanced_truncation", "multiport_bound", "assess", "simulate_checked",
           "constrained_figure", "window_share", "electrical_bound", "winding_coefficient",
           "ENVELOPE_SHARE", "PEAK_SHARE", "envelope_bound", "envelope_items", "envelope_response",
           "linear_params", "port_responses", "law_params", "law_responses",
           "record_power_statistics", "ANGLE_MAX_RAD", "DRAFT_FACTOR", "mean_draft", "wave_at",
           "split_remedy", "left_linear_range"]
