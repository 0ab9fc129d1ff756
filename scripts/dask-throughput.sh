#!/usr/bin/env bash
# Captures per second of `python/examples/decode_folder.py` on a Dask LocalCluster of 1 and
# of 2 worker processes (one thread each, loopback), on the same captures in one run; writes
# the table into docs/python.md between the dask-throughput markers.
#
#   pip install "./python[dask]"; bash scripts/dask-throughput.sh
#
# SLF_CAPTURES (default 8) realistic scenes (seeds 1..N) of SLF_SIZE (default 60) lenslets a
# side, pixel mask, k = 1, decoded with SLF_PRESET (default: default). PYTHON picks the
# interpreter that has the package.
set -euo pipefail
cd "$(dirname "$0")/.."
py=${PYTHON:-python3}
n=${SLF_CAPTURES:-8}
size=${SLF_SIZE:-60}
preset=${SLF_PRESET:-default}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

"$py" - "$dir/captures" "$n" "$size" <<'PY'
import sys
import slf
root, n, size = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
for seed in range(1, n + 1):
    slf.simulate(slf.scene("realistic", size=size, seed=seed), k=1).save(f"{root}/scene{seed:02}")
PY

rows=""
base=""
for w in 1 2; do
  line=$("$py" python/examples/decode_folder.py "$dir/captures" "$dir/out$w" --workers "$w" --preset "$preset" | tail -1)
  echo "$line"
  secs=$(echo "$line" | sed -E 's/.* in ([0-9.]+) s .*/\1/')
  rate=$(echo "$line" | sed -E 's/.*: ([0-9.]+) captures\/s/\1/')
  base=${base:-$rate}
  speedup=$(awk -v r="$rate" -v b="$base" 'BEGIN { printf "%.2f", r / b }')
  rows="$rows| $w | $n | $secs | $rate | $speedup |"$'\n'
done

# Without Dask: one process, each decode on every core (rayon), one capture after another.
alone=$("$py" - "$dir/captures" "$dir/alone" "$preset" <<'PY'
import sys, time
import slf.batch
start = time.perf_counter()
results = slf.batch.decode_folder(sys.argv[1], sys.argv[2], preset=sys.argv[3], threads=None)
wall = time.perf_counter() - start
assert all(r.ok for r in results), [r.error for r in results if not r.ok]
print(f"{wall:.2f} {len(results) / wall:.3f}")
PY
)
secs=${alone% *}
rate=${alone#* }
speedup=$(awk -v r="$rate" -v b="$base" 'BEGIN { printf "%.2f", r / b }')
rows="$rows| none: one process, each decode on all $(nproc) cores | $n | $secs | $rate | $speedup |"$'\n'

table="| Dask workers (1 thread each) | captures | seconds | captures / s | against 1 worker |
| --- | --- | --- | --- | --- |
${rows}
$n realistic scenes of $size x $size lenslets (5 x 5 views), pixel mask, k = 1, preset \`$preset\`,
on a LocalCluster of this machine ($(nproc) cores, shared), $(date -u +%Y-%m-%d); wall time
includes the cluster's task overhead but not its start."
"$py" - "$table" <<'PY'
import re, sys
text = open("docs/python.md").read()
begin, end = "<!-- dask-throughput:begin -->", "<!-- dask-throughput:end -->"
new = re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda m: f"{begin}\n{sys.argv[1]}\n{end}", text, flags=re.S)
open("docs/python.md", "w").write(new)
PY
echo "docs/python.md: table written"
