"""Evaluation: closed-loop episodes of a planner in a scenario, their metrics, figures, the batch evaluation,
the demo and the simulate / evaluate / demo commands.
"""
