"""What a sweep runs: sea states (a grid or a weighted list from a CSV), wave seeds, and named
quantities varied over values (plant parameters, controller settings, scene parameters),
crossed into cases. Each case has a key (a hash of everything that decides its result), so a
store on disk knows which cases it already holds.
"""
from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import asdict, dataclass, field

from ... import defaults

from ...errors import InputError
from ...waves import SeaState


WAVE_DIRECTION = "direction"    # --vary direction=0,45: NED headings in degrees, of the hydro data


@dataclass(frozen=True)
class Case:
    """One closed-loop simulation of a sweep: its sea, seed, the values of the varied
    quantities (name -> value) and what is fixed; `index` places it in the result grid."""
    model: str
    sea: SeaState
    seed: int
    varied: tuple                       # ((name, value), ...) in the sweep's order
    index: tuple                        # (sea index, seed index, value index per varied name)
    params: tuple = ()                  # fixed plant parameter overrides ((name, value), ...)
    scene_params: tuple = ()            # fixed scene parameters
    controller: str | None = None
    settings: tuple = ()                # fixed controller settings
    duration: float = 600.0             # s; build_cases fills these from the "sweep.*" defaults
    dt: float = 0.05
    method: str = "rk4"
    roles: dict = field(default_factory=dict, compare=False)   # varied name -> its kind
    inputs: tuple = ()                  # content hashes of what made the plant ((name, sha), ...)
    design: bool = False                # tune the controller for the case's sea (--design)
    robust: bool = False                # ... within the robustness floors (--robust)
    amplitudes: str = "deterministic"   # or "random": Rayleigh amplitudes (waves.irregular)
    nonlinear: str = "scene"            # "always", "invalid": the nonlinear plant (run_case)
    record: str = ""                    # a measured record's path (--records; not in the key)
    record_sha256: str = ""             # ... and the hash of its bytes (in the key)

    @property
    def key(self) -> str:
        """A hash of everything that decides the result (not of where it sits in the grid):
        the case's settings and the content of its inputs (scene, hydro data, radiation fit,
        package version; `mbcontrol.plant.provenance`), so an edited scene never reuses a
        stored result."""
        record = {k: v for k, v in asdict(self).items() if k not in ("index", "roles",
                                                                       "record")}
        if not record["record_sha256"]:    # a sea state's case keeps the key it had before
            record.pop("record_sha256")
        for flag in ("design", "robust"):  # the keys of stores made before they existed
            if not record[flag]:
                record.pop(flag)
        if record["amplitudes"] == "deterministic":
            record.pop("amplitudes")
        if record["nonlinear"] == "scene":
            record.pop("nonlinear")
        sea = record["sea"]             # a long-crested sea keeps the key it had before
        for name in ("direction", "spread"):
            if sea[name] != sea[name]:   # NaN: not given
                sea.pop(name)
        if "spread" not in sea or sea["spread"] == 0:
            sea.pop("spreading")
        text = json.dumps(record, sort_keys=True, default=float)
        return hashlib.sha256(text.encode()).hexdigest()[:20]

    def resolved(self) -> tuple[dict, dict, dict]:
        """(plant params, scene params, controller settings) with the varied values in."""
        params, scene, settings = dict(self.params), dict(self.scene_params), dict(self.settings)
        for name, value in self.varied:
            if self.roles[name] != "wave":
                {"param": params, "scene": scene, "setting": settings}[self.roles[name]][name] = value
        return params, scene, settings

    @property
    def direction_deg(self) -> float | None:
        """The wave direction varied for this case (degrees, NED heading), or None."""
        return next((v for n, v in self.varied if self.roles.get(n) == "wave"), None)


def build_cases(model: str, seas, *, seeds: int = 1, vary: dict | None = None, roles=None,
                params=None, scene_params=None, controller=None, settings=None,
                duration: float | None = None, dt: float | None = None,
                method: str | None = None, inputs: dict | None = None,
                design: bool = False, robust: bool = False,
                amplitudes: str = "deterministic", nonlinear: str = "scene") -> list[Case]:
    """Every sea x seed x combination of the varied values. roles: varied name -> "param",
    "scene" or "setting" (see `roles_for`); inputs: the plant's provenance (content hashes),
    part of every case's key. duration, dt and method left out: the "sweep.*" defaults.
    design: each case's controller is tuned for its sea (studies.design.sea); robust:
    within the robustness floors; amplitudes: the seas' ("deterministic" or "random",
    waves.irregular); nonlinear: "scene", "invalid" or "always" (`case_run.run_case`)."""
    duration = defaults.resolve("sweep.duration", duration)
    dt, method = defaults.resolve("sweep.dt", dt), defaults.resolve("sweep.method", method)
    vary = dict(vary or {})
    names = list(vary)
    cases = []
    for (i, sea), seed, combo in itertools.product(
            enumerate(seas), range(seeds),
            itertools.product(*[list(enumerate(vary[n])) for n in names])):
        cases.append(Case(model, sea, seed, tuple((n, float(v)) for n, (_, v) in zip(names, combo)),
                          (i, seed) + tuple(k for k, _ in combo),
                          tuple(sorted((params or {}).items())),
                          tuple(sorted((scene_params or {}).items())), controller,
                          tuple(sorted((settings or {}).items())), float(duration), float(dt),
                          method, dict(roles or {}), tuple(sorted((inputs or {}).items())),
                          bool(design), bool(robust), amplitudes, nonlinear))
    return cases


def roles_for(names, scene, plant_parameters, controller_class=None) -> dict:
    """Which kind each varied name is: a scene [parameters] name ("scene"), a plant parameter
    ("param") or a setting of the controller ("setting"); ValueError naming the choices."""
    import inspect
    settings = set(inspect.signature(controller_class).parameters) if controller_class else set()
    roles = {}
    for name in names:
        kinds = [k for k, pool in (("scene", set(scene.parameters)),
                                   ("param", set(plant_parameters)), ("setting", settings))
                 if name in pool]
        if not kinds and name == WAVE_DIRECTION:
            kinds = ["wave"]
        if not kinds:
            raise InputError(f"--vary {name}: not a scene parameter ({', '.join(scene.parameters) or 'none'}), "
                             f"plant parameter or controller setting of {scene.name}, nor `direction` "
                             "(wave headings, degrees)")
        if len(kinds) > 1:
            raise InputError(f"--vary {name}: ambiguous, it is a {' and a '.join(kinds)}")
        roles[name] = kinds[0]
    return roles
