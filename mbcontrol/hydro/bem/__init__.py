"""BEM with Capytaine, to the body-frame dataset: one run of all bodies (`solve`), a mirror-symmetric
array on its planes (`array_bem`), each body alone (`isolated`), or each among its neighbours
within a radius (`neighbours`). Uses the mesh and data stages."""
