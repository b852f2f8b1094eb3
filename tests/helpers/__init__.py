"""Shared test helpers: reference solutions, small scenes, the README reader. Tests import them as
`tests.helpers.<name>` (the `tests` package is the rootdir's; no test touches sys.path)."""
