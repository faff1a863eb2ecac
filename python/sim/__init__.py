"""The simulated world: static obstacles, the crowd models, the humans' predictions, the robot, the scenarios.

Imports the solver face at most; knows nothing of planners or evaluation.
"""
