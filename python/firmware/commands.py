"""The `firmware` and `firmware-report` commands of humanmpc-gen."""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict
from pathlib import Path
from typing import Any

from ..codegen.cli import SPEC_HELP, non_negative_int, output_dir, positive_int
from ..codegen.spec import SpecError, load_spec
from ..status import OUTCOME_NAMES, STOP_REASONS
from .controller import DEADLINE_PROBE_MS, ControllerAgreement, ControllerRun, run_controller_firmware
from .image import CPUS, FirmwareError, image_size, load_replay_file, run_firmware
from .report import ControllerRow, controller_markdown, footprint_report, report_markdown


def _cmd_firmware(args: argparse.Namespace) -> int:
    try:
        run, agree, elf = run_firmware(args.dir, args.cpu, load_replay_file(args.replay), steps=args.steps,
                                       seed=args.seed, n_humans=args.humans, cold=args.cold, timeout=args.timeout)
    except FirmwareError as err:
        print(f"humanmpc-gen: {err}", file=sys.stderr)
        return 1
    print(f"# {run.name} ({run.real}) on {args.cpu} under QEMU {CPUS[args.cpu].machine}; "
          f"sizeof({run.name}_solver) = {run.solver_bytes} B")
    print(f"{'t':>4} {'status':>6} {'stop':>16} {'qp_it':>5} {'a':>10} {'omega':>10} {'instructions':>13}")
    for s in run.steps:
        stop = STOP_REASONS.get(s.stop_reason, str(s.stop_reason)) or "-"
        print(f"{s.t:>4} {s.status:>6} {stop:>16} {s.qp_iterations:>5} "
              f"{s.u0[0]:>10.6f} {s.u0[1]:>10.6f} {s.instructions:>13,}")
    ins = run.instructions
    size = image_size(elf)
    print(f"instructions per RTI step (QEMU icount, not cycles): mean {ins.mean():,.0f}, min {ins.min():,}, "
          f"max {ins.max():,}")
    print(f"replay image: flash {size.flash:,} B (text {size.text:,} + data {size.data:,}; includes the replay), "
          f"RAM {size.ram:,} B")
    print(f"against the host library: max |u0 diff| {agree.max_u0_diff:.3g}, max relative cost diff "
          f"{agree.max_cost_rel_diff:.3g}, same status/stop decisions: {agree.same_decisions}"
          + (f" ({agree.first_mismatch})" if agree.first_mismatch else ""))
    if args.controller_steps == 0:
        return 0
    try:
        crun, cagree, celf, _ = run_controller_firmware(args.dir, args.cpu, steps=args.controller_steps,
                                                        seed=args.seed, cold=args.cold, timeout=args.timeout)
    except FirmwareError as err:
        print(f"humanmpc-gen: {err}", file=sys.stderr)
        return 1
    _print_controller(crun, cagree, celf, args.cpu)
    return 0


def _print_controller(run: ControllerRun, agree: ControllerAgreement, elf: Path, cpu: str) -> None:
    print()
    print(f"# the controller of {run.name} ({run.real}) on {cpu}: <name>_controller_step on recorded inputs; "
          f"sizeof({run.name}_controller) = {run.controller_bytes} B")
    print(f"{'period':>6} {'outcome':>12} {'stop':>16} {'people':>12} {'v':>9} {'omega':>9} {'a':>9} "
          f"{'instructions':>13}")
    for s in run.steps:
        stop = (STOP_REASONS.get(s.stop_reason, str(s.stop_reason)) or "-") if s.stop else "-"
        outcome = OUTCOME_NAMES.get(s.outcome, str(s.outcome)) + ("+rec" if s.recovered else "")
        people = ",".join(str(i) for i in s.people_index) or "-"
        print(f"{s.t:>6} {outcome:>12} {stop:>16} {people:>12} {s.command[0]:>9.5f} {s.command[1]:>9.5f} "
              f"{s.u[0]:>9.5f} {s.instructions:>13,}")
    ins = run.instructions
    size = image_size(elf)
    print(f"instructions per controller period (QEMU icount, not cycles): mean {ins.mean():,.0f}, min {ins.min():,}, "
          f"max {ins.max():,}")
    print(f"controller image: flash {size.flash:,} B (text {size.text:,} + data {size.data:,}; includes the replay), "
          f"RAM {size.ram:,} B, stack high-water mark {run.stack_bytes:,} B")
    print(f"clock hook: the controller's own time of the periods / SysTick's: "
          f"{sum(s.time_total_ms for s in run.steps) * 1e6 / max(1, int(ins.sum())):.5f}; a deadline of "
          f"{DEADLINE_PROBE_MS:g} ms stopped the robot with reason "
          f"{STOP_REASONS.get(run.probe_stop_reason, str(run.probe_stop_reason))} after {run.probe_time_ms:.4f} ms")
    print(f"controller against the host library: max |command diff| {agree.max_command_diff:.3g}, max |u diff| "
          f"{agree.max_u_diff:.3g}, max relative to the bounds {agree.max_rel:.3g} (median {agree.median_rel:.3g}), "
          f"periods with other decisions: {agree.outcome_mismatches} of {agree.steps}, other people: "
          f"{agree.people_mismatches}" + (f" ({agree.first_mismatch})" if agree.first_mismatch else ""))


