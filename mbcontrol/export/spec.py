"""What an exported controller is made of: its measured inputs, its parameters, its constant
data and the C engine that runs it, read off the controller for its plant.

A controller class says whether it leaves Python by the law protocol's class attributes
(controllers.law): `exportable`, and its `kind`, which picks the engine (`csrc/`) that runs
it: "linear" (passive, reactive: the CasADi-generated static law with its gains as
parameters), "switching" (latching, declutching) or "predictive" (the linear MPC, read
through its `export_view`: Kalman filter, AR forecast and the condensed QP, solved by the
dual active-set solver of `csrc/mbc_qp.c`). A class that is not exportable may say why in
`export_refusal` (NMPC: its NLP solver, IPOPT, is not code-generatable). Oracles cannot
leave Python: an MPC with the true future wave or the plant's whole state would need what
no device measures, so they are refused here.

The caller's controller is never reset or changed: an MPC is read through
`Mpc.export_view(plant)` (its frozen settings and a setup built afresh for the plant);
another law through a private copy bound to the plant (its reset rebinds, so the copy's
binding leaves the original as it was).
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..errors import InputError
from ..sim import export_refusal, exportable, law_kind, name_of, period_of

# The exported QP's iteration cap per variable: the bound on a step's time. Past it the step
# takes the previous plan's next move (within the force and rate limits; mbc_mpc.c).
QP_MAX_ITER_PER_VARIABLE = 3      # the sphere's 40-variable QPs in H 2.5 m waves took at most 62


@dataclass
class Parameter:
    name: str
    value: float
    unit: str
    description: str


@dataclass
class ControllerSpec:
    """kind: "law", "switching" or "mpc"; inputs: plant output names the controller reads (in
    order); outputs: the force commands (u__<pto>, N or N m); parameters: tunable after
    export; defines: C macros (name -> text); arrays: C constant arrays (name -> (type,
    values)); casadi: CasADi functions to generate into the sources; engine: csrc files."""
    kind: str
    name: str
    inputs: list
    outputs: list
    parameters: list
    defines: dict = field(default_factory=dict)
    arrays: dict = field(default_factory=dict)
    casadi: list = field(default_factory=list)
    engine: list = field(default_factory=list)
    context: str = ""                       # the C context struct's fields
    settings: dict = field(default_factory=dict)     # the bound controller's describe()
    headers: list = field(default_factory=list)      # csrc headers mbc_controller.h includes
    declarations: list = field(default_factory=list)  # more lines of mbc_controller.h
    tables: list = field(default_factory=list)       # more C definitions of mbc_data.c


def controller_spec(controller, plant) -> ControllerSpec:
    """The spec of `controller` for `plant`, by its class's `kind` (the engine), if it is
    `exportable`; the controller itself is left as it is (see the module docstring)."""
    build = ENGINES.get(law_kind(controller))
    if not exportable(controller) or build is None:
        from mbcontrol.controllers import REGISTRY
        can = [n for n, cls in REGISTRY.items() if exportable(cls)]
        why = export_refusal(controller) or (
            "its class is not exportable" if build is not None
            else f"no C engine for a law of kind {law_kind(controller)!r}")
        raise InputError(f"export: controller {name_of(controller)!r} cannot be exported "
                         f"({why}); exportable: {', '.join(can)}")
    spec = build(controller, plant)
    # s; the FMU samples on this grid (0: at every communication point)
    spec.defines["MBC_SAMPLE_PERIOD"] = repr(float(period_of(controller) or 0.0))
    return spec


def bound_copy(controller, plant):
    """A shallow copy of `controller` bound to `plant` by its own reset (which rebinds what
    it sets): the original keeps its binding and its run."""
    twin = copy.copy(controller)
    twin.reset(plant)
    return twin


def sparse_rows(A: np.ndarray):
    """(row starts, columns, values) of A's nonzeros, row by row (compressed sparse rows)."""
    A = np.asarray(A, float)
    rows, cols = np.nonzero(A)
    start = np.searchsorted(rows, np.arange(A.shape[0] + 1))
    return start, cols, A[rows, cols]


def _ptos(plant):
    return [p.name for p in plant.scene.ptos]


