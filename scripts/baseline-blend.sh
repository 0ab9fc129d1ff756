#!/usr/bin/env bash
# Issue 63, item 3: the baseline blend on kronecker masks (slf_host::decode::blend). Every
# scene `slf scene` names and the real crops when present (SLF_REAL), at each setting of
# SLF_SETTINGS (default kronecker k = 3 and 1), `--seed 1`: the default (the blend, with
# --error-map), the default without the blend, the PPID and demosaic baselines, the preview
# and the preview with the blend; PSNR / SSIM / SA against the truth, the blended output's
# estimated PSNR and rank correlation (`slf eval --error-map`), and each decode's seconds.
# The blend's rule was chosen on the 18 synthetic scenes at kronecker k = 3 (the real crops'
# figures were printed beside them then); k = 1 was not looked at before.
#
# SLF_RESUME=1 keeps the captures OUT_DIR's table already holds (a run that stopped); the page
# names the commits whose binaries made its rows (OUT_DIR/made-at; SLF_MADE_AT names the
# commit of an SLF_BIN built earlier).
#
#   RAYON_NUM_THREADS=1 bash scripts/baseline-blend.sh OUT_DIR > docs/results-baseline-blend.md
set -euo pipefail
out=${1:?usage: baseline-blend.sh OUT_DIR}
cd "$(dirname "$0")/.."
. scripts/scene-tables.sh
table_setup
add_real_scenes
rows="$out/blend.tsv"
[ -n "${SLF_RESUME:-}" ] && [ -f "$rows" ] || : > "$rows"
row() {
  local cols=() ev e rho
  awk -F'\t' -v s="$s" -v c="$scene" '$1 == s && $2 == c { found = 1 } END { exit !found }' "$rows" && return 0
  decode_eval "$cap" --error-map "$out/map.npy"
  cols+=("$p" "$t")
  ev=$("$slf" eval "$lf" "$out/rec.npy" --error-map "$out/map.npy" 2>&1 || true)
  read -r e rho < <(echo "$ev" | awk '/^estimate PSNR/ { e = $3; r = $15 } END { sub(/,/, "", r); print (e == "" ? "nan" : e), (r == "" ? "nan" : r) }')
  cols+=("$e" "$rho")
  decode_eval "$cap" --baseline-blend false; cols+=("$p" "$t")
  decode_eval "$cap" --method ppid; cols+=("$p" "$t")
  decode_eval "$cap" --method demosaic; cols+=("$p" "$t")
  decode_eval "$cap" --preset preview; cols+=("$p" "$t")
  decode_eval "$cap" --preset preview --baseline-blend true; cols+=("$p" "$t")
  (IFS=$'\t'; echo "$s	$scene	${cols[*]}") >> "$rows"
  # The commit whose binary made the rows (a resumed run adds its own).
  grep -qx "$made" "$out/made-at" 2>/dev/null || echo "$made" >> "$out/made-at"
}
made=${SLF_MADE_AT:-$(git rev-parse --short HEAD)}
settings=${SLF_SETTINGS:-kronecker:3 kronecker:1}
each_capture "$settings" 1 row
STAMP_LINE=$(stamp "bash scripts/baseline-blend.sh OUT_DIR") && export STAMP_LINE
python3 - "$rows" "$size" "$(paste -sd, "$out/made-at" 2>/dev/null || git rev-parse --short HEAD)" "${RAYON_NUM_THREADS:-all}" "$settings" <<'PY'
import statistics, sys
asked = sys.argv[5].split()
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
rows = [r for r in rows if r[0] in asked]
real = lambda scene: scene.endswith("_128")
print("# The baseline blend on kronecker masks (issue 63)")
print()
print(__import__("os").environ["STAMP_LINE"])
print()
print(f"Made by `bash scripts/baseline-blend.sh OUT_DIR` at {sys.argv[3]}: synthetic scenes at {sys.argv[2]} x "
      f"{sys.argv[2]} lenslets and the real crops, 5 x 5 views, `slf simulate --seed 1`, "
      f"`RAYON_NUM_THREADS={sys.argv[4]}`. PSNR in dB. \"blend\" is the default (each kronecker block mixed from "
      "the decode and PPID by their held-out errors), \"decode\" the default with `--baseline-blend false` "
      "(the default before), \"baselines\" the better of PPID and the neighbourhood demosaic; \"preview + blend\" "
      "is `--preset preview --baseline-blend true`. The estimate is the blended output's (`--error-map`, "
      "`slf eval --error-map`): its PSNR less the true one, and the rank correlation of the estimated and true RMS "
      "errors of blocks of 5 x 5 lenslets. Times: seconds of one decode each. The blend's rule was chosen on the "
      "synthetic scenes at kronecker k = 3, with the real crops' (\\*) figures printed beside them; k = 1 was not "
      "looked at before.")
