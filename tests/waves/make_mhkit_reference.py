"""Reference values from MHKiT (not a test): run in a separate environment that has MHKiT,

    python3 -m venv /tmp/mhkit-venv && /tmp/mhkit-venv/bin/pip install "mhkit[wave]==1.1.2"
    /tmp/mhkit-venv/bin/python tests/waves/make_mhkit_reference.py

and paste what it prints into tests/features/waves/test_mhkit_reference.py (MHKiT is not a test extra:
its wave module needs the [wave] extra, ~40 packages including the AWS and scikit-learn stacks,
and it downgrades python-dateutil in the project environment). Only MHKiT, numpy and pandas
are used here: nothing from mbcontrol.
"""
import gzip
from pathlib import Path

import numpy as np
import pandas as pd
from mhkit.wave import resource

SITES = Path(__file__).resolve().parents[3] / "shared" / "data" / "sites"
F = np.linspace(0.005, 1.0, 4000)      # Hz: a fine uniform grid, 0.005 to 1 Hz
DEPTH = 399.0                          # m: the depth MHKiT's PacWave example uses for J


def pacwave():
    seas = pd.read_csv(SITES / "pacwave_cluster_32.csv")
    rows = []
    for hm0, tp in zip(seas.Hm0, seas.Tp):
        S = resource.jonswap_spectrum(F, float(tp), float(hm0), gamma=3.3)
        rows.append([float(resource.significant_wave_height(S).squeeze()),
                     float(resource.energy_period(S).squeeze()),
                     float(resource.energy_flux(S, h=DEPTH).squeeze()),
                     float(resource.energy_flux(S, h=DEPTH, deep=True).squeeze())])
    return rows


def buoy():
    with gzip.open(SITES / "46042w1996.txt.gz", "rt") as fh:
        lines = [l.split() for l in fh if l.strip()]
    f = np.array([float(h) for h in lines[0][4:]])
    S = np.array([[float(v) for v in l[4:]] for l in lines[1:]])
    S = S[~np.any(S >= 999.0, axis=1)]
    spec = pd.DataFrame(S.T, index=f)
    hm0 = resource.significant_wave_height(spec).values
    te = resource.energy_period(spec).values
    J = resource.energy_flux(spec, h=2000.0).values
    pick = np.arange(0, len(hm0), 1000)
    return {"hours": len(hm0), "pick": pick.tolist(), "hm0": hm0[pick].tolist(),
            "te": te[pick].tolist(), "J": J[pick].tolist(), "mean_hm0": float(hm0.mean()),
            "mean_te": float(te.mean()), "mean_J": float(J.mean())}


if __name__ == "__main__":
    np.set_printoptions(precision=10)
    print("PACWAVE_MHKIT = [  # Hm0 (m), Te (s), J (W/m) in 399 m, J deep (W/m)")
    for r in pacwave():
        print("    (" + ", ".join(f"{v:.8g}" for v in r) + "),")
    print("]")
    b = buoy()
    print("BUOY_MHKIT = {")
    for k, v in b.items():
        print(f"    {k!r}: " + (repr([float(f'{x:.8g}') for x in v]) if isinstance(v, list) and k != 'pick' else repr(v if not isinstance(v, float) else float(f'{v:.10g}'))) + ",")
    print("}")
