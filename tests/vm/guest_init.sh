#!/bin/sh
# /init of the hardware lab's guest (busybox sh, PID 1). Mounts the kernel
# file systems, loads the modules in /etc/lab-modules, runs each script in
# /etc/lab-checks in turn and powers off. The checks print
# `RESULT <name>: PASS|FAIL <detail>` lines on the console; run_lab.sh on the
# host collects them. A check exiting non-zero (a crash) is reported too, and
# fails its results on the host. No `set -e`: PID 1 exiting panics the
# kernel, and a broken check must not stop the ones after it. "LAB done"
# tells the host the guest got to the end.
/bin/busybox --install -s
export PATH=/usr/bin:/usr/sbin:/bin:/sbin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
mount -t tmpfs tmpfs /tmp
echo "LAB booted $(uname -r) in $(cut -d' ' -f1 /proc/uptime) s"

# modprobe pulls in dependencies (depmod ran at build time); /sbin/modprobe is
# also what the kernel runs to load usb_f_fs when configfs asks for "ffs".
while read -r module; do
  [ -n "$module" ] || continue
  modprobe "$module" || echo "LAB modprobe $module failed"
done </etc/lab-modules
mount -t configfs configfs /sys/kernel/config
# From here the kernel keeps its messages off the console, so they cannot
# split a RESULT line; the serious ones are printed after the checks.
dmesg -n 1

# The same sanitizer settings as .ci/run, for check programs built with them.
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export ASAN_OPTIONS=detect_leaks=1

while read -r check; do
  [ -n "$check" ] || continue
  echo "LAB check $check at $(cut -d' ' -f1 /proc/uptime) s"
  timeout 240 sh "/checks/$check" </dev/null
  status=$?
  if [ "$status" -ne 0 ]; then
    echo "LAB check $check exited with status $status"
  fi
done </etc/lab-checks

# Raw records start <facility * 8 + level>; the kernel's facility is 0, so
# <0>..<3> are emergency to error.
dmesg -r | grep '^<[0-3]>' | sed 's/^/LAB kernel: /'
echo "LAB done in $(cut -d' ' -f1 /proc/uptime) s"
sync
poweroff -f
