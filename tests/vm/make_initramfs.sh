#!/usr/bin/env bash
# Packs the hardware lab's initramfs: busybox, the guest init, the kernel's
# modules that the checks need (with their dependencies), extra out-of-tree
# modules, the check scripts and programs, and every library `ldd` lists for
# them, at the same paths as on this machine.
#
#   make_initramfs.sh --out FILE --kernel K --busybox FILE --init FILE
#       [--module NAME]... [--extra-module FILE.ko]... [--check FILE.sh]...
#       [--program FILE]... [--library SONAME]...
#       [--packed-module NAME]... [--packed-extra-module FILE.ko]...
#       [--file PATH]... [--data-file PATH]...
#
# --module and --extra-module are loaded at boot; --packed-module and
# --packed-extra-module are only packed (with their dependencies), for a
# check that loads them itself with its own options (vivid, v4l2loopback).
#
# --library packs a library that a program opens at run time (dlopen), which
# ldd cannot see: the hal backends' libusb-1.0.so.0 and libgpiod.so.2.
#
# --file packs any other file at the same path, with its mode and, for an
# ELF file, the libraries ldd lists: plug-ins and data a library finds by a
# path it was built with (libcamera's IPA modules and their configuration).
#
# --data-file packs a file the checks read into /etc/lab/ under its own name:
# a fixed place, wherever the checkout is (the guest mounts a tmpfs over
# /tmp, which would hide a file packed at a path under it).
#
# The guest runs the checks in the order given.
set -euo pipefail

out='' kernel='' busybox='' init=''
modules=() extra_modules=() checks=() programs=() libraries=()
packed_modules=() packed_extra_modules=() files=() data_files=()
while [ $# -gt 0 ]; do
  case $1 in
  --out) out=$2 ;;
  --kernel) kernel=$2 ;;
  --busybox) busybox=$2 ;;
  --init) init=$2 ;;
  --module) modules+=("$2") ;;
  --extra-module) extra_modules+=("$2") ;;
  --check) checks+=("$2") ;;
  --program) programs+=("$2") ;;
  --library) libraries+=("$2") ;;
  --packed-module) packed_modules+=("$2") ;;
  --packed-extra-module) packed_extra_modules+=("$2") ;;
  --file) files+=("$2") ;;
  --data-file) data_files+=("$2") ;;
  *)
    echo "make_initramfs.sh: unknown argument $1" >&2
    exit 2
    ;;
  esac
  shift 2
done
for name in out kernel busybox init; do
  if [ -z "${!name}" ]; then
    echo "make_initramfs.sh: --$name is required" >&2
    exit 2
  fi
done

root="$out.d"
rm -rf "$root"
mkdir -p "$root"/{bin,sbin,usr/bin,usr/sbin,dev,proc,sys,tmp,run,checks,etc}

# Copies the libraries FILE loads to the same paths under the root.
copy_libraries() {
  local file=$1 listing lib
  # ldd prints "name => /path (addr)" or "/path (addr)"; vdso has no path.
  # A static binary makes ldd exit 1 with "not a dynamic executable".
  if ! listing=$(LC_ALL=C ldd "$file" 2>&1); then
    grep -q 'not a dynamic executable' <<<"$listing" && return 0
    echo "make_initramfs.sh: ldd $file: $listing" >&2
    exit 1
  fi
  if grep -q 'not found' <<<"$listing"; then
    echo "make_initramfs.sh: $file: a library is missing:" >&2
    echo "$listing" >&2
    exit 1
  fi
  while read -r lib; do
    [ -e "$root$lib" ] || install -D -m 755 "$(readlink -f "$lib")" "$root$lib"
  done < <(grep -o '/[^ ]*' <<<"$listing")
}

install -m 755 "$busybox" "$root/bin/busybox"
copy_libraries "$busybox"
ln -s busybox "$root/bin/sh"
install -m 755 "$init" "$root/init"

# Modules: the kernel's own, found with the dependencies modprobe would load.
moddir="lib/modules/$kernel"
mkdir -p "$root/$moddir"
for module in "${modules[@]}" "${packed_modules[@]}"; do
  # "insmod PATH" per module to load, "builtin NAME" for built-in ones; an
  # unknown module fails the build here rather than the check in the guest.
  depends=$(modprobe -S "$kernel" --show-depends "$module")
  while read -r verb path _; do
    if [ "$verb" = insmod ]; then
      install -D -m 644 "$path" "$root$path"
    fi
  done <<<"$depends"
done
for module in "${extra_modules[@]}" "${packed_extra_modules[@]}"; do
  install -D -m 644 "$module" "$root/$moddir/extra/$(basename "$module")"
done
for file in modules.builtin modules.builtin.modinfo modules.order; do
  if [ -e "/$moddir/$file" ]; then
    cp "/$moddir/$file" "$root/$moddir/"
  fi
done
depmod -b "$root" "$kernel"
# The modules the init loads at boot, in order (dependencies come with them).
printf '%s\n' "${modules[@]}" "${extra_modules[@]##*/}" | sed 's/\.ko$//' >"$root/etc/lab-modules"

for check in "${checks[@]}"; do
  install -m 755 "$check" "$root/checks/$(basename "$check")"
done
printf '%s\n' "${checks[@]##*/}" >"$root/etc/lab-checks"
for program in "${programs[@]}"; do
  # Without its debug information (camhead's is most of its 80 MB): the
  # guest has no debugger, and a sanitizer's report there names functions
  # by their symbols, which stay.
  install -m 755 "$program" "$root/usr/bin/"
  objcopy --strip-debug "$root/usr/bin/$(basename "$program")"
  copy_libraries "$program"
done
for soname in "${libraries[@]}"; do
  # Where the dynamic loader would find it here; the guest looks in the same
  # place. awk reads to the end: an early exit would kill ldconfig with
  # SIGPIPE, which pipefail turns into a silent failure of this script.
  path=$(/sbin/ldconfig -p | awk -v name="$soname" '$1 == name && /x86-64/ && !found { print $NF; found = 1 }')
  if [ -z "$path" ]; then
    echo "make_initramfs.sh: --library $soname: not installed (ldconfig -p lists no such file)" >&2
    exit 1
  fi
  [ -e "$root$path" ] || install -D -m 755 "$(readlink -f "$path")" "$root$path"
  copy_libraries "$path"
done
for file in "${files[@]}"; do
  install -D -m "$(stat -L -c %a "$file")" "$(readlink -f "$file")" "$root$file"
  if [ "$(head -c 4 "$file" | tail -c 3)" = ELF ]; then
    copy_libraries "$file"
  fi
done
for file in "${data_files[@]}"; do
  install -D -m 644 "$file" "$root/etc/lab/$(basename "$file")"
done

# newc is the format the kernel unpacks; sorted names and fixed times keep
# the archive reproducible. gzip -1: the guest unpacks it under emulation.
find "$root" -exec touch -h -d @0 {} +
(cd "$root" && find . | LC_ALL=C sort | cpio -o -H newc -R 0:0 --quiet) | gzip -1 >"$out.tmp"
mv "$out.tmp" "$out"
rm -rf "$root"
