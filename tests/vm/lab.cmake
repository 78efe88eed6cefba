# Builds the lab's initramfs from what camhead_vm_check() collected and
# registers vm.boot, the fixture that the vm.<result> tests read.
# Included at the end of tests/vm/CMakeLists.txt.

# --- What the machine has -------------------------------------------------------
# The kernel the lab boots must be Debian's (the container's own kernel has no
# image in /boot): the newest /boot/vmlinuz-K with modules and headers for K.
set(CAMHEAD_VM_KERNEL "" CACHE STRING
  "Kernel release the hardware lab boots (empty: the newest /boot/vmlinuz-* with modules and headers)")
set(vm_missing)
# The guest runs this machine's own binaries and kernel.
if(NOT CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  list(APPEND vm_missing "an x86_64 host (the guest runs this machine's kernel and binaries)")
endif()
set(vm_kernel "${CAMHEAD_VM_KERNEL}")
if(NOT vm_kernel)
  file(GLOB vm_images /boot/vmlinuz-*)
  set(vm_releases)
  foreach(image IN LISTS vm_images)
    string(REGEX REPLACE "^/boot/vmlinuz-" "" release "${image}")
    if(EXISTS /lib/modules/${release}/modules.dep AND EXISTS /usr/src/linux-headers-${release}/Makefile)
      list(APPEND vm_releases ${release})
    endif()
  endforeach()
  if(vm_releases)
    list(SORT vm_releases COMPARE NATURAL ORDER DESCENDING)
    list(GET vm_releases 0 vm_kernel)
  elseif(vm_images)
    list(APPEND vm_missing "modules and headers matching a /boot/vmlinuz-* (linux-image-amd64, linux-headers-amd64)")
  else()
    list(APPEND vm_missing "a kernel image in /boot (linux-image-amd64)")
  endif()
endif()
if(vm_kernel)
  string(REGEX MATCH "^[0-9]+\\.[0-9]+" vm_series "${vm_kernel}")
  set(vm_kernel_source /usr/src/linux-source-${vm_series}.tar.xz)
  set(vm_headers /usr/src/linux-headers-${vm_kernel})
  foreach(path /boot/vmlinuz-${vm_kernel} /lib/modules/${vm_kernel}/modules.dep ${vm_headers}/Makefile)
    if(NOT EXISTS ${path})
      list(APPEND vm_missing "${path}")
    endif()
  endforeach()
  if(NOT EXISTS ${vm_kernel_source})
    list(APPEND vm_missing "${vm_kernel_source} (linux-source-${vm_series})")
  endif()
endif()

# v4l2loopback's source, from Debian's v4l2loopback-dkms (the newest
# /usr/src/v4l2loopback-VERSION). Optional: without it the lab runs and the
# vm.v4l2_loopback_* results skip, saying what to install.
file(GLOB vm_v4l2loopback_sources /usr/src/v4l2loopback-*/v4l2loopback.c)
set(vm_v4l2loopback_source "")
if(vm_v4l2loopback_sources)
  list(SORT vm_v4l2loopback_sources COMPARE NATURAL ORDER DESCENDING)
  list(GET vm_v4l2loopback_sources 0 vm_v4l2loopback_c)
  get_filename_component(vm_v4l2loopback_source ${vm_v4l2loopback_c} DIRECTORY)
endif()

# Tools (tool:package); sbin is searched too, where a non-root PATH leaves it out.
foreach(pair qemu-system-x86_64:qemu-system-x86 busybox:busybox-static cpio:cpio gzip:gzip
    depmod:kmod modprobe:kmod make:make xz:xz-utils)
  string(REPLACE ":" ";" pair "${pair}")
  list(GET pair 0 tool)
  list(GET pair 1 package)
  string(MAKE_C_IDENTIFIER "CAMHEAD_VM_${tool}" var)
  string(TOUPPER ${var} var)
  find_program(${var} ${tool} PATHS /usr/sbin /sbin)
  if(NOT ${var})
    list(APPEND vm_missing "${tool} (${package})")
  endif()
endforeach()
# The host side of the display checks (screen_helper.py: QEMU monitor
# screendumps). Optional: without it only the vm.drm_* screen results skip.
# Debian's own first (clang-format depends on it), not a virtualenv's.
find_program(CAMHEAD_VM_PYTHON3 python3 PATHS /usr/bin NO_DEFAULT_PATH)
find_program(CAMHEAD_VM_PYTHON3 python3)
set(vm_screen_args)
if(CAMHEAD_VM_PYTHON3)
  set(vm_screen_args --python3 ${CAMHEAD_VM_PYTHON3}
    --screen-helper ${CMAKE_CURRENT_SOURCE_DIR}/screen_helper.py)
endif()

# --- vm.boot: boots once, leaves lab/results.txt; skips (77) where it cannot --
set(lab_dir ${vm_lab_dir})
get_property(vm_scripts DIRECTORY PROPERTY vm_scripts)
get_property(vm_results DIRECTORY PROPERTY vm_results)
get_property(vm_programs DIRECTORY PROPERTY vm_programs)
get_property(vm_modules DIRECTORY PROPERTY vm_modules)
get_property(vm_packed_modules DIRECTORY PROPERTY vm_packed_modules)
get_property(vm_libraries DIRECTORY PROPERTY vm_libraries)
get_property(vm_files DIRECTORY PROPERTY vm_files)
get_property(vm_data_files DIRECTORY PROPERTY vm_data_files)

if(vm_missing)
  list(JOIN vm_missing ", " missing_text)
  message(STATUS "Hardware lab (tests/vm): vm.* tests will skip, missing: ${missing_text}")
  set(skip_message "hardware lab skipped: missing ${missing_text} (cmake/bootstrap.sh installs the packages)")
  add_test(NAME vm.boot COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/run_lab.sh
    --skip "${skip_message}" --out-dir ${lab_dir})
else()
  message(STATUS "Hardware lab (tests/vm): kernel ${vm_kernel}")
  if(NOT vm_v4l2loopback_source)
    message(STATUS "Hardware lab (tests/vm): vm.v4l2_loopback_* will skip, missing "
      "/usr/src/v4l2loopback-* (v4l2loopback-dkms)")
  endif()
  list(JOIN vm_results " " expect_text)
  add_test(NAME vm.boot COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/run_lab.sh
    --qemu ${CAMHEAD_VM_QEMU_SYSTEM_X86_64} --kernel /boot/vmlinuz-${vm_kernel}
    --initrd ${lab_dir}/initramfs.cpio.gz --out-dir ${lab_dir} --timeout 480
    --expect "${expect_text}" ${vm_screen_args})
  if(NOT CAMHEAD_VM_PYTHON3)
    message(STATUS "Hardware lab (tests/vm): the vm.drm_* screendump results will skip, "
      "missing python3")
  endif()
endif()
# Boot and checks take ~3 min on an idle 2-core machine, most of it the four
# 100-cycle fault loops (~1 min built with the sanitizers, which run 10);
# TCG on a loaded CI machine can take longer. The guest gives each check
# script 240 s; run_lab.sh stops qemu itself at 480 s and then reports the
# console. RUN_SERIAL: the guest is one emulated CPU, and the fault loops
# hold frame times (usb_replug_100: no camera frame missed at 10 fps, its
# worst composite near the 100-ms interval on an idle host); beside a
# two-threaded renderer test on the other core that guest ran slow enough to
# miss frames. COST: started first, alone, rather than waiting at the end.
set_tests_properties(vm.boot PROPERTIES FIXTURES_SETUP camhead_vm_lab SKIP_RETURN_CODE 77
  TIMEOUT 540 LABELS vm COST 180 RUN_SERIAL TRUE)

if(vm_missing)
  return()
endif()

# --- The lab's build -----------------------------------------------------------
# gpio-sim.ko: three files of Debian's kernel source, patched at build time.
add_custom_command(OUTPUT ${lab_dir}/gpio-sim/gpio-sim.ko
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/build_gpio_sim.sh
    ${vm_kernel_source} ${vm_headers} ${lab_dir}/gpio-sim
  DEPENDS build_gpio_sim.sh ${vm_kernel_source} ${vm_headers}/Makefile
  COMMENT "Building gpio-sim.ko for ${vm_kernel} out of tree"
  VERBATIM)

# v4l2loopback.ko: Debian's DKMS source, built here (~3 s), loaded by its check.
set(vm_extra_depends)
set(vm_args)
if(vm_v4l2loopback_source)
  add_custom_command(OUTPUT ${lab_dir}/v4l2loopback/v4l2loopback.ko
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/build_v4l2loopback.sh
      ${vm_v4l2loopback_source} ${vm_headers} ${lab_dir}/v4l2loopback
    DEPENDS build_v4l2loopback.sh ${vm_v4l2loopback_source}/v4l2loopback.c
      ${vm_headers}/Makefile
    COMMENT "Building v4l2loopback.ko for ${vm_kernel} out of tree"
    VERBATIM)
  list(APPEND vm_extra_depends ${lab_dir}/v4l2loopback/v4l2loopback.ko)
  list(APPEND vm_args --packed-extra-module ${lab_dir}/v4l2loopback/v4l2loopback.ko)
endif()

# vimc.ko: its folder of Debian's kernel source, built here (~10 s), loaded
# by the libcamera check; only where that check has its program
# (vm_build_vimc, CMakeLists.txt).
if(vm_build_vimc)
  add_custom_command(OUTPUT ${lab_dir}/vimc/vimc.ko
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/build_vimc.sh
      ${vm_kernel_source} ${vm_headers} ${lab_dir}/vimc
    DEPENDS build_vimc.sh ${vm_kernel_source} ${vm_headers}/Makefile
    COMMENT "Building vimc.ko for ${vm_kernel} out of tree"
    VERBATIM)
  list(APPEND vm_extra_depends ${lab_dir}/vimc/vimc.ko)
  list(APPEND vm_args --packed-extra-module ${lab_dir}/vimc/vimc.ko)
endif()

list(REMOVE_DUPLICATES vm_modules)
foreach(module configfs ${vm_modules})
  list(APPEND vm_args --module ${module})
endforeach()
if(vm_packed_modules)
  list(REMOVE_DUPLICATES vm_packed_modules)
endif()
foreach(module IN LISTS vm_packed_modules)
  list(APPEND vm_args --packed-module ${module})
endforeach()
foreach(script IN LISTS vm_scripts)
  list(APPEND vm_args --check ${script})
endforeach()
foreach(program IN LISTS vm_programs)
  list(APPEND vm_args --program $<TARGET_FILE:${program}>)
endforeach()
list(REMOVE_DUPLICATES vm_libraries)
foreach(library IN LISTS vm_libraries)
  list(APPEND vm_args --library ${library})
endforeach()
if(vm_files)
  list(REMOVE_DUPLICATES vm_files)
endif()
foreach(file IN LISTS vm_files)
  list(APPEND vm_args --file ${file})
endforeach()
list(APPEND vm_extra_depends ${vm_files})
foreach(file IN LISTS vm_data_files)
  list(APPEND vm_args --data-file ${file})
endforeach()
list(APPEND vm_extra_depends ${vm_data_files})
add_custom_command(OUTPUT ${lab_dir}/initramfs.cpio.gz
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/make_initramfs.sh
    --out ${lab_dir}/initramfs.cpio.gz --kernel ${vm_kernel}
    --busybox ${CAMHEAD_VM_BUSYBOX} --init ${CMAKE_CURRENT_SOURCE_DIR}/guest_init.sh
    --extra-module ${lab_dir}/gpio-sim/gpio-sim.ko ${vm_args}
  DEPENDS make_initramfs.sh guest_init.sh ${vm_scripts} ${vm_programs}
    ${lab_dir}/gpio-sim/gpio-sim.ko ${vm_extra_depends} /lib/modules/${vm_kernel}/modules.dep
    ${CAMHEAD_VM_BUSYBOX}
  COMMENT "Packing the hardware lab's initramfs"
  VERBATIM)
add_custom_target(camhead_vm_lab ALL DEPENDS ${lab_dir}/initramfs.cpio.gz)
