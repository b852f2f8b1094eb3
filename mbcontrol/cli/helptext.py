"""The long descriptions of the commands' --help (what a result means, how it is checked)."""

SIMULATE_HELP = """Simulate a model in waves on the nonlinear process plant, open or closed loop.

Every result is checked before it is printed: the PTOs' mean absorbed power against the
complex-conjugate bound of the simulated wave (multiport, straight from the BEM data), the
energy balance (the PTOs cannot absorb more than the waves did work), and the motions
against the validity of linear hydrodynamics (significant heave relative to the free surface
within the body's mean draft; roll and pitch within 30 deg). A result that fails is printed
marked INVALID with its reasons ("valid": false, "invalid_reasons" in --json, at the top
and per PTO) and the command exits with status 3, unless --allow-invalid.
Statistics are over the record after the wave's ramp and the controller's warm-up.
A predictive controller's forecast is causal unless asked (--set forecast=known: the true
future wave, reported as a non-causal upper bound).

--set values are numbers, true/false, none, or words (e.g. --set forecast=ar).
"""

DESIGN_HELP = """Tune a PTO controller for a sea, then check, bound and simulate it.

The controller is tuned by its module's tuner (passive: optimal damping; reactive: complex-
conjugate matching, or the best stable pair in a sea; latching / declutching: hold time by
closed-loop simulation, regular waves only; mpc: its defaults, given the wave), within the
PTO's force and stroke limits unless --unconstrained. It prints the tuned parameters, the
power linear theory predicts, the stability margins of a linear law (gain, phase, distance
of the Nyquist curve from -1, closed-loop poles), the complex-conjugate and force/stroke-
constrained power bounds, and the metrics of a closed-loop simulation on the nonlinear plant
with the share of each bound it reaches. It ends with the `mbcontrol simulate` command line
that re-runs that simulation (the parameters as --set KEY=VALUE).

Safe by default: a reactive law is tuned within the least gain and phase margins of
`mbcontrol defaults` (design.gain_margin_min 2, design.phase_margin_min_deg 30 deg);
--aggressive asks for the unconstrained optimum (e.g. complex-conjugate control, near the
stability edge), flagged when below them. --bode FILE and --nyquist FILE draw the designed
linear law's loop L(s) with its margins marked (python-control's stability_margins).

On a scene with nonlinear hydrostatics and Froude-Krylov forces, a passive or reactive law is
also tuned with the linear model's envelope lifted (the PTO's limits kept) and simulated on
that plant: how far past the linear range it goes and the power it gains or loses against
the design inside the envelope (JSON "envelope_lifted"; null elsewhere).

Example:
  mbcontrol design sphere --controller passive --wave regular --height 2.5 --period 9.6664
"""


BENCH_HELP = """Speed against accuracy for one model in one sea, measured on this machine.

Runs every integration method over a ladder of steps (rk3, rk4, dopri5, exp-rk4: period/4
down to period/256) or tolerances (cvodes, adams: rtol 1e-3..1e-7), and the radiation model
at several fit tolerances (fewer states), and measures for each run:
  error: max over joint coordinates of RMS(q - q_ref)/RMS(q_ref) after the ramp, q_ref a
         converged dopri5 run (its own error is printed);
  cost:  wall time of excitation synthesis + time-stepping (compilation excluded), one core.
Writes work_precision.png, work_precision.csv and work_precision.nc to --out, prints the
table, and names the cheapest setting within 1 % RMS. With --stability, adds each method's
largest stable step (stability.csv).

Example:
  mbcontrol bench sphere --wave jonswap --hs 2.5 --tp 9.67 --duration 300
"""


