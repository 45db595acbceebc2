#!/bin/bash
# Interleaved A/B timing of two builds of an example that prints "... <number> ns" on its last line
# (`examples/scene_cost.rs`), in A B B A order each round: the position within a round (the machine warming up
# or slowing down between runs) falls on both builds alike, which `tools/ab.sh`'s A B order does not undo.
# Prints the median over rounds of (B1 + B2) / (A1 + A2), and the medians of the A-then-B and B-then-A pairs'
# own ratios (their spread shows what the order alone does).
#
#   tools/abba.sh OLD_BINARY NEW_BINARY ROUNDS ARGS...
#   e.g. tools/abba.sh /tmp/scene_cost_old target/release/examples/scene_cost 20 80 1000x16 lanes
set -euo pipefail
if [ $# -lt 3 ]; then
  sed -n 2,9p "$0" >&2
  exit 2
fi
a=$1; b=$2; rounds=$3; shift 3
ns() { "$@" 2>&1 | tail -1 | grep -o '[0-9.]* ns' | cut -d' ' -f1; }
for _ in $(seq "$rounds"); do
  a1=$(ns "$a" "$@"); b1=$(ns "$b" "$@"); b2=$(ns "$b" "$@"); a2=$(ns "$a" "$@")
  echo "$a1 $b1 $b2 $a2"
done | python3 -c '
import statistics, sys
rows = [tuple(map(float, line.split())) for line in sys.stdin if line.strip()]
both = [(b1 + b2) / (a1 + a2) for a1, b1, b2, a2 in rows]
ab = [b1 / a1 for a1, b1, b2, a2 in rows]
ba = [b2 / a2 for a1, b1, b2, a2 in rows]
print(f"B/A median {statistics.median(both):.3f} (A then B {statistics.median(ab):.3f}, "
      f"B then A {statistics.median(ba):.3f}) n {len(rows)}")
'
