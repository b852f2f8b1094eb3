"""Analysis of a plant and of its runs: linearisation, frequency responses, bounds, metrics.

Modules: `linearize` (exact, to a named python-control StateSpace), `frequency` (the
frequency-domain solution straight from the BEM data, state-space responses, RAOs), `bounds`
(complex-conjugate and constrained power bounds), `ports` (the device seen from all its PTOs:
multiport responses and bound), `validity` (the physics checks every reported result
passes), `summary` (a run's metrics, verdict and provenance: the simulate --json contract),
`metrics` (power, PAPR, peaks, limit violations), `reduce` (balanced truncation), `result`
(`Result`: one run with its summary, what `mbcontrol.simulate` returns).
"""
from ..lazy import face
# linearize and summary name both a module and its function: bound here, so that the function
# (not the submodule an import of it would set) is the package's attribute. Both are light.
from .linearize import linearize
from .summary import summary

# name -> (submodule, its name there): loaded on first use, so that `simulate --json` imports
# no bound's, reduction's or plotting's code (tests/features/cli/test_startup.py)
_WHERE = {
    "complex_conjugate_bound": ("bounds", "complex_conjugate_bound"),
    "pseudo_spectral_bound": ("bounds", "pseudo_spectral_bound"),
    "pto_thevenin": ("bounds", "pto_thevenin"),
    "constrained_figure": ("constrained", "constrained_figure"),
    "window_share": ("constrained", "window_share"),
    "electrical_bound": ("electrical", "electrical_bound"),
    "winding_coefficient": ("electrical", "winding_coefficient"),
    "envelope_bound": ("envelope", "envelope_bound"),
    "envelope_items": ("envelope", "envelope_items"),
    "envelope_response": ("envelope", "envelope_response"), "peak_share": ("envelope", "peak_share"),
    "excitation_transfer": ("frequency", "excitation_transfer"),
    "frequency_domain_response": ("frequency", "frequency_domain_response"),
    "mechanical_matrices": ("frequency", "mechanical_matrices"),
    "regular_wave_amplitudes": ("frequency", "regular_wave_amplitudes"),
    "statespace_response": ("frequency", "statespace_response"),
    "analysis_window": ("metrics", "analysis_window"),
    "electrical_power": ("metrics", "electrical_power"), "pto_metrics": ("metrics", "pto_metrics"),
    "mooring_summary": ("mooring_stats", "mooring_summary"),
    "tension_lines": ("mooring_stats", "tension_lines"),
    "tension_statistics": ("mooring_stats", "tension_statistics"),
    "linear_params": ("ports", "linear_params"), "multiport_bound": ("ports", "multiport_bound"),
    "port_responses": ("ports", "port_responses"),
    "law_params": ("power_statistics", "law_params"),
    "law_responses": ("power_statistics", "law_responses"),
    "record_power_statistics": ("power_statistics", "record_power_statistics"),
    "balanced_truncation": ("reduce", "balanced_truncation"), "Result": ("result", "Result"),
    "assess": ("validity", "assess"), "left_linear_range": ("validity", "left_linear_range"),
    "mean_draft": ("validity", "mean_draft"), "simulate_checked": ("validity", "simulate_checked"),
    "split_remedy": ("validity", "split_remedy"), "wave_at": ("validity", "wave_at"),
}

# the documented public part; the other names above serve the later stages of the flow
# (controllers, studies, cli), which may enter this package only here (tests/test_layout.py)
__all__ = ["Result", "summary", "assess", "simulate_checked", "linearize",
           "frequency_domain_response", "statespace_response", "regular_wave_amplitudes",
           "complex_conjugate_bound", "pseudo_spectral_bound", "multiport_bound",
           "electrical_bound", "pto_metrics", "electrical_power", "analysis_window",
           "balanced_truncation", "mooring_summary", "tension_statistics"]

__getattr__, __dir__ = face(__name__, globals(), _WHERE)
