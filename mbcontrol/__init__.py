"""mbcontrol: control design for multibody marine systems (wave-energy converters first).

    import mbcontrol as mbc
    r = mbc.simulate("sphere", wave=mbc.regular(height=1.0, period=8.0),
                     controller="passive", settings={"damping": 6e5}, duration=120)
    print(r.valid, r.mean_power_W["pto"])           # True, W
    r.to_xarray().to_netcdf("r.nc")                 # mbc.Result.read("r.nc") reads it back

The public API is `__all__` (what `dir(mbcontrol)` shows), each name loaded on first use so
that ``import mbcontrol`` stays cheap:

- models: `load` (a catalogue name, scene path, Scene or plant -> the ProcessPlant),
  `load_scene` (-> the Scene alone), `list_models`, `build_plant`, `Fidelity`, `Scene`,
  `ProcessPlant`;
- waves: `regular(height, period)`, `jonswap(hs, tp, gamma=3.3)` (600 s repeat period by
  default), `Wave`, and the module `waves` (spectra, sites, records);
- runs: `simulate` (one checked `Result`), its siblings `simulate_batch` (a list of them)
  and `simulate_convolution` (the direct-convolution reference); `Result` (time, named
  states, outputs and inputs, summary, validity, provenance; netCDF and python-control);
- analysis: `linearize` (-> a named control.StateSpace), `frequency_domain_response`,
  `complex_conjugate_bound`, `pto_metrics`;
- controllers and studies: the package `controllers` (the laws, their registry and tuners),
  `design` (tune, bound, simulate and score a law for a sea), `sweep` (power over seas);
- export: `export_controller` (C and FMU), `export_plant` (FMU);
- `defaults` (the registry of default settings) and the errors every stage raises
  (`MbcontrolError`, `InputError`, `SimulationError`).

Everything else lives in documented submodules, one per stage of the flow (imports run one
way, left to right):

    scene -> multibody -> hydro -> plant -> sim -> analysis -> controllers -> studies -> cli
"""
from .lazy import face
from .checkout import install as _from_checkout

_from_checkout()   # a checkout's controllers/ and models/ as mbcontrol.controllers, .models

__version__ = "0.2.0"

# name -> (module of the package, its name there; None: the module itself)
_WHERE = {
    "load": ("api", "load"), "load_scene": ("scene", "load_scene"),
    "list_models": ("scene", "list_models"), "build_plant": ("plant", "build_plant"),
    "Fidelity": ("plant", "Fidelity"), "Scene": ("scene", "Scene"),
    "ProcessPlant": ("plant", "ProcessPlant"),
    "regular": ("waves", "regular"), "jonswap": ("api", "jonswap"), "Wave": ("waves", "Wave"),
    "waves": ("waves", None),
    "simulate": ("api", "simulate"), "simulate_batch": ("api", "simulate_batch"),
    "simulate_convolution": ("api", "simulate_convolution"), "Result": ("analysis", "Result"),
    "linearize": ("analysis", "linearize"),
    "frequency_domain_response": ("analysis", "frequency_domain_response"),
    "complex_conjugate_bound": ("analysis", "complex_conjugate_bound"),
    "pto_metrics": ("analysis", "pto_metrics"),
    "controllers": ("controllers", None), "design": ("studies.design", "design"),
    "sweep": ("studies.sweep", "sweep"),
    "export_controller": ("export", "export_controller"),
    "export_plant": ("export", "export_plant"),
    "defaults": ("defaults", None), "MbcontrolError": ("errors", "MbcontrolError"),
    "InputError": ("errors", "InputError"), "SimulationError": ("errors", "SimulationError"),
}

__all__ = list(_WHERE)

__getattr__, __dir__ = face(__name__, globals(), _WHERE, listed=__all__ + ["__version__"])
