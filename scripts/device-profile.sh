#!/usr/bin/env bash
# Where the device's instructions go (issue 30): runs the device binary on qemu's emulated
# Cortex-M7 (mps2-an500) with the counting plugin's profile (scripts/wincount/wincount.c, prof=) and
# prints, per function of the device ELF, the instructions of a screened-ensemble tile and
# of a DCT tile (one full-view patch each; the windows of scripts/budgets.sh).
# Needs what budgets.sh needs: thumbv7em-none-eabihf, qemu-system-arm, gcc, llvm-nm.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/device-build.sh
# Windows: 1 the white balance, 2 one synthesis, 3 the first ensemble tile, then the other
# ensemble tiles and the DCT tiles (T of each).
run() {
  timeout 600 qemu-system-arm -M mps2-an500 -nographic -semihosting-config enable=on,target=native \
    -kernel "$elf" -plugin "target/libwincount.so,start=$begin,end=$end,prof=$1:$1" -d plugin -D "$2" \
    > target/profile-device.log
}
run 3 target/profile-ensemble.log
tiles=$(grep -c '^tile ' target/profile-device.log)
patches=$(awk '/^tile / { print $5; exit }' target/profile-device.log)
python3 scripts/device-profile.py "$elf" target/profile-ensemble.log 3 3 "screened ensemble tile ($patches full-view patch(es))"
echo
run $((3 + tiles)) target/profile-dct.log
python3 scripts/device-profile.py "$elf" target/profile-dct.log $((3 + tiles)) $((3 + tiles)) "DCT tile ($patches full-view patch(es))"
