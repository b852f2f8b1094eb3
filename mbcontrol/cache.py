"""Where BEM results, radiation fits and compiled code are cached: $MBCONTROL_CACHE, else
~/.cache/mbcontrol. Generated C and compiled libraries go here and nowhere else."""
from __future__ import annotations

import os
from pathlib import Path


def cache_dir() -> Path:
    """The cache folder (created if missing)."""
    path = Path(os.environ.get("MBCONTROL_CACHE", Path.home() / ".cache" / "mbcontrol"))
    path.mkdir(parents=True, exist_ok=True)
    return path
