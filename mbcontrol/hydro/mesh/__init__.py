"""The bodies' wetted surfaces, the first stage of the hydrodynamics: primitive and revolution
geometry and mesh files to Capytaine meshes and lids (`geometry`, `revolution`), fixed obstacles on
the sea bed (`obstacles`), and hydrostatics of a mesh at large angles (`large_angle`)."""