def _law_spec(controller, plant) -> ControllerSpec:
    c = bound_copy(controller, plant)
    names = _ptos(plant)
    reactive = hasattr(c, "stiffness_per_pto")     # a stiffness term: position measured too
    inputs = ([f"{n}__position" for n in names] if reactive else []) + \
        [f"{n}__velocity" for n in names]
    nu = len(names)
    gains = c.damping_per_pto
    stiffness = c.stiffness_per_pto if reactive else np.zeros(nu)
    params = [Parameter(f"damping_{n}", float(v), "N s/m or N m s/rad", f"damping of PTO {n}")
              for n, v in zip(names, gains)]
    if reactive:
        params += [Parameter(f"stiffness_{n}", float(v), "N/m or N m/rad",
                             f"stiffness of PTO {n}") for n, v in zip(names, stiffness)]
    params += [Parameter(f"force_max_{n}", float(v), "N or N m",
                         f"saturation of PTO {n}'s command (inf: none)")
               for n, v in zip(names, c.saturation)]
    y = ca.SX.sym("y", len(inputs))
    p = ca.SX.sym("p", len(params))
    v = y[nu:] if reactive else y
    x = y[:nu] if reactive else ca.SX.zeros(nu)
    k = p[nu:2 * nu] if reactive else ca.SX.zeros(nu)
    f_max = p[len(params) - nu:]
    u = -(p[:nu] * v + k * x)
    law = ca.Function("law", [y, p], [ca.fmin(ca.fmax(u, -f_max), f_max)])
    return ControllerSpec("law", c.name, inputs, [f"u__{n}" for n in names], params,
                          casadi=[law], engine=["mbc_law.c"],
                          defines={"MBC_LAW": "MBC_CAT(MBC_PREFIX, law)",
                                   "MBC_LAW_SZ_ARG": str(max(law.sz_arg(), 2)),
                                   "MBC_LAW_SZ_RES": str(max(law.sz_res(), 1))},
                          context=f"double params[{len(params)}];\n"
                                  f"    casadi_int iw[{max(law.sz_iw(), 1)}];\n"
                                  f"    double w[{max(law.sz_w(), 1)}];",
                          settings=c.describe())


def _switching_spec(controller, plant) -> ControllerSpec:
    c = bound_copy(controller, plant)
    names = _ptos(plant)
    nu = len(names)
    latching = hasattr(c, "brake_inertia")         # a brake holds the body: no motion held
    hold = c.latch_time if latching else c.declutch_time
    inertia = c.brake_inertia if latching else np.ones(nu)
    params = [Parameter(f"damping_{n}", float(v), "N s/m or N m s/rad",
                        f"damping of PTO {n} while engaged")
              for n, v in zip(names, c.damping_per_pto)]
    params += [Parameter("latch_time" if latching else "declutch_time", float(hold), "s",
                         "hold from each velocity zero crossing")]
    params += [Parameter(f"force_max_{n}", float(v), "N or N m",
                         f"saturation of PTO {n}'s command (inf: none)")
               for n, v in zip(names, c.saturation)]
    params += [Parameter(f"inertia_{n}", float(v), "kg or kg m^2",
                         f"inertia the brake of PTO {n} assumes" if latching else "unused")
               for n, v in zip(names, inertia)]
    return ControllerSpec(
        "switching", c.name, [f"{n}__velocity" for n in names], [f"u__{n}" for n in names],
        params, engine=["mbc_switching.c"],
        defines={"MBC_MOVES_WHILE_HELD": "0" if latching else "1"},
        arrays={"MBC_VELOCITY_INDEX": ("int", list(range(nu)))},
        context=f"double params[{len(params)}];\n"
                f"    int held[{nu}], has_prev;\n"
                f"    double release[{nu}], sign[{nu}], v_prev[{nu}], u_prev[{nu}], t_prev;",
        settings=c.describe())


