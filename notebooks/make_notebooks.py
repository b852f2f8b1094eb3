"""Write the example notebooks from the cells below (keeps them reviewable as Python).

Run: python notebooks/make_notebooks.py   (tests execute the .ipynb files top to bottom)
"""
from pathlib import Path

import nbformat

TOUR = [
    ("md", "# Tour: the seed's hinged barge\n\nScene file → BEM data in body frames → "
           "radiation state-space model → nonlinear process plant → linear control plant → "
           "closed loop. Every number below is computed when the notebook runs."),
    ("code", "import numpy as np\nfrom mbcontrol import waves\nfrom mbcontrol.scene import "
             "load_scene\nfrom mbcontrol.plant import build_plant\nfrom mbcontrol.analysis.linearize "
             "import linearize\nfrom mbcontrol.sim import simulate\nfrom "
             "mbcontrol.analysis import frequency_domain_response, statespace_response\n"
             "from mbcontrol.controllers import make"),
    ("md", "## The scene\nTwo 0.6 m barges: barge 1 pivots on a fixed post, barge 2 is hinged "
           "to it with a PTO damper (`models/hinged_barge.toml`)."),
    ("code", "scene = load_scene('hinged_barge')\n[(j.name, j.type, j.parent, j.child, j.point)"
             " for j in scene.joints]"),
    ("md", "## The process plant\nStates are the joint angles and rates plus the radiation "
           "states; the hydro DOFs are only those the joints can move."),
    ("code", "plant = build_plant(scene)\nprint(plant.states[:4], '+', plant.nx - 4, "
             "'radiation states')\nprint('hydro DOFs:', plant.hydro.dofs)\nprint('radiation fit "
             "error: %.2f %%' % (100 * plant.hydro.radiation.fit_error))"),
    ("md", "## Linear control plant\nExact Jacobians at rest into a named python-control "
           "`StateSpace`. Coulomb friction is left out of the linear model (its smoothed slope "
           "at zero velocity is not a useful linear damping)."),
    ("code", "sys = linearize(plant, params={'hinge_friction__coulomb': 0.0})\nprint(sys.nstates,"
             " 'states; stable:', bool(np.all(np.linalg.eigvals(sys.A).real < 0)))\n"
             "omega = np.array([4.0, 6.0, 8.0, 10.0])\nfd = frequency_domain_response(plant, "
             "omega, params={'hinge_friction__coulomb': 0.0}, outputs=['hinge'])[:, 0]\n"
             "ss = statespace_response(sys, plant, omega, outputs=['hinge'])[:, 0]\n"
             "print('hinge RAO (rad/m), BEM-direct:', np.round(abs(fd), 4))\n"
             "print('hinge RAO (rad/m), state space:', np.round(abs(ss), 4))\n"
             "assert np.allclose(abs(ss), abs(fd), rtol=0.02)"),
    ("md", "## Closed loop on the nonlinear plant\nA passive damper added to the PTO, sampled "
           "every step (zero-order hold), in a regular wave."),
    ("code", "wave = waves.regular(0.02, 1.0)\nfor c in (0.0, 1.0, 3.0):\n    ds = simulate(plant,"
             " wave, duration=20.0, dt=0.005, controller=make('passive', damping=c))\n"
             "    last = ds.time > 10\n    print(f'added damping {c:3.1f} N m s/rad: mean PTO "
             "power {1e3 * float(ds.hinge_pto__power[last].mean()):.3f} mW')"),
    ("code", "from mbcontrol.plotting import "
             "time_series\nfig = time_series(ds.sel(time=slice(10, 20)), ['eta', 'hinge', "
             "'hinge_pto__power'])"),
]


CONTROLLERS = [
    ("md", "# Controllers against the bounds: the 10 m sphere in a regular wave\n\n"
           "H 2.5 m, T 9.6664 s (the issue's case). Each controller runs on the nonlinear "
           "process plant in closed loop; its mean power (from the PTO's work) is set beside the "
           "complex-conjugate bound and the constrained (2 MN, 4 m) pseudo-spectral bound."),
    ("code", "import numpy as np\n"
             "import matplotlib.pyplot as plt\nfrom mbcontrol import waves\n"
             "from mbcontrol.plant import build_plant\nfrom mbcontrol.sim import simulate\n"
             "from mbcontrol.analysis import complex_conjugate_bound, pseudo_spectral_bound\n"
             "from mbcontrol.controllers import make\n"
             "from mbcontrol.controllers.passive import optimal_damping\n"
             "from mbcontrol.controllers.reactive import reactive_tuning\n"
             "from mbcontrol.controllers.latching import optimal_latch_time, steady_mean_power\n"
             "from mbcontrol.analysis import pto_metrics\n"
             "plant = build_plant('sphere')\nwave = waves.regular(2.5, 9.6664)\n"
             "F_MAX, Z_MAX = 2e6, 4.0"),
    ("md", "## Bounds\nThe constrained bound lets the force hold the wave's harmonics inside the "
           "hydro data's band: a saturating controller's force is not sinusoidal, and with the "
           "wave frequency alone the 'bound' is 8 % too low."),
    ("code", "cc = complex_conjugate_bound(plant, wave).power\n"
             "ps1 = pseudo_spectral_bound(plant, wave, force_max=F_MAX, stroke_max=Z_MAX).mean_power\n"
             "ps = pseudo_spectral_bound(plant, wave, force_max=F_MAX, stroke_max=Z_MAX, "
             "harmonics=18, oversample=4).mean_power\n"
             "print(f'complex-conjugate {cc/1e3:.0f} kW; constrained: sinusoidal force "
             "{ps1/1e3:.0f} kW, with harmonics {ps/1e3:.0f} kW')"),
    ("md", "## Controllers\nPassive and reactive are tuned by linear theory (unconstrained, so "
           "they show what the limits cost); latching's latch time and damping are searched on the plant "
           "(latch time around the classical (T - T_n) / 2, bracketing its sharp peak); "
           "MPC respects the limits (Kalman filter on the joint encoders, AR forecast)."),
    ("code", "c_opt, _ = optimal_damping(plant, wave)\nc_r, k_r, _ = reactive_tuning(plant, wave)\n"
             "latch, c_l, _ = optimal_latch_time(plant, wave, force_max=np.inf, tune_damping=True)\n"
             "controllers = {\n"
             "    'passive': make('passive', damping=c_opt, force_max=np.inf),\n"
             "    'latching': make('latching', damping=c_l, latch_time=latch,"
             " force_max=np.inf),\n"
             "    'reactive': make('reactive', damping=c_r, stiffness=k_r, force_max=np.inf),\n"
             "    # envelope=False: the limits of the bound it is held against, force and stroke\n"
             "    'MPC 2 MN, 4 m': make('mpc', horizon_s=10.0, dt_s=0.2, force_max=F_MAX, "
             "stroke_max=Z_MAX, wave=wave, forecast='ar',\n"
             "                          envelope=False),\n}\n"
             "power, peaks, runs = {}, {}, {}\n"
             "for name, c in controllers.items():\n"
             "    ds = simulate(plant, wave, duration=150.0, dt=0.01, controller=c)\n"
             "    power[name] = steady_mean_power(ds, 'pto', wave.period, skip_periods=8)  # after the MPC's 5-period warm-up\n"
             "    m = pto_metrics(ds, 'pto', 60.0)\n"
             "    peaks[name] = (m['max_force'], m['max_stroke'])\n    runs[name] = ds\n"
             "    print(f'{name:14s} {power[name]/1e3:7.1f} kW  ({100*power[name]/cc:5.1f} % of CC)  "
             "max |F| {m[\"max_force\"]/1e6:.2f} MN, max |z| {m[\"max_stroke\"]:.2f} m')\n"
             "assert power['reactive'] > power['latching'] > power['passive'] > 0\n"
             "assert abs(power['reactive'] / cc - 1) < 0.02\n"
             "assert 0.97 * ps < power['MPC 2 MN, 4 m'] < 1.002 * ps"),
    ("code", "fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 3.8))\n"
             "names = list(power)\nax.barh(names, [power[n] / 1e3 for n in names], color='C0')\n"
             "ax.axvline(cc / 1e3, color='k', ls='--', label='complex-conjugate bound')\n"
             "ax.axvline(ps / 1e3, color='C3', ls=':', label='bound at 2 MN, 4 m')\n"
             "ax.set_xlabel('mean absorbed power (kW)')\nax.legend(loc='lower right', fontsize=8)\n"
             "for n in ('reactive', 'MPC 2 MN, 4 m'):\n"
             "    d = runs[n].sel(time=slice(120, 150))\n"
             "    bx.plot(d.time, d.pto__force / 1e6, label=f'{n}: force (MN)')\n"
             "bx.axhline(F_MAX / 1e6, color='C3', ls=':')\nbx.axhline(-F_MAX / 1e6, color='C3', ls=':')\n"
             "bx.set_xlabel('time (s)')\nbx.set_ylabel('PTO force, MN')\nbx.legend(fontsize=8)\nfig.tight_layout()\n"
             "# written under out/ (the README's copy, notebooks/figures/, is refreshed from it by hand)\n"
             "from pathlib import Path\nPath('../out/figures').mkdir(parents=True, exist_ok=True)\n"
             "fig.savefig('../out/figures/controllers_sphere.png', dpi=110)"),
]


