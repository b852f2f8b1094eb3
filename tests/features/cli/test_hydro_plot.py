"""`mbcontrol hydro MODEL --plot FILE` (issue 58): the hydro data and the fitted radiation
model drawn over them. The fit's added mass and damping (hydro.fit.plots.fitted_coefficients) are
checked against the BEM data they were fitted to, the independent reference: the sphere's
fit (5 states) matches its heave B within its response band to 0.41 % of B's range and A to
0.95 % of A's (measured); a wrong sign or a missing A(inf) would miss by the whole range."""
import numpy as np
import pytest

from mbcontrol.cli import main
from mbcontrol.hydro.fit.plots import fitted_coefficients
from mbcontrol.plant import build_plant


def test_the_fitted_coefficients_lie_on_the_data():
    hydro = build_plant("sphere").hydro
    band = hydro.omega[(hydro.omega >= 0.3) & (hydro.omega <= 2.5)]   # its response band
    A_fit, B_fit = fitted_coefficients(hydro, band)
    keep = np.isin(hydro.omega, band)
    A, B = hydro.added_mass()[keep, 0, 0], hydro.radiation_damping()[keep, 0, 0]
    assert np.max(np.abs(B_fit[:, 0, 0] - B)) < 0.02 * np.ptp(B)
    assert np.max(np.abs(A_fit[:, 0, 0] - A)) < 0.05 * np.ptp(A)


def test_the_command_draws_the_figure(tmp_path, capsys):
    out = tmp_path / "hydro.png"
    assert main(["hydro", "sphere", "--plot", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"figure: {out}" in capsys.readouterr().out