def _check_exportable_mpc(settings, setup) -> None:
    """Refuse an MPC the C engine cannot run as a device would."""
    if settings.oracle:
        raise InputError("export: this MPC is an oracle (forecast 'known' or estimator "
                         "'state'): it needs the future wave or the whole plant state, which a "
                         "device does not measure; export a causal one (forecast 'ar')")
    if setup.qp.n_env:
        raise InputError("export: this MPC keeps the linear model's envelope (relative heave "
                         "against a surface probe, angles), which the C engine does not hold "
                         "yet; export one without it (--set envelope=false, "
                         "make('mpc', ..., envelope=False)) and keep the device in range "
                         "another way")


def _mpc_spec(c, plant) -> ControllerSpec:
    if not hasattr(c, "export_view"):
        raise InputError(f"export: the predictive law {c.name!r} has no export_view(plant) "
                         f"(its settings and setup, as controllers.Mpc gives them)")
    view = c.export_view(plant)             # settings and a fresh setup: c is left alone
    settings, setup = view.settings, view.setup
    _check_exportable_mpc(settings, setup)
    cp, qp, kal = setup.cp, setup.qp, setup.kalman
    outputs = list(plant.outputs)
    names = list(cp.ptos)
    nu, N = len(names), qp.N
    kalman_inputs = [outputs[i] for i in cp.y_index]
    velocity_inputs = [f"{n}__velocity" for n in names]
    inputs = kalman_inputs + [v for v in velocity_inputs if v not in kalman_inputs]
    nz, nd, nxi = cp.nz, cp.nd, kal.nxi
    ar = setup.ar                           # the AR predictor's configuration
    ar_order = ar.order if ar is not None else 1
    window = ar.window if ar is not None else 1
    forms = qp.forms
    arrays = {
        "MBC_KALMAN_INDEX": ("int", [inputs.index(n) for n in kalman_inputs]),
        "MBC_VELOCITY_INDEX": ("int", [inputs.index(n) for n in velocity_inputs]),
        "MBC_Y_REST": ("double", cp.y_rest), "MBC_PHI": ("double", kal.Phi),
        "MBC_GAMMA": ("double", kal.Gamma), "MBC_K": ("double", kal.K),
        "MBC_C": ("double", kal.C), "MBC_CXI": ("double", kal.C_xi),
        "MBC_PHI_XI": ("double", kal.Phi_xi), "MBC_PPRED": ("double", qp.Phi),
        "MBC_OM": ("double", qp.Om), "MBC_QZ": ("double", qp.Qz_v), "MBC_QD": ("double", qp.Qd_v),
        "MBC_STROKE": ("double", qp.stroke), "MBC_RATE": ("double", qp.rate),
        "MBC_FORCE_MAX": ("double", setup.limits["force"]),
        "MBC_BLOCK_OF": ("int", qp.block_of),       # move blocking: each step's block
    }
    form_rows = _qp_form_arrays(forms, arrays)
    nv_max = max(f.n_var for f in forms)
    na_max = max(max(f.A.shape[0] for f in forms), 1)
    warm = [float(v) for v in setup.warm_up_damping]
    params = [Parameter(f"warm_up_damping_{n}", v, "N s/m or N m s/rad",
                        f"passive damper of PTO {n} until the first AR fit")
              for n, v in zip(names, warm)]
    params += [Parameter("warm_up_s", float(setup.warm_up_planned), "s",
                         "planned warm-up (the AR fit waits for it)"),
               Parameter("blend_s", float(setup.blend_s), "s",
                         "take-over from the damper to the MPC")]
    window_max = 4 * window                  # room for a warm-up up to 4x longer
    defines = {
        "MBC_NU": str(nu), "MBC_NY": str(len(kalman_inputs)), "MBC_NK": str(kal.Phi.shape[0]),
        "MBC_NZ": str(nz), "MBC_ND": str(nd), "MBC_NXI": str(nxi), "MBC_N": str(N),
        "MBC_NB": str(qp.n_b),
        "MBC_P": str(ar_order), "MBC_AR_WINDOW": str(window), "MBC_WINDOW_MAX": str(window_max),
        "MBC_AR_REFIT": str(ar.refit if ar is not None else 1),
        "MBC_AR_RIDGE": repr(ar.ridge if ar is not None else 0.0),
        "MBC_FORECAST": {"none": "0", "ar": "1", "model": "2"}[settings.forecast],
        "MBC_DT": repr(settings.dt_s), "MBC_FS": repr(qp.Fs), "MBC_LS": repr(qp.Ls),
        "MBC_HAS_STROKE": str(int(qp.has_stroke)), "MBC_HAS_RATE": str(int(qp.has_rate)),
        "MBC_NFORMS": str(len(forms)),
        "MBC_QP_ITER_PER_VARIABLE": str(QP_MAX_ITER_PER_VARIABLE),
    }
    context = _mpc_context(n_params=len(params), n_kalman=kal.Phi.shape[0], nu=nu, nd=nd, N=N,
                           nb=qp.n_b, ar_order=ar_order, window_max=window_max, nv_max=nv_max,
                           na_max=na_max, n_forms=len(forms))
    return ControllerSpec("mpc", c.name, inputs, [f"u__{n}" for n in names], params,
                          defines=defines, arrays=arrays, engine=["mbc_mpc.c", "mbc_qp.c"],
                          context=context, settings=view.description, headers=["mbc_qp.h"],
                          declarations=MPC_FORM_DECLARATIONS,
                          tables=["const mbc_form MBC_FORMS[] = {" + ", ".join(form_rows)
                                  + "};\n"])


