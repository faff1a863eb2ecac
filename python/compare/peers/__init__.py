"""The other solvers of the comparison, one module each: Ipopt (a C program against Debian's Ipopt) and
acados (driven in its own Python 3.12 venv by acados_peer.py, which imports nothing of humanmpc).
"""
