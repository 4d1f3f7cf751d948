#!/bin/sh
# vm_prepare.sh CACHE - the kernel side of the linux-port VM test, built once into CACHE (a
# directory of the build tree, never the repository):
#   CACHE/vmlinux              Debian's linux-image-amd64 kernel, uncompressed (PVH boot:
#                              TCG skips SeaBIOS and the in-guest xz decompression, ~4 s)
#   CACHE/modules/*.ko         can, can-raw, can-dev, vcan, configfs from that kernel, and
#                              irq_sim_oot, gpio-sim-oot built here out of tree
#   CACHE/kernel-release       e.g. 6.1.0-56-amd64
# Debian's amd64 kernels do not enable CONFIG_GPIO_SIM or CONFIG_IRQ_SIM, hence the
# out-of-tree build from the matching linux-source (the drivers poke struct gpio_device, so
# gpiolib.h must be the same version). The packages are fetched with `apt-get download`
# into CACHE and unpacked with `dpkg -x`: nothing is installed into /.
# Exit status: 0 ready, 77 cannot be done on this machine (reason printed), 1 failed.
set -eu
CACHE=${1:?usage: vm_prepare.sh CACHE}
mkdir -p "$CACHE"
CACHE=$(cd "$CACHE" && pwd)
skip() { echo "vm_prepare: SKIP: $*"; exit 77; }
[ -f "$CACHE/ready" ] && exit 0

for t in apt-get apt-cache dpkg make gcc python3 tar; do
    command -v "$t" >/dev/null 2>&1 || skip "no '$t' on this machine"
done

# The kernel's ABI name drifts with Debian's security updates (6.1.0-56 -> -57, the old one
# leaves the archive): resolve it from the metapackage each time the cache is built.
KPKG=$(apt-cache depends linux-image-amd64 2>/dev/null |
       awk '/Depends: linux-image-[0-9]/ {print $2; exit}')
[ -n "$KPKG" ] || skip "apt-cache knows no linux-image-amd64 (not Debian, or no apt lists)"
KREL=${KPKG#linux-image-}            # 6.1.0-56-amd64
ABI=${KREL%-amd64}                   # 6.1.0-56
SERIES=${KREL%%.0-*}                 # 6.1
KVER=$(apt-cache show --no-all-versions "$KPKG" | awk '/^Version:/ {print $2; exit}')
echo "vm_prepare: kernel $KREL ($KVER) into $CACHE"

D=$CACHE/debs
mkdir -p "$D"
if [ ! -f "$D/.complete-$KREL" ]; then
    # apt-get download writes into the current directory; run it in a subshell there.
    if ! (cd "$D" && apt-get download -q "$KPKG" "linux-headers-$KREL" \
              "linux-headers-$ABI-common" "linux-kbuild-$SERIES" \
              "linux-source-$SERIES=$KVER" >download.log 2>&1); then
        tail -5 "$D/download.log"
        skip "apt-get download of the kernel packages failed (offline?)"
    fi
    touch "$D/.complete-$KREL"
fi

R=$CACHE/root
rm -rf "$R"
mkdir -p "$R"
for deb in "$D"/*"$ABI"*.deb "$D"/linux-kbuild-"$SERIES"_*.deb; do
    dpkg -x "$deb" "$R"
done
H=$R/usr/src/linux-headers-$KREL
# The arch headers' Makefile names the -common tree by its absolute install path.
sed -i "s#/usr/src/linux-headers-$ABI-common#$R/usr/src/linux-headers-$ABI-common#" "$H/Makefile"

# ---- gpio-sim + irq_sim out of tree
M=$CACHE/mod
rm -rf "$M"
mkdir -p "$M"
SRCTAR=$(ls "$D"/linux-source-"$SERIES"_*.deb)
dpkg-deb --fsys-tarfile "$SRCTAR" | tar -xf - -O "./usr/src/linux-source-$SERIES.tar.xz" \
    >"$M/src.tar.xz"
# One tar call: each one decompresses the whole 140 MB tarball.
LS=linux-source-$SERIES
tar -xJf "$M/src.tar.xz" -C "$M" --strip-components=3 \
    "$LS/drivers/gpio/gpio-sim.c" "$LS/drivers/gpio/gpiolib.h" "$LS/kernel/irq/irq_sim.c"
rm -f "$M/src.tar.xz"
# irq_to_desc() is not exported to modules in 6.1: hand the interrupt over by number.
mv "$M/irq_sim.c" "$M/irq_sim_oot.c"
sed -i 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq(irqnum);/' "$M/irq_sim_oot.c"
grep -q 'generic_handle_irq(irqnum);' "$M/irq_sim_oot.c" ||
    { echo "vm_prepare: irq_sim.c changed upstream: the patch no longer applies"; exit 1; }
echo 'MODULE_LICENSE("GPL");' >>"$M/irq_sim_oot.c"
# A separate irq_sim module: linked into gpio-sim it would clash with any second user.
printf 'obj-m += irq_sim_oot.o gpio-sim-oot.o\ngpio-sim-oot-y := gpio-sim.o\n' >"$M/Makefile"
make -s -C "$H" M="$M" modules >"$M/build.log" 2>&1 ||
    { cat "$M/build.log"; echo "vm_prepare: the gpio-sim module build failed"; exit 1; }

mkdir -p "$CACHE/modules"
K=$R/lib/modules/$KREL/kernel
# Debian ships no modules.dep in the .deb (depmod runs at install): the init script loads
# these in dependency order (can -> can-raw, can-dev -> vcan, configfs -> irq_sim -> gpio-sim).
cp "$K/net/can/can.ko" "$K/net/can/can-raw.ko" "$K/drivers/net/can/dev/can-dev.ko" \
   "$K/drivers/net/can/vcan.ko" "$K/fs/configfs/configfs.ko" \
   "$M/irq_sim_oot.ko" "$M/gpio-sim-oot.ko" "$CACHE/modules/"
strip --strip-debug "$CACHE/modules/"*.ko 2>/dev/null || true

# Debian ships no extract-vmlinux: the bzImage holds one xz stream.
python3 - "$R/boot/vmlinuz-$KREL" "$CACHE/vmlinux" <<'EOF'
import lzma, sys
data = open(sys.argv[1], 'rb').read()
start = data.find(b'\xfd7zXZ\x00')
if start < 0:
    sys.exit('vmlinuz: no xz stream')
open(sys.argv[2], 'wb').write(lzma.LZMADecompressor().decompress(data[start:]))
EOF
echo "$KREL" >"$CACHE/kernel-release"
# Unpacked trees are 600 MB; only the outputs above are needed again.
rm -rf "$R"
touch "$CACHE/ready"
echo "vm_prepare: ready"
