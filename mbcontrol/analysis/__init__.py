"""Analysis of a plant and of its runs: linearisation, frequency responses, bounds, metrics.

Modules: `linearize` (exact, to a named python-control StateSpace), `frequency` (the
frequency-domain solution straight from the BEM data, state-space responses, RAOs), `bounds`
(complex-conjugate and constrained power bounds), `ports` (the device seen from all its PTOs:
multiport responses and bound), `validity` (the physics checks every reported result
passes), `summary` (a run's metrics, verdict and provenance: the simulate --json contract),
`metrics` (power, PAPR, peaks, limit violations), `reduce` (balanced truncation).
"""
from .bounds import complex_conjugate_bound, pseudo_spectral_bound, pto_thevenin
from .frequency import (excitation_transfer, frequency_domain_response, mechanical_matrices,
                        regular_wave_amplitudes, statespace_response)
from .linearize import linearize
from .metrics import electrical_power, pto_metrics
from .ports import multiport_bound
from .reduce import balanced_truncation
from .summary import summary
from .validity import assess, simulate_checked

__all__ = ["linearize", "frequency_domain_response", "statespace_response", "excitation_transfer",
           "regular_wave_amplitudes", "mechanical_matrices", "complex_conjugate_bound",
           "pseudo_spectral_bound", "pto_thevenin", "pto_metrics", "electrical_power", "summary",
           "balanced_truncation", "multiport_bound", "assess", "simulate_checked"]
