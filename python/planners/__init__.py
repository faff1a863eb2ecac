"""Planners for the simulated world: the interface (observation in, command out), the DWB baseline, the
global path on the static map, the generated MPC solver as a planner, which solver it loads (the tools' cache of
generated solvers, a user's folder used as it is), and the registry of planners by name.
"""
