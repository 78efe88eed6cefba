// See shared_library.h.
#include "camhead/hal/shared_library.h"

#include <cstdio>
#include <cstdlib>
#include <utility>

#include <dlfcn.h>

namespace camhead::hal {
namespace {

std::string last_dl_error() {
  const char *text = dlerror();
  return text != nullptr ? text : "unknown error";
}

} // namespace

SharedLibrary::SharedLibrary(std::string soname, std::string debian_package)
    : soname_(std::move(soname)), package_(std::move(debian_package)) {
  // RTLD_LOCAL: the library's symbols serve this table only and cannot
  // interpose on anything else in the process.
  handle_ = dlopen(soname_.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle_ == nullptr) {
    error_ = soname_ + " (Debian package " + package_ + ") cannot be loaded: " + last_dl_error();
  }
}

SharedLibrary::~SharedLibrary() {
  if (handle_ != nullptr) {
    dlclose(handle_);
  }
}

void *SharedLibrary::find(const char *symbol) {
  if (handle_ == nullptr) {
    return nullptr;
  }
  dlerror(); // clear an earlier message, so that the one below is this lookup's
  void *address = dlsym(handle_, symbol);
  if (address == nullptr && error_.empty()) {
    error_ = soname_ + " (Debian package " + package_ + ") has no " + symbol +
             ": another version than camhead was built for? " + last_dl_error();
  }
  return address;
}

void abort_unloaded_library(const std::string &error) {
  std::fprintf(stderr, "camhead: a device library was called although it did not load: %s\n",
               error.c_str());
  std::abort();
}

} // namespace camhead::hal
