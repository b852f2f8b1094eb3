"""One simulated run as one object: `Result`, what `mbcontrol.simulate` (and its siblings
`simulate_batch`, `simulate_convolution`) return.

A Result holds the run's Dataset as `mbcontrol.sim.simulate` recorded it (every output, the
inputs u, the excitation w, the wave elevation and the states over time; the run record and
provenance in its attrs), the signals' roles (which variables are states, outputs, inputs and
disturbances) and its summary (`analysis.summary`: the metrics per PTO, the physics verdict
of `analysis.validity`, provenance: the `mbcontrol simulate --json` contract).

Files: `to_xarray()` is a Dataset that xarray's own ``to_netcdf`` writes as it is. netCDF
holds no dict, list, bool or None attributes, so those (the run record, the summary, the
verdict) are flattened to JSON strings, and the attribute ``mbc_encoded_attrs`` (JSON) says
which and of what type (`mbcontrol.results.encode`); the summary travels in
attrs["summary"], the roles in attrs["signals"]. `Result.from_xarray` reads such a Dataset
back (as opened by plain ``xarray.open_dataset``, or already decoded), `Result.read` a file.
"""
from __future__ import annotations

import copy
import json
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..results import ENCODED_ATTRS, decode, encode, read_dataset, write_dataset

ROLES = ("states", "outputs", "inputs", "disturbances")