def _cmd_report(args: argparse.Namespace) -> int:
    try:
        humans = [int(h) for h in args.humans.split(",")]
    except ValueError:
        raise SpecError([f"--humans: {args.humans!r} is not a comma-separated list of integers"], "firmware-report") \
            from None
    cpus = [c.strip() for c in args.cpus.split(",")]
    precisions = [p.strip() for p in args.precisions.split(",")]
    bad = [c for c in cpus if c not in CPUS] + [p for p in precisions if p not in ("double", "float")]
    if bad:
        raise SpecError([f"unknown CPU or precision {b!r}: CPUs {', '.join(CPUS)}; precisions double, float"
                         for b in bad], "firmware-report")
    controller_rows: list[ControllerRow] = []
    ram_bytes = args.ram_kib * 1024 if args.ram_kib else None
    try:
        rows = footprint_report(load_spec(args.spec), humans, cpus, precisions, steps=args.steps, out_dir=args.out,
                                seed=args.seed, controller_steps=args.controller_steps, ram_bytes=ram_bytes,
                                controller_rows=controller_rows)
    except FirmwareError as err:
        print(f"humanmpc-gen: {err}", file=sys.stderr)
        return 1
    table = report_markdown(rows)
    if controller_rows:
        table += ("\nThe navigation controller's replay image (<name>_controller_step over a recorded closed "
                  "loop)" + (f", linked into {args.ram_kib} KiB of RAM" if ram_bytes else "") + ":\n\n"
                  + controller_markdown(controller_rows))
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "firmware_report.md").write_text(table)
    (args.out / "firmware_report.json").write_text(json.dumps(
        {"solver": [asdict(r) for r in rows], "controller": [asdict(r) for r in controller_rows]}, indent=2) + "\n")
    print(table, end="")
    print(f"(written to {args.out / 'firmware_report.md'} and .json)")
    return 0


def add_firmware_parser(subparsers: Any) -> None:
    """The `firmware` and `firmware-report` commands of humanmpc-gen."""
    p = subparsers.add_parser(
        "firmware", help="cross-compile a generated solver for a Cortex-M and run a replay under QEMU",
        description="Write DIR/firmware/ (start-up code, linker script, a replay program with recorded inputs "
        "embedded as constants, a footprint program, Makefile), cross-compile it with arm-none-eabi-gcc for "
        "--cpu, run it under qemu-system-arm with semihosting and instruction counting, and compare its results "
        "with the host library on the same inputs. Without --replay the inputs are recorded from a closed loop "
        "of the host solver in a random crowd. Then the same for the navigation controller "
        "(<name>_controller_step): a closed loop of the host controller (a path past a wall of obstacle points, "
        "walking people with tracker ids and covariances) recorded and replayed period by period, with a "
        "clock installed by <name>_controller_set_clock.")
    p.add_argument("dir", type=Path, help="generated solver folder")
    p.add_argument("--cpu", choices=sorted(CPUS), default="cortex-m7",
                   help="cortex-m4 (mps2-an386, single-precision FPU) or cortex-m7 (mps2-an500); default cortex-m7")
    p.add_argument("--replay", type=Path, help="a replay .npz (humanmpc.compare.replay format) instead of a "
                   "recorded loop")
    p.add_argument("--steps", type=positive_int, default=60, help="steps of the recorded loop (default 60)")
    p.add_argument("--seed", type=non_negative_int, default=0, help="seed of the recorded crowd (default 0)")
    p.add_argument("--humans", type=non_negative_int, help="humans in the recorded crowd (default: the solver's N_h)")
    p.add_argument("--cold", action="store_true",
                   help="reset the solver (and the controller) before every step (each step then depends on its own "
                   "inputs only)")
    p.add_argument("--controller-steps", type=non_negative_int, default=140,
                   help="control periods of the recorded controller loop replayed after the solver's (default 140, "
                   "0: none)")
    p.add_argument("--timeout", type=float, default=600.0, help="QEMU time limit in seconds (default 600)")
    p.set_defaults(func=_cmd_firmware)

    p = subparsers.add_parser(
        "firmware-report", help="footprint and instruction counts over N_h, CPUs and precisions",
        description="Generate one solver per N_h and precision (from SPEC or the default spec), cross-compile "
        "the footprint and replay programs for each CPU, run the replays under QEMU and print the table of "
        "flash, RAM and instructions per RTI step (QEMU icount: instructions, not cycles) with the agreement "
        "with the host library; with --controller-steps the same for the navigation controller's replay image, "
        "optionally linked into the RAM of a smaller part (--ram-kib).")
    p.add_argument("spec", nargs="?", help=SPEC_HELP)
    p.add_argument("--humans", default="5,10,30", help="N_h values (default 5,10,30)")
    p.add_argument("--cpus", default="cortex-m4,cortex-m7", help="CPUs (default cortex-m4,cortex-m7)")
    p.add_argument("--precisions", default="double,float", help="precisions (default double,float)")
    p.add_argument("--steps", type=int, default=20, help="replay steps per run (default 20)")
    p.add_argument("--seed", type=non_negative_int, default=0, help="seed of the recorded crowds (default 0)")
    p.add_argument("--controller-steps", type=non_negative_int, default=0,
                   help="also replay a recorded controller closed loop of this many periods per row (its image's RAM "
                   "with the stack, flash, instructions per period, agreement with the host; default 0: none)")
    p.add_argument("--ram-kib", type=non_negative_int, default=0,
                   help="link the controller images into this much RAM (KiB; the stack at its top), e.g. 192 for an "
                   "STM32F405: an image that does not fit fails to link (default 0: the board's 4 MiB)")
    p.add_argument("--out", type=output_dir, default=Path("out/firmware"), help="output folder (default out/firmware)")
    p.set_defaults(func=_cmd_report)
