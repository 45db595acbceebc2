#!/bin/bash
# Interleaved A/B timing of two builds of an example that prints "... <number> ns" on its last line
# (`examples/step_cost.rs`, `examples/scene_cost.rs`): runs A and B alternately ROUNDS times, so load on a
# shared machine hits both alike, and prints the medians, the minima, the median of the per-round ratios B/A
# and the ratio of the minima. With --abba each round runs A B B A and its ratio is (B1 + B2) / (A1 + A2): the
# position within a round (the machine warming up or slowing down between runs) then falls on both builds
# alike, which the A B order does not undo (a few percent on stop 37's machine); it also prints the medians of
# the A-then-B and B-then-A pairs' own ratios, whose spread shows what the order alone does.
#
#   tools/ab.sh [--abba] OLD_BINARY NEW_BINARY ROUNDS ARGS...
#   e.g. tools/ab.sh /tmp/step_cost_old target/release/examples/step_cost 12 1000 16 10 sway
#        tools/ab.sh --abba /tmp/scene_cost_old target/release/examples/scene_cost 20 80 1000x16 lanes
set -euo pipefail
abba=false
if [ "${1:-}" = --abba ]; then
  abba=true
  shift
fi
if [ $# -lt 3 ]; then
  sed -n 2,12p "$0" >&2
  exit 2
fi
a=$1; b=$2; rounds=$3; shift 3
ns() { "$@" 2>&1 | tail -1 | grep -o '[0-9.]* ns' | cut -d' ' -f1; }
for _ in $(seq "$rounds"); do
  if $abba; then
    a1=$(ns "$a" "$@"); b1=$(ns "$b" "$@"); b2=$(ns "$b" "$@"); a2=$(ns "$a" "$@")
    echo "$a1 $b1 $b2 $a2"
  else
    echo "$(ns "$a" "$@") $(ns "$b" "$@")"
  fi
done | python3 -c '
import statistics, sys
rows = [tuple(map(float, line.split())) for line in sys.stdin if line.strip()]
if len(rows[0]) == 4:
    both = [(b1 + b2) / (a1 + a2) for a1, b1, b2, a2 in rows]
    ab = [b1 / a1 for a1, b1, b2, a2 in rows]
    ba = [b2 / a2 for a1, b1, b2, a2 in rows]
    print(f"B/A median {statistics.median(both):.3f} (A then B {statistics.median(ab):.3f}, "
          f"B then A {statistics.median(ba):.3f}) n {len(rows)}")
    sys.exit()
a = [r[0] for r in rows]; b = [r[1] for r in rows]
ratios = [y / x for x, y in rows]
print(f"A median {statistics.median(a)} min {min(a)} | B median {statistics.median(b)} min {min(b)} | "
      f"B/A median {statistics.median(ratios):.3f} min/min {min(b) / min(a):.3f} n {len(rows)}")
'
