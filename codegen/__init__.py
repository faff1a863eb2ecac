"""humanmpc.codegen: YAML spec -> CasADi-generated model functions + rendered C solver package."""

__version__ = "0.1.0"