SWEEP_HELP = """Simulate a model in closed loop over sea states (an Hs x Tp grid or a weighted
list) or measured records, wave seeds and varied settings, and report power, capture width and
annual energy.

Each case is a JONSWAP sea simulated for --duration s with the chosen controller (default:
the scene's PTO law); its metrics are those of `simulate --json` (mean and electrical power,
PAPR, F98, stroke, limit violations). Cases run on a local Dask cluster (--workers N, default
one per core; 0 runs them in this process) or on an existing one (--scheduler ADDRESS).
With --store DIR each finished case is kept in DIR/cases, so an interrupted sweep resumes
where it stopped and a rerun with the same inputs computes nothing; DIR/sweep.nc holds the
labelled result (xarray). --vary NAME=v1,v2 adds a dimension: NAME is a scene parameter,
a plant parameter, a setting of the controller, or `direction` (wave headings in degrees, among
the hydro data's).

Linear theory in milliseconds: --domain frequency computes every sea's mean power under a
linear law (the scene's PTO law, or --controller passive|reactive) and its complex-conjugate
bound straight from the BEM data, nothing simulated (a few hundred seas in tens of ms), with
the time-domain sweep's JSON keys plus "conjugate_bound_W"; --domain both also simulates each
sea and adds "frequency_domain_power_W" and "relative_difference" (time / frequency - 1).

Short-crested seas: a --seas file's columns `direction` (degrees, NED: where the waves travel
to, +x towards +y) and `spread` (degrees, the directional spread sigma, the circular standard
deviation), per sea, or --spread DEG for every sea (it overrides the file's), with the
spreading function --spreading cos2s (default; one s = 2 / sigma^2 - 1) or mitsuyasu (Goda's
s_max (f / fp)^5 below the peak, ^-2.5 above; sigma at the peak). Each component travels in
its own direction, drawn stratified from the spreading function; the hydro data need headings
around the mean (mbcontrol.hydro.headings_for_spread: mean +- 3 sigma on 15 deg steps, or the
whole circle, which then keeps the whole spreading function).

Measured seas: --records DIR runs one case per file of DIR (hidden files left out), each a
measured free-surface elevation record at the scene's origin read as `simulate --wave elevation
--eta FILE` reads it (two columns, time s and elevation m; mbcontrol.waves.from_record). Every
file is checked before any case runs; files that are not usable records are refused together,
each named, and nothing runs. A case runs for --duration s, or by default for its record's own
length (a longer run repeats the record, noted). Its row is labelled by the file name
("record", with "record_sha256" and "duration_s") and carries the record's own Hs (4 std of
its elevation), Tp (the peak of its periodogram), Te and energy flux (its own spectrum), so the
table, JSON and capture widths read as a sea-state sweep's; the figure places each record at
its Hs and Tp. Records carry no occurrence weights: no annual energy is given (the notes say
so). The store keys a case by its file's content (SHA-256): an edited file is run again, a
renamed one is not. With --scheduler the workers read the files: they must see DIR. Not with
--seeds, --amplitudes random, --spread or --isolated (a record is one measured realisation).

A farm: --isolated NAME=VALUE (scene parameters that make one device out of the farm's scene,
e.g. n=1 for array_grid) also runs the lone device over the same cases and reports the q-factor
per sea, q = farm power / (devices x power of one device alone), and the same ratio of the annual
energies (module mbcontrol.studies.farm).

The --json summary is a contract: {"model", "cases", "computed", "reused", "wall_time_s",
"valid_cases", "invalid_cases", "invalid": [{"hs", "tp", "seed", "reasons"}], "failed_cases",
"failed": [{"hs", "tp", "seed", "reasons"}], "notes", "seas": [{"hs", "tp", "weight",
"mean_power_W", "capture_width_m", "energy_flux_W_per_m", "invalid_cases", "failed_cases",
...}], "weighted_mean_power_W", "annual_energy_MWh",
"annual_energy_coverage", "annual_energy_unchecked_MWh", "provenance":
{"model", "version", "scene_sha256", "hydro_sha256", "radiation_sha256", "controller",
"settings", "amplitudes"}, and with --isolated "farm": {"devices", "isolated_devices",
"isolated_scene_params", "q_factor", "annual_energy_isolated_MWh", "q_annual",
"isolated_invalid_cases", "isolated_wall_time_s"} and "q_factor" per sea, and with
--nonlinear invalid per sea "nonlinear_cases" (cases whose linear run left the linear
range and ran on the nonlinear plant) and "linear_mean_power_W" (those linear runs' mean,
INVALID, for comparison; null where none), and with
--design per sea "settings" (the tuned values), "predicted_power_W", "bound_W",
"percent_of_bound", "inside_envelope", "meets_robustness_floors", "fell_back" and
"fallback" (the law that ran), and "fell_back_seas", "fell_back" [{"hs", "tp", "to"}] and
"zero_seas" [{"hs", "tp", "weight", "kind", "why"}] in the summary, and with a PTO
rated_power "rated_power_W" (the weighted figures then cap each sea's power at it), and with
--seeds N >= 2 per sea "valid_seeds", "mean_power_stderr_W" and "mean_power_ci95_W" [lo,
hi] (Student's t over the valid seeds) with "power_std_W", "power_min_W", "power_max_W"
(IEC TS 62600-100 Annex D's per-bin statistics), and for a linear law (the scene's PTO law,
passive, reactive; nothing varied) per sea "spectral_cv" (one record's mean power: its
standard deviation over records / mean, from the frequency-domain solution), "bandwidth_hz"
(B_s of the power density), "effective_samples" (valid seeds / cv^2) and
"spectral_stderr_W" and "expected_power_W" (linear theory's, for a spread sea the
spreading-weighted sum over directions), per sea "direction_deg", "spread_deg" and
"spreading" when given, and for a weighted list "annual_energy_ci95_MWh" [lo, hi] and
"annual_energy_budget": {"components": [{"component" (statistical, model, radiation_fit,
linear_vs_nonlinear, parameters, scene_parameters, resource), "type" (A or B), "over_seas" (quadrature, linear, one term),
"std_MWh" (null when absent), "dof", "source", "absent" (why not, or null),
"share_of_variance"}], "combined_std_MWh", "effective_dof", "coverage_factor", "method"},
and where a PTO converts (a drivetrain, an efficiency below 1)
"annual_electrical_energy_MWh", "annual_electrical_energy_ci95_MWh" and
"annual_electrical_energy_budget" (the same form),
and with --identified per sea "model_std_W" and "parameter_std_W"}
(per sea, means over the valid seeds; lists over the varied values when --vary
is given; weighted figures only for a weighted --seas file; a sea with no valid case counts
as producing nothing there, the share of the year that is valid is annual_energy_coverage,
and annual_energy_unchecked_MWh is the figure the failed cases would have given).

Error bars: --seeds N (N >= 2) gives each sea its standard error and 95 % interval over
records; --amplitudes random makes each record a real sea's (Rayleigh amplitudes: what a
20-minute measured record scatters by; use --duration 1200 as IEC's sea tests do), while the
default deterministic amplitudes estimate the expected power. The annual energy's budget adds,
in quadrature, the statistical part (each sea's standard error over its seeds, or with one
seed of a linear law the spectral estimate), the radiation fit's effect (linear laws), the
model's error and the parameters' covariance of an identification (--identified
summary.json: its values are run, its calibrated error (else its validation error) is the
model error, its covariance goes through linear theory's sensitivities), and the resource's interannual variability when
the --seas file has weights_<year> columns; a part that cannot be evaluated is listed as
absent with the reason.

Every case is checked like `simulate`'s results (power bound of its own wave, energy
balance, linear-hydrodynamics range); a case that fails is counted and listed, never
averaged. A case whose run raises (a divergence, a solver that gave up) is a result too:
counted in failed_cases with its sea, seed and reason, never averaged; the other cases run
and the JSON and store are written. Controllers run causally: an MPC forecasts the excitation from what it measures
(AR) unless --set forecast=known (an oracle: a non-causal upper bound, labelled so in
provenance.settings). A store remembers the inputs it was made from (content hashes of the
scene, hydro data and radiation fit, and the package version) and refuses others.
--set values are numbers, true/false, none or words (--set forecast=ar).

Per-sea design: with --design the controller is tuned for each sea state as `mbcontrol
design` tunes it for one (passive, reactive: linear theory within the PTO's force and stroke
limits and inside the linear model's envelope: each body's predicted significant heave
relative to the surface within 90 % of its mean draft, roll and pitch within 90 % of 30 deg;
latching, declutching: their simulated tuners; mpc: a horizon of one peak period). A sea where
no setting stays inside is flagged (inside_envelope false; the closest setting runs). bound_W
is the most any PTO force could absorb in that sea inside the same envelope (linear theory,
mbcontrol.analysis.envelope), so percent_of_bound says how much a law leaves. --set values
override the tuned ones. A reactive law is tuned within the robustness floors as `design`
tunes it (gain margin 2, phase margin 30 deg at the least: design.gain_margin_min,
design.phase_margin_min_deg); --aggressive tunes the unconstrained optimum, whose laws below
the floors are flagged (meets_robustness_floors). A sea where the tuned law cannot hold the
PTO's limits or the envelope falls back to a detuned or force-saturated damper and says so
(fell_back, fallback per sea; fell_back_seas in the summary); a sea no law serves is kept
with its reason (zero_seas) and counts as zero. Without --design, a damped law named with no settings absorbs
nothing, and says so on stderr.

Examples:
  mbcontrol sweep rm3 --hs 1 2 3 --tp 8 10 12 --duration 300 --store out/rm3 --plot pm.png
  mbcontrol sweep oswec --seas ../shared/data/sites/pacwave_cluster_32.csv --width 18 --json
  mbcontrol sweep rm3 --seas ../shared/data/sites/pacwave_cluster_32.csv --controller reactive \
      --design --json
  mbcontrol sweep sphere --hs 1 2 3 --tp 8 10 --controller passive --set damping=4e5 \
      --seeds 4 --amplitudes random --json
  mbcontrol sweep oswec --seas ../shared/data/sites/pacwave_cluster_32.csv --spread 30 --json
  mbcontrol sweep sphere --records data/probe_records --controller passive --set damping=4e5 \
      --store out/records --json
  mbcontrol sweep array_grid --scene-param n=3 --scene-param scale=25 --isolated n=1 \
      --seas ../shared/data/sites/pacwave_cluster_32.csv --vary direction=0,45
"""
