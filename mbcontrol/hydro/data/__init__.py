"""The body-frame hydro dataset (xarray) every source produces: its units and matrix layout
(`dataset`), the maps from BEM frames (z up) to body frames at each CoG, NED (`frames`, ERRATA
G10-G13), and NetCDF files written atomically (`netcdf`). Uses the mesh stage only."""
