"""Sea states at a site: the SeaState a sweep runs, grids of them, a site's weighted list (a CSV
with Hm0, Tp and/or Te, weights and its own energy flux J), a year of buoy spectra (NOAA NDBC
files) and the joint Hm0 x Te occurrence table they give.

Te and Tp: when a file gives both, both are kept as given (the site's own ratio; PacWave's file
has Te / Tp = 0.858 throughout); when it gives only Te, Tp = Te / te_over_tp(gamma) of the
JONSWAP spectrum the sea will be simulated with. J (`site_energy_flux`): the flux of the
site's own sea (its Hm0, Tp and Te / Tp) in the device's depth; a file's J column is kept
(`SeaState.j`) but not used (PacWave's is off, see `site_energy_flux`).
"""
from __future__ import annotations

import csv
import dataclasses
import gzip
import math
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import WaveError
from .flux import G, RHO, energy_flux
from .spectra import te_over_tp

if TYPE_CHECKING:
    import xarray as xr

WEIGHT_SUM_TOLERANCE = 0.02        # a weighted list's weights must sum to 1 within this


@dataclass(frozen=True)
class SeaState:
    """A JONSWAP sea: significant height hs (m), peak period tp (s), peak enhancement gamma,
    and its weight (share of the year; NaN on a grid that carries no occurrence); te (s) and
    j (W/m) are the energy period and energy flux the source gave (NaN when it gave none);
    direction (rad, NED: where the waves travel to) and spread (rad, the circular standard
    deviation of a `spreading` function, "cos2s" or "mitsuyasu"; waves.Spreading): NaN when not
    given (the data's heading; long-crested), spread 0 long-crested."""
    hs: float
    tp: float
    gamma: float = 3.3
    weight: float = math.nan
    te: float = math.nan                 # energy period (s), when the source gave it
    j: float = math.nan                  # energy flux (W/m), when the source gave it
    direction: float = math.nan          # rad, NED mean direction, when given
    spread: float = math.nan             # rad, directional spread sigma, when given
    spreading: str = "cos2s"             # the spreading function's kind (waves.Spreading)

    @property
    def spread_given(self) -> bool:
        """True for a short-crested sea (a spread sigma > 0)."""
        return math.isfinite(self.spread) and self.spread > 0


def grid(hs, tp, gamma: float = 3.3) -> list[SeaState]:
    """Every Hs with every Tp, unweighted."""
    return [SeaState(float(h), float(t), gamma) for h in hs for t in tp]


def site_energy_flux(sea: SeaState, depth: float = math.inf, rho: float = RHO,
                     g: float = G) -> float:
    """J (W/m) of a sea in water of `depth` m and density `rho` (those of the simulated
    device, so that P / J is a capture width): the flux of the site's own sea when its file
    gave Te and Tp (a JONSWAP spectrum of the site's Hm0 and Tp whose Te / Tp is the site's:
    its gamma from `gamma_for_te_over_tp`), else of the simulated JONSWAP sea (hs, tp, gamma).

    A file's J column (kept as `sea.j`) is not used: PacWave's is what MHKiT's example
    computed with its spectrum evaluated at frequencies pi/2 too high (reproduced to 1e-10 in
    tests/waves), 4.3 % below to 22 % above the flux of the file's own Hm0 and Te.
    """
    from .spectra import gamma_for_te_over_tp
    gamma = sea.gamma
    if math.isfinite(sea.te) and sea.tp > 0:
        gamma = gamma_for_te_over_tp(sea.te / sea.tp)
    return energy_flux(sea.hs, sea.tp, gamma, depth, rho, g)


