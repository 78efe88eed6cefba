#!/bin/sh
# Guest: the GPIO quadrature backend on a gpio-sim chip (camhead_gpio_vm_check).
exec camhead_gpio_vm_check
