#!/bin/bash
# Interleaved A/B timing of two builds of an example that prints "... <number> ns" on its last line
# (`examples/step_cost.rs`): runs A and B alternately ROUNDS times, so load on a shared machine hits both
# alike, and prints the medians, the minima, the median of the per-round ratios B/A and the ratio of the
# minima.
#
#   tools/ab.sh OLD_BINARY NEW_BINARY ROUNDS ARGS...
#   e.g. tools/ab.sh /tmp/step_cost_old target/release/examples/step_cost 12 1000 16 10 sway
set -euo pipefail
if [ $# -lt 3 ]; then
  sed -n 2,7p "$0" >&2
  exit 2
fi
a=$1; b=$2; rounds=$3; shift 3
ns() { "$@" 2>&1 | tail -1 | grep -o '[0-9.]* ns' | cut -d' ' -f1; }
for _ in $(seq "$rounds"); do
  echo "$(ns "$a" "$@") $(ns "$b" "$@")"
done | python3 -c '
import statistics, sys
rows = [tuple(map(float, line.split())) for line in sys.stdin if line.strip()]
a = [r[0] for r in rows]; b = [r[1] for r in rows]
ratios = [y / x for x, y in rows]
print(f"A median {statistics.median(a)} min {min(a)} | B median {statistics.median(b)} min {min(b)} | "
      f"B/A median {statistics.median(ratios):.3f} min/min {min(b) / min(a):.3f} n {len(rows)}")
'
