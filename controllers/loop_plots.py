"""Figures of a linear PTO law's loop L(s) = K(s) G(s) (controllers.margins): Bode and Nyquist
plots with the gain, phase and stability margins marked, in python-control's conventions.

The marks (`loop_marks`) are the numbers control.stability_margins(L) returns: the gain margin
nearest 1 in log (L(0) on the negative real axis included), the signed phase margin
remainder(arg L, 360 deg) - 180 deg at the gain crossover with the least |margin|, and the
stability margin min |1 + L| (python-control's looks at interior minima only: inf for a
passive damper, whose least |1 + L| = 1 is at omega = 0 and infinity; the figures mark the
least over omega >= 0). They are read off controllers.margins' frequency-response
search (Margins), which python-control's polynomial method matches where it works (the
sphere; tests/controllers/test_loop_plots.py) and misses or overflows on high-order loops.
Axes: frequency in rad/s, magnitude in dB of L (dimensionless: force per force), phase in deg.
"""
from __future__ import annotations

import math

import numpy as np

from mbcontrol.plotting import plt, save


def loop_marks(margins) -> dict:
    """{"gain_margin" (factor), "gain_margin_dB", "phase_crossover_rad_s", "phase_margin_deg"
    (signed, python-control's), "gain_crossover_rad_s", "stability_margin",
    "stability_margin_rad_s"} of controllers.margins' Margins: control.stability_margins'
    (gm, pm, sm, wpc, wgc, wms); inf where there is no crossing, nan for its frequency."""
    gm = float(margins.gain_margin)
    return {"gain_margin": gm,
            "gain_margin_dB": 20 * math.log10(gm) if 0 < gm < math.inf else math.inf,
            "phase_crossover_rad_s": float(margins.phase_crossover_rad_s),
            "phase_margin_deg": float(margins.phase_margin_signed_deg),
            "gain_crossover_rad_s": float(margins.gain_crossover_rad_s),
            "stability_margin": float(margins.stability_margin),
            "stability_margin_rad_s": float(margins.stability_margin_rad_s)}


def _response(L, omega):
    """L at each omega (rad/s): L(i omega), or L(z = exp(i omega dt)) when sampled."""
    point = np.exp(1j * omega * float(L.dt)) if L.isdtime(strict=True) else 1j * omega
    return np.array([complex(np.asarray(L(x)).ravel()[0]) for x in point])


def _grid(margins, n: int = 1500) -> np.ndarray:
    """A log frequency grid (rad/s) over the loop's modes and its crossings."""
    L = margins.loop
    lam = np.linalg.eigvals(np.asarray(L.A)) if L.nstates else np.array([1.0])
    if L.isdtime(strict=True):
        lam = np.log(lam[np.abs(lam) > 0]) / float(L.dt)
    scale = np.abs(lam[np.abs(lam) > 0]) if np.any(np.abs(lam) > 0) else np.array([1.0])
    marks = [w for w in (margins.gain_crossover_rad_s, margins.phase_crossover_rad_s,
                         margins.stability_margin_rad_s) if np.isfinite(w) and w > 0]
    low = min([float(np.min(scale)) / 30, *[w / 10 for w in marks]])
    high = max([float(np.max(scale)) * 30, *[w * 10 for w in marks]])
    if L.isdtime(strict=True):
        high = min(high, math.pi / float(L.dt))
    grid = np.geomspace(low, high, n)
    return np.unique(np.concatenate([grid, marks]))


def _title(margins) -> str:
    sampled = f", sampled every {margins.period_s:g} s" if margins.period_s else ""
    return (f"loop L = K G of PTO '{margins.pto}', {margins.law} law{sampled} "
            f"(negative feedback, closed loop {'stable' if margins.stable else 'UNSTABLE'})")


def _gm_text(m: dict) -> str:
    if math.isinf(m["gain_margin"]):
        return "GM = inf (L never crosses the negative real axis)"
    where = ("ω = 0 (static)" if m["phase_crossover_rad_s"] == 0
             else f"ω = {m['phase_crossover_rad_s']:.3g} rad/s")
    return f"GM = {m['gain_margin']:.3g} ({m['gain_margin_dB']:.3g} dB) at {where}"


def _pm_text(m: dict) -> str:
    if math.isinf(m["phase_margin_deg"]):
        return "PM = inf (|L| < 1 throughout)"
    return (f"PM = {m['phase_margin_deg']:+.3g}° at ω = {m['gain_crossover_rad_s']:.3g} rad/s "
            f"(python-control's sign; mbcontrol's unsigned: {abs(m['phase_margin_deg']):.3g}°)")


