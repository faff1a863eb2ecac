"""Package data of humanmpc.codegen: the Jinja2 templates of the generated solver package (read with
importlib.resources by humanmpc.codegen.resources; no code here)."""
