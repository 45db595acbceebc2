#!/usr/bin/env python3
"""Floating-point operations executed per dynamic joint per substep, in lane operations (a 256-bit `vmulps`
counts 8, a `vmulpd` 4, a scalar `mulss` 1), by kind and precision: the check on the operation counts of
`SUBSTEP_WORK` in `benches/support/perf_report.rs` (its divisions and square roots, and its totals of adds,
subtracts, multiplies, divisions and square roots), which are minimums and so must not exceed what runs. Runs
`scene_cost` under callgrind for FRAMES frames and for none (the setup alone) and takes the difference.

    python3 tools/arithmetic_ops.py target/release/examples/scene_cost 20 1000x16

Lanes the kernel pads (a group's spare lanes) count too; what the counting rule leaves out (comparisons,
selects, conversions, signs and absolute values) is not counted here either. Needs valgrind and objdump (Linux,
x86-64).
"""

import collections
import os
import re
import subprocess
import sys
import tempfile

OPERATION = re.compile(r"v?(add|sub|mul|div|sqrt)(ps|pd|ss|sd)$")


def lanes(mnemonic, operands):
    """Lane operations of one execution of an arithmetic instruction."""
    suffix = mnemonic[-2:]
    if suffix in ("ss", "sd"):
        return 1
    bits = 512 if "zmm" in operands else 256 if "ymm" in operands else 128
    return bits // (32 if suffix == "ps" else 64)


def arithmetic(binary):
    """Address -> (kind, lanes) of every add, subtract, multiply, division and square root in the binary."""
    found = {}
    listing = subprocess.run(["objdump", "-d", "--no-show-raw-insn", binary], capture_output=True, text=True,
                             check=True).stdout
    for line in listing.splitlines():
        m = re.match(r"\s*([0-9a-f]+):\s+(\S+)\s*(.*)", line)
        if m and OPERATION.match(m.group(2)):
            op = OPERATION.match(m.group(2))
            kind = f"{op.group(1)} {'f32' if op.group(2) in ('ps', 'ss') else 'f64'}"
            found[int(m.group(1), 16)] = (kind, lanes(m.group(2), m.group(3)))
    return found


def executed(binary, args):
    """Address -> executions, from callgrind with per-instruction counts (positions: instr line)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "callgrind.out")
        subprocess.run(["valgrind", "--tool=callgrind", "--dump-instr=yes", f"--callgrind-out-file={out}", binary,
                        *args], capture_output=True, check=True)
        counts = collections.Counter()
        address = 0
        for line in open(out):
            parts = line.split()
            if len(parts) < 3 or not parts[2].isdigit():
                continue
            token = parts[0]
            if token.startswith("0x"):
                address = int(token, 16)
            elif token.startswith(("+", "-")):
                address += int(token)
            elif token != "*":
                continue
            counts[address] += int(parts[2])
        return counts


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    binary, frames, scene = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    joints, chains = {"1000x16": (16, 1000), "100x16": (16, 100)}[scene]
    found = arithmetic(binary)
    run, setup = executed(binary, [str(frames), scene]), executed(binary, ["0", scene])
    totals = collections.Counter()
    for address, (kind, width) in found.items():
        totals[kind] += (run[address] - setup[address]) * width
    # scene_cost runs 4 substeps per 60 Hz frame at the default settings.
    joint_substeps = frames * 4 * chains * (joints - 1)
    for kind in sorted(totals):
        print(f"{kind}: {totals[kind] / joint_substeps:.2f} lane operations per joint per substep")
    for precision in ("f32", "f64"):
        total = sum(n for kind, n in totals.items() if kind.endswith(precision))
        print(f"all {precision}: {total / joint_substeps:.2f} lane operations per joint per substep")


if __name__ == "__main__":
    main()
