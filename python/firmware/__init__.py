"""The generated solver as firmware: Cortex-M builds run under QEMU, footprint and instruction counts."""