def read_seas(path, gamma: float = 3.3) -> list[SeaState]:
    """Sea states from a CSV with columns Hm0 and Tp and/or Te (only Te: Tp = Te / (Te/Tp of
    the JONSWAP spectrum of this gamma)), optional weights (summing to 1), J (W/m, the
    site's energy flux), direction (degrees, NED: where the waves travel to, +x towards +y)
    and spread (degrees, the directional spread sigma, 0 to 81: `waves.Spreading`; 0 is
    long-crested), kept in radians. Errors name the file, row and column."""
    path = Path(path)
    try:
        with path.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as exc:
        raise WaveError(f"{path}: cannot read the seas file ({exc.strerror})") from None
    if not rows:
        raise WaveError(f"{path}: no sea states (expected a header with Hm0 and Tp or Te, "
                        f"then one row per sea)")
    columns = set(rows[0])
    period = "Tp" if "Tp" in columns else "Te" if "Te" in columns else None
    if "Hm0" not in columns or period is None:
        raise WaveError(f"{path}: expected columns Hm0 and Tp (or Te), found "
                        f"{', '.join(sorted(c for c in columns if c))}")
    ratio = te_over_tp(gamma)
    seas = []
    for i, row in enumerate(rows, start=2):              # row 1 is the header
        values = {}
        for name in ("Hm0", period, "weights", "Te", "J") + DIRECTIONAL:
            text = (row.get(name) or "").strip()
            if name in ("weights", "Te", "J") and not text or name not in columns:
                continue
            try:
                values[name] = float(text)
            except ValueError:
                raise WaveError(f"{path}: row {i}, column {name}: expected a number, got "
                                f"{text!r}") from None
        for name in ("Hm0", period) + (("J",) if "J" in values else ()):
            if not values[name] > 0 or not math.isfinite(values[name]):
                raise WaveError(f"{path}: row {i}, column {name}: expected a positive "
                                f"number, got {values[name]:g}")
        if values.get("weights", 0.0) < 0:
            raise WaveError(f"{path}: row {i}, column weights: expected >= 0, got "
                            f"{values['weights']:g}")
        _check_directional(path, i, values)
        tp = values[period] if period == "Tp" else values[period] / ratio
        seas.append(SeaState(values["Hm0"], tp, gamma, values.get("weights", math.nan),
                             values.get("Te", math.nan), values.get("J", math.nan),
                             math.radians(values.get("direction", math.nan)),
                             math.radians(values.get("spread", math.nan))))
    weights = [s.weight for s in seas]
    if "weights" in columns:
        if any(math.isnan(w) for w in weights):
            row = 2 + next(k for k, w in enumerate(weights) if math.isnan(w))
            raise WaveError(f"{path}: row {row}, column weights: missing (every row needs one)")
        total = sum(weights)
        if abs(total - 1.0) > WEIGHT_SUM_TOLERANCE:
            raise WaveError(f"{path}: weights sum to {total:.4g}; expected 1 within "
                            f"{WEIGHT_SUM_TOLERANCE} (shares of the year)")
        if abs(total - 1.0) > 1e-9:         # rounding in the file: shares of the year add to 1
            warnings.warn(f"{path}: weights sum to {total:.6g}; normalised to 1",
                          UserWarning, stacklevel=2)
            seas = [dataclasses.replace(s, weight=s.weight / total) for s in seas]
    return seas


DIRECTIONAL = ("direction", "spread")     # optional seas-file columns, degrees
SPREAD_MAX_DEG = math.degrees(math.sqrt(2.0))   # 81.03 deg: s = 0, the uniform distribution


def _check_directional(path, row: int, values: dict) -> None:
    """A seas file's direction (finite degrees) and spread (0 <= sigma < 81.03 degrees)."""
    if "direction" in values and not math.isfinite(values["direction"]):
        raise WaveError(f"{path}: row {row}, column direction: expected a finite angle "
                        f"(degrees, NED: where the waves travel to), got {values['direction']:g}")
    spread = values.get("spread", 0.0)
    if not 0 <= spread < SPREAD_MAX_DEG:
        raise WaveError(f"{path}: row {row}, column spread: expected a directional spread "
                        f"sigma from 0 (long-crested) to below {SPREAD_MAX_DEG:.2f} degrees "
                        f"(cos-2s, s > 0), got {spread:g}")


