"""Catalogue scenes with a drivetrain added to their first PTO (tests only): written beside a
copy that reads the catalogue's hydro data."""
from pathlib import Path

from mbcontrol.scene import catalogue_dir

DRIVETRAIN = """
[pto.drivetrain]
gear_ratio = {gear}
torque_constant = "{kt}"
winding_resistance = "{resistance}"
inertia = {inertia}
friction = {friction}
phases = 3
"""


def catalogue_copy(folder: Path, model: str, suffix: str, appended: str, *, kernel_judged: bool = False) -> Path:
    """`folder/<model>_<suffix>.toml`: the catalogue scene, its hydro file made absolute,
    with `appended` added to its last table (its only PTO in the scenes used here).
    kernel_judged: its radiation fit judged by the kernel, so it does not depend on the device
    (springs, drivetrains) and variants of one device share one fit."""
    text = (catalogue_dir() / f"{model}.toml").read_text()
    if kernel_judged:
        text = text.replace("[hydro]\n", '[hydro]\nfit_judged_by = "kernel"\n', 1)
    text = text.replace('file = "', f'file = "{catalogue_dir()}/')
    text = "\n".join(line for line in text.splitlines()
                     if not line.startswith(("source =", "source_bodies")))
    path = folder / f"{model}_{suffix}.toml"
    path.write_text(text + appended)
    return path


def with_drivetrain(folder: Path, model: str, *, gear=12.0, kt=6.7, resistance="0.5 ohm",
                    inertia=2.0, friction=1.0) -> Path:
    """`folder/<model>_dt.toml`: the catalogue scene with the drivetrain table appended to its
    only PTO (it must be the file's last table)."""
    return catalogue_copy(folder, model, "dt", DRIVETRAIN.format(
        gear=gear, kt=kt, resistance=resistance, inertia=inertia, friction=friction))
