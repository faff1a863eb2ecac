"""Package data of humanmpc.codegen: the hand-written C runtime copied into every generated solver (read
with importlib.resources by humanmpc.codegen.resources; no Python code here)."""
