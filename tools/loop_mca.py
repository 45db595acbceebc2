#!/usr/bin/env python3
"""Static throughput and latency of one loop of a compiled function, by llvm-mca.

  tools/loop_mca.py BINARY SYMBOL                 lists the function's loops (backward jumps) and their sizes
  tools/loop_mca.py BINARY SYMBOL START END [CPU] runs llvm-mca on the instructions from START to END (hex
                                                   addresses from the list; jumps dropped), for CPU (znver3)

SYMBOL is a substring of the mangled name (e.g. sweep8_avx2_version). Prints llvm-mca's summary for 50
iterations (the loop's resource bound: "Block RThroughput") and for 1 (the cycles of one iteration alone, its
dependency chain), e.g. for stop 44's figures on the shape-matching sweep:
  tools/loop_mca.py target/release/examples/scene_cost sweep8_avx2_version   (then the loop of ~820 instructions)
"""
import re
import subprocess
import sys
import tempfile


def instructions(binary, symbol):
    names = subprocess.run(["nm", binary], capture_output=True, text=True, check=True).stdout.split("\n")
    matches = [line.split()[-1] for line in names if symbol in line]
    if len(matches) != 1:
        sys.exit(f"{len(matches)} symbols match {symbol!r}")
    dump = subprocess.run(["objdump", "-d", "--no-show-raw-insn", binary, f"--disassemble={matches[0]}"],
                          capture_output=True, text=True, check=True).stdout
    out = []
    for line in dump.split("\n"):
        m = re.match(r"\s+([0-9a-f]+):\s+(\S+)\s*(.*)", line)
        if m:
            out.append((int(m.group(1), 16), m.group(2), re.sub(r"<[^>]*>|#.*", "", m.group(3)).strip()))
    return out


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    ins = instructions(sys.argv[1], sys.argv[2])
    if len(sys.argv) == 3:
        for address, op, args in ins:
            target = re.match(r"([0-9a-f]+)$", args)
            if op.startswith("j") and target and int(target.group(1), 16) < address:
                start = int(target.group(1), 16)
                size = sum(1 for a, _, _ in ins if start <= a <= address)
                print(f"{start:x} {address:x}  {size} instructions")
        return
    start, end = int(sys.argv[3], 16), int(sys.argv[4], 16)
    cpu = sys.argv[5] if len(sys.argv) > 5 else "znver3"
    body = [f"{op} {args}".strip() for a, op, args in ins
            if start <= a <= end and not op.startswith(("j", "call", "nop", "xchg", "data16", "cs"))]
    with tempfile.NamedTemporaryFile("w", suffix=".s") as f:
        f.write("\n".join(body) + "\n")
        f.flush()
        for iterations in (50, 1):
            report = subprocess.run(["llvm-mca", f"-mcpu={cpu}", f"-iterations={iterations}", f.name],
                                    capture_output=True, text=True, check=True).stdout
            print(f"-- {iterations} iteration(s), {len(body)} instructions")
            print("\n".join(report.split("\n")[:10]))


if __name__ == "__main__":
    main()
