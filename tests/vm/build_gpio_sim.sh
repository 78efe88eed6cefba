#!/usr/bin/env bash
# Builds gpio-sim.ko out of tree for the hardware lab.
#
#   build_gpio_sim.sh LINUX_SOURCE_TARBALL HEADERS_DIR OUT_DIR
#
# Debian's kernels leave CONFIG_GPIO_SIM unset, so the module is built from
# three files of Debian's own linux-source package (never committed here):
# drivers/gpio/gpio-sim.c, drivers/gpio/gpiolib.h and kernel/irq/irq_sim.c,
# which gpio-sim needs and the kernel does not build either (CONFIG_IRQ_SIM).
# Both go into one module named gpio-sim. One change makes irq_sim.c build
# outside the kernel: irq_to_desc() is not exported, so
# handle_simple_irq(irq_to_desc(n)) becomes generic_handle_irq(n), which
# looks the descriptor up and calls the same flow handler.
set -euo pipefail

if [ $# -ne 3 ]; then
  echo "usage: $0 LINUX_SOURCE_TARBALL HEADERS_DIR OUT_DIR" >&2
  exit 2
fi
tarball=$1 headers=$2 out=$3

work="$out/src"
rm -rf "$work"
mkdir -p "$work"

# The tarball's top folder is linux-source-X.Y; all three files are three
# folders deep. --occurrence stops reading once all three are found (the
# whole archive takes ~12 s to decompress).
top=$(basename "$tarball" .tar.xz)
tar -xJf "$tarball" -C "$work" --strip-components=3 --occurrence=1 \
  "$top/drivers/gpio/gpio-sim.c" "$top/drivers/gpio/gpiolib.h" "$top/kernel/irq/irq_sim.c"

# The module is called gpio-sim, so its main object needs another name.
mv "$work/gpio-sim.c" "$work/gpio-sim-main.c"
sed -i 's/handle_simple_irq(irq_to_desc(\([a-z_]*\)))/generic_handle_irq(\1)/' "$work/irq_sim.c"
if grep -q 'irq_to_desc' "$work/irq_sim.c"; then
  echo "build_gpio_sim.sh: irq_sim.c still calls irq_to_desc(); the patch no longer applies to this kernel source" >&2
  exit 1
fi
cat >"$work/Kbuild" <<'EOF'
obj-m := gpio-sim.o
gpio-sim-y := gpio-sim-main.o irq_sim.o
EOF

# Kbuild's own chatter (and "Skipping BTF generation") only matters on failure.
if ! log=$(make -C "$headers" M="$work" -j2 modules 2>&1); then
  echo "$log" >&2
  echo "build_gpio_sim.sh: building gpio-sim.ko against $headers failed" >&2
  exit 1
fi
cp "$work/gpio-sim.ko" "$out/gpio-sim.ko"
