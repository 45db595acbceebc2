#!/usr/bin/env python3
"""Instruction classes executed in one function, by callgrind count: how much of a SIMD kernel ran at the full
vector width. The figures in src/core/lanes/{polar,lengths}.rs come from it, e.g.

    KDW_SOLVER=lanes python3 tools/instruction_mix.py polar8_avx2_version -- \\
        target/release/examples/step_cost 64 16 20 sway

FUNCTION is the end of the function's demangled name. Prints the executed instructions of that function (not
of its callees), split into 256-bit (ymm), 128-bit packed (xmm), scalar floating point (..ss/..sd) and other,
and the share that reads or writes the stack. Needs valgrind and objdump (Linux, x86-64).

With `--body MIN` before FUNCTION it prints instead the instructions of that function executed at least MIN
times, in address order and without its branches and calls: the body of its hot loop, as `llvm-mca` reads it.
For example, one group of shape matching's sweep (`scene_cost 20 1000x16` runs it 280 000 times):

    python3 tools/instruction_mix.py --body 260000 match_shape8_avx2_version -- \\
        target/release/examples/scene_cost 20 1000x16 lanes > /tmp/body.s
    llvm-mca -mcpu=znver3 -iterations=100 /tmp/body.s
"""

import collections
import os
import re
import subprocess
import sys
import tempfile


def function_range(binary, suffix):
    """Start and end address of the function whose demangled name ends with `suffix`."""
    symbols = subprocess.run(["nm", "-C", "-S", binary], capture_output=True, text=True, check=True).stdout
    for line in symbols.splitlines():
        parts = line.split(None, 3)
        if len(parts) == 4 and parts[3].endswith(suffix):
            start, size = int(parts[0], 16), int(parts[1], 16)
            return start, start + size
    sys.exit(f"no function ending in {suffix!r} in {binary}")


def disassembly(binary, start, end):
    out = subprocess.run(
        ["objdump", "-d", "--no-show-raw-insn", f"--start-address={start:#x}", f"--stop-address={end:#x}", binary],
        capture_output=True, text=True, check=True).stdout
    code = {}
    for line in out.splitlines():
        m = re.match(r"\s*([0-9a-f]+):\s+(.*)", line)
        if m:
            code[int(m.group(1), 16)] = m.group(2)
    return code


def executed(profile, start, end):
    """Instruction address -> executions, from a callgrind profile recorded with --dump-instr=yes."""
    counts = collections.Counter()
    address = 0
    skip_next = False
    for raw in open(profile):
        if raw.startswith("calls="):
            skip_next = True  # the next cost line is the call's inclusive cost
            continue
        fields = raw.split()
        if len(fields) < 3 or not re.match(r"^(0x[0-9a-f]+|[+-]\d+|\*)$", fields[0]):
            continue
        token = fields[0]
        if token.startswith("0x"):
            address = int(token, 16)
        elif token[0] in "+-":
            address += int(token)
        if skip_next:
            skip_next = False
            continue
        if start <= address < end:
            counts[address] += int(fields[2])
    return counts


def print_body(code, counts, least):
    """The instructions run at least `least` times, as assembly for llvm-mca: no branches, calls or padding,
    and objdump's symbol annotations dropped."""
    for address in sorted(code):
        text = code[address]
        mnemonic = text.split()[0] if text else ""
        if counts.get(address, 0) < least or mnemonic.startswith(("j", "call", "nop", "ret")):
            continue
        print(re.sub(r"\s*(<[^>]*>|#.*)$", "", text))


def main():
    args = sys.argv[1:]
    body = None
    if args[:1] == ["--body"] and len(args) > 1:
        body, args = int(args[1]), args[2:]
    if "--" not in args or args.index("--") != 1:
        sys.exit(__doc__)
    suffix, command = args[0], args[2:]
    binary = command[0]
    start, end = function_range(binary, suffix)
    with tempfile.TemporaryDirectory() as tmp:
        profile = os.path.join(tmp, "callgrind.out")
        subprocess.run(["valgrind", "--tool=callgrind", "--dump-instr=yes", f"--callgrind-out-file={profile}"]
                       + command, check=True, capture_output=True)
        counts = executed(profile, start, end)
    code = disassembly(binary, start, end)
    if body is not None:
        print_body(code, counts, body)
        return
    classes = collections.Counter()
    stack = 0
    for address, n in counts.items():
        text = code.get(address, "")
        mnemonic = text.split()[0] if text else ""
        if "ymm" in text:
            kind = "256-bit"
        elif re.match(r"v?\w+(ss|sd)$", mnemonic) and "xmm" in text:
            kind = "scalar floating point"
        elif "xmm" in text:
            kind = "128-bit"
        else:
            kind = "other"
        classes[kind] += n
        stack += n if "(%rsp)" in text else 0
    total = sum(counts.values())
    if total == 0:
        sys.exit(f"{suffix}: not executed")
    print(f"{suffix}: {total} instructions")
    for kind, n in classes.most_common():
        print(f"  {kind:22} {100 * n / total:5.1f} %")
    print(f"  {'stack reads/writes':22} {100 * stack / total:5.1f} %")


if __name__ == "__main__":
    main()
