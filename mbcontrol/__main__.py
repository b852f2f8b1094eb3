"""`python -m mbcontrol`: the `mbcontrol` command."""
import sys

from .cli import main

sys.exit(main())
