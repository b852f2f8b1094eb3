"""SI units of a plant's named signals, and the signals of a PTO's drivetrain."""
from __future__ import annotations


_BODY_UNITS = {"Surge": ("m", "N"), "Sway": ("m", "N"), "Heave": ("m", "N"),
               "Roll": ("rad", "N m"), "Pitch": ("rad", "N m"), "Yaw": ("rad", "N m")}
_ENERGY_UNITS = {"radiated_power": "W", "excitation_power": "W", "energy": "J",
                 "mooring_power": "W"}


DRIVETRAIN_SIGNALS = {"current": "A", "voltage": "V", "winding_loss": "W", "friction_loss": "W",
                      "electrical_power": "W", "mechanical_power": "W",
                      "hull_force": "force"}   # N or N m, as the PTO's force


def drivetrain_signals(d, x, v, force, acceleration) -> list:
    """A drivetrain's signals (DRIVETRAIN_SIGNALS, in order) from the PTO position x and
    velocity v, the machine's force (the PTO force) and the PTO acceleration a: current
    F / (gear kt'), voltage R I + kt' gear v (a current-controlled drive; the inductive
    L dI/dt, whose mean power is zero, is left out), winding loss R I^2, friction loss
    gear^2 b v^2, electrical power delivered -F v - R I^2, and the mechanical power the joint
    puts in, -(F - gear^2 (J a + b v + K x)) v = electrical + losses + d/dt(gear^2 (J v^2 +
    K x^2) / 2) (the shaft spring's part has mean zero over a periodic motion), and the force
    on the hull F - gear^2 (J a + b v + K x) (what force_max_on = "hull" limits)."""
    current = force / d.force_per_current
    winding = d.winding_resistance * current ** 2
    friction = d.gear_ratio ** 2 * d.friction * v * v
    shaft = d.gear_ratio ** 2 * (d.inertia * acceleration + d.friction * v + d.stiffness * x)
    return [current, d.winding_resistance * current + d.kt * d.gear_ratio * v, winding,
            friction, -force * v - winding, -(force - shaft) * v, force - shaft]


def _coordinate_unit(plant, name: str) -> str:
    """rad for rotations, m for translations, from the joint that owns the coordinate."""
    for joint in plant.scene.joints:
        if name == joint.name:
            if joint.type == "free":
                return _BODY_UNITS[joint.dofs[0]][0]
            return "rad" if joint.type == "revolute" else "m"
        if name.startswith(joint.name + "__"):
            return _BODY_UNITS[name.split("__")[-1]][0]
    return ""


def signal_unit(plant, signal: str) -> str:
    """SI unit of a plant's named state, input, disturbance or output."""
    if signal in _ENERGY_UNITS:
        return _ENERGY_UNITS[signal]
    if signal.startswith("radiation_") or signal.startswith("w__field_"):
        return "internal"
    if signal.endswith("__field_range"):
        return "1"
    if signal.startswith("w__moordyn_"):
        return "N"                      # a force on a Coupled point, n-frame
    if signal.startswith("w__"):
        return _BODY_UNITS[signal.split("__")[-1]][1]
    base = signal[3:] if signal.startswith("u__") else signal
    for pto in plant.scene.ptos:
        if base == pto.name or base.startswith(pto.name + "__"):
            coord = "m" if pto.between_points else _coordinate_unit(plant, pto.joint)
            force = "N m" if coord == "rad" else "N"
            kind = "force" if base == pto.name else base.split("__")[-1]
            return {"position": coord, "velocity": f"{coord}/s", "power": "W",
                    **DRIVETRAIN_SIGNALS, "force": force, "hull_force": force}[kind]
    if signal.endswith("__tension"):
        return "N"
    if signal.endswith(("__span", "__height")):
        return "m"
    if signal.endswith("__vel"):
        return f"{_coordinate_unit(plant, signal[:-5])}/s"
    if "__" in signal and signal.split("__")[-1] in _BODY_UNITS and \
            signal.split("__")[0] in plant.topology.bodies:
        return _BODY_UNITS[signal.split("__")[-1]][0]
    return _coordinate_unit(plant, signal)
