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
