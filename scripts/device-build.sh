# Sourced by scripts/budgets.sh and scripts/device-profile.sh: builds the counting plugin
# (scripts/wincount/wincount.c) and the device binary (the `device` profile), and sets
# `elf` and the addresses `begin` / `end` of its bench_begin / bench_end markers.
# Needs: thumbv7em-none-eabihf target, qemu-system-arm, gcc, llvm-nm.
mkdir -p target
gcc -O2 -shared -fPIC -fvisibility=hidden -o target/libwincount.so scripts/wincount/wincount.c
cargo build --profile device -q -p slf-device --target thumbv7em-none-eabihf
elf=target/thumbv7em-none-eabihf/device/slf-device
# Thumb symbols carry bit 0; instruction addresses do not.
addr() { local v; v=$(llvm-nm "$elf" | awk -v s="$1" '$3 == s { print $1 }'); printf '0x%x' $(( 0x$v & ~1 )); }
begin=$(addr bench_begin)
end=$(addr bench_end)