WORK_PRECISION = [
    ("md", "# Speed against accuracy: RM3 in a JONSWAP sea\n\n"
           "Every integration method over a ladder of steps (or tolerances), and the radiation "
           "model at several fit orders, each measured for error and wall time on this machine. "
           "Error: the largest, over the joint coordinates, of RMS(q − q_ref)/RMS(q_ref) after "
           "the wave ramp, against a converged dopri5 run. Cost: excitation synthesis plus "
           "time-stepping, one core, compilation excluded. The same chart comes from "
           "`mbcontrol bench rm3 --wave jonswap --hs 2.5 --tp 8`."),
    ("code", "import numpy as np\nimport matplotlib.pyplot as plt\nfrom mbcontrol import waves\n"
             "from mbcontrol.studies import workprecision as wp\nfrom mbcontrol.plant import build_plant\n"
             "from mbcontrol.sim import linear_stability_limit\n"
             "sea = waves.irregular(2.5, 8.0, gamma=3.3, seed=1, duration=300)\n"
             "ds = wp.work_precision('rm3', sea, duration=300, methods=('rk3', 'rk4', 'dopri5', "
             "'exp-rk4', 'cvodes'),\n                       rtols=(1e-4, 1e-6), "
             "radiation_tols=(0.2, 0.1, 0.05), repeats=2)\nprint(wp.table(ds))"),
    ("md", "## The chart\nDown and to the left is better. A line stops where its method "
           "becomes unstable; the radiation-order points show the model error a cruder fit "
           "costs, against the time it saves."),
    ("code", "# written under out/ (the README's copy, notebooks/figures/, is refreshed from it by hand)\n"
             "from pathlib import Path\nPath('../out/figures').mkdir(parents=True, exist_ok=True)\n"
             "fig = wp.plot(ds, '../out/figures/work_precision_rm3.png')"),
    ("md", "## The cheapest run within 1 % RMS, and where each method fails\n"
           "The largest stable step comes from the linearised one-step map (its spectral "
           "radius ≤ 1); the scene's fit has 36 radiation states, whose fastest poles limit "
           "the explicit methods but not exp-rk4, which advances the radiation exactly."),
    ("code", "best = wp.cheapest(ds, 0.01, series=['rk3', 'rk4', 'dopri5', 'exp-rk4', 'cvodes'])\n"
             "print(f\"cheapest within 1 %: {best['method']} at dt {best['dt_s']:.3g} s, error "
             "{best['rms_error']:.1e}, {best['rtf']:,.0f}x real time\")\n"
             "plant = build_plant('rm3')\n"
             "limits = {m: linear_stability_limit(plant, m, 4.0) for m in ('rk3', 'rk4', "
             "'dopri5', 'exp-rk4')}\nprint({m: round(v, 3) for m, v in limits.items()})\n"
             "assert best['rms_error'] <= 0.01\nassert limits['exp-rk4'] > 1.5 * limits['rk4']\n"
             "rk4 = ds.where((ds.series == 'rk4') & ds.stable, drop=True)\n"
             "# RK4's error falls ~16x per halving of the step in the asymptotic range\n"
             "ratios = rk4.rms_error.values[:-1] / rk4.rms_error.values[1:]\nprint('rk4 error "
             "ratios per halving:', np.round(ratios, 1))"),
]


