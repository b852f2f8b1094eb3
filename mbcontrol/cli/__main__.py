"""python -m mbcontrol.cli"""
import sys

from . import main

sys.exit(main())
