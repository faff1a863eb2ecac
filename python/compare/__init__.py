"""Speed and optimality against other solvers: the RTI bench in random crowds, replays, the peers (Ipopt in C,
acados in its own venv), RCSO and the comparison report.
"""
