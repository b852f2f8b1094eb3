"""mbcontrol: control design for multibody marine systems (wave-energy converters first)."""
__version__ = "0.1.0"