IDENTIFICATION = [
    ("md", "# Identification against a real flume experiment\n\n"
           "The seed's section 4 closes its method on tank data: unknown parameters fitted so "
           "that the model reproduces measured responses in regular waves. Here: a box-like "
           "section with rounded bilges spanning a 0.6 m flume (Sundsdal et al. 2025, "
           "`../shared/data/tank`), on a rig that frees two of sway, heave and roll at a time "
           "(series 4: sway+heave, 5: sway+roll, 6: heave+roll), 24 mm waves at up to 14 "
           "frequencies. The model is `models/flume_section.toml`: the rig as a joint tree, 2-D "
           "hydrodynamics from long Capytaine prisms differenced in length, the rig's measured "
           "springs and damping, and viscous damping left for the fit."),
    ("code", "import glob, math, warnings\nimport numpy as np\n"
             "from mbcontrol.studies.identify import fit\n"
             "from mbcontrol.studies.identify import report as rep\n"
             "from mbcontrol.studies.identify.flume import load_runs\n"
             "from mbcontrol.studies.identify.setup import flume_identification, prediction\n"
             "files = sorted(glob.glob('../../shared/data/tank/scenario_c/[456]*.csv.xz'))\n"
             "with warnings.catch_warnings(record=True) as caught:\n"
             "    warnings.simplefilter('always')\n"
             "    runs = load_runs(files, drop_bad=True)\n"
             "print(caught[0].message)\n"
             "print(len(runs), 'usable runs; steady windows from',\n"
             "      min(r.window[1] - r.window[0] for r in runs).__round__(1), 'to',\n"
             "      max(r.window[1] - r.window[0] for r in runs).__round__(1), 's')\n"
             "for r in runs[:3]:\n"
             "    print(r.name, r.group, f'omega {r.omega} rad/s, incident amplitude '\n"
             "          f'{1e3 * r.amplitude:.2f} mm, window {r.window[0]:.1f}-{r.window[1]:.1f} s')"),
    ("md", "## The model as built, against the data\n"
           "Potential flow plus the rig's measured springs and damping, nothing fitted. Errors "
           "are of first-harmonic amplitudes over each run's steady window (after the ramp "
           "has passed the model, before the model's reflection returns from the paddle)."),
    ("code", "problem = flume_identification('flume_section', None, runs=runs)\n"
             "before = rep.amplitude_rows(problem, {})\n"
             "print(rep.error_table(before, 'scene values'))"),
    ("md", "## The seed's method and the gradient method\n"
           "The seed fits with Nelder-Mead on Eq. 67 (peaks and lows, model minus measured, "
           "squared). On series 6 alone both methods minimise that same cost; Gauss-Newton "
           "uses exact sensitivities, integrated with the plant in the compiled code. Series 6 "
           "blocks sway, whose 8 s mode is what needs the default 60 s of settling; its "
           "slowest free mode is roll (1.28 s), so each run starts from rest 30 s before its "
           "window here (the cost at the scene values and at the optimum agrees with 60 s to "
           "4 digits: 2.270 and 0.8940), which halves the cost of the comparison."),
    ("code", "series6 = [r for r in runs if r.group == 'series 6']\n"
             "with warnings.catch_warnings():\n"
             "    warnings.simplefilter('ignore')\n"
             "    seed = flume_identification('flume_section', None, runs=series6, cost='peaks',\n"
             "                                settle=30)\n"
             "    gn6 = fit(seed, 'gauss-newton')\n"
             "    nm6 = fit(seed, 'nelder-mead', max_evaluations=300)\n"
             "for r in (nm6, gn6):\n"
             "    print(f'{r.method:13s} cost {r.cost_initial:.4g} -> {r.cost:.4g} with '\n"
             "          f'{r.simulations} simulations in {r.wall_time_s:.1f} s')\n"
             "print({k: round(v, 3) for k, v in gn6.values.items()})\n"
             "print({k: round(v, 3) for k, v in nm6.values.items()})\n"
             "assert gn6.simulations < nm6.simulations and gn6.cost <= nm6.cost * 1.01"),
    ("md", "## Every run, harmonic cost, with error bars\n"
           "All 31 usable runs, the scene's `[identify]` parameters. Standard errors come from "
           "the Gauss-Newton Hessian at the optimum scaled by the residual variance; the "
           "warning names what one wave height cannot separate."),
    ("code", "with warnings.catch_warnings(record=True) as caught:\n"
             "    warnings.simplefilter('always')\n"
             "    result = fit(problem, 'gauss-newton')\n"
             "for w in caught:\n    print('warning:', w.message)\n"
             "print(rep.parameter_table(problem, result))\n"
             "after = rep.amplitude_rows(problem, result.values)\n"
             "print(rep.error_table(after, 'identified'))\n"
             "errors = {c: e['rms_relative_error'] for c, e in rep.channel_errors(after).items()}\n"
             "assert max(errors.values()) <= 0.10\n"
             "fig = rep.plot_amplitudes({'scene values': before, 'identified': after},\n"
             "                          title='flume section: response amplitude operators')"),
    ("code", "fig = rep.plot_time_series(problem, '5021_2', {'scene values': {}, "
             "'identified': result.values})"),
    ("md", "## Cross-validation by series\nEach series predicted by a fit on the other two."),
    ("code", "for held_out in ('series 4', 'series 5', 'series 6'):\n"
             "    train = [r for r in runs if r.group != held_out]\n"
             "    test = [r for r in runs if r.group == held_out]\n"
             "    with warnings.catch_warnings():\n"
             "        warnings.simplefilter('ignore')\n"
             "        p = flume_identification('flume_section', None, runs=train)\n"
             "        r = fit(p, 'gauss-newton')\n"
             "    e = rep.channel_errors(rep.amplitude_rows(prediction(p, test), r.values))\n"
             "    print(held_out, 'predicted:', {c: f\"{100 * v['rms_relative_error']:.1f} %\"\n"
             "                                   for c, v in e.items()})\n"
             "    assert max(v['rms_relative_error'] for v in e.values()) <= 0.20"),
    ("md", """## What the roll damping means
The scene's identified set (chosen by cross-validation, see the README) fits a linear viscous roll damping B_l and a scale on the roll radiation kernel; a quadratic part B_q, when fitted (`--fit viscous__Roll`), acts like the linear one at one wave height and goes to its bound. Their combination at the resonance, the equivalent linear damping B_eq = B_l + 8/(3 pi) omega phi_a B_q (phi_a the measured roll amplitude there), is what the data determine. As a share of critical damping 2 sqrt(C (I + A)) at the roll resonance (sway clamped, 1.28 s):"""),
    ("code", """from mbcontrol.hydro import read_netcdf
from mbcontrol.scene import load_scene
scene = load_scene('flume_section')
ds = read_netcdf(scene.hydro.file)
roll = dict(radiating_dof='section__Roll', influenced_dof='section__Roll')
I = [b for b in scene.bodies if b.name == 'section'][0].inertia[0][0]
C = float(ds.hydrostatic_stiffness.sel(**roll))
scale = result.values['section__Roll__added_mass_scale']
kernel = result.values.get('section__Roll__radiation_scale', 1.0)
w = 2 * math.pi / 1.28
# the plant's meaning (plant.process.build_process_plant): added_mass_scale scales A(inf) only;
# radiation_scale the kernel: B(w) and A(w) - A(inf) together
A_inf = float(ds.added_mass_inf.sel(**roll))
A = scale * A_inf + kernel * (float(ds.added_mass.sel(**roll).interp(omega=w)) - A_inf)
B_pot = kernel * float(ds.radiation_damping.sel(**roll).interp(omega=w))
peak = max((r for r in after if r['channel'] == 'Roll'), key=lambda r: r['measured'])
names = [p.name for p in problem.fit]
g = np.zeros(len(names))
g[names.index('viscous__Roll_linear')] = 1.0
if 'viscous__Roll' in names:        # a quadratic part, when fitted: its equivalent linear share
    g[names.index('viscous__Roll')] = 8 / (3 * math.pi) * w * peak['measured']
# a parameter at its bound (result.at_bound) has no sigma: it is held there, and the
# interval below is the reduced problem's, conditional on that
sd = np.array([0.0 if n in result.at_bound else result.std[n] for n in names])
cov = result.correlation * np.outer(sd, sd)
B_eq = sum(g[i] * result.values[n] for i, n in enumerate(names))
sigma = math.sqrt(g @ cov @ g)
critical = 2 * math.sqrt(C * (I + A))
print('at a bound:', result.at_bound or 'none')
print(f'roll amplitude at resonance {math.degrees(peak["measured"]):.1f} deg ({peak["run"]})')
print(f'potential-flow damping (radiation scale {kernel:.3f}) {B_pot:.3f} N m s/rad: '
      f'{100 * B_pot / critical:.1f} % of critical')
print(f'viscous, equivalent linear {B_eq:.3f} +- {sigma:.3f} N m s/rad: '
      f'{100 * B_eq / critical:.1f} +- {100 * sigma / critical:.1f} % of critical')
assert sigma < 0.5 * B_eq      # the combination is seen by the data"""),
]


