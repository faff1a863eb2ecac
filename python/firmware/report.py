"""The footprint report (humanmpc-gen firmware-report): flash, RAM and instructions per RTI step over
N_h, CPUs and precisions, and the same for the navigation controller's image replaying a recorded
closed loop (optionally linked into the RAM of a smaller part), with the agreement with the host: the
tables of docs/firmware.md."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..bindings import load
from ..codegen.spec import Spec, resolve_spec
from .controller import run_controller_firmware
from .image import (
    build_firmware,
    compare_with_host,
    host_results,
    image_size,
    parse_replay_output,
    print_progress,
    record_replay,
    require_tools,
    run_qemu,
    write_firmware,
)

# -- the footprint report -----------------------------------------------------------------------


@dataclass
class ReportRow:
    n_h: int
    cpu: str
    precision: str
    flash: int
    ram: int
    text: int
    data: int
    bss: int
    solver_bytes: int
    insn_mean: float
    insn_max: int
    qp_iterations_mean: float  # interior-point iterations per step (steps that solved a QP)
    steps: int
    max_u0_diff_to_host: float
    same_decisions_as_host: bool


@dataclass
class ControllerRow:
    """The controller's replay image (<name>_controller_step over a recorded closed loop) on one CPU."""

    n_h: int
    cpu: str
    precision: str
    flash: int          # the replay image: code, constants and the recorded periods
    ram: int            # data + bss: the static controller (with its solver) and the program's inputs
    stack: int          # the stack's high-water mark over the run
    ram_limit: int      # bytes of RAM the image was linked into (0: the board's 4 MiB)
    controller_bytes: int
    insn_mean: float    # instructions per control period (QEMU icount)
    insn_max: int
    periods: int
    max_rel: float      # command and u against the host, relative to the bounds, max over the periods
    median_rel: float
    mismatched_periods: int

    @property
    def ram_total(self) -> int:
        return self.ram + self.stack


def footprint_report(base: Spec, humans: Sequence[int], cpus: Sequence[str], precisions: Sequence[str], *,
                     steps: int, out_dir: Path, seed: int = 0, controller_steps: int = 0,
                     ram_bytes: int | None = None, log: Callable[[str], None] | None = None,
                     controller_rows: list[ControllerRow] | None = None) -> list[ReportRow]:
    """Generate one package per (N_h, precision), build both programs per CPU, run the replay; with
    controller_steps, also the controller's replay of that many periods (linked into ram_bytes of RAM
    when given), its rows appended to controller_rows."""
    from ..codegen.build import build
    from ..codegen.generate import generate

    say = log or print_progress
    quiet: Callable[[str], None] = lambda _msg: None  # noqa: E731
    require_tools()
    rows: list[ReportRow] = []
    for nh in humans:
        replay = None
        for precision in precisions:
            data = base.to_dict()
            data.update(name=f"fw_h{nh}_{precision}", precision=precision)
            data["humans"]["max"] = nh
            spec = resolve_spec(data, "report spec")
            d = generate(spec, out_dir / spec.name, force=True, log=quiet)
            build(d, log=quiet)
            host = load(d)
            if replay is None:  # one replay per N_h, recorded with the first precision's host solver
                replay = record_replay(host, steps=steps, seed=seed)
            fw = write_firmware(d, replay)
            host_steps = host_results(host, replay)
            for cpu in cpus:
                say(f"[humanmpc] N_h={nh} {precision} {cpu}")
                size = image_size(build_firmware(fw, cpu, "footprint"))
                run = parse_replay_output(run_qemu(build_firmware(fw, cpu, "replay"), cpu))
                agree = compare_with_host(run, host_steps)
                ins = run.instructions
                qp_it = [s.qp_iterations for s in run.steps if s.qp_status >= 0]
                rows.append(ReportRow(nh, cpu, precision, size.flash, size.ram, size.text, size.data, size.bss,
                                      run.solver_bytes, float(ins.mean()), int(ins.max()),
                                      float(np.mean(qp_it)) if qp_it else 0.0, len(ins),
                                      agree.max_u0_diff, agree.same_decisions))
                if controller_steps > 0 and controller_rows is not None:
                    say(f"[humanmpc] N_h={nh} {precision} {cpu}: the controller, {controller_steps} periods")
                    crun, cagree, celf, _ = run_controller_firmware(d, cpu, steps=controller_steps, seed=seed,
                                                                    ram_bytes=ram_bytes, log=quiet)
                    csize = image_size(celf)
                    cins = crun.instructions
                    controller_rows.append(ControllerRow(
                        nh, cpu, precision, csize.flash, csize.ram, crun.stack_bytes, ram_bytes or 0,
                        crun.controller_bytes, float(cins.mean()), int(cins.max()), len(cins), cagree.max_rel,
                        cagree.median_rel, len(cagree.mismatched_periods)))
    return rows


def report_markdown(rows: Sequence[ReportRow]) -> str:
    out = ["| N_h | CPU | precision | flash [B] (text + data) | RAM [B] (data + bss) | solver struct [B] | "
           "instructions / RTI step, mean | max | QP iterations / step | steps | same decisions as host | "
           "max abs(u0 diff) to host |",
           "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|"]
    for r in rows:
        out.append(f"| {r.n_h} | {r.cpu} | {r.precision} | {r.flash:,} | {r.ram:,} | {r.solver_bytes:,} | "
                   f"{r.insn_mean:,.0f} | {r.insn_max:,} | {r.qp_iterations_mean:.1f} | {r.steps} | "
                   f"{'yes' if r.same_decisions_as_host else 'no'} | {r.max_u0_diff_to_host:.2g} |")
    return "\n".join(out) + "\n"


def controller_markdown(rows: Sequence[ControllerRow]) -> str:
    out = ["| N_h | CPU | precision | RAM [B] (data + bss + stack) | linked into [B] | flash [B] (image with the "
           "replay) | controller struct [B] | instructions / period, mean | max | periods | against the host: "
           "max / median rel. diff | periods with other decisions |",
           "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|"]
    for r in rows:
        limit = f"{r.ram_limit:,}" if r.ram_limit else "4 MiB"
        out.append(f"| {r.n_h} | {r.cpu} | {r.precision} | {r.ram:,} + {r.stack:,} = {r.ram_total:,} | {limit} | "
                   f"{r.flash:,} | {r.controller_bytes:,} | {r.insn_mean:,.0f} | {r.insn_max:,} | {r.periods} | "
                   f"{r.max_rel:.2g} / {r.median_rel:.2g} | {r.mismatched_periods} |")
    return "\n".join(out) + "\n"
