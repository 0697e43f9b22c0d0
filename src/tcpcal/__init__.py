"""tcpcal: TCP and TOOL-frame calibration solvers (unit-agnostic, numpy/scipy only)."""
