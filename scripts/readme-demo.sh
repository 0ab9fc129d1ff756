#!/usr/bin/env bash
# The README's demo table, from `slf demo` itself (the shipped ensemble, then the DCT):
#
#   bash scripts/readme-demo.sh           # writes the table between the demo markers
#   bash scripts/readme-demo.sh --check   # fails if the README's PSNR / SSIM / SA differ
#
# The quality columns are deterministic (fixed seeds), so CI checks them; the seconds are
# this machine's, so --check leaves them out.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p slf-host
out=target/readme-demo
rows=""
totals=""
for basis in ensemble dct; do
  log=$(./target/release/slf demo --dictionary "$basis" --out "$out/$basis")
  rows="$rows$(echo "$log" | grep '^| depth ' | sed -E "s/^\| depth \| pixel \| ([0-9]+) \|/| depth | pixel | \1 | $basis |/")"$'\n'
  totals="$totals $basis $(echo "$log" | sed -nE 's/.*total ([0-9.]+) s$/\1/p') s,"
done
table="| scene | mask | k | basis | PSNR dB | SSIM | SA deg | decode s |
| --- | --- | --- | --- | --- | --- | --- | --- |
${rows}
\`slf demo\` and \`slf demo --dictionary dct\` (depth scene, 100 x 100 lenslets, pixel mask,
$(nproc) threads; the default decode with the shipped ensemble, screened); in all:${totals%,}."
python3 - "$table" "${1:-}" <<'PY'
import re, sys
table, mode = sys.argv[1], sys.argv[2]
text = open("README.md").read()
begin, end = "<!-- demo:begin -->", "<!-- demo:end -->"
old = re.search(re.escape(begin) + "(.*?)" + re.escape(end), text, re.S)
assert old, "README.md has no demo markers"
def quality(block):
    # scene, mask, k, basis, PSNR, SSIM, SA of each row: everything but the seconds.
    return [tuple(c.strip() for c in line.split("|")[1:8]) for line in block.splitlines() if line.startswith("| depth ")]
if mode == "--check":
    want, have = quality(table), quality(old.group(1))
    if want != have:
        sys.exit(f"README.md's demo table is stale:\n  README: {have}\n  demo:   {want}\n(bash scripts/readme-demo.sh)")
    print(f"README.md's demo table matches slf demo ({len(want)} rows)")
else:
    open("README.md", "w").write(text.replace(old.group(0), f"{begin}\n{table}\n{end}"))
    print("README.md: demo table written")
PY