def read_year_weights(path) -> dict[str, np.ndarray]:
    """label -> weights of each row of a seas CSV in one year, from columns named
    weights_<label> (e.g. weights_2019): the interannual variability of the resource
    (`studies.sweep.budget.resource`). {} when the file has none; errors name the file, row
    and column; each year's weights must sum to 1 within WEIGHT_SUM_TOLERANCE."""
    path = Path(path)
    with path.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    columns = [c for c in (rows[0] if rows else {}) if c and c.startswith("weights_")]
    years = {}
    for column in columns:
        values = []
        for i, row in enumerate(rows, start=2):
            text = (row.get(column) or "").strip()
            try:
                value = float(text)
            except ValueError:
                raise WaveError(f"{path}: row {i}, column {column}: expected a number (the "
                                f"sea's share of that year), got {text!r}") from None
            if not value >= 0:
                raise WaveError(f"{path}: row {i}, column {column}: expected >= 0, got "
                                f"{value:g}")
            values.append(value)
        total = sum(values)
        if abs(total - 1.0) > WEIGHT_SUM_TOLERANCE:
            raise WaveError(f"{path}: column {column} sums to {total:.4g}; expected 1 within "
                            f"{WEIGHT_SUM_TOLERANCE} (shares of that year)")
        years[column[len("weights_"):]] = np.array(values) / total
    if len(years) == 1:
        raise WaveError(f"{path}: one weights_<year> column ({columns[0]}); interannual "
                        f"variability needs two or more years")
    return years


def read_ndbc_spectra(path) -> tuple[np.ndarray, np.ndarray, list]:
    """(f in Hz, S in m^2/Hz per row, row stamps) from an NDBC spectral wave density file
    (text or .gz: header 'YY MM DD hh [mm] f1 f2 ...', one hour a row; rows with the
    missing-value code 999 are dropped)."""
    path = Path(path)
    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt") as fh:
        lines = [l.split() for l in fh if l.strip()]
    header = [h.lstrip("#") for h in lines[0]]
    n_time = sum(1 for h in header if h in ("YY", "YYYY", "MM", "DD", "hh", "mm"))
    try:
        f = np.array([float(h) for h in header[n_time:]])
    except ValueError:
        raise WaveError(f"{path}: header {' '.join(header[:8])}...: expected date columns "
                        f"then frequencies in Hz") from None
    stamps, rows = [], []
    for k, parts in enumerate(lines[1:], start=2):
        if len(parts) != n_time + f.size:
            raise WaveError(f"{path}: line {k} has {len(parts)} values; expected "
                            f"{n_time + f.size}")
        values = np.array([float(v) for v in parts[n_time:]])
        if np.any(values >= 999.0):
            continue
        stamps.append(" ".join(parts[:n_time]))
        rows.append(values)
    return f, np.array(rows), stamps


def occurrence(hm0, te, hs_edges, te_edges) -> xr.DataArray:
    """Joint occurrence (share of the records) over Hm0 x Te bins, labelled by bin centres.

    Records outside the edges are not in any bin: attrs["outside"] counts them (the table then
    sums to 1 - outside / records), so an annual energy can say what it left out."""
    import xarray as xr             # here: reading a site's seas needs no xarray
    hm0, te = np.asarray(hm0, float), np.asarray(te, float)
    counts, _, _ = np.histogram2d(hm0, te, bins=[hs_edges, te_edges])
    share = counts / max(len(hm0), 1)
    centre = lambda e: 0.5 * (np.asarray(e[:-1]) + np.asarray(e[1:]))  # noqa: E731
    return xr.DataArray(share, coords={"hs": centre(hs_edges), "te": centre(te_edges)},
                        dims=("hs", "te"), name="occurrence",
                        attrs={"records": int(len(hm0)),
                               "outside": int(len(hm0) - counts.sum()),
                               "hs_edges": list(map(float, hs_edges)),
                               "te_edges": list(map(float, te_edges))})