POWER_MATRIX = [
    ("md", "# Power matrix and annual energy at a real site: RM3 at PacWave South\n\n"
           "WEC-Sim's RM3 two-body point absorber under a passive PTO tuned in the frequency "
           "domain, simulated in closed loop on the nonlinear plant over the 32 weighted sea "
           "states of PacWave South (`../shared/data/sites`, from MHKiT's examples), on a local "
           "Dask cluster; then a power matrix over an Hs x Tp grid, and the annual energy at "
           "NOAA buoy 46042 (Monterey Bay) from a year of hourly spectra."),
    ("code", "import math, numpy as np\n"
             "from mbcontrol import waves\nfrom mbcontrol.plant import build_plant\n"
             "from mbcontrol.controllers.passive import optimal_damping\n"
             "from mbcontrol.studies.sweep import grid, read_seas, sweep, power_matrix, occurrence\n"
             "from mbcontrol.waves import HOURS_PER_YEAR\n"
             "from mbcontrol.studies.sweep.plots import plot_sweep\n"
             "seas = read_seas('../../shared/data/sites/pacwave_cluster_32.csv')\n"
             "print(len(seas), 'sea states; weights sum to', round(sum(s.weight for s in seas), 6))"),
    ("md", "## Tune the PTO\nThe damping that maximises mean power in the site's most "
           "energetic sea state (largest weight x energy flux), from the BEM data (linear theory)."),
    ("code", "plant = build_plant('rm3')\n"
             "design = max(seas, key=lambda s: s.weight * waves.site_energy_flux(s))\n"
             "wave = waves.irregular(design.hs, design.tp, duration=1200, band=(0.5, 3.0))\n"
             "damping, power = optimal_damping(plant, wave)\n"
             "print(f'design sea Hs {design.hs:.2f} m, Tp {design.tp:.2f} s: damping {damping:.3g} N s/m, '\n"
             "      f'{power / 1e3:.1f} kW (frequency domain)')"),
    ("md", "## The site, in closed loop, on Dask\nEvery sea state with the tuned damping "
           "and half and twice it (`vary`), 20 minutes each, two local workers. Every case is "
           "checked against physics (`mbcontrol.analysis.validity`): in PacWave's big seas "
           "the float's significant motion relative to the free surface exceeds its 2.5 m "
           "mean draft, where linear hydrodynamics no longer describe it. Those cases are "
           "counted and left out (NaN in `mean_power_W`, their reported values kept in "
           "`mean_power_W__unchecked`): the annual energy below counts them as producing "
           "nothing, a lower bound, and prints the linear figure with them beside it."),
    ("code", "ds, summary = sweep('rm3', seas, controller='passive', vary={'damping': [0.5 * damping, damping, 2 * damping]},\n"
             "                    duration=1200, dt=0.05, workers=2, progress=False)\n"
             "power = ds.mean_power_W.mean('seed')              # NaN where a case failed its checks\n"
             "unchecked = ds.get('mean_power_W__unchecked', ds.mean_power_W).mean('seed')\n"
             "for k, d in enumerate(ds.damping.values):\n"
             "    p = power.isel(damping=k)\n"
             "    valid = np.isfinite(p.values)\n"
             "    aep = float((p.fillna(0.0) * ds.weight).sum()) * HOURS_PER_YEAR / 1e6\n"
             "    linear = float((unchecked.isel(damping=k) * ds.weight).sum()) * HOURS_PER_YEAR / 1e6\n"
             "    print(f'damping {d:.3g} N s/m: {valid.sum()} of {valid.size} seas valid '\n"
             "          f'({100 * float(ds.weight[valid].sum()):.0f} % of the year); annual energy {aep:.0f} MWh '\n"
             "          f'(a lower bound; {linear:.0f} MWh with the failed seas)')\n"
             "print(summary['invalid_cases'], 'of', summary['cases'], 'cases failed their checks, e.g.',\n"
             "      summary['invalid'][0]['reasons'] if summary['invalid'] else '-')\n"
             "assert summary['computed'] == 96 and summary['invalid_cases'] == int((~ds.valid).sum())"),
    ("md", "## Power matrix\nAn Hs x Tp grid with the tuned damping; capture width ratio "
           "against the float's 20 m diameter."),
    ("code", "hs, tp = [1.0, 2.0, 3.0, 4.0, 5.0], [6.0, 8.0, 10.0, 12.0, 14.0, 16.0]\n"
             "pm, pm_summary = sweep('rm3', grid(hs, tp), controller='passive', settings={'damping': damping},\n"
             "                       duration=1200, dt=0.05, workers=2, width=20.0, progress=False)\n"
             "table = power_matrix(pm)\n"
             "print((table / 1e3).round(1).to_pandas() if hasattr(table, 'to_pandas') else table)\n"
             "fig = plot_sweep(pm, pm_summary)"),
    ("md", "## Annual energy at buoy 46042 (Monterey Bay, 1996)\nHm0 and Te of every hour "
           "from the spectral moments, binned into an occurrence table (0.5 m x 1 s); each "
           "occupied bin simulated at its own centre (Tp from Te through the Te/Tp of the "
           "JONSWAP spectrum simulated), so no power is interpolated across bins or clipped to "
           "a matrix's edge; records outside the table are counted."),
    ("code", "f, S, stamps = waves.read_ndbc_spectra('../../shared/data/sites/46042w1996.txt.gz')\n"
             "hm0, te = waves.spectral_hm0_te(f, S)\n"
             "table_occ = waves.occurrence(hm0, te, np.arange(0, 8.5, 0.5), np.arange(3, 21, 1.0))\n"
             "bins = waves.bin_seas(table_occ, gamma=3.3)\n"
             "occ_ds, occ_summary = sweep('rm3', bins, controller='passive', settings={'damping': damping},\n"
             "                            duration=1200, dt=0.05, workers=2, progress=False)\n"
             "aep_46042 = occ_summary['annual_energy_MWh']\n"
             "print(f'{len(stamps)} hours ({table_occ.attrs[\"outside\"]} outside the table), {len(bins)} occupied bins; '\n"
             "      f'median Hm0 {np.median(hm0):.2f} m, Te {np.median(te):.1f} s; annual energy {aep_46042:.0f} MWh '\n"
             "      f'from the valid bins ({100 * occ_summary[\"annual_energy_coverage\"]:.0f} % of the year; '\n"
             "      f'{occ_summary[\"annual_energy_unchecked_MWh\"]:.0f} MWh with the {occ_summary[\"invalid_cases\"]} failed ones)')\n"
             "assert abs(float(table_occ.sum()) - 1) < 0.01 and aep_46042 > 0"),
]


