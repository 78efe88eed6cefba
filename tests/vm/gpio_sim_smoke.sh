#!/bin/sh
# Guest: gpio-sim edges reach libgpiod (camhead_vm_gpio_sim_smoke).
if [ ! -d /sys/kernel/config/gpio-sim ]; then
  echo "RESULT gpio_sim_edges: FAIL gpio-sim module not loaded (no /sys/kernel/config/gpio-sim)"
  exit 1
fi
exec camhead_vm_gpio_sim_smoke