def loop_bode(margins, *, path=None, title: str | None = None):
    """Magnitude (dB) and phase (deg) of L(i omega) against omega (rad/s, log), with the
    0 dB and -180 deg lines, the gain margin (a bar from |L| to 0 dB at the phase crossover;
    at omega = 0 written on the plot) and the phase margin (a bar from -180 deg to arg L at
    the gain crossover) marked; the figure (written to `path` as PNG when given)."""
    L, m = margins.loop, loop_marks(margins)
    omega = _grid(margins)
    H = _response(L, omega)
    phase = np.degrees(np.unwrap(np.angle(H)))
    wc = m["gain_crossover_rad_s"]
    if np.isfinite(wc):        # the branch on which arg L(i wc) = -180 + PM (python-control)
        at = float(np.interp(wc, omega, phase))
        phase += 360 * round((m["phase_margin_deg"] - 180 - at) / 360)
    fig, (ax_mag, ax_ph) = plt.subplots(2, 1, sharex=True, figsize=(7.5, 6.2))
    ax_mag.semilogx(omega, 20 * np.log10(np.abs(H)), color="C0")
    ax_ph.semilogx(omega, phase, color="C0")
    ax_mag.axhline(0, color="k", lw=0.8, ls="--")
    ax_ph.axhline(-180, color="k", lw=0.8, ls="--")
    w180 = m["phase_crossover_rad_s"]
    if np.isfinite(m["gain_margin"]):      # at omega = 0: on the plot's left edge
        at = w180 if w180 > 0 else omega[0]
        ax_mag.vlines(at, -m["gain_margin_dB"], 0, color="C3", lw=2)
        ax_mag.plot(at, -m["gain_margin_dB"], "o", color="C3")
    if np.isfinite(m["phase_margin_deg"]):
        ax_ph.vlines(wc, -180, -180 + m["phase_margin_deg"], color="C2", lw=2)
        ax_ph.plot(wc, -180 + m["phase_margin_deg"], "o", color="C2")
        ax_mag.axvline(wc, color="C2", lw=0.8, ls=":")
    ax_mag.text(0.02, 0.05, _gm_text(m), transform=ax_mag.transAxes, color="C3", fontsize=9)
    ax_ph.text(0.98, 0.9, _pm_text(m), transform=ax_ph.transAxes, color="C2", fontsize=9,
               ha="right")
    ax_mag.set_ylabel("|L| (dB)")
    ax_ph.set_ylabel("arg L (deg)")
    ax_ph.set_xlabel("ω (rad/s)")
    for ax in (ax_mag, ax_ph):
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(title or _title(margins), fontsize=10)
    fig.tight_layout()
    if path:
        save(fig, path)
    return fig


def loop_nyquist(margins, *, path=None, title: str | None = None):
    """L(i omega) in the complex plane, omega >= 0 (solid) and its mirror omega < 0 (dashed):
    the whole curve (left) and near -1 (right) with the unit circle, the circle of radius
    min |1 + L| about -1 (stability margin), -1 / GM and the phase margin's point marked;
    the figure (written to `path` as PNG when given)."""
    L, m = margins.loop, loop_marks(margins)
    omega = np.concatenate([[0.0], _grid(margins)])
    H = _response(L, omega)
    fig, axes = plt.subplots(1, 2, figsize=(11, 6.4))
    t = np.linspace(0, 2 * np.pi, 361)
    for k, ax in enumerate(axes):
        ax.plot(H.real, H.imag, color="C0", label="L(iω), ω ≥ 0")
        ax.plot(H.real, -H.imag, color="C0", ls="--", lw=0.8, label="ω < 0")
        ax.plot(-1, 0, "+", color="k", ms=12, mew=2)
        ax.axhline(0, color="k", lw=0.5)
        ax.axvline(0, color="k", lw=0.5)
        ax.set_xlabel("Re L")
        ax.set_ylabel("Im L")
        ax.grid(True, alpha=0.3)
        if k == 1:
            ax.plot(np.cos(t), np.sin(t), color="0.5", lw=0.8, ls=":", label="|L| = 1")
            sm = m["stability_margin"]
            ax.plot(-1 + sm * np.cos(t), sm * np.sin(t), color="C1", lw=1,
                    label=f"min |1 + L| = {sm:.3g} at ω = {m['stability_margin_rad_s']:.3g} rad/s")
            if np.isfinite(m["gain_margin"]):
                ax.plot(-1 / m["gain_margin"], 0, "o", color="C3", label=_gm_text(m))
            if np.isfinite(m["phase_margin_deg"]):
                point = _response(L, np.array([m["gain_crossover_rad_s"]]))[0]
                ax.plot(point.real, point.imag, "o", color="C2", label=_pm_text(m))
            ax.set_xlim(-2.5, 1.5)
            ax.set_ylim(-2, 2)
            ax.set_aspect("equal")
            ax.set_title("near -1 (+)", fontsize=10)
            ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13))
        else:
            ax.set_title("whole curve", fontsize=10)
    fig.suptitle(title or _title(margins), fontsize=10)
    fig.tight_layout()
    if path:
        save(fig, path)
    return fig
