"""The radiation fit's band for a user's own BEM file when the scene gives no fit_omega_max.

A third-party file runs to whatever frequency its author chose, and its top is where panel
methods are least accurate: irregular frequencies, negative damping, lost reciprocity (WEC-Sim's
rm3.out: damping repaired to 0 at 5.12-5.2 rad/s, plate heave noisy above 4 rad/s). Fitted
there, a model spends its states on those artefacts and misses the band that matters (rm3 in
heave, tol 1 %: 0.7 % with the band below, 5.6 % to 5 rad/s).

The band that matters is the device's: the fit is judged by the error it causes in the device's
response, weighted by how much the device moves (module response_error: full weight where its
wave motion is at least MOVES of its peak, proportionally less below). The default band ends
where that weight has fallen to MOVES, the device's wave motion to MOVES² (1 %) of its peak,
for good: there a 10 % response error counts as 1 %, the default tolerance, and a sea that
drives the device there drives it at a hundredth of its peak. A device moving at every frequency
of the file gets the whole file.
"""
from __future__ import annotations

import numpy as np

from .kernel import kernel_data, reciprocal
from .response_error import MOVES, Device


def moving_band(device: Device, data, dofs) -> float:
    """Highest BEM frequency (rad/s) at which the device's wave motion (per unit amplitude, its
    PTOs free) is at least MOVES² of its peak; the file's top frequency if it moves there."""
    w, K, _ = kernel_data(data, list(dofs), None)
    weight = device.restricted(list(dofs)).at(w, reciprocal(K)[0]).weight
    moving = np.nonzero(weight >= MOVES)[0]
    return float(w[moving[-1]]) if moving.size else float(w[-1])


def default_fit_band(scene_name: str, device: Device, data, dofs) -> float:
    """moving_band, said once per fit (console status) with what sets it instead."""
    from ...console import status
    band = moving_band(device, data, dofs)
    status(f"{scene_name}: radiation fit band 0-{band:.3g} rad/s of {data.attrs.get('converted_from')}'s "
           f"0-{float(data['omega'].max()):.3g}: where the device's wave motion is at least "
           f"{MOVES ** 2:.0%} of its peak ([hydro] fit_omega_max sets it)", __name__)
    return band