DRIVETRAIN_TOML = '''
[pto.drivetrain]
gear_ratio = 12.0
torque_constant = 670.0
winding_resistance = "20 ohm"
inertia = 2.0
friction = 1.0
'''

ELECTRICAL = [
    ("md", "# Designed for electricity: the 10 m sphere with a drivetrain\n\n"
           "The catalogue sphere with a gear (12), a three-phase machine (670 N m/A) and 20 ohm "
           "windings on its PTO (`[pto.drivetrain]`). The same device is tuned for mechanical "
           "and for electrical power; both designs run on the nonlinear plant, and the figure "
           "shows why they differ: with winding losses the optimal load is no longer the "
           "complex conjugate of the device's impedance."),
    ("code", "import tempfile\nfrom pathlib import Path\nimport numpy as np\n"
             "import matplotlib.pyplot as plt\nfrom mbcontrol import build_plant, waves\n"
             "from mbcontrol.analysis import pto_metrics\nfrom mbcontrol.controllers import make\n"
             "from mbcontrol.controllers.impedance import electrical_optimum, intrinsic_impedance\n"
             "from mbcontrol.controllers.passive import optimal_damping\n"
             "from mbcontrol.controllers.reactive import reactive_tuning\n"
             "from mbcontrol.scene import catalogue_dir\nfrom mbcontrol.sim import simulate\n\n"
             "text = (catalogue_dir() / 'sphere.toml').read_text()\n"
             "text = text.replace('file = \"', f'file = \"{catalogue_dir()}/')\n"
             "text = '\\n'.join(l for l in text.splitlines()\n"
             "                  if not l.startswith(('source =', 'source_bodies')))\n"
             f"text += {DRIVETRAIN_TOML!r}\n"
             "scene = Path(tempfile.mkdtemp()) / 'sphere_drivetrain.toml'\n"
             "scene.write_text(text)\nplant = build_plant(scene)\n"
             "[s for s in plant.outputs if s.startswith('pto__')]"),
    ("md", "## Tuned for mechanical or for electrical power\nIn a regular wave (H 2 m, T 9 s), "
           "without the PTO's limits, so that only the objective differs."),
    ("code", "wave = waves.regular(2.0, 9.0)\ndesigns = {}\n"
             "for objective in ('mechanical', 'electrical'):\n"
             "    c, _ = optimal_damping(plant, wave, objective=objective)\n"
             "    cr, kr, _ = reactive_tuning(plant, wave, objective=objective)\n"
             "    designs[f'passive, {objective}'] = make('passive', damping=c, force_max=np.inf)\n"
             "    designs[f'reactive, {objective}'] = make('reactive', damping=cr, stiffness=kr,\n"
             "                                             force_max=np.inf)\n"
             "rows = {}\nfor name, controller in designs.items():\n"
             "    ds = simulate(plant, wave, duration=300, dt=0.02, controller=controller)\n"
             "    rows[name] = pto_metrics(ds, plant.scene.ptos[0])\n"
             "bound = electrical_optimum(plant, wave)['power_W']\n"
             "print(f'electrical bound {bound / 1e3:.1f} kW')\n"
             "for name, m in rows.items():\n"
             "    print(f\"{name:<24} mechanical {m['mean_power_W'] / 1e3:6.1f} kW, electrical \"\n"
             "          f\"{m['mean_electrical_power_W'] / 1e3:6.1f} kW, winding loss \"\n"
             "          f\"{m['mean_winding_loss_W'] / 1e3:6.1f} kW \"\n"
             "          f\"({100 * m['mean_electrical_power_W'] / bound:.1f} % of the bound)\")\n"
             "for law in ('passive', 'reactive'):\n"
             "    assert (rows[f'{law}, electrical']['mean_electrical_power_W']\n"
             "            > rows[f'{law}, mechanical']['mean_electrical_power_W'])\n"
             "assert max(m['mean_electrical_power_W'] for m in rows.values()) <= bound * 1.001"),
    ("md", "## The optimal load against frequency\nThe mechanical optimum loads the PTO with "
           "conj(Z_i). Away from resonance, where |Z_i| is large, the reactive force that "
           "matching needs would drive a large current through the windings: the electrical "
           "optimum gives up reactance for damping, and delivers a falling share of the "
           "complex-conjugate bound (1 % at 0.3 rad/s, 98 % near the 1.44 rad/s resonance)."),
    ("code", "omega = np.linspace(0.3, 2.0, 60)\nZ, F = intrinsic_impedance(plant, omega)\n"
             "loads, ratio = [], []\nfor w, z, f in zip(omega, Z, F):\n"
             "    opt = electrical_optimum(plant, waves.regular(2.0, 2 * np.pi / w))\n"
             "    loads.append(opt['load_impedance'][0])\n"
             "    ratio.append(opt['power_W'] / (np.abs(f) ** 2 / (8 * z.real)))\n"
             "loads = np.array(loads)\n"
             "fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 3.8))\n"
             "ax.plot(omega, Z.real / 1e3, 'C0--', label='mechanical optimum: damping Re Z_i')\n"
             "ax.plot(omega, loads.real / 1e3, 'C0', label='electrical optimum: damping')\n"
             "ax.plot(omega, -Z.imag / 1e3, 'C1--', label='mechanical optimum: reactance -Im Z_i')\n"
             "ax.plot(omega, loads.imag / 1e3, 'C1', label='electrical optimum: reactance')\n"
             "ax.set_xlabel('wave frequency, rad/s')\n"
             "ax.set_ylabel('optimal PTO impedance, kN s/m')\n"
             "ax.legend(fontsize=8)\nax.grid(alpha=0.3)\nbx.plot(omega, 100 * np.array(ratio))\n"
             "bx.set_xlabel('wave frequency, rad/s')\n"
             "bx.set_ylabel('electrical / complex-conjugate bound, %')\nbx.grid(alpha=0.3)\n"
             "fig.suptitle('sphere, 20 ohm drivetrain: the load that maximises electrical power')\n"
             "fig.tight_layout()"),
]


