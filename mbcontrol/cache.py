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


def status(message: str) -> None:
    """One line on stderr for a long job the cache will spare next time (a radiation fit, a
    compilation): what it is doing and how long it usually takes. MBCONTROL_QUIET=1 hides it."""
    import sys
    if not os.environ.get("MBCONTROL_QUIET"):
        print(f"mbcontrol: {message}", file=sys.stderr, flush=True)
