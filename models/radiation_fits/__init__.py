"""Radiation fits shipped with the catalogue (data only: radiation_*.npz, keyed as the cache is;
see mbcontrol.hydro.fit.store and models/generate_hydro.py --ship-fits)."""
