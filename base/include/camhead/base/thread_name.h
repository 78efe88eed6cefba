// Names the calling thread, as `top -H`, `ps -L`, gdb and the kernel's
// messages show it: "camhead-render" says which of camhead's threads is busy
// or stuck where a bare "camhead" does not. Linux keeps 15 characters; a
// longer name is cut. A thread that cannot be named keeps its name: the name
// helps a person, nothing depends on it.
#pragma once

#include <cstddef>

#include <pthread.h>

namespace camhead::base {

inline void name_this_thread(const char *name) {
  char cut[16] = {};
  for (std::size_t i = 0; i + 1 < sizeof cut && name[i] != '\0'; ++i)
    cut[i] = name[i];
  static_cast<void>(pthread_setname_np(pthread_self(), cut));
}

} // namespace camhead::base
