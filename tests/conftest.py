"""Test-suite set-up: the shared helpers beside this file (sphere_reference.py) import by name
from any test folder (tests run with --import-mode=importlib, which adds no folder to sys.path)."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