EXPORT = [
    ("md", "# Controllers out of Python: C and FMI 2.0\n\n"
           "A causal MPC designed for the sphere in a JONSWAP sea, exported as self-contained C "
           "and as an FMI 2.0 co-simulation FMU, with the plant as a second FMU. fmpy (the "
           "Python FMI runner) validates both and closes the loop between them; the result "
           "is compared with the Python controller on the Python plant, and the C step is "
           "timed against the Python step. `mbcontrol export` does the same from the command "
           "line."),
    ("code", "import tempfile\nfrom pathlib import Path\n\nimport matplotlib.pyplot as plt\n"
             "import numpy as np\nfrom fmpy import read_model_description\n"
             "from fmpy.validation import validate_fmu\n\n"
             "from mbcontrol.controllers import make\n"
             "from mbcontrol.studies.design import tune\n"
             "from mbcontrol.export import export_controller\n"
             "from mbcontrol.export.checks import footprint, step_timing\n"
             "from mbcontrol.export.cosim import closed_loop\n"
             "from mbcontrol.export.plant import export_plant\n"
             "from mbcontrol.plant import build_plant\nfrom mbcontrol.scene import load_scene\n"
             "from mbcontrol.sim import simulate\nfrom mbcontrol.waves import irregular\n\n"
             "plant = build_plant(load_scene('sphere'))\n"
             "wave = irregular(2.0, 9.0, seed=3, duration=240.0)\n"
             "parameters, _, _, extra = tune(plant, wave, 'mpc', plant.scene.ptos[0], True, None, [])\n"
             "# the C engine does not hold the linear model's envelope yet: both twins without it\n"
             "mpc = make('mpc', **parameters, **extra, envelope=False)\n"
             "folder = Path(tempfile.mkdtemp(prefix='mbcontrol_export_'))\n"
             "exported = export_controller(mpc, plant, folder)\n"
             "dt = mpc.dt_s / 5\n"
             "plant_fmu = export_plant(plant, wave, folder, dt=dt)\n"
             "for fmu in (exported.fmu, plant_fmu):\n"
             "    md = read_model_description(str(fmu))\n"
             "    print(fmu.name, 'problems:', validate_fmu(str(fmu)) or 'none')\n"
             "    for v in md.modelVariables:\n"
             "        if v.causality in ('input', 'output'):\n"
             "            print(f'   {v.causality:6s} {v.name}')\n"
             "print('C sources:', sorted(p.name for p in exported.c_folder.iterdir()))"),
    ("md", "## The two FMUs in closed loop, in fmpy\n\n"
           "At each communication step the master hands the plant's outputs to the "
           "controller, its force command to the plant, then steps both (the controller "
           "FMU's output feeds through from its inputs). The same loop in Python: "
           "`simulate` with the Python controller."),
    ("code", "run = closed_loop(plant_fmu, exported.fmu, duration=240.0, step=dt)\n"
             "ref = simulate(plant, wave, duration=240.0, dt=dt, controller=mpc, method='rk4')\n"
             "t = run['time'][:-1]\nu_ref = ref['u__pto'].values[:t.size]\n"
             "x_ref = ref['pto__position'].values[:t.size]\n"
             "x_fmu = run['y'][:-1, run['outputs'].index('pto__position')]\n"
             "fig, (ax, bx, cx) = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True)\n"
             "ax.plot(ref['time'], ref['u__pto'] / 1e3, lw=2.5, color='0.75', label='Python')\n"
             "ax.plot(t, run['u'][:, 0] / 1e3, lw=0.9, color='C0', label='FMUs in fmpy')\n"
             "ax.set_ylabel('PTO force, kN')\nax.legend(loc='upper left')\n"
             "bx.plot(ref['time'], ref['pto__position'], lw=2.5, color='0.75', label='Python')\n"
             "bx.plot(t, x_fmu, lw=0.9, color='C1', label='FMUs in fmpy')\n"
             "bx.set_ylabel('heave, m')\nbx.legend(loc='upper left')\n"
             "peak = np.max(np.abs(u_ref))\n"
             "cx.semilogy(t, np.abs(run['u'][:, 0] - u_ref) / peak + 1e-18, lw=0.8, color='C3')\n"
             "cx.set_ylabel('|force difference|\\n/ peak force')\ncx.set_xlabel('time, s')\n"
             "cx.set_ylim(1e-17, 1e-3)\n"
             "cx.axvline(mpc.describe()['warm_up_s'], color='k', ls=':', lw=1)\n"
             "cx.text(mpc.describe()['warm_up_s'], 1e-4, ' MPC takes over', fontsize=9)\n"
             "for a in (ax, bx, cx):\n    a.grid(alpha=0.3)\n"
             "fig.suptitle('sphere, JONSWAP Hs 2 m, Tp 9 s: causal MPC, Python against its FMU')\n"
             "fig.tight_layout()\n"
             "print(f'largest force difference {np.max(np.abs(run[\"u\"][:, 0] - u_ref)) / peak:.2g} "
             "of the peak force; heave {np.max(np.abs(x_fmu - x_ref)) / np.max(np.abs(x_ref)):.2g} of the peak')\n"
             "from mbcontrol.analysis import summary\n"
             "verdict = summary(ref, plant)   # the run's own physics checks\n"
             "print('Python run valid:', verdict['valid'], *verdict['invalid_reasons'])"),
    ("md", "The comparison is of the export, not of the MPC: this causal MPC drives the "
           "sphere past the range where linear hydrodynamics hold (its relative heave beyond "
           "the draft, as the check says), so its power here is not a number to quote; the "
           "C code reproduces it all the same."),
    ("md", "## The step, timed\n\nThe C library steps through this run's measurements "
           "(timed inside C); the Python controller through the same ones."),
    ("code", "timing = step_timing(mpc, exported, ref, plant)\n"
             "for side in ('c', 'python'):\n"
             "    s = timing[side]\n"
             "    print(f\"{side:6s} median {s['median']:8.1f} us  p99 {s['p99']:8.1f} us  \"\n"
             "          f\"max {s['max']:8.1f} us  ({s['steps']} steps)\")\n"
             "print(f\"median speed-up {timing['speed_up_median']:.0f}x; memory:\", footprint(exported))"),
    ("md", "## On a real target\n\n"
           "- **C library** (`c/mbc_controller.h` documents it): `init(&ctx, params)` once "
           "(`NULL`: the designed values), then `step(&ctx, measurements, t, force)` from the "
           "control task at its sample time, with `t` in seconds and increasing; `reset(&ctx)` "
           "restarts it. The context holds all the state (no allocation, no globals), so two "
           "PTOs run two contexts. A static law (passive, reactive) can run at any rate; "
           "latching and declutching want the drive's fastest loop (they switch at the first "
           "sample after a velocity zero crossing); the MPC acts every `dt_s` and holds its "
           "command between (call it every sample or every `dt_s`): put it in a task of "
           "period `dt_s` whose budget covers its 99th percentile, not its median.\n"
           "- **FMU in Simulink** (FMU Import block, co-simulation): inputs are the named "
           "measured signals in SI units, the output the PTO force command; set the block's "
           "sample time to the controller's period (or the loop's); the FMU feeds through, "
           "so no extra delay. OpenModelica and fmpy load it the same way; `sources/` inside "
           "the FMU rebuilds it for another platform."),
]


