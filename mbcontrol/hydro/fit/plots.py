"""The hydrodynamic coefficients a plant uses, drawn (`mbcontrol hydro SCENE --plot FILE`):
per DOF (the diagonal entries, at most MAX_COLUMNS), the added mass A(omega) and the radiation
damping B(omega) of the data as dots with the fitted radiation model over them, and the
excitation force per metre of wave amplitude |F_ex(omega)| (heading 0) of the data. The fit
is K_fit(j omega) = C (j omega I - A_r)^-1 B_r + D_r of K = B + j omega (A - A(inf)), so its
damping is Re K_fit and its added mass A(inf) + Im K_fit / omega; frequencies above the fit's
band (the scene's fit_omega_max) are shaded: the model is not held to the data there.
"""
from __future__ import annotations

import numpy as np

MAX_COLUMNS = 6


def _unit(dof: str, kind: str) -> str:
    turning = dof.endswith(("Roll", "Pitch", "Yaw"))
    return {"A": "kg m²" if turning else "kg", "B": "N m s" if turning else "N s/m",
            "F": "N m/m" if turning else "N/m"}[kind]


def fitted_coefficients(hydro, omega) -> tuple[np.ndarray, np.ndarray]:
    """(A_fit, B_fit), each (n_omega, n, n) on the radiation model's DOFs: the added mass and
    damping the fitted radiation model stands for, A(inf) + Im K_fit / omega and Re K_fit."""
    omega = np.asarray(omega, float)
    K = hydro.radiation.frequency_response(omega)
    index = [list(hydro.dofs).index(d) for d in hydro.radiation.dofs]
    a_inf = hydro.added_mass_inf[np.ix_(index, index)]
    return a_inf + K.imag / omega[:, None, None], K.real


def hydro_figure(hydro, path, *, name: str, fit_omega_max: float = np.inf):
    """Draw `hydro` (a HydroModel) to `path` (the format its suffix names); returns the path."""
    import matplotlib.pyplot as plt

    from ...plotting import save
    dofs = list(hydro.dofs)[:MAX_COLUMNS]
    omega = np.asarray(hydro.omega, float)
    fine = np.geomspace(omega[0], omega[-1], 400)
    rad = hydro.radiation
    A_fit, B_fit = fitted_coefficients(hydro, fine)
    index = [list(rad.dofs).index(d) for d in dofs]
    A, B = np.diagonal(hydro.added_mass(), axis1=1, axis2=2), \
        np.diagonal(hydro.radiation_damping(), axis1=1, axis2=2)
    F = np.abs(hydro.excitation_coefficients(0.0))
    fig, axes = plt.subplots(3, len(dofs), figsize=(3.2 * len(dofs) + 1, 7.5), squeeze=False,
                             sharex=True)
    for c, (dof, k) in enumerate(zip(dofs, index)):
        j = list(hydro.dofs).index(dof)
        panels = ((A[:, j], A_fit[:, k, k], "A", "added mass"),
                  (B[:, j], B_fit[:, k, k], "B", "radiation damping"),
                  (F[:, j], None, "F", "|excitation| per m of wave"))
        for r, (data, fit, kind, label) in enumerate(panels):
            ax = axes[r, c]
            ax.plot(omega, data, "o", ms=2.5, color="0.35", label="data")
            if fit is not None:
                ax.plot(fine, fit, "-", color="C3", lw=1.2, label=f"fit ({rad.order} states)")
            if np.isfinite(fit_omega_max) and fit_omega_max < omega[-1]:
                ax.axvspan(fit_omega_max, omega[-1], color="0.9", zorder=0,
                           label="above the fit's band")
            ax.set_ylabel(f"{label}, {_unit(dof, kind)}", fontsize=8)
            ax.grid(alpha=0.3)
            ax.tick_params(labelsize=7)
            if r == 0:
                ax.set_title(dof.replace("__", " "), fontsize=9)
            if r == 2:
                ax.set_xlabel("ω, rad/s", fontsize=8)
    axes[1, 0].legend(fontsize=7)
    more = f"; {len(hydro.dofs) - len(dofs)} more DOFs not drawn" if len(hydro.dofs) > len(dofs) \
        else ""
    fig.suptitle(f"{name}: hydrodynamic coefficients (diagonal entries) and the radiation fit "
                 f"({rad.order} states, error {rad.fit_error:.2%}){more}", fontsize=10)
    fig.tight_layout()
    out = save(fig, path)
    plt.close(fig)
    return out
