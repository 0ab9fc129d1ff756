# Sourced by the scripts that tabulate decodes per scene (hard-cases.sh, sensor-results.sh,
# plausible-results.sh, error-map-results.sh, shear-check-results.sh): the scene lists with the
# real crops, a scene's light field and capture, and one decode measured.
# They set `out` and call `table_setup` first. It brings scripts/stamp.sh (each page's stamp).

. scripts/stamp.sh

# Every scene `slf scene` names but `random`: the test scenes, the realistic ones and the hard
# cases (the issue-49 tables run over all of them).
all_scenes="smooth texture depth saturated dark outdoor tungsten office led mosaic mosaic-2 field print speculars narrow dim canopy canopy-dim"

# table_setup: builds the release binary and sets $slf, $size (SLF_SIZE, default 48) and
# $scenes (SLF_SCENES, default every scene); makes $out.
table_setup() {
  cargo build --release -q -p slf-host
  slf=${SLF_BIN:-./target/release/slf}
  size=${SLF_SIZE:-48}
  scenes=${SLF_SCENES:-$all_scenes}
  mkdir -p "$out"
}

# Appends the real content the project evaluates to $scenes when present (scripts/real-eval.sh's
# crops in $SLF_REAL, default /tmp/hci/real; their licence allows evaluation only).
add_real_scenes() {
  local real=${SLF_REAL:-/tmp/hci/real} f
  for f in "$real"/*_128.npy; do
    [ -f "$f" ] && scenes="$scenes real:$f"
  done
  return 0
}

# grid_table_setup: table_setup for the tables behind a turned lenslet array (issue 66):
# 64 x 64-lenslet scenes (SLF_SCENES, default outdoor tungsten office led) and the HCI crops
# when present; $ks (SLF_KS, default 1 3), $grids (SLF_GRIDS, deg:px each, default 0.3:5.04
# 1:5.1) and $sensor, the sensor's flags (30 % vignetting, 1 % PRNU).
grid_table_setup() {
  SLF_SIZE=${SLF_SIZE:-64} SLF_SCENES=${SLF_SCENES:-outdoor tungsten office led} table_setup
  add_real_scenes
  ks=${SLF_KS:-1 3}
  grids=${SLF_GRIDS:-0.3:5.04 1:5.1}
  sensor=(--vignetting 0.3 --prnu 0.01)
}

# grid_calibration BIN DIR FLAGS...: BIN's calibration into DIR of the sensor $sensor and
# FLAGS (a grid's) describe, from its own calibration captures of $lf (2 exposures each; a
# flat does not see the mask), made once; prints calibrate's report (from its standard error).
grid_calibration() {
  local bin=$1 dir=$2
  shift 2
  [ -d "$dir" ] && return 0
  rm -rf "$out/cc" "$out/cc-cap"
  "$bin" simulate "$lf" -o "$out/cc-cap" "${sensor[@]}" "$@" --calibration-captures "$out/cc" --exposures 2 > /dev/null 2>&1
  "$bin" calibrate "$out/cc" -o "$dir" 2>&1 > /dev/null
  rm -rf "$out/cc" "$out/cc-cap"
}

# grid_captures K G: the captures of $lf at pixel K snapshots on the sensor $sensor, aligned
# and behind grid G (deg:px), each with this binary's calibration of its sensor (all made once):
# sets $cal_aligned, $aligned, $cal and $cap.
grid_captures() {
  local k=$1 g=$2
  cal_aligned="$out/cal-$scene-aligned"
  grid_calibration "$slf" "$cal_aligned" > /dev/null
  aligned="$out/cap-$scene-$k-aligned"
  [ -d "$aligned" ] || "$slf" simulate "$lf" -o "$aligned" -s "$k" --seed 1 "${sensor[@]}" > /dev/null 2>&1
  cal="$out/cal-$scene-$g"
  grid_calibration "$slf" "$cal" --rotation "${g%:*}" --pitch "${g#*:}" > /dev/null
  cap="$out/cap-$scene-$k-$g"
  [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" -s "$k" --seed 1 "${sensor[@]}" \
    --rotation "${g%:*}" --pitch "${g#*:}" > /dev/null 2>&1
}

# grid_scores: sets $psnr (without the 2 edge lenslets: a turned array's corners reach past
# the sensor), $q (SSIM) and $a (SA) of the decode in $out/rec.npy against $lf.
grid_scores() {
  psnr=$("$slf" eval "$lf" "$out/rec.npy" --border 2 | awk '/^PSNR/ { print $2 }')
  read -r q a < <("$slf" eval "$lf" "$out/rec.npy" | awk '/^SSIM/ { q = $2 } /^SA/ { a = $2 } END { print q, a }')
}

# grid_measure BIN CALIBRATION CAPTURE ARGS...: prints PSNR (interior) / SSIM / SA and seconds
# of BIN's decode of CAPTURE with ARGS (grid-shear.sh, grid-halves.sh).
grid_measure() {
  local bin=$1 calibration=$2 cap=$3 start end secs
  shift 3
  start=$(date +%s.%N)
  "$bin" decode "$cap" -o "$out/rec.npy" --quiet --calibration "$calibration" "$@" > /dev/null
  end=$(date +%s.%N)
  grid_scores
  secs=$(python3 -c "print(f'{$end - $start:.1f}')")
  echo "$psnr $q $a $secs"
}

# scene_light_field TOKEN: sets $scene (its name) and $lf (its light field: a real crop, or
# `slf scene` rendered into $out once).
scene_light_field() {
  scene=$1
  if [ "${scene#real:}" != "$scene" ]; then
    lf=${scene#real:}
    scene=$(basename "$lf" .npy)
  else
    lf="$out/$scene.npy"
    [ -f "$lf" ] || "$slf" scene "$scene" --size "$size" -o "$lf" > /dev/null
  fi
}

# decode_eval CAPTURE ARGS...: decodes CAPTURE with ARGS against $lf; sets $p $q $a (PSNR,
# SSIM, SA), $t (the decode's seconds) and $log (the decode's summary).
decode_eval() {
  local cap=$1 rec="$out/rec.npy"; shift
  log=$("$slf" decode "$cap" -o "$rec" --quiet "$@")
  t=$(echo "$log" | awk '/ in [0-9.]+ s/ { for (i = 1; i < NF; i++) if ($i == "in") print $(i + 1) }')
  read -r p q a < <("$slf" eval "$lf" "$rec" | awk '/^PSNR/ { p = $2 } /^SSIM/ { q = $2 } /^SA/ { a = $2 } END { print p, q, a }')
}

# scene_capture SETTING SEED: sets $mask, $k (from SETTING, MASK:K) and $cap, the capture of $lf
# with that mask and seed, simulated into $out once.
scene_capture() {
  mask=${1%:*}; k=${1#*:}
  cap="$out/cap-$scene-$mask-$k"
  [ -d "$cap" ] || "$slf" simulate "$lf" -o "$cap" --mask "$mask" -s "$k" --seed "$2" > /dev/null 2>&1
  return 0
}

# each_capture SETTINGS SEED COMMAND...: for each setting (MASK:K) and each scene of $scenes,
# sets $s (the setting), $scene, $lf, $mask, $k and $cap (scene_light_field, scene_capture)
# and runs COMMAND.
each_capture() {
  local settings=$1 seed=$2 token; shift 2
  for s in $settings; do
    for token in $scenes; do
      scene_light_field "$token"
      scene_capture "$s" "$seed"
      "$@"
    done
  done
}
