"""Loading scene files: a path or a catalogue name -> a validated Scene."""
from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path

from ..errors import SceneError
from .model import Scene
from .parse import parse_scene

# The catalogue's largest scene is 8 kB; a scene file is a page of text, never megabytes (a
# repeat block makes large devices from a few lines).
MAX_SCENE_BYTES = 1 << 20


def catalogue_dir() -> Path:
    return Path(str(resources.files("mbcontrol.models")))


def list_models() -> list[str]:
    """Names of the scene files shipped in the catalogue (models/*.toml)."""
    return sorted(p.stem for p in catalogue_dir().glob("*.toml"))


def resolve(path_or_name: str | Path) -> Path:
    path = Path(path_or_name)
    if path.suffix == ".toml" or path.exists():
        if not path.exists():
            raise SceneError(f"{path}: no such scene file")
        return path
    candidate = catalogue_dir() / f"{path_or_name}.toml"
    if not candidate.exists():
        raise SceneError(f"{path_or_name}: not a file and not a catalogue model; "
                         f"the catalogue has {', '.join(list_models())}")
    return candidate


def load_scene(path_or_name: str | Path, parameters: dict | None = None) -> Scene:
    """Read and validate a scene file, or a catalogue model by name (see `list_models`).

    parameters: values for the scene's [parameters] table (e.g. {"N": 8} for barge_chain);
    a name the scene does not declare is an error.
    """
    path = resolve(path_or_name)
    try:
        size = path.stat().st_size
        if not path.is_file():
            raise SceneError(f"{path}: not a file; expected a TOML scene file (see models/*.toml)")
        if size > MAX_SCENE_BYTES:
            raise SceneError(f"{path}: {size} bytes; expected a scene file of at most "
                             f"{MAX_SCENE_BYTES} bytes (a [[body]] repeat = \"i = 1..N\" makes "
                             f"many bodies from a few lines)")
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise SceneError(f"{path}: cannot read the scene file: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"{path}: not a text scene file: byte {exc.object[exc.start]:#04x} at "
                         f"offset {exc.start} is not UTF-8; expected a TOML scene "
                         f"(see models/*.toml)") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML: {exc}") from None
    return parse_scene(data, path, parameters)