@dataclass(frozen=True, eq=False)
class Result:
    """A simulated run: its record over time, its summary and its verdict.

    dataset: the run as simulated (xarray.Dataset over "time", s; attrs as Python values);
    summary: `mbcontrol.analysis.summary` of it (dict); state_names, output_names,
    input_names (u: the PTO commands, N or N m), disturbance_names (w: the wave excitation):
    the plant's signal names, in its order. Read the numbers through the properties: `time`
    (s), `states`, `outputs`, `inputs`, `disturbances` (arrays, one column per name, SI units
    as `units(name)` says), `valid`, `invalid_reasons`, `mean_power_W` (by PTO name, W),
    `metrics` (every metric per PTO), `provenance`; ``result["pto__power"]`` is one signal.
    """
    dataset: object
    summary: dict
    state_names: tuple
    output_names: tuple
    input_names: tuple
    disturbance_names: tuple

    @classmethod
    def from_run(cls, ds, plant, *, states: bool = True) -> Result:
        """The Result of a Dataset `mbcontrol.sim.simulate` made with `plant` (checked here
        unless its attrs hold a verdict already). states False: the run recorded none (a
        direct-convolution reference)."""
        from .summary import summary
        excitation = plant.disturbances[:len(plant.disturbances) - plant.wave_rows]
        return cls(ds, summary(ds, plant), tuple(plant.states) if states else (),
                   tuple(plant.outputs), tuple(plant.inputs), tuple(excitation))

    # --- the numbers -------------------------------------------------------------------
    @property
    def time(self) -> np.ndarray:
        """Sample times (s), from 0."""
        return self.dataset["time"].values

    @property
    def states(self) -> np.ndarray:
        """States over time, (n_time, len(state_names)), as the plant defines them (SI)."""
        return self.dataset["state"].sel(state_name=list(self.state_names)).values

    @property
    def outputs(self) -> np.ndarray:
        """Outputs over time, (n_time, len(output_names)), SI (see `units`)."""
        return self._columns(self.output_names)

    @property
    def inputs(self) -> np.ndarray:
        """The applied PTO commands u over time, (n_time, len(input_names)), N or N m."""
        return self._columns(self.input_names)

    @property
    def disturbances(self) -> np.ndarray:
        """The wave excitation w over time, (n_time, len(disturbance_names)), N or N m."""
        return self._columns(self.disturbance_names)

    def __getitem__(self, name: str) -> np.ndarray:
        """One recorded signal over time, by name (an output, input, disturbance or "eta")."""
        if name not in self.dataset.data_vars or "time" not in self.dataset[name].dims:
            raise KeyError(f"{name!r}: not a signal of this run; expected one of "
                           f"{', '.join(self.output_names + self.input_names)}, ...")
        return self.dataset[name].values

    def units(self, name: str) -> str:
        """The unit of a recorded signal ("" when it has none)."""
        return str(self.dataset[name].attrs.get("units", ""))

    def _columns(self, names) -> np.ndarray:
        if not names:
            return np.zeros((self.time.size, 0))
        return np.column_stack([self.dataset[name].values for name in names])

    # --- the summary -------------------------------------------------------------------
    @property
    def valid(self) -> bool:
        """True when the run passed every physics check (`mbcontrol.analysis.validity`)."""
        return bool(self.summary["valid"])

    @property
    def invalid_reasons(self) -> list[str]:
        """Why the run failed its checks, each with its remedy (empty when valid)."""
        return list(self.summary["invalid_reasons"])

    @property
    def warnings(self) -> list[str]:
        """What the checks noted without failing the run."""
        return list(self.summary.get("validity_warnings", []))

    @property
    def metrics(self) -> dict:
        """Every metric per PTO name (`mbcontrol.analysis.pto_metrics`, over the statistics
        window `summary["window_start_s"]`..`["window_end_s"]`): power (W), force (N), ..."""
        return copy.deepcopy(self.summary["ptos"])

    @property
    def mean_power_W(self) -> dict[str, float]:
        """Mean absorbed power per PTO name (W, positive absorbed), over the statistics window."""
        return {name: m["mean_power_W"] for name, m in self.summary["ptos"].items()}

    @property
    def provenance(self) -> dict:
        """What made the run: model, scene/hydro/radiation hashes, method, step (s), wave,
        controller, parameters (SI, by name), package versions."""
        from ..results import record
        attrs = self.dataset.attrs
        keys = ("model", "scene_sha256", "hydro_sha256", "radiation_sha256", "method", "dt_s",
                "duration_s", "hydro_source", "conventions")
        out = {k: attrs[k] for k in keys if k in attrs}
        for key in ("wave", "controller", "parameters", "versions"):
            out[key] = copy.deepcopy(record(attrs, key))
        return out

    def __repr__(self) -> str:
        power = ", ".join(f"{k}: {v:.4g} W" for k, v in self.mean_power_W.items())
        return (f"Result({self.summary.get('model')!r}, {self.time[-1]:g} s, "
                f"{'valid' if self.valid else 'INVALID'}, mean power {{{power}}})")

    # --- conversions -------------------------------------------------------------------
    def to_xarray(self):
        """The run as a Dataset ``to_netcdf`` writes as it is: attributes netCDF cannot hold
        flattened to JSON strings (module docstring), the summary in attrs["summary"], the
        signals' roles in attrs["signals"]. `Result.from_xarray` reads it back."""
        return encode(self._recorded())

    def _recorded(self):
        ds = self.dataset.copy()
        ds.attrs["summary"] = copy.deepcopy(self.summary)
        ds.attrs["signals"] = {role: list(getattr(self, f"{role[:-1]}_names"))
                               for role in ROLES}
        return ds

    @classmethod
    def from_xarray(cls, ds) -> Result:
        """The Result a `to_xarray()` Dataset holds, encoded (as plain xarray opens its file)
        or decoded."""
        if ENCODED_ATTRS in ds.attrs:
            ds = decode(ds)
        attrs = dict(ds.attrs)
        for key in ("summary", "signals"):
            if isinstance(attrs.get(key), str):
                attrs[key] = json.loads(attrs[key])
        if "summary" not in attrs or "signals" not in attrs:
            raise InputError("Result.from_xarray: expected a Dataset made by Result.to_xarray "
                             "(attrs 'summary' and 'signals'); a bare simulate Dataset needs "
                             "its plant: Result.from_run(ds, plant)")
        summary, signals = attrs.pop("summary"), attrs.pop("signals")
        ds = ds.copy()
        ds.attrs = attrs
        return cls(ds, summary, *(tuple(signals[role]) for role in ROLES))

    def to_netcdf(self, path, **options):
        """Write the run to netCDF at `path`, atomically (`mbcontrol.results.write_dataset`:
        options precision, every, compress); `Result.read(path)` reads it back."""
        return write_dataset(self._recorded(), path, **options)

    @classmethod
    def read(cls, path) -> Result:
        """The Result a file holds (written by `to_netcdf`, or `to_xarray().to_netcdf`)."""
        return cls.from_xarray(read_dataset(path))

    def to_timeresponse(self):
        """The run as python-control's ``TimeResponseData``: time (s); outputs, states and
        inputs with their names; the inputs are u then w, as `mbcontrol.linearize` orders a
        plant's inputs, so the record can be replayed through the linearised plant
        (``control.forced_response(sys, res.time, res.inputs, X0)``)."""
        import control
        return control.TimeResponseData(
            self.time, self.outputs.T, states=self.states.T,
            inputs=np.hstack([self.inputs, self.disturbances]).T,
            output_labels=list(self.output_names), state_labels=list(self.state_names),
            input_labels=list(self.input_names + self.disturbance_names),
            sysname=str(self.summary.get("model", "")), title=repr(self), plot_inputs=False)
