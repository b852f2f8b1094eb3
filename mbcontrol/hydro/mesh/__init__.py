"""The bodies' wetted surfaces, the first stage of the hydrodynamics: primitive and revolution
geometry and mesh files to Capytaine meshes and lids (`geometry`, `revolution`), fixed obstacles on
the sea bed (`obstacles`), hydrostatics of primitives at large angles (`large_angle`), and the
nonlinear hydrostatic and Froude-Krylov pressure over a body's instantaneous wetted surface:
any closed surface as panels (`panels`), bodies of revolution in closed form (`axisymmetric`)."""