MPC_FORM_DECLARATIONS = [
    "typedef struct { int nv, na, soft; const double *H; const int *A_start, *A_col; "
    "const double *A_val, *lbx, *ubx, *g_slack; } mbc_form;",
    "#define MBC_FORMS MBC_CAT(MBC_PREFIX, forms)", "extern const mbc_form MBC_FORMS[];"]


def _qp_form_arrays(forms, arrays: dict) -> list:
    """Each QP form's matrices into `arrays` (constraint rows in compressed sparse rows); the C
    initialisers of the forms' table."""
    form_rows = []
    for i, form in enumerate(forms):
        start, col, val = sparse_rows(form.A)
        arrays.update({f"MBC_F{i}_H": ("double", form.H), f"MBC_F{i}_ASTART": ("int", start),
                       f"MBC_F{i}_ACOL": ("int", col), f"MBC_F{i}_AVAL": ("double", val)})
        for part in ("lbx", "ubx", "g_slack"):
            arrays[f"MBC_F{i}_{part.upper()}"] = ("double", getattr(form, part))
        form_rows.append(f"{{{form.n_var}, {form.A.shape[0]}, {int(form.soft)}, "
                         + ", ".join(f"MBC_F{i}_{p}" for p in
                                     ("H", "ASTART", "ACOL", "AVAL", "LBX", "UBX", "G_SLACK"))
                         + "}")
    return form_rows


def _mpc_context(*, n_params, n_kalman, nu, nd, N, nb, ar_order, window_max, nv_max, na_max,
                 n_forms) -> str:
    """The C engine's per-instance state, sized for this MPC (nb: the QP's force variables,
    N nu without move blocking)."""
    nv = N * nu
    return "\n    ".join([
        f"double params[{n_params}];",
        f"double s[{n_kalman}], u_prev[{nu}], first_t, next_t, warm_up_end;",
        "int has_last, warm_done, has_plan, has_coef, last_form;",
        f"double hist[{window_max * max(nd, 1)}];",
        "int hist_len, hist_start, since_fit, min_samples, window;",
        f"double coef[{max(nd, 1) * ar_order}], maps[{max(nd, 1) * (N + 1) * ar_order}];",
        f"double D[{max(N * nd, 1)}], plan[{nv}], q[{nb}], freep[{nv}];",
        f"double g[{nv_max}], x[{nv_max}], lba[{na_max}], uba[{na_max}];",
        f"mbc_qp qp[{n_forms}];",
        f"double J0[{n_forms}][{nv_max * nv_max}];",
        f"double qp_work[MBC_QP_WORK({nv_max}, {na_max})];",
        f"int qp_iwork[MBC_QP_IWORK({nv_max}, {na_max})];",
        "long solves, failures, soft_solves, ar_fits, ar_unstable_fits, qp_iterations_max;"])


# the law's kind (controllers.law.KINDS) -> the spec of the engine that runs it
ENGINES = {"linear": _law_spec, "switching": _switching_spec, "predictive": _mpc_spec}