FARM = [
    ("md", "# Farms: two layouts of four floats, and what each float gains or loses\n\n"
           "`array_grid` lays out n × n of array4's heaving cylinders; its scene parameters "
           "choose the layout (`n`, `spacing`, `stagger`: odd rows shifted along x, and a "
           "Froude `scale`). Here two layouts of four floats at tank scale, 1 m apart: a square "
           "grid and a staggered one. The **q-factor** is the farm's power over that of as "
           "many floats alone (q > 1: the floats' radiated and scattered waves help each "
           "other; q < 1: they shade each other). First from the BEM data in the frequency "
           "domain, then from closed-loop simulations in irregular seas "
           "(`mbcontrol.studies.farm.farm_sweep`, as `mbcontrol sweep --isolated n=1`)."),
    ("code", "import numpy as np\nimport matplotlib.pyplot as plt\n"
             "from mbcontrol import defaults\nfrom mbcontrol.hydro import matrix\nfrom mbcontrol.plant import build_plant\n"
             "from mbcontrol.scene import load_scene\nfrom mbcontrol.studies.farm import farm_sweep\n"
             "from mbcontrol.studies.sweep import grid\n\n"
             "defaults.set('log.quiet', True)   # no BEM progress bars on the page\n"
             "LAYOUTS = {'grid': {'n': 2}, 'staggered': {'n': 2, 'stagger': 0.5}}\n"
             "fig, axes = plt.subplots(1, 2, figsize=(8, 3.6), sharey=True)\n"
             "for ax, (name, params) in zip(axes, LAYOUTS.items()):\n"
             "    scene = load_scene('array_grid', params)\n"
             "    xy = np.array([b.cog[:2] for b in scene.bodies])\n"
             "    ax.scatter(xy[:, 0], xy[:, 1], s=900, c='C0', alpha=0.6)\n"
             "    for b, (x, y) in zip(scene.bodies, xy):\n"
             "        ax.annotate(b.name, (x, y), ha='center', va='center', fontsize=8)\n"
             "    ax.annotate('', xy=(-0.4, 1.05), xytext=(-1.1, 1.05), arrowprops={'arrowstyle': '->'})\n"
             "    ax.text(-1.1, 1.12, 'waves, 0 deg', fontsize=8)\n"
             "    ax.set_title(name)\n    ax.set_xlabel('x (north), m')\n    ax.set_aspect('equal')\n"
             "    ax.set_xlim(-1.3, 1.3)\n    ax.set_ylim(-1.0, 1.4)\n    ax.grid(alpha=0.3)\n"
             "axes[0].set_ylabel('y (east), m')\nfig.tight_layout()"),
    ("md", "## q against frequency, from the BEM data\n\n"
           "In regular waves of frequency ω the floats' motion solves "
           "[−ω²(M + A(ω)) − iω(B(ω) + c) + K] X = F(ω), the coupled matrices of the array's "
           "BEM (no radiation fit, no time stepping), c the scene's PTO damping; each float "
           "absorbs ½ c ω² |X_i|². The same for one float alone (n = 1) gives q."),
    ("code", "def fd_power(params, beta):\n"
             "    scene = load_scene('array_grid', params)\n"
             "    data, dofs = build_plant(scene).hydro.data, [f'{b.name}__Heave' for b in scene.bodies]\n"
             "    w = data['omega'].values\n"
             "    A, B = matrix(data['added_mass'], dofs), matrix(data['radiation_damping'], dofs)\n"
             "    K = matrix(data['hydrostatic_stiffness'], dofs)\n"
             "    F = data['excitation_force'].sel(wave_direction=beta, influenced_dof=dofs).values\n"
             "    M, c, eye = np.diag([b.mass for b in scene.bodies]), scene.ptos[0].damping, np.eye(len(dofs))\n"
             "    P = [np.sum(0.5 * c * wk**2 * np.abs(np.linalg.solve(\n"
             "        -wk**2 * (M + A[k]) - 1j * wk * (B[k] + c * eye) + K, F[k]))**2) for k, wk in enumerate(w)]\n"
             "    return w, np.array(P), len(dofs)\n\n"
             "fig, ax = plt.subplots(figsize=(8, 4))\n"
             "for beta, ls in ((0.0, '-'), (np.pi / 4, '--')):\n"
             "    w, alone, _ = fd_power({'n': 1}, beta)\n"
             "    for name, params in LAYOUTS.items():\n"
             "        w, farm, n = fd_power(params, beta)\n"
             "        keep = w <= 12.0   # the 80 mm mesh is resolved below ~12 rad/s\n"
             "        ax.plot(w[keep], (farm / (n * alone))[keep], ls, label=f'{name}, {np.degrees(beta):.0f} deg')\n"
             "ax.axhline(1.0, color='k', lw=0.8)\nax.set_xlabel('wave frequency, rad/s')\n"
             "ax.set_ylabel('q = farm power / (4 x one float alone)')\n"
             "ax.set_title('four floats 1 m apart, passive PTOs (60 N s/m): interaction factor')\n"
             "ax.grid(alpha=0.3)\nax.legend(ncol=2, fontsize=8)\nfig.tight_layout()"),
    ("md", "## q in irregular seas, closed loop\n\n"
           "Three JONSWAP seas around the floats' resonance (5.7 rad/s, 1.1 s), each farm and "
           "one float alone simulated 60 s with the same seeds; q per sea from the simulated "
           "mean powers. The farm's radiation model is fitted column by column "
           "(`[hydro] radiation_fit = \"columns\"`)."),
    ("code", "seas = grid([0.04], [0.9, 1.1, 1.4])\nrows = {}\n"
             "for name, params in LAYOUTS.items():\n"
             "    ds, summary = farm_sweep('array_grid', seas, scene_params=params, isolated={'n': 1, 'stagger': 0.0},\n"
             "                             duration=60.0, dt=0.02, workers=0, progress=False)\n"
             "    rows[name] = summary\n"
             "print(f\"{'Tp s':>6s}\" + ''.join(f'{n:>22s}' for n in rows))\n"
             "for k, sea in enumerate(seas):\n"
             "    cells = ''.join(f\"{s['seas'][k]['mean_power_W']:10.2f} W  q {s['seas'][k]['q_factor']:5.3f}\" for s in rows.values())\n"
             "    print(f'{sea.tp:6.2f}' + cells)"),
    ("md", "Which layout wins depends on the sea: the frequency-domain curves show the same "
           "floats gaining up to a third in one band and losing half in the next, and the "
           "irregular seas average over those bands. For a site, `mbcontrol sweep MODEL "
           "--scene-param ... --isolated n=1 --seas SITE.csv` gives the farm's power matrix, its "
           "annual energy and the q of each sea and of the year (the README has 25 floats at "
           "PacWave)."),
]