for s in asked:
    sel = [r for r in rows if r[0] == s]
    if not sel:
        continue
    f = lambda r, i: float(r[i])
    mask, k = s.split(":")
    d = []
    print()
    print(f"**{mask} k = {k}** ({len(sel)} scenes)")
    print()
    print("| scene | blend | decode | PPID | demosaic | blend - max(decode, baselines) | estimate - true | rank | preview | preview + blend | s: decode / blend / PPID / preview / preview + blend |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in sel:
        blend, dec, pp, dm, pv, pvb = f(r, 2), f(r, 6), f(r, 8), f(r, 10), f(r, 12), f(r, 14)
        base = max(pp, dm)
        m = blend - max(dec, base)
        bias = f(r, 4) - blend if r[4] != "nan" else float("nan")
        d.append(dict(m=m, vs_dec=blend - dec, vs_base=blend - base, bias=bias, rho=f(r, 5), pv=pv - base, pvb=pvb - base,
                      t=f(r, 3) / f(r, 7), tp=f(r, 15) / f(r, 13), real=real(r[1])))
        star = " \\*" if real(r[1]) else ""
        print(f"| {r[1]}{star} | {blend:.2f} | {dec:.2f} | {pp:.2f} | {dm:.2f} | {m:+.2f} | {bias:+.2f} | {f(r, 5):.3f} | "
              f"{pv:.2f} | {pvb:.2f} | {f(r, 7):.2f} / {f(r, 3):.2f} / {f(r, 9):.2f} / {f(r, 13):.2f} / {f(r, 15):.2f} |")
    ms = [x["m"] for x in d]
    print()
    print(f"- Blend against the better of the decode and the baselines: worst {min(ms):+.2f} dB, mean {statistics.mean(ms):+.2f}; "
          f"more than 0.1 dB under it on {sum(x < -0.1 for x in ms)} of {len(ms)} "
          f"(real crops: {', '.join('%+.2f' % x['m'] for x in d if x['real']) or 'none'}).")
    vd = [x["vs_dec"] for x in d]
    print(f"- Blend against the decode alone: {min(vd):+.2f} to {max(vd):+.2f} dB (mean {statistics.mean(vd):+.2f}); "
          f"below the strongest baseline on {sum(x['vs_base'] < 0 for x in d)} (the decode alone: "
          f"{sum(x['vs_base'] - x['vs_dec'] < 0 for x in d)}).")
    print(f"- Preview below the strongest baseline on {sum(x['pv'] < 0 for x in d)}, with the blend on "
          f"{sum(x['pvb'] < 0 for x in d)} (worst {min(x['pv'] for x in d):+.2f} and {min(x['pvb'] for x in d):+.2f} dB).")
    b = [x["bias"] for x in d if x["bias"] == x["bias"]]
    rho = [x["rho"] for x in d if x["rho"] == x["rho"]]
    if b:
        print(f"- Estimated PSNR of the blended output less the true: median {statistics.median(b):+.2f} "
              f"({min(b):+.2f} to {max(b):+.2f}), within 1 dB on {sum(abs(x) <= 1 for x in b)} of {len(b)}; "
              f"rank median {statistics.median(rho):.3f}, at least 0.7 on {sum(x >= 0.7 for x in rho)}.")
    print(f"- Time, blend over decode: median {statistics.median(x['t'] for x in d):.2f} "
          f"({min(x['t'] for x in d):.2f} to {max(x['t'] for x in d):.2f}); preview + blend over preview: "
          f"median {statistics.median(x['tp'] for x in d):.2f}.")
PY
