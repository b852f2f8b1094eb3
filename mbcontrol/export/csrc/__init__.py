"""The hand-written C sources an export copies beside its generated code: the QP solver, the
MPC and switching-law engines, the FMI 2.0 wrappers and the timing harness (package data)."""
