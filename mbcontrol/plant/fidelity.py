"""Fidelity options: model no more than a scene needs, and measure what leaving things out costs.

A `Fidelity` names four simplifications of the full process plant (its defaults are the full
model, exactly what `build_plant(scene)` returns):

- radiation_tol: a looser radiation fit (fewer radiation states);
- couplings="drop": no hydrodynamic radiation coupling between different bodies (the
  off-diagonal body blocks of A(w), B(w) and A(inf) are zeroed, so the fit splits per body);
  the excitation, diffraction by the neighbours included, is kept;
- freeze: DOFs of free (or composite) joints removed, e.g. sway, roll and yaw in head seas;
- kinematics="linear": the exact linearisation about rest, with the quadratic energy-audit
  outputs kept to second order so the audit still closes;
- pressure="linear": linear hydrostatics and Froude-Krylov forces where the scene asks for
  nonlinear ones ([hydro] hydrostatics = froude_krylov = "nonlinear"), so `auto` measures
  what the nonlinear pressure changes in the user's waves.

`plant_for(scene, fidelity, waves=...)` builds the plant of one choice; `auto(scene, waves, tol)`
simulates the full model and simplified candidates in the user's waves, and picks the cheapest
whose error stays within `tol` (mbcontrol.studies.fidelity_auto holds the search and its report).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import casadi as ca
import numpy as np
import xarray as xr

from ..errors import FidelityError
from ..hydro import HydroModel, fit_hydro_model, fit_method, load_hydro_data
from ..multibody import build_topology
from ..scene import DOF_NAMES, Scene, load_scene
from .freeze import as_wave_list, freeze_report, frozen_scene
from .process import ProcessPlant, active_hydro_dofs, assemble_plant, device_around

AUDIT_OUTPUTS = ("energy", "excitation_power", "radiated_power")   # plus "<pto>__power"


@dataclass(frozen=True)
class Fidelity:
    """Which simplifications a plant uses; the defaults are the full model.

    radiation_tol : radiation fit tolerance (hydro.radiation, "Error"; None: the scene's).
    couplings : "keep" or "drop" the radiation coupling between different bodies.
    freeze : body DOFs "<body>__<Dof>" of free/composite joints to remove, names of revolute or
        prismatic joints to block (as a test rig does), or "auto" (free-joint DOFs the waves
        cannot excite; needs waves, see `freeze_report`).
    kinematics : "exact" (the nonlinear plant) or "linear" (its linearisation about rest).
    pressure : "scene" (hydrostatics and Froude-Krylov forces as the scene says) or "linear".
    """
    radiation_tol: float | None = None
    couplings: str = "keep"
    freeze: tuple[str, ...] | str = ()
    kinematics: str = "exact"
    pressure: str = "scene"

    def __post_init__(self):
        if self.pressure not in ("scene", "linear"):
            raise FidelityError(f"Fidelity.pressure: expected 'scene' or 'linear', got "
                                f"{self.pressure!r}")
        if self.radiation_tol is not None and not (np.isfinite(self.radiation_tol)
                                                   and 0 < self.radiation_tol < 1):
            raise FidelityError(f"Fidelity.radiation_tol: expected None or a number in (0, 1), "
                                f"got {self.radiation_tol!r}")
        if self.couplings not in ("keep", "drop"):
            raise FidelityError(f"Fidelity.couplings: expected 'keep' or 'drop', got "
                                f"{self.couplings!r}")
        if self.kinematics not in ("exact", "linear"):
            raise FidelityError(f"Fidelity.kinematics: expected 'exact' or 'linear', got "
                                f"{self.kinematics!r}")
        if isinstance(self.freeze, str):
            if self.freeze != "auto":
                raise FidelityError(f"Fidelity.freeze: expected 'auto' or a list of body DOFs "
                                    f"'<body>__<Dof>', got {self.freeze!r}")
            return
        freeze = tuple(sorted(set(self.freeze)))
        bad = [d for d in freeze if d.count("__") > 1 or d.count("__") == 1
               and d.split("__")[1] not in DOF_NAMES or not d]
        if bad:
            raise FidelityError(f"Fidelity.freeze: {bad} are not body DOFs '<body>__<Dof>' with "
                                f"<Dof> one of {', '.join(DOF_NAMES)}, nor joint names")
        object.__setattr__(self, "freeze", freeze)

    @property
    def is_full(self) -> bool:
        """True for the defaults: the full model, as build_plant(scene) builds it."""
        return self == Fidelity()

    def label(self, scene_tol: float | None = None) -> str:
        """Short description, e.g. 'radiation_tol=0.05, couplings=drop' ('full' when none)."""
        parts = []
        if self.radiation_tol is not None and self.radiation_tol != scene_tol:
            parts.append(f"radiation_tol={self.radiation_tol:g}")
        if self.couplings != "keep":
            parts.append(f"couplings={self.couplings}")
        if self.freeze:
            parts.append("freeze=" + (self.freeze if isinstance(self.freeze, str)
                                      else "(" + ", ".join(self.freeze) + ")"))
        if self.kinematics != "exact":
            parts.append(f"kinematics={self.kinematics}")
        if self.pressure != "scene":
            parts.append(f"pressure={self.pressure}")
        return ", ".join(parts) or "full"

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["freeze"] = d["freeze"] if isinstance(d["freeze"], str) else list(d["freeze"])
        return d


# ----------------------------------------------------------------------------- plant_for

def linear_pressure_scene(scene: Scene) -> Scene:
    """The scene with linear hydrostatics and Froude-Krylov forces (the hydro data's)."""
    if scene.hydro.hydrostatics == "linear":
        return scene
    return dataclasses.replace(scene, hydro=dataclasses.replace(
        scene.hydro, hydrostatics="linear", froude_krylov="linear"))


def plant_for(scene: Scene | str, fidelity: Fidelity | None = None, *, waves=None,
              hydro: HydroModel | None = None, reference: ProcessPlant | None = None,
              freeze_threshold: float | None = None,
              hydro_corrections: bool = False) -> ProcessPlant:
    """The process plant of `scene` at `fidelity` (default: the full model).

    waves : a Wave or a list of them; needed for freeze="auto" and used as the band of the
        coupling report (otherwise the radiation fit band). hydro : the full plant's HydroModel,
        to reuse its data (no second read or BEM run). reference : the full plant, if built.
    hydro_corrections : hydro scale factors as parameters (see `assemble_plant`). The plant's notes["fidelity"] records the resolved options (freeze as an explicit list),
    the frozen-DOF evidence and the size of the dropped coupling.
    """
    scene = load_scene(scene) if not isinstance(scene, Scene) else scene
    fidelity = Fidelity() if fidelity is None else fidelity
    wave_list = as_wave_list(waves)
    notes: dict = {}
    if fidelity.freeze == "auto":
        if not wave_list:
            raise FidelityError("Fidelity.freeze = 'auto' needs the scene's waves: call "
                                "plant_for(scene, fidelity, waves=...) or mbcontrol.studies.fidelity_auto.auto")
        reference = reference or plant_for(scene, Fidelity(radiation_tol=fidelity.radiation_tol))
        notes["freeze"] = freeze_report(reference, wave_list, freeze_threshold)
        fidelity = dataclasses.replace(fidelity, freeze=tuple(
            d for d, row in notes["freeze"].items() if row["frozen"]))
    if fidelity.pressure == "linear":
        scene = linear_pressure_scene(scene)
    frozen = frozen_scene(scene, fidelity.freeze)
    if fidelity.couplings == "keep" and not fidelity.freeze and hydro is None:
        plant = assemble_plant(scene, radiation_tol=fidelity.radiation_tol,
                               hydro_corrections=hydro_corrections)
    else:
        model = _hydro_model(scene, frozen, fidelity, hydro, wave_list, notes)
        plant = assemble_plant(frozen, model, hydro_corrections=hydro_corrections)
    if fidelity.kinematics == "linear":
        plant = linearised_plant(plant)
    plant.notes["fidelity"] = {"options": fidelity.as_dict(), **notes}
    return plant


def _hydro_model(scene, frozen, fidelity, hydro, waves, notes) -> HydroModel | None:
    """The frozen scene's HydroModel, from the full model's data, couplings dropped if asked."""
    dofs = active_hydro_dofs(frozen, build_topology(frozen))
    if not dofs:
        return None
    if hydro is None:
        source, data = load_hydro_data(scene, active_hydro_dofs(scene, build_topology(scene)))
        limit = scene.hydro.fit_omega_max
    else:
        source, data, limit = hydro.source, hydro.data, hydro.fit_omega_max
    tol = scene.hydro.radiation_tol if fidelity.radiation_tol is None else fidelity.radiation_tol
    if fidelity.couplings == "drop":
        band = wave_band(waves) if waves else (float(data["omega"].min()),
                                               min(float(data["omega"].max()), limit))
        notes["couplings"] = coupling_size(data, dofs, band)
        data = drop_couplings(data)
        source = f"{source} (couplings between bodies dropped)"
    return fit_hydro_model(data, dofs, tol, source, limit, scene.hydro.response_band,
                           fit_method(scene.hydro.radiation_fit, dofs, data),
                           device_around(frozen, source, data, dofs) if scene.hydro.fit_judged_by == "response" else None)


# ----------------------------------------------------------------------------- couplings

def _body(dof) -> str:
    return str(dof).split("__")[0]


def drop_couplings(data: xr.Dataset) -> xr.Dataset:
    """A copy of body-frame BEM data without radiation coupling between different bodies.

    A(w), B(w), A(inf) (and A(0) when present) keep only their same-body blocks, so the radiation
    fit (which fits exactly uncoupled groups separately) becomes block-diagonal per body.
    """
    rows, cols = data["influenced_dof"].values, data["radiating_dof"].values
    same = xr.DataArray(np.equal.outer([_body(d) for d in rows], [_body(d) for d in cols]),
                        coords={"influenced_dof": rows, "radiating_dof": cols},
                        dims=("influenced_dof", "radiating_dof"))
    out = data.copy()
    for name in ("added_mass", "radiation_damping", "added_mass_inf", "added_mass_zero"):
        if name in out:
            out[name] = data[name].where(same, 0.0)
    return out


def coupling_size(data: xr.Dataset, dofs, band: tuple[float, float]) -> dict:
    """How large the radiation coupling between different bodies is over a wave band (rad/s).

    impedance: max over the band of |Z_ij(w)| / sqrt(|Z_ii(w)| |Z_jj(w)|), Z = B(w) + i w A(w)
    the radiation load per unit velocity (what couplings="drop" removes: A(inf) and the memory
    kernel together); kernel: max |K_ij(w)| / sqrt(max|K_ii| max|K_jj|) over the band, with
    K = B + i w (A - A(inf)) the memory kernel the radiation states fit. Both dimensionless
    (the geometric mean makes translation-rotation pairs comparable); pairs name the DOFs.
    """
    dofs = list(dofs)
    w = data["omega"].values
    inside = (w >= band[0]) & (w <= band[1])
    if inside.sum() < 2:     # a regular wave: the two data frequencies around it
        i = int(np.clip(np.searchsorted(w, band[0]), 1, w.size - 1))
        inside = np.zeros(w.size, bool)
        inside[i - 1:i + 1] = True

    def matrix(name):
        da = data[name].sel(influenced_dof=dofs, radiating_dof=dofs)
        return da.transpose(..., "influenced_dof", "radiating_dof").values

    A, B, A_inf = matrix("added_mass")[inside], matrix("radiation_damping")[inside], \
        matrix("added_mass_inf")
    w = w[inside][:, None, None]
    Z, K = np.abs(B + 1j * w * A), np.abs(B + 1j * w * (A - A_inf))
    out = {"band_rad_s": [float(band[0]), float(band[1])], "impedance": 0.0,
           "impedance_pair": None, "kernel": 0.0, "kernel_pair": None}
    Zd, Kd = np.einsum("kii->ki", Z), np.einsum("kii->ki", K).max(axis=0)
    for i, di in enumerate(dofs):
        for j, dj in enumerate(dofs):
            if _body(di) == _body(dj):
                continue
            with np.errstate(divide="ignore", invalid="ignore"):
                z = np.nan_to_num(Z[:, i, j] / np.sqrt(Zd[:, i] * Zd[:, j]))
                k = float(np.nan_to_num(K[:, i, j].max() / np.sqrt(Kd[i] * Kd[j])))
            if z.max() > out["impedance"]:
                out.update(impedance=float(z.max()), impedance_pair=[di, dj],
                           impedance_omega=float(w[int(np.argmax(z)), 0, 0]))
            if k > out["kernel"]:
                out.update(kernel=k, kernel_pair=[di, dj])
    return out


def has_couplings(plant: ProcessPlant) -> bool:
    """True when the plant's radiation couples different bodies (couplings='drop' can act)."""
    if plant.hydro is None:
        return False
    dofs = list(plant.hydro.dofs)
    A_inf, B = plant.hydro.added_mass_inf, plant.hydro.radiation_damping()
    other = ~np.equal.outer([_body(d) for d in dofs], [_body(d) for d in dofs])
    return bool(np.any(A_inf[other] != 0) or np.any(B[:, other] != 0))


# ----------------------------------------------------------------------------- freeze


def wave_band(waves) -> tuple[float, float]:
    """(lowest, highest) frequency, rad/s, of the components carrying the waves' energy: those
    whose amplitude^2 is at least 1e-3 of the largest component's."""
    lo, hi = np.inf, 0.0
    for wave in as_wave_list(waves):
        a2 = wave.amplitude ** 2
        w = wave.omega[a2 >= 1e-3 * a2.max()]
        lo, hi = min(lo, float(w.min())), max(hi, float(w.max()))
    return lo, hi


# ----------------------------------------------------------------------------- linear

def linearised_plant(plant: ProcessPlant) -> ProcessPlant:
    """The exact linearisation of `plant` about rest, as a ProcessPlant with its signal names.

    With z = [x, u, w]: f_lin = f(0; p) + (df/dz)(0; p) z, so the parameters stay symbolic (the
    Jacobians are CasADi expressions of p, sparse as the plant's). Outputs are linearised too,
    except the quadratic audit outputs (energy, excitation_power, radiated_power and each
    <pto>__power), which are their exact second-order expansion at rest, y(0) + g.z + 1/2 z'Hz,
    so the energy audit of the linear plant closes: where the energy's gradient at rest is zero
    (notes["energy_gradient_at_rest"], J per state unit) d(energy)/dt equals the audited powers
    exactly, as in the nonlinear plant. A smoothed Coulomb friction becomes its slope at v = 0.
    """
    x, p = ca.SX.sym("x", plant.nx), ca.SX.sym("p", len(plant.p0))
    u, w = ca.SX.sym("u", len(plant.inputs)), ca.SX.sym("w", len(plant.disturbances))
    z = ca.vertcat(x, u, w)
    f, y = plant.f(x, u, w, p), plant.h(x, u, w, p)
    quadratic = [i for i, name in enumerate(plant.outputs) if name in AUDIT_OUTPUTS
                 or any(name == f"{pto.name}__power" for pto in plant.scene.ptos)]
    hessians = [ca.hessian(y[i], z)[0] for i in quadratic]
    # evaluating at z = 0 with p symbolic folds every constant: only p-dependent entries remain
    at_rest = ca.Function("at_rest", [z, p], [f, ca.jacobian(f, z), y, ca.jacobian(y, z),
                                              *hessians])
    rest = np.concatenate([plant.x0(), np.zeros(z.shape[0] - plant.nx)])
    f0, Jf, y0, Jy, *H = at_rest(ca.DM(rest), p)
    dz = z - ca.DM(rest)            # rest: the scene's pose, or where mooring lines hold it
    y_lin = y0 + ca.mtimes(Jy, dz)
    terms = [ca.SX.zeros(1)] * len(plant.outputs)
    for i, Hi in zip(quadratic, H):
        terms[i] = 0.5 * ca.mtimes([dz.T, Hi, dz])
    y_lin += ca.vertcat(*terms)
    f_fun = ca.Function("f", [x, u, w, p], [f0 + ca.mtimes(Jf, dz)], ["x", "u", "w", "p"],
                        ["xdot"])
    h_fun = ca.Function("h", [x, u, w, p], [y_lin], ["x", "u", "w", "p"], ["y"])
    notes = dict(plant.notes)
    if "energy" in plant.outputs:
        gradient = ca.Function("g", [p], [Jy[plant.outputs.index("energy"), :plant.nx]])
        notes["energy_gradient_at_rest"] = float(np.max(np.abs(np.asarray(gradient(plant.p0))),
                                                        initial=0.0))
    return dataclasses.replace(plant, f=f_fun, h=h_fun, notes=notes, parts=None, held=None)