CODESIGN = [
    ("md", "# Co-design for a site: does a causal controller move the optimum?\n\n"
           "WecOptTool's co-design picks a hull and a drivetrain by the non-causal bound: the "
           "most power any force could deliver, knowing the whole wave. A device runs a causal "
           "controller. Here the WaveBot at Froude scale 10 (`models/wavebot.toml` with "
           "`scale = 10`: 17.6 m wide, 880 t, the tutorial drivetrain scaled, 1.5 MN on the "
           "force on the hull) has its keel radius r2 (at constant volume) and its generator "
           "inertia J (both in model-scale units) chosen for PacWave's 32 seas twice: by the "
           "site's annual energy of the absorbed-power bound, and by the annual absorbed energy of a "
           "reactive law designed for each sea, simulated on the nonlinear plant and checked, "
           "with its 95 % interval. The study is one command; it ran for the figures below (a "
           "BEM per hull, cached by content) and its `--json` output is kept beside this "
           "notebook:\n\n"
           "```bash\n"
           "mbcontrol codesign wavebot --scene-param scale=10 --scene-param rated=1500 \\\n"
           "    --vary r2=0.05,0.35,0.87912 --vary J=0,2,6,12,24 --workers 2 \\\n"
           "    --objective annual_energy --controller reactive --against mechanical_bound \\\n"
           "    --seas ../shared/data/sites/pacwave_cluster_32.csv --store out/codesign_site \\\n"
           "    --plot out/codesign_site.png --json > notebooks/data/codesign_wavebot_pacwave.json\n"
           "```"),
    ("code", "import json\nimport numpy as np\n"
             "from mbcontrol.studies.codesign.compare import compare_optima, describe\n"
             "from mbcontrol.studies.codesign.plots import plot_codesign\n"
             "result = json.load(open('data/codesign_wavebot_pacwave.json'))\n"
             "bound = result['against']\nspec = result['provenance']['spec']\n"
             "print(spec['model'], dict(spec['scene_params']), '|', result['objective_name'], "
             "'with', spec['controller'], 'against', bound['objective_name'], '|', "
             "f\"{result['wall_time_s'] + bound['wall_time_s']:.0f} s\")"),
    ("md", "## Both objectives, design by design\n\nThe causal figure carries its 95 % "
           "interval (the phases' scatter and the radiation fit's effect, `sweep`'s budget); "
           "the bound has none: one number per sea, in the sea's expected spectrum. A causal "
           "point is invalid when some seas have no law that keeps the hull force within its "
           "rating (they count as producing nothing; the share of the year covered is shown)."),
    ("code", "print(f\"{'r2':>8s} {'J':>5s} {'reactive, MWh':>17s} {'bound, MWh':>11s} "
             "{'share':>6s}  checks\")\n"
             "for p, q in zip(result['points'], bound['points']):\n"
             "    assert p['params'] == q['params'] and q['valid']\n"
             "    note = 'valid' if p['valid'] else '; '.join(p['reasons'])\n"
             "    print(f\"{p['params']['r2']:8.3f} {p['params']['J']:5.0f} {p['objective']:9.1f} "
             "+- {p['error_95']:4.1f} {q['objective']:11.1f} "
             "{p['objective'] / q['objective']:6.3f}  {note}\")"),
    ("code", "fig = plot_codesign(result, unit='MWh')"),
    ("md", "## The verdict\n\nThe causal optimum against the causal annual energy at the "
           "bound's optimum; where both are valid, the difference's half-width is "
           "sqrt(e1² + e2²), conservative because the designs share seas and phases (their "
           "errors are correlated). The absorbed-power bound does not depend on J (the limit "
           "is on the hull, the drivetrain inside the PTO), so a tie there counts as the same "
           "optimum; where the drivetrain matters is the electrical bound (README), which "
           "peaks at J = 12, where the designed law covers 8 % of the year."),
    ("code", "again = compare_optima(result, bound)\n"
             "assert again['verdict'] == result['comparison']['verdict']\n"
             "print(describe(again, 'MWh'))\n"
             "valid = [p['params'] for p in result['points'] if p['valid']]\n"
             "shares = [s['share'] for s in again['share_of_other'] if s['params'] in valid]\n"
             "print(f'where it is valid, the reactive law absorbs {min(shares):.1%}..{max(shares):.1%} '\n"
             "      'of the bound')"),
]


def build(cells):
    """A notebook of the cells; its first code cell starts with `%matplotlib inline`, so the
    figures show in the notebook and on the documentation site (also where MPLBACKEND=Agg)."""
    nb = nbformat.v4.new_notebook()
    first = next(i for i, (kind, _) in enumerate(cells) if kind == "code")
    cells = [(k, "%matplotlib inline\n" + src if i == first else src)
             for i, (k, src) in enumerate(cells)]
    nb.cells = [nbformat.v4.new_markdown_cell(src) if kind == "md" else
                nbformat.v4.new_code_cell(src) for kind, src in cells]
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}
    return nb


if __name__ == "__main__":
    here = Path(__file__).parent
    nbformat.write(build(TOUR), here / "tour_hinged_barge.ipynb")
    nbformat.write(build(CONTROLLERS), here / "controllers_sphere.ipynb")
    nbformat.write(build(WORK_PRECISION), here / "work_precision_rm3.ipynb")
    nbformat.write(build(IDENTIFICATION), here / "identification_flume.ipynb")
    nbformat.write(build(POWER_MATRIX), here / "power_matrix.ipynb")
    nbformat.write(build(ELECTRICAL), here / "electrical_sphere.ipynb")
    nbformat.write(build(EXPORT), here / "export_fmu.ipynb")
    nbformat.write(build(FARM), here / "farm_layouts.ipynb")
    nbformat.write(build(CODESIGN), here / "codesign.ipynb")
    print("wrote", here / "tour_hinged_barge.ipynb")
